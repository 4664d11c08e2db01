//! Dry cohesion between particles, seed 001 (Sec. 6.2.4; `seed-001-notes.md` §1.6–2): Hamaker van der Waals with
//! an inner cutoff, the square well, and the mapping between the two by the head-on escape velocity (seed 001
//! ch. 7, App. D).
//!
//! Hamaker, sphere–sphere (eq 6.34, written with the effective radius R* = R₁R₂/(R₁+R₂) so that equal spheres give
//! the printed A·r/(12H²)): F = A·R*/(6H²), attractive, with H the surface gap. Below the inner cutoff H_cut
//! (eq 6.37) and in overlap the force stays at its value at H_cut, which is the surface-adhesion force
//! 2πR*γ_s·… with γ_s = A/(24πH_cut²) (continuity at H_cut). Sphere–wall (eq 6.36): twice the sphere–sphere value
//! at equal radius (R* → R).
//!
//! Square well (seed 001 §3, App. D): a pair inside the well (centre distance below 2 r_outer) has potential −D.
//! A head-on pair escapes when its relative normal speed after the collision still climbs out of the well:
//! v_esc = √((4D/m)(1/e² − 1)) (eq 7.5 = D10), m the mass of one of two equal particles.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

/// Hamaker van der Waals attraction with an inner cutoff (seed 001 eqs 6.34–6.37).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Hamaker {
    /// Hamaker constant A, J (seed 001's fluidized beds: 3.34e-19 … 1e-17 J, i.e. 3.34e-12 … 1e-10 erg).
    pub constant_j: f64,
    /// Inner cutoff H_cut, m (seed 001: 4e-10 m, an average interatomic distance).
    pub cutoff_m: f64,
}

impl Hamaker {
    /// The attractive force between two spheres of effective radius `r_star_m` at surface gap `gap_m` (negative
    /// in overlap), N: A R*/(6 max(H, H_cut)²).
    pub fn pair_force_n(&self, r_star_m: f64, gap_m: f64) -> f64 {
        let h = gap_m.max(self.cutoff_m);
        self.constant_j * r_star_m / (6.0 * h * h)
    }

    /// The attractive force between a sphere of radius `radius_m` and a plane, N (eq 6.36: twice the sphere–sphere
    /// value at equal radius, i.e. R* → R).
    pub fn wall_force_n(&self, radius_m: f64, gap_m: f64) -> f64 {
        self.pair_force_n(radius_m, gap_m)
    }

    /// The surface energy that makes the constant force below H_cut continuous, J/m² (γ_s = A/(24π H_cut²)).
    pub fn surface_energy_j_per_m2(&self) -> f64 {
        self.constant_j / (24.0 * PI * self.cutoff_m * self.cutoff_m)
    }

    /// The potential energy of the attraction at gap `gap_m` ≥ H_cut relative to infinite separation, J:
    /// −A R*/(6H).
    pub fn pair_potential_j(&self, r_star_m: f64, gap_m: f64) -> f64 {
        -self.constant_j * r_star_m / (6.0 * gap_m)
    }
}

/// Square-well cohesion (seed 001 §1.7 of the notes): well depth D between the hard core r_inner and r_outer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SquareWell {
    /// Well depth D, J (seed 001 Table 7.1: 1e-11, 5e-11, 1e-10 J, i.e. 1e-4 … 1e-3 erg).
    pub depth_j: f64,
    /// r_outer / r_inner (seed 001's beds: 1.01).
    pub outer_to_inner_radius_ratio: f64,
}

impl SquareWell {
    /// The head-on escape velocity of two equal particles of mass `particle_mass_kg` whose contacts restitute
    /// `restitution` of the normal speed (seed 001 eq 7.5): √((4D/m)(1/e² − 1)), m/s (a relative speed).
    pub fn escape_velocity_m_per_s(&self, particle_mass_kg: f64, restitution: f64) -> f64 {
        (4.0 * self.depth_j / particle_mass_kg * (1.0 / (restitution * restitution) - 1.0)).sqrt()
    }

    /// The well depth that gives escape velocity `escape_m_per_s` (seed 001 eq 7.6): m v²/(4(1/e² − 1)), J.
    pub fn depth_for_escape_velocity_j(escape_m_per_s: f64, particle_mass_kg: f64, restitution: f64) -> f64 {
        particle_mass_kg * escape_m_per_s * escape_m_per_s / (4.0 * (1.0 / (restitution * restitution) - 1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1 erg = 1e-7 J.
    const ERG: f64 = 1e-7;

    #[test]
    fn hamaker_force_is_continuous_at_the_cutoff_and_constant_inside() {
        let h = Hamaker {
            constant_j: 1e-18,
            cutoff_m: 4e-10,
        };
        let r_star = 0.25e-3;
        let at_cut = h.pair_force_n(r_star, 4e-10);
        assert_eq!(h.pair_force_n(r_star, 1e-10), at_cut);
        assert_eq!(h.pair_force_n(r_star, -1e-6), at_cut);
        assert!((h.pair_force_n(r_star, 4e-10 * (1.0 + 1e-12)) / at_cut - 1.0).abs() < 1e-11);
        // The constant force is the adhesion force 4π R* γ_s of the continuous surface energy (2π r γ_s at equal
        // radius r = 2 R*, eq 6.37).
        assert!((at_cut / (4.0 * PI * r_star * h.surface_energy_j_per_m2()) - 1.0).abs() < 1e-12);
        // The wall pulls twice as hard on a sphere of radius 2 R* (eq 6.36).
        assert!((h.wall_force_n(2.0 * r_star, 1e-9) / h.pair_force_n(r_star, 1e-9) - 2.0).abs() < 1e-12);
    }

    /// Seed 001's derived table (notes §3.2): F_max/W at H_cut for 1 mm beads of 2650 kg/m³ is 6.4, 14.3, 19.1,
    /// 20.3 and 191 for A = 3.34e-12, 7.49e-12, 1.0e-11, 1.06e-11 and 1e-10 erg.
    #[test]
    fn hamaker_maximum_force_over_weight_matches_seed_001() {
        let radius: f64 = 0.5e-3;
        let weight = 2650.0 * 4.0 / 3.0 * PI * radius.powi(3) * 9.81;
        for (a_erg, ratio) in [
            (3.34e-12, 6.4),
            (7.49e-12, 14.3),
            (1.0e-11, 19.1),
            (1.06e-11, 20.3),
            (1e-10, 191.0),
        ] {
            let h = Hamaker {
                constant_j: a_erg * ERG,
                cutoff_m: 4e-10,
            };
            let got = h.pair_force_n(radius / 2.0, 0.0) / weight;
            assert!((got / ratio - 1.0).abs() < 0.01, "A = {a_erg} erg: {got} vs {ratio}");
        }
    }

    /// VALIDATION B5: seed 001 Table 7.1, D = 1e-4, 5e-4, 1e-3 erg → v_esc = 0.179, 0.400, 0.566 cm/s for the
    /// Table 6.2 beads (m = 1.3875e-6 kg) with the restitution of K_n = 800 N/m, η_n = 0.79e-3 kg/s (0.9487; the
    /// table's printed 0.94 would give 0.195, 0.436, 0.616 cm/s).
    #[test]
    fn b5_square_well_escape_velocities_match_seed_001_table_7_1() {
        let mass = 1.3875e-6;
        let restitution = crate::engine::models::normal::linear_spring_restitution(800.0, 0.79e-3, mass / 2.0);
        assert!((restitution - 0.9487).abs() < 1e-4, "{restitution}");
        for (d_erg, v_cm_per_s) in [(1e-4, 0.179), (5e-4, 0.400), (1e-3, 0.566)] {
            let well = SquareWell {
                depth_j: d_erg * ERG,
                outer_to_inner_radius_ratio: 1.01,
            };
            let v = well.escape_velocity_m_per_s(mass, restitution) * 100.0;
            assert!(
                (v - v_cm_per_s).abs() < 0.0006,
                "D = {d_erg} erg: {v} cm/s vs {v_cm_per_s}"
            );
            let back = SquareWell::depth_for_escape_velocity_j(v / 100.0, mass, restitution);
            assert!((back / well.depth_j - 1.0).abs() < 1e-12);
        }
    }
}
