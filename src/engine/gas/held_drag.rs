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

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::coupling::Stencil;
use super::fluid_forces::{DragVelocities, FluidForces, per_particle};
use crate::engine::Vec3;
use crate::engine::team::Team;

/// When the gas's force on a particle (its drag coefficient, the gas velocity and the pressure gradient at it) is
/// evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DragUpdate {
    /// Every DEM step, at the particle's current position and slip (the reaction spread every step).
    #[default]
    EveryDemStep,
    /// Once per gas step, at the first DEM sub-step after it, and held over the sub-steps; the drag uses each
    /// sub-step's particle velocity (CFDEM's coupling interval), or under `cell_averaged` drag velocities each
    /// sub-step's mean particle velocity of the cell the particle was in at the evaluation.
    EveryGasStep,
}

/// One particle's held values.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct HeldForce {
    /// K, N·s/m.
    pub coefficient_n_s_per_m: f64,
    /// The gas velocity interpolated to the particle (cell-averaged: at its cell's centre), m/s.
    pub gas_velocity_m_per_s: Vec3,
    /// −V ∇p at the particle, N.
    pub pressure_force_n: Vec3,
    /// Σ over the sub-steps so far of the particle's velocity, m/s (instantaneous velocities only).
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

/// What the cell-averaged scheme holds besides each particle's values: the particles' cells and volumes at the
/// evaluation, and per cell the solid volume, the mean particle velocity of the present sub-step and its sum.
#[derive(Debug, Clone, Default)]
pub(crate) struct HeldCells {
    pub cell: Vec<usize>,
    pub volume_m3: Vec<f64>,
    pub solid_volume_m3: Vec<f64>,
    pub momentum: Vec<Vec3>,
    pub mean_velocity_m_per_s: Vec<Vec3>,
    pub mean_velocity_sum_m_per_s: Vec<Vec3>,
    /// The occupied cells in order of first occupation.
    pub occupied: Vec<usize>,
}

/// The held values of all particles since the last gas step.
#[derive(Debug, Clone, Default)]
pub(crate) struct HeldDrag {
    pub forces: Vec<HeldForce>,
    /// The interpolation stencils of the three velocity components at the evaluation (they spread the reaction).
    pub stencils: Vec<[Stencil; 3]>,
    /// Each particle's position and velocity at the evaluation (what a checkpoint holds).
    pub evaluated_at: Vec<(Vec3, Vec3)>,
    /// Cell-averaged drag velocities only.
    pub cells: HeldCells,
    /// Whether the values belong to the present frozen field (false from each freeze until the first sub-step).
    pub valid: bool,
}

/// The held-drag state a checkpoint holds: per particle, position and velocity at the evaluation and the velocity
/// sum since (cell-averaged: the sum of its cell's mean particle velocity, the same for every particle of a cell).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HeldDragSnapshot {
    pub position_m: Vec<Vec3>,
    pub velocity_m_per_s: Vec<Vec3>,
    pub velocity_sum_m_per_s: Vec<Vec3>,
}

impl FluidForces {
    /// The gas's force on each particle under held drag (evaluated first if this is the first sub-step after a
    /// freeze), added to `force`.
    pub(super) fn add_held_forces(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        force: &mut [Vec3],
        team: Option<&Team>,
    ) {
        if !self.held.valid {
            self.evaluate_held(positions_m, velocities_m_per_s, radii_m, team);
        }
        let held = &mut self.held;
        match self.drag_velocities {
            DragVelocities::Instantaneous => {
                for ((h, v), f) in held.forces.iter_mut().zip(velocities_m_per_s).zip(force.iter_mut()) {
                    *f += h.force_at(v);
                }
            }
            DragVelocities::CellAveraged => {
                let cells = &mut held.cells;
                held_mean_velocities(cells, velocities_m_per_s);
                for ((h, &c), f) in held.forces.iter().zip(&cells.cell).zip(force.iter_mut()) {
                    *f += (h.gas_velocity_m_per_s - cells.mean_velocity_m_per_s[c]) * h.coefficient_n_s_per_m
                        + h.pressure_force_n;
                }
                for &c in &cells.occupied {
                    cells.mean_velocity_sum_m_per_s[c] += cells.mean_velocity_m_per_s[c];
                }
            }
        }
    }

    /// Evaluates and holds every particle's K, u and pressure force under the present frozen field (the first
    /// sub-step after a gas step, or a restore within one); the velocity sums start at zero. Cell-averaged: with the
    /// cell's mean particle velocity and the gas velocity at its centre, as the every-step scheme computes them.
    fn evaluate_held(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        team: Option<&Team>,
    ) {
        let mut held = std::mem::take(&mut self.held);
        let n = positions_m.len();
        held.forces.resize(n, Default::default());
        held.stencils.resize(n, Default::default());
        held.evaluated_at.clear();
        held.evaluated_at
            .extend(positions_m.iter().copied().zip(velocities_m_per_s.iter().copied()));
        match self.drag_velocities {
            DragVelocities::Instantaneous => {
                let this = &*self;
                let compute = |(i, (record, stencils)): (usize, (&mut HeldForce, &mut [Stencil; 3]))| {
                    let (k, u, pressure_force) =
                        this.evaluate(&positions_m[i], &velocities_m_per_s[i], radii_m[i], stencils);
                    *record = HeldForce {
                        coefficient_n_s_per_m: k,
                        gas_velocity_m_per_s: u,
                        pressure_force_n: pressure_force,
                        velocity_sum_m_per_s: Vec3::zeros(),
                    };
                };
                per_particle(team, &mut held.forces, &mut held.stencils, compute);
            }
            DragVelocities::CellAveraged => {
                self.evaluate_held_cells(&mut held, positions_m, velocities_m_per_s, radii_m)
            }
        }
        held.valid = true;
        self.held = held;
    }

    /// The cell-averaged evaluation: each particle's cell, the cells' solid volumes and mean particle velocities,
    /// K per particle from its cell's slip (the drag law once per cell and particle radius), u at the cell centre,
    /// −V∇p interpolated to the particle.
    fn evaluate_held_cells(
        &self,
        held: &mut HeldDrag,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
    ) {
        let cells = &mut held.cells;
        let n_cells = self.grid.cells();
        cells.cell.clear();
        cells.cell.extend(positions_m.iter().map(|x| self.cell_of(x)));
        cells.volume_m3.clear();
        cells
            .volume_m3
            .extend(radii_m.iter().map(|r| 4.0 / 3.0 * PI * r.powi(3)));
        cells.solid_volume_m3.clear();
        cells.solid_volume_m3.resize(n_cells, 0.0);
        cells.momentum.resize(n_cells, Vec3::zeros());
        cells.mean_velocity_m_per_s.resize(n_cells, Vec3::zeros());
        cells.mean_velocity_sum_m_per_s.resize(n_cells, Vec3::zeros());
        cells.occupied.clear();
        for (&c, &v) in cells.cell.iter().zip(&cells.volume_m3) {
            if cells.solid_volume_m3[c] == 0.0 {
                cells.occupied.push(c);
                cells.mean_velocity_sum_m_per_s[c] = Vec3::zeros();
            }
            cells.solid_volume_m3[c] += v;
        }
        held_mean_velocities(cells, velocities_m_per_s);
        // K for the cell's first particle radius, reused for every particle of that radius in the cell.
        let mut reference: Vec<(usize, f64, f64)> = Vec::with_capacity(cells.occupied.len());
        let mut reference_of = vec![usize::MAX; n_cells];
        for (i, &c) in cells.cell.iter().enumerate() {
            let u = self.cell_gas_velocity(self.cell_indices(c));
            let slip = u - cells.mean_velocity_m_per_s[c];
            let k = match reference_of[c] {
                usize::MAX => {
                    let k = self.cell_drag_coefficient(c, &slip, radii_m[i]);
                    reference_of[c] = reference.len();
                    reference.push((c, radii_m[i], k));
                    k
                }
                r if reference[r].1 == radii_m[i] => reference[r].2,
                _ => self.cell_drag_coefficient(c, &slip, radii_m[i]),
            };
            let mut grad = Vec3::zeros();
            for a in 0..self.grid.axes() {
                held.stencils[i][a] = self.lattice_stencil(a, &positions_m[i]);
                grad[a] = held.stencils[i][a].apply(&self.minus_pressure_gradient_pa_per_m[a]);
            }
            held.forces[i] = HeldForce {
                coefficient_n_s_per_m: k,
                gas_velocity_m_per_s: u,
                pressure_force_n: grad * cells.volume_m3[i],
                velocity_sum_m_per_s: Vec3::zeros(),
            };
        }
    }

    /// Hands the gas the reaction of the held drag over the sub-steps since the last freeze (once, before the gas
    /// step reads [`Self::mean_reaction`] or [`Self::mean_exchange`]), serially in particle order. Instantaneous:
    /// K (n u − Σv) per particle, spread with its held stencils. Cell-averaged: per cell Σ_i K_i (n u_c − Σ v_sm),
    /// half to each of the cell's two faces along each axis. Does nothing under the every-step scheme, whose
    /// reaction is spread as it goes.
    pub fn settle_held_reaction(&mut self) {
        if self.drag_update != DragUpdate::EveryGasStep || !self.held.valid {
            return;
        }
        let steps = f64::from(self.steps());
        let per_volume = 1.0 / self.grid.cell_volume_m3();
        let held = std::mem::take(&mut self.held);
        match self.drag_velocities {
            DragVelocities::Instantaneous => {
                for (h, stencils) in held.forces.iter().zip(&held.stencils) {
                    let k = h.coefficient_n_s_per_m;
                    let drag_sum = (h.gas_velocity_m_per_s * steps - h.velocity_sum_m_per_s) * k;
                    for (a, stencil) in stencils.iter().enumerate().take(self.grid.axes()) {
                        let exchange = &mut self.momentum_exchange[a];
                        for c in 0..stencil.count {
                            let (face, w) = (stencil.face[c], stencil.weight[c] * per_volume);
                            exchange.add_transfer(face, -(w * drag_sum[a]));
                            exchange.add_exchange_sums(face, w * k * steps, w * k * h.velocity_sum_m_per_s[a]);
                        }
                    }
                }
            }
            DragVelocities::CellAveraged => {
                let cells = &held.cells;
                let mut drag_sum = vec![Vec3::zeros(); self.grid.cells()];
                let mut k_sum = vec![0.0; self.grid.cells()];
                for (h, &c) in held.forces.iter().zip(&cells.cell) {
                    let k = h.coefficient_n_s_per_m;
                    drag_sum[c] += (h.gas_velocity_m_per_s * steps - cells.mean_velocity_sum_m_per_s[c]) * k;
                    k_sum[c] += k;
                }
                let half_per_volume = 0.5 * per_volume;
                for &c in &cells.occupied {
                    let (d, k, v_sum) = (drag_sum[c], k_sum[c], cells.mean_velocity_sum_m_per_s[c]);
                    let idx = self.cell_indices(c);
                    for a in 0..self.grid.axes() {
                        for face in self.cell_faces(idx, a) {
                            let exchange = &mut self.momentum_exchange[a];
                            exchange.add_transfer(face, -(half_per_volume * d[a]));
                            exchange.add_exchange_sums(
                                face,
                                half_per_volume * k * steps,
                                half_per_volume * k * v_sum[a],
                            );
                        }
                    }
                }
            }
        }
        self.held = held;
        self.held.valid = false;
    }

    /// The held-drag state for a checkpoint: `None` under the every-step scheme or before the first sub-step.
    pub fn held_snapshot(&self) -> Option<HeldDragSnapshot> {
        let held = &self.held;
        (self.drag_update == DragUpdate::EveryGasStep && held.valid).then(|| HeldDragSnapshot {
            position_m: held.evaluated_at.iter().map(|(x, _)| *x).collect(),
            velocity_m_per_s: held.evaluated_at.iter().map(|(_, v)| *v).collect(),
            velocity_sum_m_per_s: match self.drag_velocities {
                DragVelocities::Instantaneous => held.forces.iter().map(|f| f.velocity_sum_m_per_s).collect(),
                DragVelocities::CellAveraged => held
                    .cells
                    .cell
                    .iter()
                    .map(|&c| held.cells.mean_velocity_sum_m_per_s[c])
                    .collect(),
            },
        })
    }

    /// Evaluates the held values again from a checkpoint's positions and velocities at the evaluation (the frozen
    /// field must already be restored) and puts the velocity sums back.
    pub fn restore_held(&mut self, snap: &HeldDragSnapshot, radii_m: &[f64]) -> Result<(), String> {
        let n = radii_m.len();
        for (what, len) in [
            ("positions", snap.position_m.len()),
            ("velocities", snap.velocity_m_per_s.len()),
            ("velocity sums", snap.velocity_sum_m_per_s.len()),
        ] {
            if len != n {
                return Err(format!(
                    "the checkpoint's held drag has {len} {what}, the run {n} particles"
                ));
            }
        }
        self.evaluate_held(&snap.position_m, &snap.velocity_m_per_s, radii_m, None);
        let held = &mut self.held;
        match self.drag_velocities {
            DragVelocities::Instantaneous => {
                for (h, sum) in held.forces.iter_mut().zip(&snap.velocity_sum_m_per_s) {
                    h.velocity_sum_m_per_s = *sum;
                }
            }
            DragVelocities::CellAveraged => {
                for (&c, sum) in held.cells.cell.iter().zip(&snap.velocity_sum_m_per_s) {
                    held.cells.mean_velocity_sum_m_per_s[c] = *sum;
                }
            }
        }
        Ok(())
    }
}

/// Each occupied cell's volume-weighted mean particle velocity (seed 002 eq 35) from the velocities `v`, with the
/// cells held at the evaluation (serially in particle order, as the every-step scheme sums it).
fn held_mean_velocities(cells: &mut HeldCells, v: &[Vec3]) {
    for &c in &cells.occupied {
        cells.momentum[c] = Vec3::zeros();
    }
    for ((&c, &volume), v) in cells.cell.iter().zip(&cells.volume_m3).zip(v) {
        cells.momentum[c] += v * volume;
    }
    for &c in &cells.occupied {
        cells.mean_velocity_m_per_s[c] = cells.momentum[c] / cells.solid_volume_m3[c];
    }
}
