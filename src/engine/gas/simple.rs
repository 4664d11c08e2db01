//! The volume-averaged gas equations (seed 000 eqs 2.23–2.24) on the staggered grid, implicit in time, solved by
//! SIMPLE pressure correction (Patankar 1980; seed 000 §2.2.2, eqs 2.42–2.65):
//!
//! ∂(ερ_g)/∂t + ∇·(ερ_g u) = 0,
//! ∂(ερ_g u)/∂t + ∇·(ερ_g uu) = −ε∇p − ∇·(ετ_g) + ερ_g g + S,
//!
//! with ρ_g constant, τ_g = −μ∇u (the ε-weighted Laplacian form), and S a momentum source per unit volume (the
//! particles' reaction to drag, or a driving pressure gradient). Convection is upwind or hybrid (Spalding:
//! central differences where the cell Péclet number is below 2, upwind above), diffusion central.
//!
//! Each time step: outer iterations of (momentum predictor with the current pressure → pressure correction from
//! continuity → corrected pressure and velocities), under-relaxed, until the mass imbalance is below tolerance.
//! Momentum systems go to BiCGStab (Jacobi-preconditioned), the pressure correction to conjugate gradients
//! preconditioned by diagonal incomplete Cholesky.

use serde::{Deserialize, Serialize};

use super::boundary_velocities::Outlets;
use super::grid::{Boundary, Grid, side};
use super::linsolve::{
    KrylovWorkspace, NEIGHBOURS, NONE, PressureSolver, SolveReport, StencilSystem, bandwidth, bicgstab_in,
    conjugate_gradient, direct_symmetric,
};
use super::momentum_rows::{Across, MomentumRow, NeighbourFace, momentum_rows};
use super::piso::PressureVelocity;
use super::pressure_sides::{PressureSide, pressure_sides};

/// The convection scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Convection {
    Upwind,
    Hybrid,
}

/// Gas properties and numerical settings.
#[derive(Debug, Clone, PartialEq)]
pub struct GasConfig {
    pub grid: Grid,
    pub density_kg_per_m3: f64,
    pub viscosity_pa_s: f64,
    pub gravity_m_per_s2: [f64; 3],
    pub convection: Convection,
    /// Under-relaxation of the momentum predictor (0–1].
    pub relax_velocity: f64,
    /// Under-relaxation of the pressure correction (0–1].
    pub relax_pressure: f64,
    pub max_outer_iterations: usize,
    /// Outer iterations stop when the mass imbalance, relative to the total face mass flow, is below this ...
    pub mass_tolerance: f64,
    /// ... and the largest velocity change of the iteration, relative to the largest velocity, below this.
    pub velocity_tolerance: f64,
    pub linear_tolerance: f64,
    pub max_linear_iterations: usize,
    /// How the pressure corrections are solved.
    pub pressure_solver: PressureSolver,
    /// How pressure and velocity are coupled within a gas step: SIMPLE's outer iterations to the tolerances, or
    /// PISO's predictor and fixed number of corrections.
    pub pressure_velocity: PressureVelocity,
    /// Boundary faces through which gas enters at their own velocity (jets through chosen distributor cells),
    /// overriding what their side says.
    pub inlet_faces: Vec<InletFace>,
    /// Inflow switched on gradually: every inlet side and inlet face is multiplied by its factor at the step's end
    /// time. `None`: full inflow from the start.
    pub inflow_ramp: Option<InflowRamp>,
    /// Inflow changed in steps (a defluidization/fluidization cycle): multiplies the ramp's factor.
    pub inflow_levels: Option<InflowLevels>,
    /// Cells outside the gas domain (solid: a kiln wall's outside), one flag per cell, or empty for none. Their
    /// faces are no-slip walls, at rest or moving with `blocked_wall_motion`.
    pub blocked: Vec<bool>,
    /// The blocked cells' walls turn about an axis (a rotary kiln's drum): the gas beside them takes the wall's
    /// tangential velocity ω × (x − x_axis) at the wall, half a cell from the face's centre. `None`: at rest.
    pub blocked_wall_motion: Option<BlockedWallMotion>,
    /// A cell whose pressure is held at the reference 0 and whose mass balance is not enforced (seed 000's kiln:
    /// "the reference pressure 0 is designated on top of the kiln"): in a domain closed by walls and blocked cells
    /// it takes up the gas volume that moving particles displace. `None`: every open cell balances its mass.
    pub pressure_reference_cell: Option<usize>,
}

/// The rotation of the blocked cells' walls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockedWallMotion {
    pub axis_point_m: [f64; 3],
    /// Unit axis (right-handed rotation).
    pub axis: [f64; 3],
    pub angular_velocity_rad_per_s: f64,
}

impl BlockedWallMotion {
    /// The wall's velocity at `x`, m/s.
    pub fn velocity_at(&self, x: [f64; 3]) -> [f64; 3] {
        let (a, w) = (self.axis, self.angular_velocity_rad_per_s);
        let r: [f64; 3] = std::array::from_fn(|k| x[k] - self.axis_point_m[k]);
        [
            w * (a[1] * r[2] - a[2] * r[1]),
            w * (a[2] * r[0] - a[0] * r[2]),
            w * (a[0] * r[1] - a[1] * r[0]),
        ]
    }
}

/// One boundary face with a prescribed normal velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InletFace {
    /// The axis the face is normal to.
    pub axis: usize,
    /// The face's index among that axis's faces (`Grid::face`).
    pub face: usize,
    /// Velocity along `axis`, m/s (positive along the axis: into the domain on the low side).
    pub velocity_m_per_s: f64,
}

/// Inflow that is off until `start_s` and then rises linearly to its full value over `duration_s` (a bed that
/// settles under gravity before the blower starts, as in an experiment; all runs of a velocity sweep then start
/// from the same packing).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InflowRamp {
    pub start_s: f64,
    #[serde(default)]
    pub duration_s: f64,
}

impl InflowRamp {
    /// The fraction of the full inflow at `time_s`: 0 up to `start_s`, 1 from `start_s + duration_s` on.
    pub fn factor(&self, time_s: f64) -> f64 {
        if time_s <= self.start_s {
            0.0
        } else if time_s >= self.start_s + self.duration_s {
            1.0
        } else {
            (time_s - self.start_s) / self.duration_s
        }
    }
}

/// Inflow held at a sequence of levels (seed 001 §6.4.2.1's hysteresis cycle: 0.1 s per level, down from bubbling
/// to zero and back up): from `start_s` on, level k multiplies every inlet side and jet during
/// [start_s + k hold_s, start_s + (k + 1) hold_s); before `start_s` the factor is 1, after the last level the last
/// level holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InflowLevels {
    #[serde(default)]
    pub start_s: f64,
    pub hold_s: f64,
    /// Multipliers of the inlet velocities, one per level.
    pub factors: Vec<f64>,
}

impl InflowLevels {
    /// The level at `time_s` (`None` before the first).
    pub fn level(&self, time_s: f64) -> Option<usize> {
        if time_s < self.start_s || self.factors.is_empty() {
            return None;
        }
        let k = ((time_s - self.start_s) / self.hold_s).floor() as usize;
        Some(k.min(self.factors.len() - 1))
    }

    pub fn factor(&self, time_s: f64) -> f64 {
        self.level(time_s).map_or(1.0, |k| self.factors[k])
    }
}

/// The gas state: everything a checkpoint needs.
#[derive(Debug, Clone, PartialEq)]
pub struct GasState {
    /// Pressure at cell centres, Pa (relative: only its gradient acts when no boundary fixes it).
    pub pressure_pa: Vec<f64>,
    /// Velocity components on their faces, m/s: `velocity[a]` has `grid.faces(a)` values.
    pub velocity_m_per_s: [Vec<f64>; 3],
    /// Gas volume fraction ε at cell centres.
    pub porosity: Vec<f64>,
    pub time_s: f64,
}

/// How one gas step went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    pub outer_iterations: usize,
    pub mass_imbalance: f64,
    /// Largest velocity change of the last outer iteration relative to the largest velocity.
    pub velocity_change: f64,
    pub converged: bool,
    pub momentum: SolveReport,
    pub pressure: SolveReport,
    /// Wall time in the linear solvers (the rest of the step is assembly and corrections), s.
    pub linear_solve_s: f64,
}

impl GasState {
    pub fn new(grid: &Grid) -> Self {
        GasState {
            pressure_pa: vec![0.0; grid.cells()],
            velocity_m_per_s: std::array::from_fn(|a| vec![0.0; grid.faces(a)]),
            porosity: vec![1.0; grid.cells()],
            time_s: 0.0,
        }
    }
}

/// Index arithmetic with periodic wrapping: `i + delta` along `axis`, or `None` outside a non-periodic grid.
pub(crate) fn step_cell(grid: &Grid, mut i: [usize; 3], axis: usize, delta: isize) -> Option<[usize; 3]> {
    let n = grid.n[axis] as isize;
    let j = i[axis] as isize + delta;
    if (0..n).contains(&j) {
        i[axis] = j as usize;
        Some(i)
    } else if grid.periodic(axis) {
        i[axis] = j.rem_euclid(n) as usize;
        Some(i)
    } else {
        None
    }
}

pub(crate) fn all_indices(dims: [usize; 3]) -> impl Iterator<Item = [usize; 3]> {
    (0..dims[2]).flat_map(move |k| (0..dims[1]).flat_map(move |j| (0..dims[0]).map(move |i| [i, j, k])))
}

/// Boundary velocity (all three components) on a side; an inlet's is multiplied by `inflow_factor`.
fn side_velocity(b: Boundary, inflow_factor: f64) -> [f64; 3] {
    match b {
        Boundary::Wall { velocity_m_per_s } => velocity_m_per_s,
        Boundary::Inlet { velocity_m_per_s } => velocity_m_per_s.map(|v| v * inflow_factor),
        Boundary::Periodic | Boundary::Outlet => [0.0; 3],
    }
}

/// The gas solver: configuration, state, and the work arrays of the last step.
pub struct GasSolver {
    pub config: GasConfig,
    pub state: GasState,
    /// Per component: the face of each unknown.
    face_of: [Vec<usize>; 3],
    /// Per component and face: ε_f A / a_P of the last momentum assembly (the pressure-correction coefficient).
    d: [Vec<f64>; 3],
    /// Per component and face: gas enters here from a plenum (an inlet side or an inlet face), so the face's
    /// porosity is 1 and its velocity is the superficial velocity.
    pub(super) plenum: [Vec<bool>; 3],
    /// The inflow ramp's factor at the end of the current step (1 without a ramp).
    pub(super) inflow_factor: f64,
    /// Per component: the index work of each unknown's momentum row, done when the solver is built (the grid, its
    /// blocked cells and boundaries do not change after).
    rows: [Vec<MomentumRow>; 3],
    /// Per cell (in cell order), its faces along each axis, low side first: see [`PressureSide`].
    pressure_sides: Vec<PressureSide>,
    /// Per component: its momentum solves' storage, reused from one solve to the next (no state: see
    /// [`KrylovWorkspace`]; one per component, whose stencils differ, so that each keeps its compacted structure).
    krylov: [KrylovWorkspace; 3],
}

impl GasSolver {
    pub fn new(config: GasConfig) -> Result<Self, String> {
        config.grid.check()?;
        let grid = &config.grid;
        if !config.blocked.is_empty() && config.blocked.len() != grid.cells() {
            return Err(format!(
                "blocked cells: expected one flag per cell ({}), got {}",
                grid.cells(),
                config.blocked.len()
            ));
        }
        let mut unknown: [Vec<u32>; 3] = std::array::from_fn(|a| vec![NONE; grid.faces(a)]);
        let mut face_of: [Vec<usize>; 3] = Default::default();
        for a in 0..grid.axes() {
            for idx in all_indices(grid.face_dims(a)) {
                let along = idx[a];
                let solved = if grid.periodic(a) {
                    along < grid.n[a]
                } else {
                    along > 0 && along < grid.n[a]
                } && !face_touches_blocked(grid, &config.blocked, a, idx);
                if solved {
                    let f = grid.face(a, idx);
                    unknown[a][f] = face_of[a].len() as u32;
                    face_of[a].push(f);
                }
            }
        }
        let d = std::array::from_fn(|a| vec![0.0; grid.faces(a)]);
        let mut plenum: [Vec<bool>; 3] = std::array::from_fn(|a| vec![false; grid.faces(a)]);
        for a in 0..grid.axes() {
            for idx in all_indices(grid.face_dims(a)) {
                let along = idx[a];
                if !grid.periodic(a)
                    && (along == 0 || along == grid.n[a])
                    && !face_touches_blocked(grid, &config.blocked, a, idx)
                {
                    let b = grid.boundary[side(a, along == grid.n[a])];
                    plenum[a][grid.face(a, idx)] = matches!(b, Boundary::Inlet { .. });
                }
            }
        }
        for (k, f) in config.inlet_faces.iter().enumerate() {
            let on_boundary = f.axis < grid.axes()
                && f.face < grid.faces(f.axis)
                && !grid.periodic(f.axis)
                && matches!(face_index(grid, f.axis, f.face)[f.axis], x if x == 0 || x == grid.n[f.axis]);
            if !on_boundary {
                return Err(format!(
                    "inlet face {k} is not a face on a non-periodic boundary of the grid"
                ));
            }
            plenum[f.axis][f.face] = true;
        }
        let rows = std::array::from_fn(|c| {
            momentum_rows(
                grid,
                &config.blocked,
                config.blocked_wall_motion,
                &unknown[c],
                &face_of[c],
                c,
            )
        });
        let pressure_sides = pressure_sides(grid, &unknown);
        let mut solver = GasSolver {
            state: GasState::new(grid),
            pressure_sides,
            config,
            face_of,
            d,
            plenum,
            inflow_factor: 1.0,
            rows,
            krylov: Default::default(),
        };
        solver.inflow_factor = solver.inflow_factor_at(solver.state.time_s);
        solver.apply_boundary_velocities();
        Ok(solver)
    }

    /// The inflow ramp's factor times the inflow level's at `time_s` (1 without either).
    pub fn inflow_factor_at(&self, time_s: f64) -> f64 {
        let ramp = self.config.inflow_ramp.map_or(1.0, |r| r.factor(time_s));
        match &self.config.inflow_levels {
            None => ramp,
            Some(levels) => ramp * levels.factor(time_s),
        }
    }

    pub(super) fn porosity_at_face(&self, a: usize, idx: [usize; 3]) -> f64 {
        let grid = &self.config.grid;
        if self.plenum[a][grid.face(a, idx)] {
            return 1.0;
        }
        let eps = &self.state.porosity;
        let hi = (idx[a] < grid.n[a]).then_some(idx);
        let lo = step_cell(grid, idx, a, -1).filter(|_| idx[a] > 0 || grid.periodic(a));
        match (lo, hi) {
            (Some(l), Some(h)) => 0.5 * (eps[grid.cell(l)] + eps[grid.cell(h)]),
            (Some(l), None) => {
                // The last face of a periodic axis is the first one.
                let mut first = idx;
                first[a] = 0;
                if grid.periodic(a) {
                    0.5 * (eps[grid.cell(l)] + eps[grid.cell(first)])
                } else {
                    eps[grid.cell(l)]
                }
            }
            (None, Some(h)) => eps[grid.cell(h)],
            (None, None) => 1.0,
        }
    }

    /// Assembles the momentum system of component `c` and stores the pressure-correction coefficients.
    fn assemble_momentum(&mut self, c: usize, dt_s: f64, old: &[f64], source: &[f64], sink: &[f64]) -> StencilSystem {
        let cfg = &self.config;
        let grid = &cfg.grid;
        let (rho, mu) = (cfg.density_kg_per_m3, cfg.viscosity_pa_s);
        let u = &self.state.velocity_m_per_s;
        let eps = &self.state.porosity;
        let p = &self.state.pressure_pa;
        let volume = grid.cell_volume_m3();
        let rows = &self.rows[c];
        let mut sys = StencilSystem::new(rows.len());
        // Only the unknowns' entries are written; the others stay 0 from `new`.
        let mut d = std::mem::take(&mut self.d[c]);
        let coefficient = |flux_into: f64, diff: f64| -> f64 {
            // flux_into > 0: flow from the neighbour into the control volume.
            match cfg.convection {
                Convection::Upwind => diff + flux_into.max(0.0),
                Convection::Hybrid => flux_into.max(diff + 0.5 * flux_into).max(0.0),
            }
        };
        let area_c = grid.face_area_m2(c);
        for (row, r) in rows.iter().enumerate() {
            let f = r.face;
            let (eps_lo, eps_hi) = (eps[r.cell_lo], eps[r.cell_hi]);
            let eps_f = 0.5 * (eps_lo + eps_hi);
            let mut ap = 0.0;
            let mut b = 0.0;
            let mut net_out = 0.0;
            let mut slot = 0;
            let mut add = |sys: &mut StencilSystem, neighbour: Result<NeighbourFace, f64>, a_nb: f64| {
                ap += a_nb;
                match neighbour {
                    Ok(nb) => {
                        if nb.unknown == NONE {
                            b += a_nb * u[c][nb.face];
                        } else {
                            sys.nb[row][slot] = nb.unknown;
                            sys.anb[row][slot] = a_nb;
                            slot += 1;
                        }
                    }
                    Err(value) => b += a_nb * value,
                }
            };
            // Along c: the control volume's faces are the centres of cell_lo and cell_hi.
            let flux_e = rho * eps_hi * 0.5 * (u[c][f] + u[c][r.east.face]) * area_c;
            let flux_w = rho * eps_lo * 0.5 * (u[c][r.west.face] + u[c][f]) * area_c;
            let diff_e = mu * eps_hi * area_c / grid.h_m[c];
            let diff_w = mu * eps_lo * area_c / grid.h_m[c];
            add(&mut sys, Ok(r.east), coefficient(-flux_e, diff_e));
            add(&mut sys, Ok(r.west), coefficient(flux_w, diff_w));
            net_out += flux_e - flux_w;
            // Across c: faces between this row of c-faces and the next along each other axis.
            for side in &r.cross {
                let dax = side.axis;
                let area_d = grid.face_area_m2(dax);
                let v_flux = 0.5 * (u[dax][side.flux_face_lo] + u[dax][side.flux_face_hi]);
                let sign = if side.high { 1.0 } else { -1.0 };
                match side.across {
                    Across::Open {
                        beyond_lo,
                        beyond_hi,
                        neighbour,
                    } => {
                        let eps_corner = 0.25 * (eps_lo + eps_hi + eps[beyond_lo] + eps[beyond_hi]);
                        let flux = rho * eps_corner * v_flux * area_d;
                        let diff = mu * eps_corner * area_d / grid.h_m[dax];
                        add(&mut sys, Ok(neighbour), coefficient(-sign * flux, diff));
                        net_out += sign * flux;
                    }
                    Across::Ghost(boundary) => {
                        // A wall or inlet along d (or blocked cells: a wall at rest or turning with
                        // `blocked_wall_motion`): the ghost value is the wall's tangential velocity, half a cell
                        // away.
                        let flux = rho * eps_f * v_flux * area_d;
                        let diff = mu * eps_f * area_d / (0.5 * grid.h_m[dax]);
                        add(
                            &mut sys,
                            Err(side_velocity(boundary, self.inflow_factor)[c]),
                            coefficient(-sign * flux, diff),
                        );
                        net_out += sign * flux;
                    }
                }
            }
            let a_p0 = rho * eps_f * volume / dt_s;
            // The implicit part of the drag: −β u per unit volume (its +β v part is in `source`).
            ap += a_p0 + net_out + sink.get(f).copied().unwrap_or(0.0) * volume;
            b += a_p0 * old[f];
            b += eps_f * (p[r.cell_lo] - p[r.cell_hi]) * area_c;
            b += (rho * eps_f * cfg.gravity_m_per_s2[c]) * volume + source.get(f).copied().unwrap_or(0.0) * volume;
            // Under-relaxation (Patankar's implicit form).
            let alpha = cfg.relax_velocity;
            ap /= alpha;
            b += (1.0 - alpha) * ap * u[c][f];
            sys.ap[row] = ap;
            sys.b[row] = b;
            d[f] = eps_f * area_c / ap;
        }
        self.d[c] = d;
        sys
    }

    /// Net mass outflow of each cell (kg/s) plus the accumulation term: the pressure-correction right-hand side
    /// with its sign flipped. `face_porosity` is [`GasSolver::face_porosities`] of the current porosity.
    pub(super) fn assemble_pressure_correction(
        &self,
        dt_s: f64,
        old_porosity: &[f64],
        face_porosity: &[Vec<f64>; 3],
    ) -> (StencilSystem, f64) {
        let grid = &self.config.grid;
        let rho = self.config.density_kg_per_m3;
        let u = &self.state.velocity_m_per_s;
        let eps = &self.state.porosity;
        let blocked = &self.config.blocked;
        let mut sys = StencilSystem::new(grid.cells());
        let mut imbalance = 0.0;
        let mut throughput = 0.0;
        let sides_per_cell = 2 * grid.axes();
        for (pcell, sides) in self.pressure_sides.chunks_exact(sides_per_cell).enumerate() {
            let mut net_out = 0.0;
            let mut slot = 0;
            for (k, side) in sides.iter().enumerate() {
                let (a, high) = (k / 2, k % 2 == 1);
                let area = grid.face_area_m2(a);
                let eps_f = face_porosity[a][side.face];
                let flux = rho * eps_f * u[a][side.face] * area;
                net_out += if high { flux } else { -flux };
                throughput += 0.5 * flux.abs();
                if let Some((solved_face, nb)) = side.solved {
                    let coeff = rho * eps_f * area * self.d[a][solved_face];
                    sys.ap[pcell] += coeff;
                    // The reference cell's p' is 0: a Dirichlet neighbour, kept out of the (symmetric) stencil.
                    if self.config.pressure_reference_cell != Some(nb) {
                        sys.nb[pcell][slot] = nb as u32;
                        sys.anb[pcell][slot] = coeff;
                        slot += 1;
                    }
                }
            }
            if (!blocked.is_empty() && blocked[pcell]) || self.config.pressure_reference_cell == Some(pcell) {
                // Outside the gas, or the reference cell: p' = 0.
                sys.ap[pcell] = 1.0;
                sys.nb[pcell] = [NONE; NEIGHBOURS];
                sys.anb[pcell] = [0.0; NEIGHBOURS];
                sys.b[pcell] = 0.0;
                continue;
            }
            let accumulation = rho * grid.cell_volume_m3() * (eps[pcell] - old_porosity[pcell]) / dt_s;
            sys.b[pcell] = -(net_out + accumulation);
            imbalance += (net_out + accumulation).abs();
        }
        (sys, imbalance / throughput.max(f64::MIN_POSITIVE))
    }

    /// The porosity of every face of each component ([`GasSolver::porosity_at_face`]), for a step's iterations
    /// (the porosity does not change during a step).
    fn face_porosities(&self) -> [Vec<f64>; 3] {
        let grid = &self.config.grid;
        std::array::from_fn(|a| {
            if a < grid.axes() {
                all_indices(grid.face_dims(a))
                    .map(|idx| self.porosity_at_face(a, idx))
                    .collect()
            } else {
                Vec::new()
            }
        })
    }

    /// Advances the gas by `dt_s` with momentum source `source[a][face]` (N/m³) and implicit sink coefficient
    /// `sink[a][face]` (the β of a drag −β u, N·s/m⁴; empty vectors mean none) on each component's faces.
    /// `old_porosity` is ε at the start of the step (the current ε is `state.porosity`).
    pub fn step(
        &mut self,
        dt_s: f64,
        source: &[Vec<f64>; 3],
        sink: &[Vec<f64>; 3],
        old_porosity: &[f64],
    ) -> StepReport {
        let axes = self.config.grid.axes();
        let old: [Vec<f64>; 3] = self.state.velocity_m_per_s.clone();
        // Boundary values are those at the end of the step (the scheme is implicit in time). Without a ramp they
        // do not change, and the step is exactly what it was before ramps existed.
        if self.config.inflow_ramp.is_some() || self.config.inflow_levels.is_some() {
            self.inflow_factor = self.inflow_factor_at(self.state.time_s + dt_s);
            self.apply_boundary_velocities();
        }
        let mut report = StepReport {
            outer_iterations: 0,
            mass_imbalance: f64::INFINITY,
            velocity_change: f64::INFINITY,
            converged: false,
            momentum: SolveReport {
                iterations: 0,
                relative_residual: 0.0,
                converged: true,
            },
            pressure: SolveReport {
                iterations: 0,
                relative_residual: 0.0,
                converged: true,
            },
            linear_solve_s: 0.0,
        };
        let face_porosity = self.face_porosities();
        if let PressureVelocity::Piso { correctors } = self.config.pressure_velocity {
            self.piso(
                dt_s,
                &old,
                source,
                sink,
                old_porosity,
                &face_porosity,
                correctors,
                &mut report,
            );
            self.state.time_s += dt_s;
            return report;
        }
        for outer in 0..self.config.max_outer_iterations {
            let before = self.state.velocity_m_per_s.clone();
            self.predict_momentum(dt_s, &old, source, sink, &mut report);
            self.apply_boundary_velocities();
            self.balance_outlets(dt_s, old_porosity);
            let (psys, imbalance) = self.assemble_pressure_correction(dt_s, old_porosity, &face_porosity);
            report.outer_iterations = outer + 1;
            report.mass_imbalance = imbalance;
            let (mut change, mut scale) = (0.0f64, 0.0f64);
            for (now, was) in self.state.velocity_m_per_s.iter().zip(&before).take(axes) {
                for (a, b) in now.iter().zip(was) {
                    change = change.max((a - b).abs());
                    scale = scale.max(a.abs());
                }
            }
            report.velocity_change = change / scale.max(f64::MIN_POSITIVE);
            if imbalance < self.config.mass_tolerance
                && report.velocity_change < self.config.velocity_tolerance
                && outer > 0
            {
                report.converged = true;
                break;
            }
            self.correct_pressure(
                &psys,
                self.config.relax_pressure,
                dt_s,
                old_porosity,
                Outlets::ZeroGradient,
                &mut report,
            );
        }
        self.state.time_s += dt_s;
        report
    }

    /// Solves the momentum equation of every component for the velocities (SIMPLE's predictor, or PISO's with
    /// `relax_velocity` 1), storing the pressure-correction coefficients d.
    pub(super) fn predict_momentum(
        &mut self,
        dt_s: f64,
        old: &[Vec<f64>; 3],
        source: &[Vec<f64>; 3],
        sink: &[Vec<f64>; 3],
        report: &mut StepReport,
    ) {
        for c in 0..self.config.grid.axes() {
            let sys = self.assemble_momentum(c, dt_s, &old[c], &source[c], &sink[c]);
            let mut x: Vec<f64> = self.face_of[c]
                .iter()
                .map(|&f| self.state.velocity_m_per_s[c][f])
                .collect();
            let t = std::time::Instant::now();
            let r = bicgstab_in(
                &mut self.krylov[c],
                &sys,
                &mut x,
                self.config.linear_tolerance,
                self.config.max_linear_iterations,
            );
            report.linear_solve_s += t.elapsed().as_secs_f64();
            report.momentum.iterations += r.iterations;
            report.momentum.relative_residual = report.momentum.relative_residual.max(r.relative_residual);
            report.momentum.converged &= r.converged;
            for (q, &f) in self.face_of[c].iter().enumerate() {
                self.state.velocity_m_per_s[c][f] = x[q];
            }
        }
    }

    /// Solves the pressure-correction system `psys` for p' and applies it: p += `relax` p', each face velocity
    /// += d (p'_lo − p'_hi), then the boundary velocities, the outlets' balance (only when `outlets` is
    /// [`Outlets::ZeroGradient`]) and the reference pressure.
    pub(super) fn correct_pressure(
        &mut self,
        psys: &StencilSystem,
        relax: f64,
        dt_s: f64,
        old_porosity: &[f64],
        outlets: Outlets,
        report: &mut StepReport,
    ) {
        let mut pc = vec![0.0; psys.len()];
        let t = std::time::Instant::now();
        let r = if self.config.pressure_solver.direct_for(psys.len(), bandwidth(psys)) {
            direct_symmetric(psys, &mut pc, true)
        } else {
            conjugate_gradient(
                psys,
                &mut pc,
                self.config.linear_tolerance,
                self.config.max_linear_iterations,
                true,
            )
        };
        report.linear_solve_s += t.elapsed().as_secs_f64();
        report.pressure.iterations += r.iterations;
        report.pressure.relative_residual = report.pressure.relative_residual.max(r.relative_residual);
        report.pressure.converged &= r.converged;
        for (pv, corr) in self.state.pressure_pa.iter_mut().zip(&pc) {
            *pv += relax * corr;
        }
        for c in 0..self.config.grid.axes() {
            for r in &self.rows[c] {
                let f = r.face;
                self.state.velocity_m_per_s[c][f] += self.d[c][f] * (pc[r.cell_lo] - pc[r.cell_hi]);
            }
        }
        self.set_boundary_velocities(outlets);
        if outlets == Outlets::ZeroGradient {
            self.balance_outlets(dt_s, old_porosity);
        }
        self.fix_reference_pressure();
    }
}

impl GasSolver {
    /// The face velocities as the particles see them: interstitial everywhere. Faces where gas enters from a
    /// plenum carry the superficial velocity (porosity 1 at the face); seen from the bed side they are U/ε of the
    /// cell inside.
    pub fn interstitial_velocity_m_per_s(&self) -> [Vec<f64>; 3] {
        let grid = &self.config.grid;
        let mut u = self.state.velocity_m_per_s.clone();
        for a in 0..grid.axes() {
            for (f, &is_plenum) in self.plenum[a].iter().enumerate() {
                if is_plenum {
                    let mut idx = face_index(grid, a, f);
                    if idx[a] == grid.n[a] {
                        idx[a] -= 1;
                    }
                    u[a][f] /= self.state.porosity[grid.cell(idx)];
                }
            }
        }
        u
    }

    /// The gas mass flow through every face in the direction of its axis, kg/s: ρ ε_f u A with the face porosity
    /// the continuity equation uses (1 where gas enters from a plenum), so a scalar carried by these flows sees the
    /// mass balance the pressure correction solved. Faces of blocked cells carry none; the z faces of a 2-D grid are
    /// zero.
    pub fn mass_flow_kg_per_s(&self) -> [Vec<f64>; 3] {
        let grid = &self.config.grid;
        let rho = self.config.density_kg_per_m3;
        let mut flow: [Vec<f64>; 3] = std::array::from_fn(|a| vec![0.0; grid.faces(a)]);
        for (a, flow) in flow.iter_mut().enumerate().take(grid.axes()) {
            let area = grid.face_area_m2(a);
            for idx in all_indices(grid.face_dims(a)) {
                let f = grid.face(a, idx);
                flow[f] = rho * self.porosity_at_face(a, idx) * self.state.velocity_m_per_s[a][f] * area;
            }
        }
        flow
    }

    /// With an outlet, the pressure there is the reference: shifts p so that the mean pressure of the cells next to
    /// the outlet faces is 0 (the zero-gradient extrapolation to the face).
    fn fix_reference_pressure(&mut self) {
        let grid = &self.config.grid;
        let (mut sum, mut count) = (0.0, 0usize);
        for a in 0..grid.axes() {
            for high in [false, true] {
                if !matches!(grid.boundary[side(a, high)], Boundary::Outlet) {
                    continue;
                }
                for idx in all_indices(grid.n) {
                    if idx[a] == if high { grid.n[a] - 1 } else { 0 } && !cell_blocked(grid, &self.config.blocked, idx)
                    {
                        sum += self.state.pressure_pa[grid.cell(idx)];
                        count += 1;
                    }
                }
            }
        }
        if count > 0 {
            let shift = sum / count as f64;
            self.state.pressure_pa.iter_mut().for_each(|p| *p -= shift);
        }
    }
}

/// Whether cell `c` is blocked.
pub(crate) fn cell_blocked(grid: &Grid, blocked: &[bool], c: [usize; 3]) -> bool {
    !blocked.is_empty() && blocked[grid.cell(c)]
}

/// Whether face `idx` of the component along `axis` has a blocked cell on either side.
pub(crate) fn face_touches_blocked(grid: &Grid, blocked: &[bool], axis: usize, idx: [usize; 3]) -> bool {
    if blocked.is_empty() {
        return false;
    }
    let n = grid.n[axis];
    let mut hi = idx;
    let mut lo = idx;
    let hi_ok = if idx[axis] < n {
        true
    } else if grid.periodic(axis) {
        hi[axis] = 0;
        true
    } else {
        false
    };
    let lo_ok = if idx[axis] > 0 {
        lo[axis] -= 1;
        true
    } else if grid.periodic(axis) {
        lo[axis] = n - 1;
        true
    } else {
        false
    };
    (hi_ok && blocked[grid.cell(hi)]) || (lo_ok && blocked[grid.cell(lo)])
}

/// The (i, j, k) of face `f` of the component along `axis`.
pub(crate) fn face_index(grid: &Grid, axis: usize, f: usize) -> [usize; 3] {
    let d = grid.face_dims(axis);
    [f % d[0], (f / d[0]) % d[1], f / (d[0] * d[1])]
}

#[cfg(test)]
mod tests {
    use super::InflowRamp;

    #[test]
    fn inflow_levels_hold_each_factor_for_its_interval() {
        let levels = super::InflowLevels {
            start_s: 1.0,
            hold_s: 0.1,
            factors: vec![1.0, 0.5, 0.0],
        };
        assert_eq!(levels.factor(0.5), 1.0);
        assert_eq!(levels.level(1.0), Some(0));
        assert_eq!(levels.factor(1.15), 0.5);
        assert_eq!(levels.factor(1.25), 0.0);
        assert_eq!(levels.factor(9.0), 0.0);
    }

    #[test]
    fn an_inflow_ramp_is_off_then_linear_then_full() {
        let ramp = InflowRamp {
            start_s: 0.5,
            duration_s: 0.25,
        };
        assert_eq!(ramp.factor(0.0), 0.0);
        assert_eq!(ramp.factor(0.5), 0.0);
        assert!((ramp.factor(0.6) - 0.4).abs() < 1e-12);
        assert_eq!(ramp.factor(0.75), 1.0);
        assert_eq!(ramp.factor(10.0), 1.0);
        let switch = InflowRamp {
            start_s: 0.5,
            duration_s: 0.0,
        };
        assert_eq!(switch.factor(0.5), 0.0);
        assert_eq!(switch.factor(0.5 + 1e-12), 1.0);
    }
}
