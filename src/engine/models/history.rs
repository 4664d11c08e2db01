//! Per-contact history: the state a contact law carries from one step to the next.
//!
//! One plain struct serves every slot combination so that the pair store stays a flat array; each model documents
//! which fields it reads. A contact that separates loses its history (a new contact starts from zero), which is what
//! all three seed models assume. The checkpoint writes every field by name (`schemas/checkpoint.md`).

use crate::engine::Vec3;

#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactHistory {
    /// True while the pair overlaps. Inactive entries are all-zero.
    pub active: bool,
    /// Thornton: the normal model has passed the yield force during this contact.
    pub yielded: bool,
    /// Tangential slot. Linear spring and Mindlin: the elastic tangential displacement u_t (m).
    /// Walton-Braun: the tangential force F_t on particle i (N).
    pub tangential: Vec3,
    /// Walton-Braun: the tangential force at the last reversal of the slip direction, F_t* (N).
    pub reversal_force_n: Vec3,
    /// Walton-Braun: unit direction of the last tangential force increment (zero before the first one).
    pub increment_direction: Vec3,
    /// Thornton: maximum overlap α_max reached in this contact (m).
    pub max_overlap_m: f64,
    /// Thornton: normal force F_max at α_max (N).
    pub max_normal_force_n: f64,
}

impl ContactHistory {
    pub const INACTIVE: ContactHistory = ContactHistory {
        active: false,
        yielded: false,
        tangential: Vec3::new(0.0, 0.0, 0.0),
        reversal_force_n: Vec3::new(0.0, 0.0, 0.0),
        increment_direction: Vec3::new(0.0, 0.0, 0.0),
        max_overlap_m: 0.0,
        max_normal_force_n: 0.0,
    };
}

/// Brings a history vector into the current tangent plane (normal `n`) by removing its normal component: contacts
/// roll and the pair rotates, so a vector stored in the previous step's tangent plane must follow it.
///
/// CHOICE: projection without restoring the length, as LIGGGHTS `tangential history` and LAMMPS `gran/hertz/history`
/// do. The length lost is second order in the rotation per step (relative (θ dt)²/2); restoring it would cost a
/// square root and a division per contact per step, a tenth of the contact kernel.
#[inline]
pub fn rotate_into_tangent_plane(v: Vec3, n: &Vec3) -> Vec3 {
    v - n * v.dot(n)
}
