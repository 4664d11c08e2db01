//! The discretised transport equation of a scalar φ carried by the gas (temperature, vapour concentration) at the
//! cell centres of the gas grid:
//!
//! ∂(ερφ)/∂t + ∇·(ερuφ) = ∇·(εΓ∇φ) + S + K (φ_p − φ),
//!
//! implicit in time, with the momentum solver's convection scheme (upwind or hybrid) and central diffusion; Γ is a
//! diffusivity times the density (kg/(m·s)), S an explicit source and K (φ_p − φ) the exchange with particles at
//! φ_p, linearised as a_P += K V, b += K φ_p V (Patankar 1980 §4.2-7). Faces carry given gas mass flows, so the
//! convective fluxes are those the continuity equation balanced.
//!
//! The equation is Patankar's form (1980 §5.7, eqs 5.57-5.62): the conservative form minus φ_P times the discrete
//! continuity equation, a_P = Σ a_nb + a_P⁰ + K V with a_P⁰ = ρ ε⁰ V / Δt (ε⁰ the porosity at the step's start).
//! CHOICE: this form, over the plainly conservative one, because a SIMPLE step satisfies continuity only to its
//! mass tolerance: in this form a uniform φ stays uniform whatever that residual is and φ stays within the values
//! it is given (a temperature does not overshoot), while the scalar's content changes by inflow − outflow + sources
//! plus Σ r_P φ_P, r_P the cell's continuity residual (tests/gas_scalar_transport.rs measures both).
//!
//! Boundary faces either give φ (an inlet's or a jet's gas, a wall held at a value: the value sits on the face, half
//! a cell from the centre) or give none (zero gradient: gas leaving carries the cell's value, a wall passes no
//! flux). Blocked cells are outside the gas: nothing crosses their faces and they keep their value. Which face
//! gets which condition is decided by the caller ([`super::transported_scalar`] from the gas solver's boundaries);
//! this module only discretises.

use serde::{Deserialize, Serialize};

use super::grid::{Grid, side};
use super::linsolve::{SolveReport, StencilSystem, bicgstab};
use super::simple::Convection;

/// Below this ‖b − A φ_start‖ / ‖b‖ a scalar's step changes nothing ([`ScalarEquation::step`]): the residual of a
/// uniform φ in a uniform field is rounding, about 1e-16 times a_P / a_P⁰.
pub const UNCHANGED_RESIDUAL: f64 = 1e-14;

/// Restarts of a scalar solve that stopped short of its tolerance (see [`ScalarEquation::step`]).
const BICGSTAB_RESTARTS: usize = 3;

/// One scalar transport step's data.
pub struct ScalarEquation<'a> {
    pub grid: &'a Grid,
    pub convection: Convection,
    pub density_kg_per_m3: f64,
    /// ρ × diffusivity, kg/(m·s).
    pub diffusion_kg_per_m_s: f64,
    /// Gas mass flow through each face in the direction of its axis, kg/s (ρ ε_f u A), per axis over
    /// `grid.faces(axis)` faces.
    pub mass_flow_kg_per_s: &'a [Vec<f64>; 3],
    /// ε at the cell centres at the end of the step (weights the diffusion).
    pub porosity: &'a [f64],
    /// ε at the cell centres at the start of the step (the storage term a_P⁰).
    pub old_porosity: &'a [f64],
    /// φ on each boundary face where the boundary gives it, `None` for zero gradient; per axis over
    /// `grid.faces(axis)` faces (interior entries are not read).
    pub boundary_value: &'a [Vec<Option<f64>>; 3],
    /// Cells outside the gas, one flag per cell, or empty for none.
    pub blocked: &'a [bool],
    /// φ held on the faces between gas and blocked cells (diffusion over the half cell), or `None`: no flux.
    pub blocked_value: Option<f64>,
    /// Explicit source per unit volume at each cell, (unit of φ)·kg/(m³·s); empty for none.
    pub source: &'a [f64],
    /// The particle exchange coefficient K per unit volume at each cell, kg/(m³·s); empty for none.
    pub exchange_coefficient: &'a [f64],
    /// K φ_p per unit volume at each cell, (unit of φ)·kg/(m³·s); empty for none.
    pub exchange_coefficient_value: &'a [f64],
    /// The plainly conservative form instead of Patankar's: a_P gains the cell's continuity residual
    /// r_P = ρ(ε − ε⁰)V/Δt + Σ F_out, so the scalar's content changes by exactly what crosses the boundary plus the
    /// sources (to the linear solve's residual), whatever the mass flows' imbalance (a vapour's mass ledger).
    pub conservative: bool,
}

/// What crossed the boundary of the gas over one step, per unit time, in (unit of φ)·kg/s.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BoundaryFlows {
    /// Into the gas through faces where it enters (inlets, jets, diffusion from a held value).
    pub in_per_s: f64,
    /// Out of the gas through faces where it leaves (outlets, diffusion into a held value).
    pub out_per_s: f64,
}

/// The neighbouring cell across the face on the `high` side of `idx` along `axis` (wrapped on a periodic axis), or
/// `None` at a non-periodic boundary.
fn neighbour(grid: &Grid, idx: [usize; 3], axis: usize, high: bool) -> Option<[usize; 3]> {
    let n = grid.n[axis] as isize;
    let j = idx[axis] as isize + if high { 1 } else { -1 };
    let mut c = idx;
    if (0..n).contains(&j) {
        c[axis] = j as usize;
        Some(c)
    } else if grid.periodic(axis) {
        c[axis] = j.rem_euclid(n) as usize;
        Some(c)
    } else {
        None
    }
}

impl ScalarEquation<'_> {
    fn is_blocked(&self, cell: usize) -> bool {
        !self.blocked.is_empty() && self.blocked[cell]
    }

    /// The neighbour coefficient for a face with mass flow `flow_into` into the cell and diffusion conductance
    /// `diffusion` (Patankar 1980 Table 5.2: upwind, or hybrid [|F_in, D + F_in/2, 0|]).
    fn neighbour_coefficient(&self, flow_into: f64, diffusion: f64) -> f64 {
        match self.convection {
            Convection::Upwind => diffusion + flow_into.max(0.0),
            Convection::Hybrid => flow_into.max(diffusion + 0.5 * flow_into).max(0.0),
        }
    }

    /// The system a_P φ_P = Σ a_nb φ_nb + b for a step of `dt_s` from `old` (φ at the step's start).
    pub fn assemble(&self, old: &[f64], dt_s: f64) -> StencilSystem {
        let grid = self.grid;
        let (rho, gamma) = (self.density_kg_per_m3, self.diffusion_kg_per_m_s);
        let eps = self.porosity;
        let volume = grid.cell_volume_m3();
        let per_cell = |values: &[f64], p: usize| values.get(p).copied().unwrap_or(0.0);
        let mut sys = StencilSystem::new(grid.cells());
        for k in 0..grid.n[2] {
            for j in 0..grid.n[1] {
                for i in 0..grid.n[0] {
                    let idx = [i, j, k];
                    let p = grid.cell(idx);
                    if self.is_blocked(p) {
                        // Outside the gas: the value stays.
                        sys.ap[p] = 1.0;
                        sys.b[p] = old[p];
                        continue;
                    }
                    let (mut ap, mut b, mut slot) = (0.0, 0.0, 0);
                    for a in 0..grid.axes() {
                        let area = grid.face_area_m2(a);
                        for high in [false, true] {
                            let mut fi = idx;
                            fi[a] += usize::from(high);
                            let face = grid.face(a, fi);
                            let flow_into = if high { -1.0 } else { 1.0 } * self.mass_flow_kg_per_s[a][face];
                            match neighbour(grid, idx, a, high) {
                                Some(nb) => {
                                    let q = grid.cell(nb);
                                    if self.is_blocked(q) {
                                        if let Some(value) = self.blocked_value {
                                            let diffusion = gamma * eps[p] * area / (0.5 * grid.h_m[a]);
                                            let a_b = self.neighbour_coefficient(0.0, diffusion);
                                            ap += a_b;
                                            b += a_b * value;
                                        }
                                        continue;
                                    }
                                    let diffusion = gamma * 0.5 * (eps[p] + eps[q]) * area / grid.h_m[a];
                                    let a_nb = self.neighbour_coefficient(flow_into, diffusion);
                                    ap += a_nb;
                                    sys.nb[p][slot] = q as u32;
                                    sys.anb[p][slot] = a_nb;
                                    slot += 1;
                                }
                                None => {
                                    if let Some(value) = self.boundary_value[a][face] {
                                        let diffusion = gamma * eps[p] * area / (0.5 * grid.h_m[a]);
                                        let a_b = self.neighbour_coefficient(flow_into, diffusion);
                                        ap += a_b;
                                        b += a_b * value;
                                    }
                                }
                            }
                        }
                    }
                    let a_p0 = rho * self.old_porosity[p] * volume / dt_s;
                    let exchange = per_cell(self.exchange_coefficient, p) * volume;
                    sys.ap[p] = ap + a_p0 + exchange;
                    if self.conservative {
                        sys.ap[p] += self.continuity_residual_kg_per_s(idx, dt_s);
                    }
                    sys.b[p] = b
                        + a_p0 * old[p]
                        + per_cell(self.exchange_coefficient_value, p) * volume
                        + per_cell(self.source, p) * volume;
                }
            }
        }
        sys
    }

    /// The continuity residual of cell `idx` over a step of `dt_s`: r_P = ρ(ε − ε⁰)V/Δt − Σ F_in, the mass the
    /// cell gained over what flowed into it through its faces, per unit time (zero when the gas step met continuity
    /// exactly).
    fn continuity_residual_kg_per_s(&self, idx: [usize; 3], dt_s: f64) -> f64 {
        let grid = self.grid;
        let p = grid.cell(idx);
        let mut net_inflow = 0.0;
        for a in 0..grid.axes() {
            for high in [false, true] {
                let mut fi = idx;
                fi[a] += usize::from(high);
                net_inflow += if high { -1.0 } else { 1.0 } * self.mass_flow_kg_per_s[a][grid.face(a, fi)];
            }
        }
        self.density_kg_per_m3 * (self.porosity[p] - self.old_porosity[p]) * grid.cell_volume_m3() / dt_s - net_inflow
    }

    /// What Patankar's form adds to the scalar's content per unit time beyond the boundary flows and the sources:
    /// Σ r_P φ_P over the cells outside blocked ones with φ at the end of the step (module documentation); zero in
    /// the conservative form, which balances it in a_P.
    pub fn continuity_flow(&self, phi: &[f64], dt_s: f64) -> f64 {
        if self.conservative {
            return 0.0;
        }
        let grid = self.grid;
        let mut sum = 0.0;
        for k in 0..grid.n[2] {
            for j in 0..grid.n[1] {
                for i in 0..grid.n[0] {
                    let p = grid.cell([i, j, k]);
                    if !self.is_blocked(p) {
                        sum += self.continuity_residual_kg_per_s([i, j, k], dt_s) * phi[p];
                    }
                }
            }
        }
        sum
    }

    /// What crosses the gas's boundary per unit time with φ at the end of the step (the conservative form's
    /// fluxes, Patankar 1980 §5.7: through a face into a cell, a_b (φ_b − φ_P) + F_in φ_P where the face gives a
    /// value φ_b, F_in φ_P where it does not; faces to blocked cells carry no mass, and diffusion into a held value
    /// there is a_b (φ_b − φ_P)). Periodic faces are interior.
    pub fn boundary_flows(&self, phi: &[f64]) -> BoundaryFlows {
        let grid = self.grid;
        let gamma = self.diffusion_kg_per_m_s;
        let eps = self.porosity;
        let mut flows = BoundaryFlows::default();
        let mut add = |flux: f64| {
            if flux >= 0.0 {
                flows.in_per_s += flux;
            } else {
                flows.out_per_s -= flux;
            }
        };
        for k in 0..grid.n[2] {
            for j in 0..grid.n[1] {
                for i in 0..grid.n[0] {
                    let idx = [i, j, k];
                    let p = grid.cell(idx);
                    if self.is_blocked(p) {
                        continue;
                    }
                    for a in 0..grid.axes() {
                        let area = grid.face_area_m2(a);
                        for high in [false, true] {
                            let mut fi = idx;
                            fi[a] += usize::from(high);
                            let face = grid.face(a, fi);
                            let flow_into = if high { -1.0 } else { 1.0 } * self.mass_flow_kg_per_s[a][face];
                            match neighbour(grid, idx, a, high) {
                                Some(nb) => {
                                    if self.is_blocked(grid.cell(nb))
                                        && let Some(value) = self.blocked_value
                                    {
                                        let diffusion = gamma * eps[p] * area / (0.5 * grid.h_m[a]);
                                        add(self.neighbour_coefficient(0.0, diffusion) * (value - phi[p]));
                                    }
                                }
                                None => {
                                    let held = self.boundary_value[a][face].map_or(0.0, |value| {
                                        let diffusion = gamma * eps[p] * area / (0.5 * grid.h_m[a]);
                                        self.neighbour_coefficient(flow_into, diffusion) * (value - phi[p])
                                    });
                                    add(held + flow_into * phi[p]);
                                }
                            }
                        }
                    }
                }
            }
        }
        flows
    }

    /// The scalar's content Σ ε ρ φ V over the cells outside blocked ones (porosity at the end of the step), in
    /// (unit of φ)·kg.
    pub fn content(&self, phi: &[f64]) -> f64 {
        let volume = self.grid.cell_volume_m3();
        (0..phi.len())
            .filter(|&c| !self.is_blocked(c))
            .map(|c| self.porosity[c] * self.density_kg_per_m3 * phi[c] * volume)
            .sum()
    }

    /// Advances φ by `dt_s` in place (φ holds the step's start on entry).
    ///
    /// CHOICE: solved for the change over the step, δ = φ − φ_start from δ = 0 (A δ = b − A φ_start), so that the
    /// relative tolerance bounds the error against the change rather than against φ itself: a temperature of 300 K
    /// solved to a relative 1e-12 of itself left an absolute error that the energy ledger saw step after step, always
    /// the same way (a heated drum drifted 2e-10 of its energy in 0.06 s; tests/drying.rs).
    ///
    /// A step whose change is at rounding level (‖b − A φ_start‖ ≤ [`UNCHANGED_RESIDUAL`] ‖b‖: a uniform φ with
    /// nothing to move it) leaves φ as it is, bit for bit, as Patankar's form promises.
    pub fn step(&self, phi: &mut [f64], dt_s: f64, tolerance: f64, max_iterations: usize) -> SolveReport {
        let mut sys = self.assemble(phi, dt_s);
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let b_norm = norm(&sys.b);
        let mut a_phi = vec![0.0; phi.len()];
        sys.apply(phi, &mut a_phi);
        for (b, a) in sys.b.iter_mut().zip(&a_phi) {
            *b -= a;
        }
        let change_norm = norm(&sys.b);
        if change_norm <= UNCHANGED_RESIDUAL * b_norm {
            return SolveReport {
                iterations: 0,
                relative_residual: if b_norm > 0.0 { change_norm / b_norm } else { 0.0 },
                converged: true,
            };
        }
        let mut delta = vec![0.0; phi.len()];
        let report = self.solve_change(&sys, &mut delta, tolerance, max_iterations);
        for (p, d) in phi.iter_mut().zip(&delta) {
            *p += d;
        }
        report
    }

    fn solve_change(&self, sys: &StencilSystem, phi: &mut [f64], tolerance: f64, max_iterations: usize) -> SolveReport {
        let mut report = bicgstab(sys, phi, tolerance, max_iterations);
        // CHOICE: BiCGStab breaks down (ρ = 0) when its residual reaches round-off short of a tight tolerance; a
        // restart from where it stopped, with a fresh shadow residual, finishes. A plug-flow bed at tolerance 1e-15
        // stopped at 6e-11 after 27 iterations (tests/gas_scalar_transport.rs); restarts are bounded.
        for _ in 0..BICGSTAB_RESTARTS {
            if report.converged || report.iterations >= max_iterations {
                break;
            }
            let again = bicgstab(sys, phi, tolerance, max_iterations - report.iterations);
            report = SolveReport {
                iterations: report.iterations + again.iterations,
                ..again
            };
        }
        report
    }
}

/// The scalar's condition on one side of a standalone problem (periodic sides follow the grid).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ScalarBoundary {
    /// φ fixed on the side (an inlet's value, a wall's temperature).
    Fixed { value: f64 },
    /// No diffusive flux; gas leaving carries the cell's value out.
    ZeroFlux,
}

/// A scalar equation over a given velocity and porosity field, without a gas solver (no blocked cells or jets;
/// porosity constant over the step): the analytic checks of the discretisation (tests/gas_validation.rs C4). In a
/// gas simulation the scalar is a [`super::transported_scalar::TransportedScalar`].
pub struct ScalarProblem<'a> {
    pub grid: &'a Grid,
    pub convection: Convection,
    pub density_kg_per_m3: f64,
    /// ρ × diffusivity, kg/(m·s).
    pub diffusion_kg_per_m_s: f64,
    /// Gas velocity components on their faces (the momentum solver's `velocity_m_per_s`).
    pub velocity_m_per_s: &'a [Vec<f64>; 3],
    pub porosity: &'a [f64],
    pub boundary: [ScalarBoundary; 6],
    /// Source per unit volume at each cell, (units of φ)·kg/(m³ s).
    pub source: &'a [f64],
}

/// Advances φ by `dt_s` in place.
pub fn step_scalar(problem: &ScalarProblem, phi: &mut [f64], dt_s: f64, tolerance: f64) -> SolveReport {
    let grid = problem.grid;
    let eps = problem.porosity;
    let mut mass_flow: [Vec<f64>; 3] = Default::default();
    let mut boundary_value: [Vec<Option<f64>>; 3] = Default::default();
    for a in 0..grid.axes() {
        let dims = grid.face_dims(a);
        let n = grid.n[a];
        mass_flow[a] = vec![0.0; grid.faces(a)];
        boundary_value[a] = vec![None; grid.faces(a)];
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let idx = [i, j, k];
                    let f = grid.face(a, idx);
                    let cell_at = |along: usize| {
                        let mut c = idx;
                        c[a] = along;
                        eps[grid.cell(c)]
                    };
                    let along = idx[a];
                    let eps_f = if grid.periodic(a) {
                        0.5 * (cell_at((along + n - 1) % n) + cell_at(along % n))
                    } else if along == 0 || along == n {
                        if let ScalarBoundary::Fixed { value } = problem.boundary[side(a, along == n)] {
                            boundary_value[a][f] = Some(value);
                        }
                        cell_at(along.min(n - 1))
                    } else {
                        0.5 * (cell_at(along - 1) + cell_at(along))
                    };
                    mass_flow[a][f] =
                        problem.density_kg_per_m3 * eps_f * problem.velocity_m_per_s[a][f] * grid.face_area_m2(a);
                }
            }
        }
    }
    ScalarEquation {
        grid,
        convection: problem.convection,
        density_kg_per_m3: problem.density_kg_per_m3,
        diffusion_kg_per_m_s: problem.diffusion_kg_per_m_s,
        mass_flow_kg_per_s: &mass_flow,
        porosity: eps,
        old_porosity: eps,
        boundary_value: &boundary_value,
        blocked: &[],
        blocked_value: None,
        source: problem.source,
        exchange_coefficient: &[],
        exchange_coefficient_value: &[],
        conservative: false,
    }
    .step(phi, dt_s, tolerance, 10_000)
}
