//! Normal contact models: linear spring-dashpot, Hertz with viscoelastic damping, Thornton elasto-plastic.
//!
//! Each variant holds typed parameters; material constants (E*, F_y) come from the pair table. A kernel returns the
//! scalar normal force on particle i along the unit normal n (positive = repulsive) together with what the
//! tangential slot needs (contact radius, elastic tangential stiffness and damping), so slots never share mutable
//! state. Velocities: `normal_velocity_m_per_s` = (v_i − v_j)·n, negative while the particles approach.

use serde::{Deserialize, Serialize};

use super::history::NormalHistory;
use super::pair_table::PairMaterial;

/// √(5/6), from the Tsuji/LIGGGHTS viscoelastic damping coefficient.
pub(super) const SQRT_FIVE_SIXTHS: f64 = 0.912_870_929_175_276_8;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum NormalModel {
    /// F_n = K_n δ − η_n v_n (seed 001 eq. 6.16 with the dissipative sign of its Appendix B; seed 002 eq. 21).
    LinearSpringDashpot {
        stiffness_n_per_m: f64,
        damping_kg_per_s: f64,
    },
    /// Hertz F_n = (4/3) E* √(R* δ) δ with the viscoelastic damping of Tsuji et al. as in LIGGGHTS
    /// `model hertz`: γ_n = 2 √(5/6) |β| √(S_n m*), S_n = 2 E* √(R* δ), β = ln e / √(ln² e + π²).
    Hertz { restitution: f64 },
    /// Thornton elasto-plastic (seed 000 eqs. 2.3–2.9): Hertz up to F_y, linear plastic loading, Hertzian unloading
    /// with the enlarged radius of curvature R' = R̄ R*.
    Thornton {
        #[serde(default)]
        plastic_slope: PlasticSlope,
    },
}

/// Slope k_y of Thornton's plastic loading branch, as a multiple of F_y/α_y.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PlasticSlope {
    /// k_y = (3/2) F_y/α_y = π p_y R*: Thornton's (1997) perfectly plastic slope, continuous with the Hertz slope at
    /// yield. Thornton's analytical restitution curve (VALIDATION A3) assumes it. Default.
    #[default]
    Continuous,
    /// k_y = (2/3) F_y/α_y, as printed under seed 000 eq. (2.7). Kinks the loading curve at yield.
    SeedPrinted,
}

/// What the normal slot passes to the tangential and rolling slots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalOutput {
    /// Total normal force on i along n (elastic + damping), N. May be negative (damping while separating).
    pub force_n: f64,
    /// Contact radius a (m); √(R* δ) for the Hertzian models, 0 for the linear model.
    pub contact_radius_m: f64,
    /// Viscous normal damping coefficient γ_n of the Hertz model (kg/s); 0 for the others.
    pub viscoelastic_damping_kg_per_s: f64,
}

/// The restitution coefficient of a linear spring–dashpot (seed 001 App. B): e = exp(−πα/√(1 − α²)) with
/// α = η/(2√(μK)), μ the reduced mass.
pub fn linear_spring_restitution(stiffness_n_per_m: f64, damping_kg_per_s: f64, reduced_mass_kg: f64) -> f64 {
    let alpha = damping_kg_per_s / (2.0 * (reduced_mass_kg * stiffness_n_per_m).sqrt());
    (-std::f64::consts::PI * alpha / (1.0 - alpha * alpha).sqrt()).exp()
}

impl NormalModel {
    /// Checks the law's own parameters: `Err((key under contact.normal, what was expected))`.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        let positive = |key, v: f64| {
            (v.is_finite() && v > 0.0)
                .then_some(())
                .ok_or((key, format!("expected a finite value > 0, got {v}")))
        };
        let non_negative = |key, v: f64| {
            (v.is_finite() && v >= 0.0)
                .then_some(())
                .ok_or((key, format!("expected a finite value >= 0, got {v}")))
        };
        match *self {
            NormalModel::LinearSpringDashpot {
                stiffness_n_per_m,
                damping_kg_per_s,
            } => {
                positive("linear_spring_dashpot.stiffness_n_per_m", stiffness_n_per_m)?;
                non_negative("linear_spring_dashpot.damping_kg_per_s", damping_kg_per_s)
            }
            NormalModel::Hertz { restitution } => (restitution.is_finite() && restitution > 0.0 && restitution <= 1.0)
                .then_some(())
                .ok_or(("hertz.restitution", format!("expected 0 < e <= 1, got {restitution}"))),
            NormalModel::Thornton { .. } => Ok(()),
        }
    }

    /// The elastic energy stored in a contact of overlap δ (the work of the elastic force from 0 to δ), J: ½kδ² for
    /// the linear spring, (8/15) E* √R* δ^{5/2} for the Hertzian laws (Thornton's plastic part not counted).
    pub fn elastic_energy_j(&self, mat: &PairMaterial, effective_radius_m: f64, overlap_m: f64) -> f64 {
        match *self {
            NormalModel::LinearSpringDashpot { stiffness_n_per_m, .. } => {
                0.5 * stiffness_n_per_m * overlap_m * overlap_m
            }
            NormalModel::Hertz { .. } | NormalModel::Thornton { .. } => {
                8.0 / 15.0 * mat.effective_youngs_modulus_pa * effective_radius_m.sqrt() * overlap_m.powf(2.5)
            }
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            NormalModel::LinearSpringDashpot { .. } => "linear_spring_dashpot",
            NormalModel::Hertz { .. } => "hertz",
            NormalModel::Thornton { .. } => "thornton",
        }
    }

    /// Normal force for overlap `overlap_m` > 0. Updates the Thornton history (α_max, F_max, yielded).
    #[inline(always)]
    pub fn force(
        &self,
        mat: &PairMaterial,
        effective_radius_m: f64,
        effective_mass_kg: f64,
        overlap_m: f64,
        normal_velocity_m_per_s: f64,
        hist: &mut NormalHistory,
    ) -> NormalOutput {
        match *self {
            NormalModel::LinearSpringDashpot {
                stiffness_n_per_m,
                damping_kg_per_s,
            } => NormalOutput {
                force_n: stiffness_n_per_m * overlap_m - damping_kg_per_s * normal_velocity_m_per_s,
                contact_radius_m: 0.0,
                viscoelastic_damping_kg_per_s: 0.0,
            },
            NormalModel::Hertz { .. } => {
                // Ordered for the latency of the chain of dependent operations from δ to F_n, which sets the force
                // loop's speed: k_n δ = a (4/3 E* δ) and γ_n = √(F m* a) with F = (2√(5/6) β)² 2E* from the pair
                // table.
                let contact_radius = (effective_radius_m * overlap_m).sqrt();
                let elastic_per_a = 4.0 / 3.0 * mat.effective_youngs_modulus_pa * overlap_m;
                let gamma_n = (mat.hertz_damping_factor_pa * effective_mass_kg * contact_radius).sqrt();
                NormalOutput {
                    force_n: (-gamma_n).mul_add(normal_velocity_m_per_s, contact_radius * elastic_per_a),
                    contact_radius_m: contact_radius,
                    viscoelastic_damping_kg_per_s: gamma_n,
                }
            }
            NormalModel::Thornton { plastic_slope } => NormalOutput {
                force_n: thornton_force(
                    mat.effective_youngs_modulus_pa,
                    effective_radius_m,
                    mat.yield_force_n,
                    plastic_slope,
                    overlap_m,
                    hist,
                ),
                contact_radius_m: (effective_radius_m * overlap_m).sqrt(),
                viscoelastic_damping_kg_per_s: 0.0,
            },
        }
    }

    /// Duration of a head-on collision at relative speed `impact_velocity_m_per_s`, for choosing the time step.
    /// Linear: t_c = π/q (seed 001 App. B). Hertz and Thornton: the elastic Hertz duration
    /// 2.87 (m*²/(R* E*² v))^{1/5} (Johnson 1985), a lower bound for Thornton (plastic contacts last longer).
    pub fn contact_time_s(
        &self,
        mat: &PairMaterial,
        effective_radius_m: f64,
        effective_mass_kg: f64,
        impact_velocity_m_per_s: f64,
    ) -> f64 {
        match *self {
            NormalModel::LinearSpringDashpot {
                stiffness_n_per_m,
                damping_kg_per_s,
            } => {
                let omega0_sq = stiffness_n_per_m / effective_mass_kg;
                let decay = damping_kg_per_s / (2.0 * effective_mass_kg);
                std::f64::consts::PI / (omega0_sq - decay * decay).sqrt()
            }
            NormalModel::Hertz { .. } | NormalModel::Thornton { .. } => {
                let e = mat.effective_youngs_modulus_pa;
                2.87 * (effective_mass_kg.powi(2) / (effective_radius_m * e * e * impact_velocity_m_per_s)).powf(0.2)
            }
        }
    }
}

/// |β| = |ln e| / √(ln² e + π²), the damping ratio that yields restitution e for a Hertz-Kelvin contact (LIGGGHTS).
#[inline]
pub fn damping_beta(restitution: f64) -> f64 {
    let ln_e = restitution.ln();
    -ln_e / (ln_e * ln_e + std::f64::consts::PI.powi(2)).sqrt()
}

/// Thornton elasto-plastic normal force (seed 000 eqs. 2.3–2.9; Thornton, J. Appl. Mech. 64, 1997).
///
/// Loading (δ ≥ α_max): Hertz F = k_n δ^{3/2}, k_n = (4/3) E* √R* (2.3–2.4), until F reaches F_y at α_y; then
/// F = F_y + k_y (δ − α_y) (2.7). Unloading and reloading below α_max after yield follow the Hertz curve of the
/// flattened contact, F = k_n √R̄ (δ − α_p)^{3/2}, R̄ = (F_y/F_max) ((2F_max + F_y)/(3F_y))^{3/2} (2.9), with the
/// residual overlap α_p fixed by F = F_max at α_max.
///
/// CHOICE: seed 000 prints the unloading branch (2.8) as F_max − k_n √R̄ (α_max − δ)^{3/2}. That curve has the
/// same end points but zero slope at α_max, returns 3/5 instead of 2/5 of F_max (α_max − α_p) and does not give
/// Thornton's restitution curve, which the thesis cites [30]; we use Thornton's form (the extraction scrambled it).
pub fn thornton_force(
    effective_youngs_modulus_pa: f64,
    effective_radius_m: f64,
    yield_force_n: f64,
    plastic_slope: PlasticSlope,
    overlap_m: f64,
    hist: &mut NormalHistory,
) -> f64 {
    let kn = 4.0 / 3.0 * effective_youngs_modulus_pa * effective_radius_m.sqrt();
    if overlap_m >= hist.max_overlap_m {
        // Loading beyond every earlier overlap: on the virgin curve.
        let hertz = kn * overlap_m * overlap_m.sqrt();
        let force = if hertz <= yield_force_n {
            hertz
        } else {
            let yield_overlap = (yield_force_n / kn).powf(2.0 / 3.0);
            let slope = match plastic_slope {
                PlasticSlope::Continuous => 1.5 * yield_force_n / yield_overlap,
                PlasticSlope::SeedPrinted => 2.0 / 3.0 * yield_force_n / yield_overlap,
            };
            hist.yielded = true;
            yield_force_n + slope * (overlap_m - yield_overlap)
        };
        hist.max_overlap_m = overlap_m;
        hist.max_normal_force_n = force;
        force
    } else if !hist.yielded {
        // Elastic unloading before yield retraces the Hertz curve.
        kn * overlap_m * overlap_m.sqrt()
    } else {
        let f_max = hist.max_normal_force_n;
        let r_bar = (yield_force_n / f_max) * ((2.0 * f_max + yield_force_n) / (3.0 * yield_force_n)).powf(1.5);
        let k_unload = kn * r_bar.sqrt();
        let plastic_overlap = hist.max_overlap_m - (f_max / k_unload).powf(2.0 / 3.0);
        let elastic = overlap_m - plastic_overlap;
        if elastic > 0.0 {
            k_unload * elastic * elastic.sqrt()
        } else {
            0.0
        }
    }
}

/// Thornton's (1997) analytical coefficient of restitution for an elastic-perfectly-plastic sphere impact at
/// `impact_velocity` above the yield velocity `yield_velocity` (1 below it).
pub fn thornton_restitution(impact_velocity: f64, yield_velocity: f64) -> f64 {
    if impact_velocity <= yield_velocity {
        return 1.0;
    }
    let r = yield_velocity / impact_velocity;
    (6.0 * 3f64.sqrt() / 5.0).sqrt()
        * (1.0 - r * r / 6.0).sqrt()
        * (r / (r + 2.0 * (6.0 / 5.0 - r * r / 5.0).sqrt())).powf(0.25)
}

/// Relative impact speed at which a Thornton contact just reaches F_y: ½ m* V_y² = (2/5) k_n α_y^{5/2}.
pub fn thornton_yield_velocity(
    effective_youngs_modulus_pa: f64,
    effective_radius_m: f64,
    effective_mass_kg: f64,
    yield_force_n: f64,
) -> f64 {
    let kn = 4.0 / 3.0 * effective_youngs_modulus_pa * effective_radius_m.sqrt();
    let yield_overlap = (yield_force_n / kn).powf(2.0 / 3.0);
    (0.8 * kn * yield_overlap.powf(2.5) / effective_mass_kg).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel_like() -> PairMaterial {
        PairMaterial {
            effective_youngs_modulus_pa: 1e8,
            effective_shear_modulus_pa: 4e7,
            friction_coefficient: 0.3,
            yield_force_n: 0.5,
            rolling_friction_coefficient: 0.0,
            hertz_damping_factor_pa: 0.0,
            tangential_damping_ratio: 1.0,
        }
    }

    #[test]
    fn thornton_is_hertz_below_yield_and_continuous_at_yield() {
        let mat = steel_like();
        let r: f64 = 1e-3;
        let kn = 4.0 / 3.0 * mat.effective_youngs_modulus_pa * r.sqrt();
        let ay = (mat.yield_force_n / kn).powf(2.0 / 3.0);
        let mut h = NormalHistory::default();
        let below = thornton_force(
            mat.effective_youngs_modulus_pa,
            r,
            mat.yield_force_n,
            PlasticSlope::Continuous,
            0.5 * ay,
            &mut h,
        );
        assert!((below - kn * (0.5 * ay).powf(1.5)).abs() < 1e-12 * below);
        assert!(!h.yielded);
        let just_above = thornton_force(
            mat.effective_youngs_modulus_pa,
            r,
            mat.yield_force_n,
            PlasticSlope::Continuous,
            ay * (1.0 + 1e-9),
            &mut h,
        );
        assert!((just_above - mat.yield_force_n).abs() < 1e-6 * mat.yield_force_n);
        assert!(h.yielded);
    }

    #[test]
    fn thornton_unloading_passes_through_max_and_leaves_plastic_overlap() {
        let mat = steel_like();
        let r: f64 = 1e-3;
        let mut h = NormalHistory::default();
        let kn = 4.0 / 3.0 * mat.effective_youngs_modulus_pa * r.sqrt();
        let ay = (mat.yield_force_n / kn).powf(2.0 / 3.0);
        let amax = 3.0 * ay;
        let fmax = thornton_force(
            mat.effective_youngs_modulus_pa,
            r,
            mat.yield_force_n,
            PlasticSlope::Continuous,
            amax,
            &mut h,
        );
        let f_back = thornton_force(
            mat.effective_youngs_modulus_pa,
            r,
            mat.yield_force_n,
            PlasticSlope::Continuous,
            amax * (1.0 - 1e-12),
            &mut h,
        );
        assert!((f_back - fmax).abs() < 1e-6 * fmax, "{f_back} vs {fmax}");
        // Residual plastic overlap: zero force at a positive overlap.
        let f_small = thornton_force(
            mat.effective_youngs_modulus_pa,
            r,
            mat.yield_force_n,
            PlasticSlope::Continuous,
            0.3 * ay,
            &mut h,
        );
        assert_eq!(f_small, 0.0);
    }

    #[test]
    fn thornton_restitution_is_one_at_yield_and_falls() {
        assert!((thornton_restitution(1.0, 1.0) - 1.0).abs() < 1e-12);
        let e2 = thornton_restitution(2.0, 1.0);
        let e10 = thornton_restitution(10.0, 1.0);
        assert!(e2 < 1.0 && e10 < e2);
    }

    #[test]
    fn damping_beta_vanishes_for_elastic() {
        assert_eq!(damping_beta(1.0), 0.0);
        assert!(damping_beta(0.5) > 0.0);
    }
}
