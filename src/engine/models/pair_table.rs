//! Material properties mixed once per species pair (E*, G*, μ, F_y, μ_r), looked up in the hot loop.
//!
//! Geometric mixing (R*, m*) depends on the two particles, not their species, and is done per contact in
//! `pair_pass.rs`. Walls are species too: a particle–wall pair uses the (particle species, wall species) entry.

use super::contact_law::ContactLaw;
use super::normal::{NormalModel, SQRT_FIVE_SIXTHS, damping_beta};
use crate::engine::particles::{SpeciesId, SpeciesTable};

/// Mixed material properties of one species pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairMaterial {
    /// Effective Young's modulus, 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2 (seed 000 eq. 2.5).
    pub effective_youngs_modulus_pa: f64,
    /// Effective shear modulus, 1/G* = 2(2−ν1)(1+ν1)/E1 + 2(2−ν2)(1+ν2)/E2 (Mindlin; as in LIGGGHTS/LAMMPS).
    pub effective_shear_modulus_pa: f64,
    /// Sliding friction coefficient μ of the pair.
    pub friction_coefficient: f64,
    /// Thornton yield force of the pair; infinite when neither species yields.
    pub yield_force_n: f64,
    /// Rolling-resistance coefficient μ_r of the pair.
    pub rolling_friction_coefficient: f64,
    /// (2√(5/6) β)² 2E*, with β = |ln e| / √(ln² e + π²) the Hertz viscoelastic damping ratio of the contact law's
    /// restitution (0 for other normal models), so that the Hertz damping γ_n = 2√(5/6) β √(S_n m*), S_n = 2E* a,
    /// is √(this · m* a). Precomputed: a logarithm per contact per step is a measurable share of the force loop.
    pub hertz_damping_factor_pa: f64,
    /// √(4G*/E*) = √(k_t/S_n): Mindlin's tangential damping is the normal one times this (LIGGGHTS' γ_t/γ_n).
    pub tangential_damping_ratio: f64,
}

/// Symmetric table of [`PairMaterial`]s, `n_species × n_species`.
#[derive(Debug, Clone, PartialEq)]
pub struct PairTable {
    n: usize,
    entries: Vec<PairMaterial>,
}

impl PairTable {
    pub fn new(species: &SpeciesTable, law: &ContactLaw) -> Self {
        let viscoelastic_beta = match law.normal {
            NormalModel::Hertz { restitution } => damping_beta(restitution),
            _ => 0.0,
        };
        let n = species.len();
        let mut entries = Vec::with_capacity(n * n);
        for a in &species.species {
            for b in &species.species {
                let inv_e = (1.0 - a.poisson_ratio.powi(2)) / a.youngs_modulus_pa
                    + (1.0 - b.poisson_ratio.powi(2)) / b.youngs_modulus_pa;
                let inv_g = 2.0 * (2.0 - a.poisson_ratio) * (1.0 + a.poisson_ratio) / a.youngs_modulus_pa
                    + 2.0 * (2.0 - b.poisson_ratio) * (1.0 + b.poisson_ratio) / b.youngs_modulus_pa;
                // CHOICE: the seeds use one material per simulation and never say how μ, μ_r or F_y combine
                // between unlike species. We take the arithmetic mean of μ and μ_r (symmetric and equal to the
                // common value for like pairs) and the smaller yield force (the softer body yields first).
                let yield_force_n = match (a.yield_force_n, b.yield_force_n) {
                    (Some(x), Some(y)) => x.min(y),
                    (Some(x), None) | (None, Some(x)) => x,
                    (None, None) => f64::INFINITY,
                };
                let damping_coefficient = 2.0 * SQRT_FIVE_SIXTHS * viscoelastic_beta;
                entries.push(PairMaterial {
                    hertz_damping_factor_pa: damping_coefficient * damping_coefficient * 2.0 / inv_e,
                    effective_youngs_modulus_pa: 1.0 / inv_e,
                    effective_shear_modulus_pa: 1.0 / inv_g,
                    tangential_damping_ratio: (4.0 * inv_e / inv_g).sqrt(),
                    friction_coefficient: 0.5 * (a.friction_coefficient + b.friction_coefficient),
                    yield_force_n,
                    rolling_friction_coefficient: 0.5
                        * (a.rolling_friction_coefficient + b.rolling_friction_coefficient),
                });
            }
        }
        PairTable { n, entries }
    }

    #[inline]
    pub fn get(&self, a: SpeciesId, b: SpeciesId) -> &PairMaterial {
        &self.entries[a.index() * self.n + b.index()]
    }
}
