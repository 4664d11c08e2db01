//! Drag held over a gas step: CFDEM's coupling interval as a named choice ([`DragUpdate::EveryGasStep`]).
//!
//! At the first DEM sub-step after a gas step, each particle's drag coefficient K_i (from the drag law at the slip
//! of that moment), the gas velocity interpolated to it u_i and its pressure force −V_i ∇p(x_i) are evaluated once
//! and held until the next gas step. Every sub-step the particle then gets f_i = K_i (u_i − v_i) − V_i ∇p(x_i) with
//! its current velocity v_i, so the drag still relaxes the slip as the particle moves (the drag law's
//! transcendental functions and the interpolation run once per gas step instead of once per DEM step).
//!
//! The gas receives the reaction once per gas step, spread with the held interpolation weights: over n sub-steps
//! the particle got Σ_s K_i (u_i − v_i,s) = K_i (n u_i − Σ_s v_i,s), so only Σ_s v_i,s is summed per particle and
//! the gas still gets exactly what the particles lost (to rounding), as in the explicit coupling; the semi-implicit
//! coupling gets n K_i and K_i Σ_s v_i,s.
//!
//! What differs from the every-step scheme ([`DragUpdate::EveryDemStep`], the default): K, u and ∇p are those at
//! the particle's position and slip at the start of the gas step; a particle that crosses a cell within one gas
//! step keeps its old cell's values until the next. With a gas step of n DEM steps that is the coupling CFDEM
//! uses (Kloss et al. 2012, Prog. Comput. Fluid Dyn. 12: the coupling interval); the validation reports of both
//! schemes are in `results/validation/`.
//!
//! A checkpoint within a gas step holds each particle's position and velocity at the evaluation and its velocity
//! sum: the held values are evaluated again from them on restore under the same frozen field, so a resumed run is
//! bit-identical.

use serde::{Deserialize, Serialize};

use super::coupling::Stencil;
use crate::engine::Vec3;

/// When the gas's force on a particle (its drag coefficient, the gas velocity and the pressure gradient at it) is
/// evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DragUpdate {
    /// Every DEM step, at the particle's current position and slip (the reaction spread every step).
    #[default]
    EveryDemStep,
    /// Once per gas step, at the first DEM sub-step after it, and held over the sub-steps; the drag uses each
    /// sub-step's particle velocity (CFDEM's coupling interval). Needs `drag_velocities: instantaneous`.
    EveryGasStep,
}

/// One particle's held values.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct HeldForce {
    /// K, N·s/m.
    pub coefficient_n_s_per_m: f64,
    /// The gas velocity interpolated to the particle, m/s.
    pub gas_velocity_m_per_s: Vec3,
    /// −V ∇p at the particle, N.
    pub pressure_force_n: Vec3,
    /// Σ over the sub-steps so far of the particle's velocity, m/s.
    pub velocity_sum_m_per_s: Vec3,
}

impl HeldForce {
    /// The gas's force on the particle at velocity `v` (drag plus pressure force), and `v` counted in the sum.
    #[inline]
    pub fn force_at(&mut self, v: &Vec3) -> Vec3 {
        self.velocity_sum_m_per_s += v;
        (self.gas_velocity_m_per_s - v) * self.coefficient_n_s_per_m + self.pressure_force_n
    }
}

/// The held values of all particles since the last gas step.
#[derive(Debug, Clone, Default)]
pub(crate) struct HeldDrag {
    pub forces: Vec<HeldForce>,
    /// The interpolation stencils of the three velocity components at the evaluation (they spread the reaction).
    pub stencils: Vec<[Stencil; 3]>,
    /// Each particle's position and velocity at the evaluation (what a checkpoint holds).
    pub evaluated_at: Vec<(Vec3, Vec3)>,
    /// Whether the values belong to the present frozen field (false from each freeze until the first sub-step).
    pub valid: bool,
}

/// The held-drag state a checkpoint holds: per particle, position and velocity at the evaluation and the velocity
/// sum since.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HeldDragSnapshot {
    pub position_m: Vec<Vec3>,
    pub velocity_m_per_s: Vec<Vec3>,
    pub velocity_sum_m_per_s: Vec<Vec3>,
}

impl HeldDrag {
    pub fn snapshot(&self) -> Option<HeldDragSnapshot> {
        self.valid.then(|| HeldDragSnapshot {
            position_m: self.evaluated_at.iter().map(|(x, _)| *x).collect(),
            velocity_m_per_s: self.evaluated_at.iter().map(|(_, v)| *v).collect(),
            velocity_sum_m_per_s: self.forces.iter().map(|f| f.velocity_sum_m_per_s).collect(),
        })
    }
}
