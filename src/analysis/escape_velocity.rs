//! The head-on escape velocity of two equal spheres with a linear spring–dashpot contact and Hamaker attraction,
//! and the Hamaker constant that matches a square well's escape velocity (seed 001 ch. 7, App. D; VALIDATION B6).
//!
//! Seed 001 maps its square-well (SW) and Hamaker beds onto each other by the minimum relative approach speed at
//! which a head-on pair separates again: analytic for the well (`SquareWell::escape_velocity_m_per_s`), found
//! numerically for Hamaker by colliding two particles at bracketing speeds (its Fig. 7.3). Here the collision is the
//! one-dimensional relative motion of the pair, μ ẅ = F_contact − F_Hamaker with μ = m/2 and the gap H as
//! coordinate, integrated by classical Runge–Kutta at t_c/4000 from a gap of `START_GAP_M`. After the contact the pair
//! escapes when its energy ½μẇ² − A R*/(6H) is positive once it is past H_cut (beyond it the motion conserves
//! energy); it is captured when it turns back.

use crate::engine::models::cohesion::Hamaker;

/// Gap at which the approach starts, m (250 H_cut): in seed 001's weakest case (A = 3.34e-19 J at 1.8 mm/s) the
/// attraction has added about 1e-4 of the pair's kinetic energy by then.
pub const START_GAP_M: f64 = 1e-7;

/// Contact times after the first touch within which a pair must have left the contact to count as escaping.
const MAX_CONTACT_TIMES: u64 = 100;

/// The restitution coefficient of a linear spring–dashpot (the contact law's property, `engine::models::normal`).
pub use crate::engine::models::normal::linear_spring_restitution;

/// A head-on collision of two equal spheres (seed 001 Table 6.2 contact: linear spring–dashpot, no cohesion model
/// inside the contact besides the constant Hamaker force below H_cut).
#[derive(Debug, Clone, Copy)]
pub struct HeadOnCollision {
    pub stiffness_n_per_m: f64,
    pub damping_kg_per_s: f64,
    /// Mass of one particle, kg.
    pub particle_mass_kg: f64,
    pub radius_m: f64,
    pub hamaker: Hamaker,
}

impl HeadOnCollision {
    fn reduced_mass_kg(&self) -> f64 {
        0.5 * self.particle_mass_kg
    }

    /// Contact time of the undamped spring π√(μ/K), s.
    fn contact_time_s(&self) -> f64 {
        std::f64::consts::PI * (self.reduced_mass_kg() / self.stiffness_n_per_m).sqrt()
    }

    /// d(H, ẇ)/dt: the force along the line of centres (positive pushes apart) over μ.
    fn rates(&self, gap_m: f64, speed_m_per_s: f64) -> (f64, f64) {
        let overlap = -gap_m;
        let contact = if overlap > 0.0 {
            // Spring and dashpot: K δ + η δ̇ with δ̇ = −Ḣ.
            self.stiffness_n_per_m * overlap - self.damping_kg_per_s * speed_m_per_s
        } else {
            0.0
        };
        let attraction = self.hamaker.pair_force_n(0.5 * self.radius_m, gap_m);
        (speed_m_per_s, (contact - attraction) / self.reduced_mass_kg())
    }

    /// Whether a pair approaching at relative speed `approach_m_per_s` separates for good.
    pub fn escapes(&self, approach_m_per_s: f64) -> bool {
        let dt = self.contact_time_s() / 4000.0;
        let (mut h, mut w) = (START_GAP_M, -approach_m_per_s);
        let mut touched = false;
        let mut steps_in_contact = 0u64;
        while steps_in_contact < MAX_CONTACT_TIMES * 4000 {
            let (k1h, k1w) = self.rates(h, w);
            let (k2h, k2w) = self.rates(h + 0.5 * dt * k1h, w + 0.5 * dt * k1w);
            let (k3h, k3w) = self.rates(h + 0.5 * dt * k2h, w + 0.5 * dt * k2w);
            let (k4h, k4w) = self.rates(h + dt * k3h, w + dt * k3w);
            h += dt / 6.0 * (k1h + 2.0 * k2h + 2.0 * k3h + k4h);
            w += dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
            touched |= h < 0.0;
            if touched {
                steps_in_contact += 1;
            }
            if touched && h > 0.0 {
                if w <= 0.0 {
                    return false;
                }
                if h >= self.hamaker.cutoff_m {
                    let energy =
                        0.5 * self.reduced_mass_kg() * w * w + self.hamaker.pair_potential_j(0.5 * self.radius_m, h);
                    return energy > 0.0;
                }
            }
        }
        false
    }

    /// The escape velocity (relative speed), m/s, by bisection to `relative_tolerance`.
    pub fn escape_velocity_m_per_s(&self, relative_tolerance: f64) -> f64 {
        let mut high = 1e-4;
        while !self.escapes(high) {
            high *= 2.0;
            assert!(high < 1e3, "no escape below 1 km/s");
        }
        let mut low = 0.0;
        while high - low > relative_tolerance * high {
            let mid = 0.5 * (low + high);
            if self.escapes(mid) {
                high = mid;
            } else {
                low = mid;
            }
        }
        0.5 * (low + high)
    }

    /// The Hamaker constant (keeping H_cut) whose escape velocity is `escape_m_per_s`, J, by bisection on log A.
    pub fn hamaker_constant_for_escape_velocity_j(&self, escape_m_per_s: f64, relative_tolerance: f64) -> f64 {
        let with = |a: f64| HeadOnCollision {
            hamaker: Hamaker {
                constant_j: a,
                ..self.hamaker
            },
            ..*self
        };
        let (mut low, mut high) = (1e-24f64, 1e-14f64);
        assert!(with(low).escapes(escape_m_per_s) && !with(high).escapes(escape_m_per_s));
        while high / low - 1.0 > relative_tolerance {
            let mid = (low * high).sqrt();
            if with(mid).escapes(escape_m_per_s) {
                low = mid;
            } else {
                high = mid;
            }
        }
        (low * high).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::models::cohesion::SquareWell;

    const ERG: f64 = 1e-7;

    /// Seed 001 Table 6.2: 1 mm beads of 2650 kg/m³, K_n = 800 N/m, η_n = 0.79e-3 kg/s.
    fn table_6_2(hamaker_erg: f64) -> HeadOnCollision {
        HeadOnCollision {
            stiffness_n_per_m: 800.0,
            damping_kg_per_s: 0.79e-3,
            particle_mass_kg: 1.3875e-6,
            radius_m: 0.5e-3,
            hamaker: Hamaker {
                constant_j: hamaker_erg * ERG,
                cutoff_m: 4e-10,
            },
        }
    }

    #[test]
    fn without_attraction_every_pair_escapes_and_rebounds_with_the_restitution() {
        let c = table_6_2(0.0);
        assert!(c.escapes(1e-6));
        let e = linear_spring_restitution(800.0, 0.79e-3, 0.5 * 1.3875e-6);
        assert!((e - 0.9487).abs() < 1e-4, "{e}");
    }

    /// VALIDATION B6: seed 001 Table 7.1 (H_cut = 4e-10 m, Table 6.2 contact): the Hamaker constants with the
    /// escape velocities of the wells D = 1e-4, 5e-4, 1e-3 erg are A = 3.34e-12, 7.49e-12, 1.06e-11 erg.
    #[test]
    fn b6_hamaker_constants_matching_the_square_wells_follow_seed_001_table_7_1() {
        let mass = 1.3875e-6;
        let e = linear_spring_restitution(800.0, 0.79e-3, 0.5 * mass);
        for (d_erg, a_erg) in [(1e-4, 3.34e-12), (5e-4, 7.49e-12), (1e-3, 1.06e-11)] {
            let well = SquareWell {
                depth_j: d_erg * ERG,
                outer_to_inner_radius_ratio: 1.01,
            };
            let v_esc = well.escape_velocity_m_per_s(mass, e);
            let a = table_6_2(0.0).hamaker_constant_for_escape_velocity_j(v_esc, 1e-4) / ERG;
            eprintln!(
                "D = {d_erg} erg: v_esc = {:.4} cm/s, A = {a:.4e} erg (seed 001: {a_erg})",
                v_esc * 100.0
            );
            assert!(
                (a / a_erg - 1.0).abs() < 0.05,
                "D = {d_erg} erg: A = {a} erg vs {a_erg}"
            );
            // And back: that A gives the well's escape velocity.
            let back = table_6_2(a).escape_velocity_m_per_s(1e-5);
            assert!((back / v_esc - 1.0).abs() < 1e-3, "{back} vs {v_esc}");
        }
    }
}
