//! The gas's forces on particles under a frozen gas field, and their reaction on the gas.
//!
//! On particle i (seed 000 eq 2.67, seed 002 eq 28, viscous-stress term neglected as seed 002 does):
//! f_i = −V_i ∇p + K_i (u(x_i) − v_i), with u interpolated to the particle and K_i from the drag law at the
//! porosity of the particle's cell. The gas receives −K_i (u − v_i) (Newton's third law), spread to the faces with
//! the same trilinear weights that interpolated u (faces on a non-periodic boundary pass their share to the next
//! face inwards, so no momentum is lost). The pressure-gradient force is not returned to the gas: its momentum
//! equation carries −ε∇p ("model A", seed 002 eq 32).

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::coupling::{face_stencil, interpolate_component};
use super::grid::Grid;
use crate::engine::Vec3;
use crate::engine::models::drag::{DragInput, DragLaw};

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

/// Each particle's drag record of one step.
type DragRecord = (Vec3, f64, Vec3);

/// Runs `compute` for every particle (index, its drag record, its force), on `pool` when given. Particles are
/// independent, so the result is the same on any thread count.
fn per_particle<F>(pool: Option<&rayon::ThreadPool>, drag: &mut [DragRecord], force: &mut [Vec3], compute: F)
where
    F: Fn((usize, (&mut DragRecord, &mut Vec3))) + Sync + Send,
{
    match pool {
        Some(pool) => pool.install(|| {
            use rayon::prelude::*;
            drag.par_iter_mut()
                .zip(force.par_iter_mut())
                .enumerate()
                .with_min_len(256)
                .for_each(compute)
        }),
        None => drag.iter_mut().zip(force.iter_mut()).enumerate().for_each(compute),
    }
}

/// A frozen gas field and the reaction accumulated since it was frozen.
#[derive(Debug, Clone)]
pub struct FluidForces {
    pub grid: Grid,
    pub drag: DragLaw,
    pub drag_velocities: DragVelocities,
    pub gas_density_kg_per_m3: f64,
    pub gas_viscosity_pa_s: f64,
    /// Gas velocity on faces (copied from the gas solver).
    pub velocity_m_per_s: [Vec<f64>; 3],
    /// −∂p/∂x_a on the faces of component a, Pa/m.
    pub minus_pressure_gradient_pa_per_m: [Vec<f64>; 3],
    pub porosity: Vec<f64>,
    /// Σ over DEM steps of the force on the gas per unit volume at each face, N/m³ (divide by `steps`).
    pub reaction_n_per_m3: [Vec<f64>; 3],
    /// Σ over DEM steps of w K / V_cell at each face, N·s/m⁴: the exchange coefficient β the semi-implicit
    /// coupling puts into the gas momentum equation as −β u.
    pub beta_sum: [Vec<f64>; 3],
    /// Σ over DEM steps of w K v / V_cell at each face (v the particle velocity the drag used), N/m³: its +β v.
    pub beta_velocity_sum: [Vec<f64>; 3],
    pub steps: u32,
    /// Workspace: each particle's drag of the current step, its coefficient K and the particle velocity used.
    drag_buffer: Vec<DragRecord>,
}

impl FluidForces {
    pub fn new(grid: Grid, drag: DragLaw, gas_density_kg_per_m3: f64, gas_viscosity_pa_s: f64) -> Self {
        let zeros = |g: &Grid| -> [Vec<f64>; 3] { std::array::from_fn(|a| vec![0.0; g.faces(a)]) };
        FluidForces {
            velocity_m_per_s: zeros(&grid),
            minus_pressure_gradient_pa_per_m: zeros(&grid),
            reaction_n_per_m3: zeros(&grid),
            beta_sum: zeros(&grid),
            beta_velocity_sum: zeros(&grid),
            porosity: vec![1.0; grid.cells()],
            steps: 0,
            drag_buffer: Vec::new(),
            grid,
            drag,
            drag_velocities: DragVelocities::Instantaneous,
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
                        let g = if grid.periodic(a) {
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
        for r in self
            .reaction_n_per_m3
            .iter_mut()
            .chain(self.beta_sum.iter_mut())
            .chain(self.beta_velocity_sum.iter_mut())
        {
            r.iter_mut().for_each(|v| *v = 0.0);
        }
        self.steps = 0;
    }

    /// The trilinear weights of component `axis` at `x` ([`face_stencil`], the interpolation's own), each face
    /// moved inwards off a non-periodic boundary.
    fn weights(&self, axis: usize, x: &Vec3, out: &mut Vec<(usize, f64)>) {
        out.clear();
        let grid = &self.grid;
        let (stencil, count) = face_stencil(grid, axis, x);
        for &(mut idx, weight) in &stencil[..count] {
            if !grid.periodic(axis) && grid.n[axis] > 1 {
                idx[axis] = idx[axis].clamp(1, grid.n[axis] - 1);
            }
            out.push((grid.face(axis, idx), weight));
        }
    }

    /// The cell holding `x` (clamped into a non-periodic grid, wrapped on a periodic axis).
    fn cell_of(&self, x: &Vec3) -> [usize; 3] {
        let grid = &self.grid;
        std::array::from_fn(|a| {
            let c = ((x[a] - grid.origin_m[a]) / grid.h_m[a]).floor() as isize;
            let n = grid.n[a] as isize;
            if grid.periodic(a) {
                c.rem_euclid(n) as usize
            } else {
                c.clamp(0, n - 1) as usize
            }
        })
    }

    /// The faces bounding cell `c` along `axis` (low, high), moved inwards off a non-periodic boundary.
    fn cell_faces(&self, c: [usize; 3], axis: usize) -> [usize; 2] {
        let grid = &self.grid;
        let mut lo = c;
        let mut hi = c;
        hi[axis] += 1;
        if grid.periodic(axis) {
            hi[axis] %= grid.n[axis];
        } else if grid.n[axis] > 1 {
            lo[axis] = lo[axis].clamp(1, grid.n[axis] - 1);
            hi[axis] = hi[axis].clamp(1, grid.n[axis] - 1);
        }
        [grid.face(axis, lo), grid.face(axis, hi)]
    }

    /// The gas velocity at the centre of cell `c`: the mean of its two faces along each axis.
    fn cell_gas_velocity(&self, c: [usize; 3]) -> Vec3 {
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
    /// With a pool, the per-particle forces of the instantaneous method are computed on it (same bits).
    pub fn add_forces(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        force: &mut [Vec3],
        pool: Option<&rayon::ThreadPool>,
    ) {
        match self.drag_velocities {
            DragVelocities::Instantaneous => {
                self.add_forces_instantaneous(positions_m, velocities_m_per_s, radii_m, force, pool)
            }
            DragVelocities::CellAveraged => {
                self.add_forces_cell_averaged(positions_m, velocities_m_per_s, radii_m, force, pool)
            }
        }
        self.steps += 1;
    }

    fn add_forces_cell_averaged(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        force: &mut [Vec3],
        pool: Option<&rayon::ThreadPool>,
    ) {
        let grid = self.grid.clone();
        let cells: Vec<usize> = positions_m.iter().map(|x| grid.cell(self.cell_of(x))).collect();
        // Volume-weighted mean particle velocity per cell (seed 002 eq 35), serially in particle order.
        let mut volume = vec![0.0; grid.cells()];
        let mut momentum = vec![Vec3::zeros(); grid.cells()];
        for i in 0..positions_m.len() {
            let v = 4.0 / 3.0 * PI * radii_m[i].powi(3);
            volume[cells[i]] += v;
            momentum[cells[i]] += velocities_m_per_s[i] * v;
        }
        // Per occupied cell: v_sm, the slip, and K for the diameter of the cell's first particle (every particle
        // of that diameter in the cell has the same K, so the drag law runs once per cell for a monodisperse bed).
        let mut slip_of_cell = vec![Vec3::zeros(); grid.cells()];
        let mut k_of_cell = vec![(f64::NAN, 0.0); grid.cells()];
        for i in 0..positions_m.len() {
            let c = cells[i];
            if k_of_cell[c].0.is_nan() {
                let slip = self.cell_gas_velocity(self.cell_of(&positions_m[i])) - momentum[c] / volume[c];
                slip_of_cell[c] = slip;
                k_of_cell[c] = (radii_m[i], self.cell_drag_coefficient(c, &slip, radii_m[i]));
            }
        }
        let mut drag = std::mem::take(&mut self.drag_buffer);
        drag.resize(positions_m.len(), (Vec3::zeros(), 0.0, Vec3::zeros()));
        let this = &*self;
        let compute = |(i, (d, f)): (usize, (&mut DragRecord, &mut Vec3))| {
            let x = &positions_m[i];
            let k_cell = cells[i];
            let v_sm = momentum[k_cell] / volume[k_cell];
            let slip = slip_of_cell[k_cell];
            let (r_ref, k_ref) = k_of_cell[k_cell];
            let k = if radii_m[i] == r_ref {
                k_ref
            } else {
                this.cell_drag_coefficient(k_cell, &slip, radii_m[i])
            };
            let mut grad = Vec3::zeros();
            for a in 0..grid.axes() {
                grad[a] = interpolate_component(&grid, &this.minus_pressure_gradient_pa_per_m[a], a, x);
            }
            *d = (slip * k, k, v_sm);
            *f += d.0 + grad * (4.0 / 3.0 * PI * radii_m[i].powi(3));
        };
        per_particle(pool, &mut drag, force, compute);
        let cell_volume = grid.cell_volume_m3();
        for (x, (d, k, v)) in positions_m.iter().zip(&drag) {
            let c = self.cell_of(x);
            for a in 0..grid.axes() {
                for face in self.cell_faces(c, a) {
                    self.reaction_n_per_m3[a][face] -= 0.5 * d[a] / cell_volume;
                    self.beta_sum[a][face] += 0.5 * k / cell_volume;
                    self.beta_velocity_sum[a][face] += 0.5 * k * v[a] / cell_volume;
                }
            }
        }
        self.drag_buffer = drag;
    }

    /// K of a particle of radius `r` in cell `c` at slip `slip` (the cell-averaged method).
    fn cell_drag_coefficient(&self, c: usize, slip: &Vec3, r: f64) -> f64 {
        self.drag.coefficient_n_s_per_m(&DragInput {
            porosity: self.porosity[c],
            slip_speed_m_per_s: slip.norm(),
            diameter_m: 2.0 * r,
            gas_density_kg_per_m3: self.gas_density_kg_per_m3,
            gas_viscosity_pa_s: self.gas_viscosity_pa_s,
        })
    }

    /// The drag, its coefficient K and the total fluid force on particle i (instantaneous velocities).
    fn instantaneous_force(&self, x: &Vec3, v: &Vec3, r: f64) -> (Vec3, f64, Vec3) {
        let grid = &self.grid;
        let volume = 4.0 / 3.0 * PI * r * r * r;
        let eps = self.porosity[grid.cell(self.cell_of(x))];
        let mut u = Vec3::zeros();
        let mut grad = Vec3::zeros();
        for a in 0..grid.axes() {
            u[a] = interpolate_component(grid, &self.velocity_m_per_s[a], a, x);
            grad[a] = interpolate_component(grid, &self.minus_pressure_gradient_pa_per_m[a], a, x);
        }
        let slip = u - v;
        let k = self.drag.coefficient_n_s_per_m(&DragInput {
            porosity: eps,
            slip_speed_m_per_s: slip.norm(),
            diameter_m: 2.0 * r,
            gas_density_kg_per_m3: self.gas_density_kg_per_m3,
            gas_viscosity_pa_s: self.gas_viscosity_pa_s,
        });
        let drag = slip * k;
        (drag, k, drag + grad * volume)
    }

    fn add_forces_instantaneous(
        &mut self,
        positions_m: &[Vec3],
        velocities_m_per_s: &[Vec3],
        radii_m: &[f64],
        force: &mut [Vec3],
        pool: Option<&rayon::ThreadPool>,
    ) {
        // Per-particle forces are independent (any thread count gives the same bits); the reaction is then
        // scattered serially in particle order.
        let mut drag = std::mem::take(&mut self.drag_buffer);
        drag.resize(positions_m.len(), (Vec3::zeros(), 0.0, Vec3::zeros()));
        let this = &*self;
        let compute = |(i, (d, f)): (usize, (&mut DragRecord, &mut Vec3))| {
            let (dr, k, total) = this.instantaneous_force(&positions_m[i], &velocities_m_per_s[i], radii_m[i]);
            *d = (dr, k, velocities_m_per_s[i]);
            *f += total;
        };
        per_particle(pool, &mut drag, force, compute);
        let cell_volume = self.grid.cell_volume_m3();
        let mut weights = Vec::with_capacity(8);
        for (x, (d, k, v)) in positions_m.iter().zip(&drag) {
            for a in 0..self.grid.axes() {
                self.weights(a, x, &mut weights);
                for &(face, w) in &weights {
                    self.reaction_n_per_m3[a][face] -= w * d[a] / cell_volume;
                    self.beta_sum[a][face] += w * k / cell_volume;
                    self.beta_velocity_sum[a][face] += w * k * v[a] / cell_volume;
                }
            }
        }
        self.drag_buffer = drag;
    }

    /// The mean reaction per unit volume over the DEM steps since the last freeze (the gas's momentum source).
    pub fn mean_reaction(&self) -> [Vec<f64>; 3] {
        Self::mean(&self.reaction_n_per_m3, self.steps)
    }

    /// The semi-implicit form of the same exchange: (β, β v) per face, averaged over the DEM steps since the last
    /// freeze; the gas then feels −β u_new + β v.
    pub fn mean_exchange(&self) -> ([Vec<f64>; 3], [Vec<f64>; 3]) {
        (
            Self::mean(&self.beta_sum, self.steps),
            Self::mean(&self.beta_velocity_sum, self.steps),
        )
    }

    fn mean(sum: &[Vec<f64>; 3], steps: u32) -> [Vec<f64>; 3] {
        let n = f64::from(steps.max(1));
        std::array::from_fn(|a| sum[a].iter().map(|v| v / n).collect())
    }
}
