//! Tangential (friction) contact models: linear spring with Coulomb limit, Hertz-Mindlin with history,
//! Walton-Braun.
//!
//! A kernel receives the normal slot's output and the tangential relative velocity at the contact point, updates the
//! contact's tangential history and returns the tangential force on particle i. Torques are formed by the caller
//! from the lever arms, so the kernels know nothing about particle radii beyond R*.

use serde::{Deserialize, Serialize};

use super::history::{TangentialHistory, rotate_into_tangent_plane};
use super::normal::NormalOutput;
use super::pair_table::PairMaterial;
use crate::engine::Vec3;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum TangentialModel {
    /// Linear spring on the accumulated elastic displacement u_t with a dashpot, truncated at μF_n
    /// (seed 001 eqs. 6.20–6.24, seed 002 eqs. 20–22; the Cundall-Strack/Silbert form).
    LinearSpringCoulomb {
        stiffness_n_per_m: f64,
        damping_kg_per_s: f64,
    },
    /// Seed 001 eqs. 6.20–6.24 read literally: the spring acts on this step's displacement only, δ_t = Δt v_t
    /// (eq. 6.24), not on one accumulated over the contact. The force is then a dashpot, −(K_t Δt + η_t) v_t,
    /// truncated at μF_n: there is no static friction, and friction acts only while the surfaces slide. The
    /// extraction leaves open whether the thesis accumulated δ_t; this model is the other reading, for probes.
    LinearStepSpringCoulomb {
        stiffness_n_per_m: f64,
        damping_kg_per_s: f64,
    },
    /// Mindlin no-slip stiffness k_t = 8 G* a on the accumulated displacement, viscoelastic damping with the normal
    /// model's restitution, truncated at μF_n: LIGGGHTS `tangential history`. Requires a Hertzian normal model.
    Mindlin,
    /// Walton-Braun (seed 000 eqs. 2.10–2.13): incremental F_t = F_t,old − k_t Δs with the micro-slip stiffness
    /// k_t = k_t0 (1 − (T − T*)/(μF_n − T*))^γ, T measured along the increment's direction.
    WaltonBraun {
        #[serde(default = "default_walton_braun_exponent")]
        exponent: f64,
    },
}

fn default_walton_braun_exponent() -> f64 {
    1.0 / 3.0
}

impl TangentialModel {
    pub fn name(&self) -> &'static str {
        match self {
            TangentialModel::LinearSpringCoulomb { .. } => "linear_spring_coulomb",
            TangentialModel::LinearStepSpringCoulomb { .. } => "linear_step_spring_coulomb",
            TangentialModel::Mindlin => "mindlin",
            TangentialModel::WaltonBraun { .. } => "walton_braun",
        }
    }

    /// Tangential force on i. `tangential_velocity` is the relative velocity of i's contact point with respect to
    /// j's, projected on the tangent plane (normal `n`).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn force(
        &self,
        mat: &PairMaterial,
        normal: &NormalOutput,
        n: &Vec3,
        tangential_velocity: &Vec3,
        dt_s: f64,
        hist: &mut TangentialHistory,
    ) -> Vec3 {
        // CHOICE: friction acts only while the normal force is compressive (a damping-induced tensile normal force
        // at separation gives no friction). LIGGGHTS uses |F_n|; the difference is confined to the last steps of
        // a contact.
        let limit = mat.friction_coefficient * normal.force_n.max(0.0);
        match *self {
            TangentialModel::LinearSpringCoulomb {
                stiffness_n_per_m,
                damping_kg_per_s,
            } => spring_with_coulomb_limit(
                stiffness_n_per_m,
                tangential_velocity * damping_kg_per_s,
                limit,
                n,
                tangential_velocity,
                dt_s,
                hist,
            ),
            TangentialModel::LinearStepSpringCoulomb {
                stiffness_n_per_m,
                damping_kg_per_s,
            } => {
                // No accumulated displacement: the spring starts from zero every step, and keeps none. A separate
                // arm, not an or-pattern with the one above and a flag: that changed the code generation of the
                // whole force loop (+2.2 % instructions in `bench dem --steps 2000`, Hertz-Mindlin, callgrind).
                hist.shear = Vec3::zeros();
                let force = spring_with_coulomb_limit(
                    stiffness_n_per_m,
                    tangential_velocity * damping_kg_per_s,
                    limit,
                    n,
                    tangential_velocity,
                    dt_s,
                    hist,
                );
                hist.shear = Vec3::zeros();
                force
            }
            TangentialModel::Mindlin => {
                let kt = 8.0 * mat.effective_shear_modulus_pa * normal.contact_radius_m;
                // γ_t = 2√(5/6) β √(k_t m*) = γ_n √(k_t/S_n) (LIGGGHTS), with √(k_t/S_n) = √(4G*/E*) per pair.
                // The dashpot force γ_t v_t is formed as (v_t √(k_t/S_n)) γ_n: γ_n comes last in the chain of
                // dependent operations that sets the force loop's speed, so it gets one multiplication, not two.
                let viscous =
                    (tangential_velocity * mat.tangential_damping_ratio) * normal.viscoelastic_damping_kg_per_s;
                spring_with_coulomb_limit(kt, viscous, limit, n, tangential_velocity, dt_s, hist)
            }
            TangentialModel::WaltonBraun { exponent } => {
                // CHOICE: k_t0 = k_n (1−ν)/(1−ν/2) (2.13) with k_n the current Hertz tangent stiffness
                // dF_n/dα = 2 E* a (PHYSICS §1), generalised to unlike materials as 8 G* a = (4G*/E*) 2E*a, which
                // equals (2.13) for like materials.
                let kt0 = 8.0 * mat.effective_shear_modulus_pa * normal.contact_radius_m;
                walton_braun(kt0, exponent, limit, n, tangential_velocity, dt_s, hist)
            }
        }
    }
}

/// Elastic displacement spring with a dashpot (whose force is `viscous` = γ_t v_t), truncated to the Coulomb limit.
#[inline]
fn spring_with_coulomb_limit(
    stiffness: f64,
    viscous: Vec3,
    limit: f64,
    n: &Vec3,
    tangential_velocity: &Vec3,
    dt_s: f64,
    hist: &mut TangentialHistory,
) -> Vec3 {
    let displacement = rotate_into_tangent_plane(hist.shear, n) + tangential_velocity * dt_s;
    let trial = -(displacement * stiffness) - viscous;
    let trial_mag2 = trial.norm_squared();
    if trial_mag2 > limit * limit {
        // Sliding: the force sits on the Coulomb limit and the spring is reset to what that force implies
        // (Cundall-Strack; LAMMPS granular).
        let force = trial * (limit / trial_mag2.sqrt());
        hist.shear = if stiffness > 0.0 {
            -(force + viscous) / stiffness
        } else {
            Vec3::zeros()
        };
        force
    } else {
        hist.shear = displacement;
        trial
    }
}

/// Walton-Braun incremental friction (seed 000 eqs. 2.10–2.12, after Walton's implementation).
///
/// In three dimensions the scalar of (2.11–2.12) is the component of the force along the direction of the current
/// increment, T = F_t·d with d = −Δs/|Δs|, and T* = F_t*·d with F_t* the force when the increment direction last
/// reversed (d·d_old < 0). In one dimension this reproduces both (2.11) (increasing) and (2.12) (decreasing)
/// exactly. The stored F_t, F_t* rotate with the contact plane.
#[inline]
fn walton_braun(
    initial_stiffness: f64,
    exponent: f64,
    limit: f64,
    n: &Vec3,
    tangential_velocity: &Vec3,
    dt_s: f64,
    hist: &mut TangentialHistory,
) -> Vec3 {
    let mut force = rotate_into_tangent_plane(hist.shear, n);
    let mut reversal = rotate_into_tangent_plane(hist.reversal_force_n, n);
    let slip = tangential_velocity * dt_s;
    let slip_mag = slip.norm();
    if slip_mag > 0.0 {
        let direction = -slip / slip_mag;
        if direction.dot(&hist.increment_direction) < 0.0 {
            reversal = force;
        }
        hist.increment_direction = direction;
        let t = force.dot(&direction);
        let t_star = reversal.dot(&direction);
        let span = limit - t_star;
        let fraction = if span > 0.0 {
            ((t - t_star) / span).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let stiffness = initial_stiffness * (1.0 - fraction).powf(exponent);
        force += direction * (stiffness * slip_mag);
    }
    let mag2 = force.norm_squared();
    if mag2 > limit * limit {
        force *= limit / mag2.sqrt();
    }
    hist.shear = force;
    hist.reversal_force_n = reversal;
    force
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mat() -> PairMaterial {
        PairMaterial {
            effective_youngs_modulus_pa: 1e8,
            effective_shear_modulus_pa: 4e7,
            friction_coefficient: 0.5,
            yield_force_n: f64::INFINITY,
            rolling_friction_coefficient: 0.0,
            hertz_damping_factor_pa: 0.0,
            tangential_damping_ratio: 1.0,
        }
    }

    /// Walton-Braun in 1-D: monotonic loading approaches μF_n with a stiffness that vanishes there, and a reversal
    /// restores the initial stiffness.
    #[test]
    fn walton_braun_saturates_and_recovers_stiffness_on_reversal() {
        let n = Vec3::new(0.0, 0.0, 1.0);
        let normal = NormalOutput {
            force_n: 2.0,
            contact_radius_m: 1e-5,
            viscoelastic_damping_kg_per_s: 0.0,
        };
        let model = TangentialModel::WaltonBraun { exponent: 1.0 / 3.0 };
        let mut h = TangentialHistory::default();
        let v = Vec3::new(-0.1, 0.0, 0.0); // pushes F_t towards +x
        let mut f = Vec3::zeros();
        for _ in 0..20000 {
            f = model.force(&mat(), &normal, &n, &v, 1e-5, &mut h);
        }
        assert!((f.x - 1.0).abs() < 1e-9, "saturates at μF_n = 1: {f:?}");
        let before = f.x;
        let kt0 = 8.0 * 4e7 * 1e-5;
        let f2 = model.force(&mat(), &normal, &n, &(-v), 1e-5, &mut h);
        let slope = (before - f2.x) / (0.1 * 1e-5);
        assert!(
            (slope - kt0).abs() < 1e-6 * kt0,
            "fresh stiffness after reversal: {slope} vs {kt0}"
        );
    }

    #[test]
    fn linear_spring_truncates_at_coulomb_limit() {
        let n = Vec3::new(1.0, 0.0, 0.0);
        let normal = NormalOutput {
            force_n: 1.0,
            contact_radius_m: 0.0,
            viscoelastic_damping_kg_per_s: 0.0,
        };
        let model = TangentialModel::LinearSpringCoulomb {
            stiffness_n_per_m: 1000.0,
            damping_kg_per_s: 0.0,
        };
        let mut h = TangentialHistory::default();
        let v = Vec3::new(0.0, 1.0, 0.0);
        let mut f = Vec3::zeros();
        for _ in 0..1000 {
            f = model.force(&mat(), &normal, &n, &v, 1e-4, &mut h);
        }
        assert!((f.norm() - 0.5).abs() < 1e-12);
        assert!(f.y < 0.0);
    }

    #[test]
    fn step_spring_is_a_dashpot_of_kt_dt_plus_eta_capped_at_coulomb() {
        let n = Vec3::new(1.0, 0.0, 0.0);
        let normal = NormalOutput {
            force_n: 1.0,
            contact_radius_m: 0.0,
            viscoelastic_damping_kg_per_s: 0.0,
        };
        let (kt, eta, dt) = (800.0, 0.79e-3, 2.25e-5);
        let model = TangentialModel::LinearStepSpringCoulomb {
            stiffness_n_per_m: kt,
            damping_kg_per_s: eta,
        };
        let mut h = TangentialHistory::default();
        // Slow sliding: the same force every step (nothing accumulates), −(K_t Δt + η_t) v_t, μF_n = 0.5 not reached.
        let v = Vec3::new(0.0, 1.0, 2.0);
        for _ in 0..1000 {
            let f = model.force(&mat(), &normal, &n, &v, dt, &mut h);
            let expected = -v * (kt * dt + eta);
            assert!(
                (f - expected).norm() < 1e-15 * expected.norm().max(1.0),
                "{f:?} vs {expected:?}"
            );
            assert_eq!(h.shear, Vec3::zeros());
        }
        // Fast sliding: on the Coulomb limit.
        let fast = Vec3::new(0.0, 100.0, 0.0);
        let f = model.force(&mat(), &normal, &n, &fast, dt, &mut h);
        assert!((f.norm() - 0.5).abs() < 1e-12);
        assert!(f.y < 0.0);
        // At rest it holds nothing, unlike the accumulated spring (no static friction).
        let f = model.force(&mat(), &normal, &n, &Vec3::zeros(), dt, &mut h);
        assert_eq!(f, Vec3::zeros());
    }
}
