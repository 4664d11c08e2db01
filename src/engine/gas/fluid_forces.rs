//! The gas's forces on particles under a frozen gas field, and their reaction on the gas.
//!
//! On particle i (seed 000 eq 2.67, seed 002 eq 28, viscous-stress term neglected as seed 002 does):
//! f_i = −V_i ∇p + K_i (u(x_i) − v_i), with u interpolated to the particle and K_i from the drag law at the
//! porosity of the particle's cell. The gas receives −K_i (u − v_i) (Newton's third law), spread to the faces with
//! the same trilinear weights that interpolated u. The share that falls on a face of a non-periodic boundary (an
//! inlet, a wall, an outlet) is the momentum of that face's half-cell control volume: the boundary, whose normal
//! velocity is prescribed, takes it (it shows up as the boundary's pressure), and the reaction arrays keep it, so
//! they still sum to exactly what the particles got. (Moving it to the next face inwards instead doubled the
//! pressure step between the first two cell layers and put the measured bed pressure drop 2 % above the bed's
//! weight in D1: 1.019-1.028 W/A, against 0.990-1.005 without.) The pressure-gradient force is not returned to the
//! gas: its momentum equation carries −ε∇p ("model A", seed 002 eq 32).

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::coupling::{FaceLattice, Stencil, floor_to_isize};
use super::exchange_accumulator::ExchangeAccumulator;
use super::grid::Grid;
use super::held_drag::{DragUpdate, HeldDrag};
use crate::engine::Vec3;
use crate::engine::models::drag::{DragInput, DragLaw};
use crate::engine::team::Team;

/// How the gas receives the drag (the particles always get K (u − v) under the frozen field).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DragCoupling {
    /// The gas gets exactly −Σ K (u − v) the particles got, as an explicit source: momentum is conserved to
    /// rounding; stable while the gas step is below about 2 ρ_g ε / β.
    #[default]
    Explicit,
    /// The gas gets −β u_new + β v with β = Σ w K / V (CFDEM's implicit coupling): unconditionally stable in the
    /// exchange term; the momentum it receives differs from the particles' by Σ K (u_new − u_frozen) (the change
    /// of the gas velocity over one gas step).
    SemiImplicit,
}

/// Which velocities the drag on a particle is computed from (seed 002 §3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DragVelocities {
    /// The particle's own velocity and the gas velocity interpolated to it (seed 002 method 2).
    #[default]
    Instantaneous,
    /// The cell's mean particle velocity and the gas velocity at the cell centre (seed 002 method 1).
    CellAveraged,
}

/// Each particle's drag record of one step: the drag, its coefficient K and the particle velocity used.
type DragRecord = (Vec3, f64, Vec3);

/// The same with the interpolation's stencils of the velocity components, which spread the reaction (instantaneous
/// velocities): computed once per particle and step, not again for the scatter.
type StencilDragRecord = (DragRecord, [Stencil; 3]);

/// Runs `compute` for every particle (index, its drag record, its force), on `team` when given (a few contiguous
/// blocks of particles per thread). Particles are independent, so the result is the same on any thread count.
pub(super) fn per_particle<R, S, F>(team: Option<&Team>, drag: &mut [R], force: &mut [S], compute: F)
where
    R: Send,
    S: Send,
    F: Fn((usize, (&mut R, &mut S))) + Sync + Send,
{
    match team {
        Some(team) if team.size() > 1 => {
            let block = drag.len().div_ceil(4 * team.size()).max(1);
            let parts: Vec<(usize, &mut [R], &mut [S])> = drag
                .chunks_mut(block)
                .zip(force.chunks_mut(block))
                .enumerate()
                .map(|(k, (d, f))| (k * block, d, f))
                .collect();
            team.map_parts(parts, |_, (start, d, f)| {
                d.iter_mut()
                    .zip(f.iter_mut())
                    .enumerate()
                    .for_each(|(i, pair)| compute((start + i, pair)))
            });
        }
        _ => drag.iter_mut().zip(force.iter_mut()).enumerate().for_each(compute),
    }
}

/// A frozen gas field and the reaction accumulated since it was frozen.
#[derive(Debug, Clone)]
pub struct FluidForces {
    pub grid: Grid,
    pub drag: DragLaw,
    pub drag_velocities: DragVelocities,
    /// When K, u(x_i) and ∇p(x_i) are evaluated: every DEM step, or once per gas step and held (`held_drag.rs`).
    pub drag_update: DragUpdate,
    pub gas_density_kg_per_m3: f64,
    pub gas_viscosity_pa_s: f64,
    /// Gas velocity on faces (copied from the gas solver).
    pub velocity_m_per_s: [Vec<f64>; 3],
    /// −∂p/∂x_a on the faces of component a, Pa/m.
    pub minus_pressure_gradient_pa_per_m: [Vec<f64>; 3],
    pub porosity: Vec<f64>,
    /// Cells outside the gas (the solver's `blocked`), or empty: the faces between them and the gas carry no
    /// pressure gradient (a blocked cell's pressure is not the gas's).
    pub blocked: Vec<bool>,
    /// The momentum exchange since the freeze, one accumulator per velocity component over its faces: the
    /// transfer is the force on the gas per unit volume, N/m³ (the reaction to drag); the coefficient is w K /
    /// V_cell, N·s/m⁴ (the β the semi-implicit coupling puts into the gas momentum equation as −β u); the
    /// coefficient-value sum is w K v / V_cell, N/m³ (its +β v, v the particle velocity the drag used).
    pub momentum_exchange: [ExchangeAccumulator; 3],
    /// The trilinear lattices of the three velocity components (built from `grid`).
    lattice: [FaceLattice; 3],
    inverse_h_per_m: [f64; 3],
    periodic: [bool; 3],
    workspace: Workspace,
    pub(super) held: HeldDrag,
}

/// Per-step scratch arrays, kept between steps to avoid allocations.
#[derive(Debug, Clone, Default)]
struct Workspace {
    /// Each particle's drag of the current step, its coefficient K and the particle velocity used (cell-averaged
    /// velocities), or the same with the particle's stencils (instantaneous).
    drag: Vec<DragRecord>,
    stencil_drag: Vec<StencilDragRecord>,
    /// Each particle's cell.
    cell: Vec<usize>,
    /// Per cell (cell-averaged drag): particle volume, Σ V v, the slip, K of the first particle's radius, Σ drag,
    /// Σ K; and the occupied cells in order of first occupation.
    solid_volume_m3: Vec<f64>,
    momentum: Vec<Vec3>,
    slip_m_per_s: Vec<Vec3>,
    reference_k: Vec<(f64, f64)>,
    drag_sum_n: Vec<Vec3>,
    k_sum_n_s_per_m: Vec<f64>,
    occupied: Vec<usize>,
}

impl FluidForces {
    pub fn new(grid: Grid, drag: DragLaw, gas_density_kg_per_m3: f64, gas_viscosity_pa_s: f64) -> Self {
        let zeros = |g: &Grid| -> [Vec<f64>; 3] { std::array::from_fn(|a| vec![0.0; g.faces(a)]) };
        FluidForces {
            velocity_m_per_s: zeros(&grid),
            minus_pressure_gradient_pa_per_m: zeros(&grid),
            momentum_exchange: std::array::from_fn(|a| ExchangeAccumulator::new(grid.faces(a))),
            porosity: vec![1.0; grid.cells()],
            blocked: Vec::new(),
            lattice: std::array::from_fn(|a| FaceLattice::new(&grid, a)),
            inverse_h_per_m: std::array::from_fn(|a| 1.0 / grid.h_m[a]),
            periodic: std::array::from_fn(|a| grid.periodic(a)),
            workspace: Workspace::default(),
            held: HeldDrag::default(),
            grid,
            drag,
            drag_velocities: DragVelocities::Instantaneous,
            drag_update: DragUpdate::EveryDemStep,
            gas_density_kg_per_m3,
            gas_viscosity_pa_s,
        }
    }

    /// Freezes a new gas field: velocities, −∇p on faces from cell pressures, porosity; clears the reaction.
    pub fn freeze(&mut self, velocity_m_per_s: &[Vec<f64>; 3], pressure_pa: &[f64], porosity: &[f64]) {
        let grid = &self.grid;
        for a in 0..grid.axes() {
            self.velocity_m_per_s[a].copy_from_slice(&velocity_m_per_s[a]);
            let dims = grid.face_dims(a);
            let n = grid.n[a];
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        let idx = [i, j, k];
                        let along = idx[a];
                        let cell = |at: usize| {
                            let mut c = idx;
                            c[a] = at;
                            pressure_pa[grid.cell(c)]
                        };
                        let g = if super::simple::face_touches_blocked(grid, &self.blocked, a, idx) {
                            0.0
                        } else if grid.periodic(a) {
                            (cell((along + n - 1) % n) - cell(along % n)) / grid.h_m[a]
                        } else if n == 1 {
                            0.0
                        } else {
                            // Boundary faces take the gradient of the next face inwards.
                            let lo = along.clamp(1, n - 1);
                            (cell(lo - 1) - cell(lo)) / grid.h_m[a]
                        };
                        self.minus_pressure_gradient_pa_per_m[a][grid.face(a, idx)] = g;
                    }
                }
            }
        }
        self.porosity.copy_from_slice(porosity);
        self.momentum_exchange.iter_mut().for_each(ExchangeAccumulator::clear);
        self.held.valid = false;
    }

    /// The cell holding `x` (clamped into a non-periodic grid, wrapped on a periodic axis), as a flat index.
    pub(crate) fn cell_of(&self, x: &Vec3) -> usize {
        let grid = &self.grid;
        grid.cell(std::array::from_fn(|a| {
            let c = floor_to_isize((x[a] - grid.origin_m[a]) * self.inverse_h_per_m[a]);
            let n = grid.n[a] as isize;
            if (0..n).contains(&c) {
                c as usize
            } else if self.periodic[a] {
                c.rem_euclid(n) as usize
            } else {
                c.clamp(0, n - 1) as usize
            }
        }))
    }

    /// The cell's index triple from its flat index.
    pub(crate) fn cell_indices(&self, c: usize) -> [usize; 3] {
        let n = self.grid.n;
        [c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])]
    }

    /// The faces bounding cell `c` along `axis` (low, high).
    pub(super) fn cell_faces(&self, c: [usize; 3], axis: usize) -> [usize; 2] {
        let grid = &self.grid;
        let lo = c;
        let mut hi = c;
        hi[axis] += 1;
        if grid.periodic(axis) {
            hi[axis] %= grid.n[axis];
        }
        [grid.face(axis, lo), grid.face(axis, hi)]
    }

    /// The gas velocity at the centre of cell `c`: the mean of its two faces along each axis.
    pub(crate) fn cell_gas_velocity(&self, c: [usize; 3]) -> Vec3 {
        let grid = &self.grid;
        let mut u = Vec3::zeros();
        for a in 0..grid.axes() {
            let mut hi = c;
            hi[a] += 1;
            if grid.periodic(a) {
                hi[a] %= grid.n[a];
            }
            let v = &self.velocity_m_per_s[a];
            u[a] = 0.5 * (v[grid.face(a, c)] + v[grid.face(a, hi)]);
        }
        u
    }

    /// Adds the gas's force on each particle to `force` and accumulates the reaction on the gas for one DEM step.
    /// With a team, the per-particle forces are computed on it (same bits: the reaction is summed serially).
    pub fn add_forces(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        force: &mut [Vec3],
        team: Option<&Team>,
    ) {
        match (self.drag_update, self.drag_velocities) {
            (DragUpdate::EveryGasStep, _) => {
                self.add_held_forces(positions_m, velocities_m_per_s, radii_m, force, team)
            }
            (DragUpdate::EveryDemStep, DragVelocities::Instantaneous) => {
                self.add_forces_instantaneous(positions_m, velocities_m_per_s, radii_m, force, team)
            }
            (DragUpdate::EveryDemStep, DragVelocities::CellAveraged) => {
                self.add_forces_cell_averaged(positions_m, velocities_m_per_s, radii_m, force, team)
            }
        }
        self.momentum_exchange
            .iter_mut()
            .for_each(ExchangeAccumulator::end_sub_step);
    }

    /// The interpolation stencil of velocity component `a` at `x`.
    pub(super) fn lattice_stencil(&self, a: usize, x: &Vec3) -> Stencil {
        self.lattice[a].stencil(x)
    }

    /// −∇p interpolated to `x`.
    #[inline]
    fn minus_pressure_gradient_at(&self, x: &Vec3) -> Vec3 {
        let mut grad = Vec3::zeros();
        for a in 0..self.grid.axes() {
            grad[a] = self.lattice[a].interpolate(&self.minus_pressure_gradient_pa_per_m[a], x);
        }
        grad
    }

    fn add_forces_cell_averaged(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        force: &mut [Vec3],
        team: Option<&Team>,
    ) {
        let mut ws = std::mem::take(&mut self.workspace);
        let cells = self.grid.cells();
        ws.cell.clear();
        ws.cell.extend(positions_m.iter().map(|x| self.cell_of(x)));
        ws.solid_volume_m3.resize(cells, 0.0);
        ws.momentum.resize(cells, Vec3::zeros());
        ws.slip_m_per_s.resize(cells, Vec3::zeros());
        ws.reference_k.resize(cells, (0.0, 0.0));
        ws.drag_sum_n.resize(cells, Vec3::zeros());
        ws.k_sum_n_s_per_m.resize(cells, 0.0);
        // Volume-weighted mean particle velocity per cell (seed 002 eq 35), serially in particle order.
        ws.occupied.clear();
        for (i, &c) in ws.cell.iter().enumerate() {
            let v = 4.0 / 3.0 * PI * radii_m[i].powi(3);
            if ws.solid_volume_m3[c] == 0.0 {
                ws.occupied.push(c);
                ws.momentum[c] = Vec3::zeros();
                ws.drag_sum_n[c] = Vec3::zeros();
                ws.k_sum_n_s_per_m[c] = 0.0;
                // K for the diameter of the cell's first particle: every particle of that diameter in the cell has
                // the same K, so the drag law runs once per cell for a monodisperse bed.
                ws.reference_k[c].0 = radii_m[i];
            }
            ws.solid_volume_m3[c] += v;
            ws.momentum[c] += velocities_m_per_s[i] * v;
        }
        // Per occupied cell: the slip between the gas at the cell centre and v_sm, and K.
        for &c in &ws.occupied {
            let v_sm = ws.momentum[c] / ws.solid_volume_m3[c];
            let slip = self.cell_gas_velocity(self.cell_indices(c)) - v_sm;
            ws.slip_m_per_s[c] = slip;
            ws.momentum[c] = v_sm;
            ws.reference_k[c].1 = self.cell_drag_coefficient(c, &slip, ws.reference_k[c].0);
        }
        let mut drag = std::mem::take(&mut ws.drag);
        drag.resize(positions_m.len(), (Vec3::zeros(), 0.0, Vec3::zeros()));
        let (this, ws_ref) = (&*self, &ws);
        let compute = |(i, (d, f)): (usize, (&mut DragRecord, &mut Vec3))| {
            let c = ws_ref.cell[i];
            let slip = ws_ref.slip_m_per_s[c];
            let (r_ref, k_ref) = ws_ref.reference_k[c];
            let k = if radii_m[i] == r_ref {
                k_ref
            } else {
                this.cell_drag_coefficient(c, &slip, radii_m[i])
            };
            let grad = this.minus_pressure_gradient_at(&positions_m[i]);
            *d = (slip * k, k, ws_ref.momentum[c]);
            *f += d.0 + grad * (4.0 / 3.0 * PI * radii_m[i].powi(3));
        };
        per_particle(team, &mut drag, force, compute);
        // The reaction per cell (serially in particle order), then half of it to each of the cell's two faces
        // along each axis.
        for (&c, (d, k, _)) in ws.cell.iter().zip(&drag) {
            ws.drag_sum_n[c] += d;
            ws.k_sum_n_s_per_m[c] += k;
        }
        let half_per_volume = 0.5 / self.grid.cell_volume_m3();
        for &c in &ws.occupied {
            let (d, k, v_sm) = (ws.drag_sum_n[c], ws.k_sum_n_s_per_m[c], ws.momentum[c]);
            let idx = self.cell_indices(c);
            for a in 0..self.grid.axes() {
                let faces = self.cell_faces(idx, a);
                let exchange = &mut self.momentum_exchange[a];
                for face in faces {
                    // x + (−y) is x − y to the bit (IEEE 754 subtraction is addition of the negation).
                    exchange.add_transfer(face, -(half_per_volume * d[a]));
                    exchange.add_exchange(face, half_per_volume * k, v_sm[a]);
                }
            }
            ws.solid_volume_m3[c] = 0.0;
        }
        ws.drag = drag;
        self.workspace = ws;
    }

    /// K of a particle of radius `r` in cell `c` at slip `slip` (the cell-averaged method).
    pub(super) fn cell_drag_coefficient(&self, c: usize, slip: &Vec3, r: f64) -> f64 {
        self.drag.coefficient_n_s_per_m(&DragInput {
            porosity: self.porosity[c],
            slip_speed_m_per_s: slip.norm(),
            diameter_m: 2.0 * r,
            gas_density_kg_per_m3: self.gas_density_kg_per_m3,
            gas_viscosity_pa_s: self.gas_viscosity_pa_s,
        })
    }

    /// K, the gas velocity u and the pressure force −V∇p at a particle at `x` moving at `v` with radius `r`, with
    /// the stencils of the velocity components at `x` in `stencils`.
    pub(super) fn evaluate(&self, x: &Vec3, v: &Vec3, r: f64, stencils: &mut [Stencil; 3]) -> (f64, Vec3, Vec3) {
        let volume = 4.0 / 3.0 * PI * r * r * r;
        let eps = self.porosity[self.cell_of(x)];
        let mut u = Vec3::zeros();
        let mut grad = Vec3::zeros();
        for a in 0..self.grid.axes() {
            let stencil = self.lattice[a].stencil(x);
            u[a] = stencil.apply(&self.velocity_m_per_s[a]);
            grad[a] = stencil.apply(&self.minus_pressure_gradient_pa_per_m[a]);
            stencils[a] = stencil;
        }
        let slip = u - v;
        let k = self.drag.coefficient_n_s_per_m(&DragInput {
            porosity: eps,
            slip_speed_m_per_s: slip.norm(),
            diameter_m: 2.0 * r,
            gas_density_kg_per_m3: self.gas_density_kg_per_m3,
            gas_viscosity_pa_s: self.gas_viscosity_pa_s,
        });
        (k, u, grad * volume)
    }

    /// The drag, its coefficient K and the total fluid force on particle i (instantaneous velocities), with the
    /// stencils of the velocity components at `x` in `stencils`.
    fn instantaneous_force(&self, x: &Vec3, v: &Vec3, r: f64, stencils: &mut [Stencil; 3]) -> (Vec3, f64, Vec3) {
        let (k, u, pressure_force) = self.evaluate(x, v, r, stencils);
        let drag = (u - v) * k;
        (drag, k, drag + pressure_force)
    }

    fn add_forces_instantaneous(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        force: &mut [Vec3],
        team: Option<&Team>,
    ) {
        // Per-particle forces are independent (any thread count gives the same bits); the reaction is then
        // scattered serially in particle order, with the interpolation's weights.
        let mut drag = std::mem::take(&mut self.workspace.stencil_drag);
        drag.resize(positions_m.len(), Default::default());
        let this = &*self;
        let compute = |(i, (d, f)): (usize, (&mut StencilDragRecord, &mut Vec3))| {
            let (record, stencils) = d;
            let (dr, k, total) =
                this.instantaneous_force(&positions_m[i], &velocities_m_per_s[i], radii_m[i], stencils);
            *record = (dr, k, velocities_m_per_s[i]);
            *f += total;
        };
        per_particle(team, &mut drag, force, compute);
        let per_volume = 1.0 / self.grid.cell_volume_m3();
        for ((d, k, v), stencils) in &drag {
            for (a, stencil) in stencils.iter().enumerate().take(self.grid.axes()) {
                let exchange = &mut self.momentum_exchange[a];
                for c in 0..stencil.count {
                    let (face, w) = (stencil.face[c], stencil.weight[c] * per_volume);
                    exchange.add_transfer(face, -(w * d[a]));
                    exchange.add_exchange(face, w * k, v[a]);
                }
            }
        }
        self.workspace.stencil_drag = drag;
    }

    /// The mean reaction per unit volume over the DEM steps since the last freeze (the gas's momentum source).
    pub fn mean_reaction(&self) -> [Vec<f64>; 3] {
        std::array::from_fn(|a| self.momentum_exchange[a].mean_transfer())
    }

    /// The semi-implicit form of the same exchange: (β, β v) per face, averaged over the DEM steps since the last
    /// freeze; the gas then feels −β u_new + β v.
    pub fn mean_exchange(&self) -> ([Vec<f64>; 3], [Vec<f64>; 3]) {
        (
            std::array::from_fn(|a| self.momentum_exchange[a].mean_coefficient()),
            std::array::from_fn(|a| self.momentum_exchange[a].mean_coefficient_value()),
        )
    }

    /// DEM sub-steps accumulated since the last freeze.
    pub fn steps(&self) -> u32 {
        self.momentum_exchange[0].steps
    }
}
