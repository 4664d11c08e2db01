//! Numerical failures of a running simulation, reported once per step with the step, particle and field involved.
//! The campaign layer treats these as the "numerical" failure class (retry from a checkpoint with a smaller dt).

use super::Vec3;
use super::particles::ParticleId;

#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum NumericalError {
    #[error("non-finite {field} of particle {} at step {step}", particle.0)]
    NonFinite {
        step: u64,
        particle: ParticleId,
        field: &'static str,
    },
    #[error(
        "excessive overlap at step {step}: particle {} and {partner} overlap by {overlap_m:.3e} m, {ratio:.3} of the smaller radius (limit {limit:.3}); reduce dt or stiffen the contact",
        particle.0
    )]
    ExcessiveOverlap {
        step: u64,
        particle: ParticleId,
        partner: String,
        overlap_m: f64,
        ratio: f64,
        limit: f64,
    },
    #[error("particle {} lost at step {step}: left the box at ({:.4}, {:.4}, {:.4}) m", particle.0, position_m.x, position_m.y, position_m.z)]
    ParticleLost {
        step: u64,
        particle: ParticleId,
        position_m: Vec3,
    },
    #[error("gas diverged at step {step}: {detail}; reduce dt or dem_steps_per_gas_step")]
    GasDiverged { step: u64, detail: String },
    #[error("{count} contacts of the restored state found no neighbour-list slot (internal error)")]
    OrphanContacts { count: usize },
}
