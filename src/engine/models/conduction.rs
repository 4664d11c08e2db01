//! Conduction through a contact (seed 000 §5.1.2.1): Q = H ΔT with the contact conductance H = 2 R_c k_s
//! (eqs. 5.3–5.4, smooth elastic spheres; Batchelor & O'Brien 1977), for particle pairs and for a particle on a wall
//! (the wall an infinite particle at its own temperature, §5.1.2.1).
//!
//! - **Contact radius.** R_c is the Hertz radius √(R* δ) the contact law reports, R* = R_i R_j/(R_i + R_j) (R_i on a
//!   smooth wall, the pair's on a glued bead). Seed 000 writes √(R α) in eq. 5.15 (√2 larger for equal spheres); Hertz's is the radius of the
//!   circle the two spheres actually share, so we use it, as `PHYSICS.md` §4 asks us to say.
//! - **Two solids.** k_s is the harmonic mean 2 k_i k_j/(k_i + k_j) of the two conductivities (the series
//!   resistance of the two half-contacts; equal to k for like materials). A wall whose material states no
//!   conductivity conducts as the particle does.
//! - **Softened particles.** A softer modulus than the material's (to afford a longer time step) gives a larger
//!   contact radius and so too much conduction. For the Hertzian laws the radius is scaled back by
//!   (E*_sim/E*_real)^(1/5), the ratio of the two materials' contact radii at the same impact velocity (Hertz:
//!   δ_max ∝ E*^(−2/5), R_c ∝ E*^(−1/5); Morris, Pannala, Ma & Hrenya 2016, Lommen et al. 2019). For the linear
//!   spring, which has no modulus, the radius is the real material's Hertz radius under the contact's normal force,
//!   (3 F_n R*/(4 E*_real))^(1/3) (CHOICE: the static equivalent; without a real modulus, √(R* δ)).

use super::contact_law::ContactOutput;
use super::normal::NormalModel;

/// The conduction constants of one species pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalPair {
    /// 2 k_s (k_s the harmonic mean of the two conductivities): the contact conductance per unit contact radius,
    /// W/(m K).
    pub conductance_per_radius_w_per_m_k: f64,
    /// R_c,real / R_c,sim for the Hertzian laws, (E*_sim/E*_real)^(1/5); 1 without a correction.
    pub radius_scale: f64,
    /// E*_real for the linear spring's radius from its force, Pa; 0 without a correction (geometric radius).
    pub real_effective_modulus_pa: f64,
}

impl ThermalPair {
    /// No conduction (a pair neither of whose species has a conductivity).
    pub const NONE: ThermalPair = ThermalPair {
        conductance_per_radius_w_per_m_k: 0.0,
        radius_scale: 1.0,
        real_effective_modulus_pa: 0.0,
    };

    /// The pair of conductivities `k_i`, `k_j` (`None`: the species states none; a wall then conducts as the
    /// particle does), with effective moduli `simulated_pa` (the contact law's E*) and `real_pa` (the real materials',
    /// `None` when neither is softened, or the correction is off).
    pub fn new(k_i: Option<f64>, k_j: Option<f64>, simulated_pa: f64, real_pa: Option<f64>) -> ThermalPair {
        let k_s = match (k_i, k_j) {
            (Some(a), Some(b)) => harmonic_mean(a, b),
            (Some(a), None) | (None, Some(a)) => a,
            (None, None) => return ThermalPair::NONE,
        };
        let (radius_scale, real_effective_modulus_pa) = match real_pa {
            Some(real) => ((simulated_pa / real).powf(0.2), real),
            None => (1.0, 0.0),
        };
        ThermalPair {
            conductance_per_radius_w_per_m_k: 2.0 * k_s,
            radius_scale,
            real_effective_modulus_pa,
        }
    }

    /// The contact radius that conducts, m, for a contact `out` of the normal law `normal` with effective radius
    /// `effective_radius_m`.
    #[inline(always)]
    pub fn contact_radius_m(&self, normal: &NormalModel, out: &ContactOutput, effective_radius_m: f64) -> f64 {
        match normal {
            NormalModel::LinearSpringDashpot { .. } => {
                if self.real_effective_modulus_pa > 0.0 {
                    (0.75 * out.normal_force_n.max(0.0) * effective_radius_m / self.real_effective_modulus_pa).cbrt()
                } else {
                    (effective_radius_m * out.overlap_m).sqrt()
                }
            }
            NormalModel::Hertz { .. } | NormalModel::Thornton { .. } => out.contact_radius_m * self.radius_scale,
        }
    }

    /// The contact conductance H = 2 R_c k_s, W/K (seed 000 eq. 5.4).
    #[inline(always)]
    pub fn conductance_w_per_k(&self, normal: &NormalModel, out: &ContactOutput, effective_radius_m: f64) -> f64 {
        self.conductance_per_radius_w_per_m_k * self.contact_radius_m(normal, out, effective_radius_m)
    }
}

/// 2ab/(a + b).
pub fn harmonic_mean(a: f64, b: f64) -> f64 {
    2.0 * a * b / (a + b)
}

/// 1/E* = (1 − ν_i²)/E_i + (1 − ν_j²)/E_j.
pub fn effective_modulus_pa(e_i: f64, nu_i: f64, e_j: f64, nu_j: f64) -> f64 {
    1.0 / ((1.0 - nu_i * nu_i) / e_i + (1.0 - nu_j * nu_j) / e_j)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Vec3;

    fn contact(overlap_m: f64, contact_radius_m: f64, normal_force_n: f64) -> ContactOutput {
        ContactOutput {
            normal: Vec3::x(),
            overlap_m,
            contact_radius_m,
            normal_force_n,
            force: Vec3::zeros(),
            tangential_force: Vec3::zeros(),
            rolling_torque: Vec3::zeros(),
        }
    }

    #[test]
    fn like_materials_conduct_with_their_own_conductivity_unlike_with_the_harmonic_mean() {
        let like = ThermalPair::new(Some(1.7), Some(1.7), 1e9, None);
        assert_eq!(like.conductance_per_radius_w_per_m_k, 3.4);
        let unlike = ThermalPair::new(Some(1.7), Some(180.0), 1e9, None);
        assert!((unlike.conductance_per_radius_w_per_m_k - 2.0 * 2.0 * 1.7 * 180.0 / 181.7).abs() < 1e-12);
        let plain_wall = ThermalPair::new(Some(15.0), None, 1e9, None);
        assert_eq!(plain_wall.conductance_per_radius_w_per_m_k, 30.0);
        assert_eq!(ThermalPair::new(None, None, 1e9, None), ThermalPair::NONE);
    }

    /// The correction makes a softened Hertz contact conduct as the real one does at the same impact velocity:
    /// the largest Hertz overlap at impact speed v is δ = (15 m* v²/(16 E* √R*))^(2/5), R_c = √(R* δ).
    #[test]
    fn the_softened_hertz_radius_scales_back_to_the_real_impact_radius() {
        let (r_star, m_star, v): (f64, f64, f64) = (0.75e-3, 1.9e-5, 0.3);
        let peak_radius = |e_star: f64| {
            let delta = (15.0 * m_star * v * v / (16.0 * e_star * r_star.sqrt())).powf(0.4);
            (r_star * delta).sqrt()
        };
        let (soft, real) = (5.0e7, 3.9e10);
        let pair = ThermalPair::new(Some(1.7), Some(1.7), soft, Some(real));
        let hertz = NormalModel::Hertz { restitution: 0.9 };
        let corrected = pair.contact_radius_m(&hertz, &contact(0.0, peak_radius(soft), 0.0), r_star);
        assert!(
            (corrected / peak_radius(real) - 1.0).abs() < 1e-12,
            "{corrected} vs {}",
            peak_radius(real)
        );
        assert!(peak_radius(soft) / peak_radius(real) > 3.0, "the softening matters");
    }

    #[test]
    fn the_linear_spring_conducts_through_the_geometric_radius_or_the_real_hertz_radius_under_its_force() {
        let lsd = NormalModel::LinearSpringDashpot {
            stiffness_n_per_m: 1e4,
            damping_kg_per_s: 0.0,
        };
        let (r_star, delta) = (1e-3, 1e-5);
        let plain = ThermalPair::new(Some(1.0), Some(1.0), 1.0, None);
        let out = contact(delta, 0.0, 1e4 * delta);
        assert!((plain.contact_radius_m(&lsd, &out, r_star) - (r_star * delta).sqrt()).abs() < 1e-18);
        let real = ThermalPair::new(Some(1.0), Some(1.0), 1.0, Some(4e10));
        let a = real.contact_radius_m(&lsd, &out, r_star);
        // Hertz: F = 4/3 E* √R* δ^(3/2) and a = √(R* δ) give F = 4 E* a³/(3 R*).
        let force = 4.0 * 4e10 * a.powi(3) / (3.0 * r_star);
        assert!((force / (1e4 * delta) - 1.0).abs() < 1e-12);
    }
}
