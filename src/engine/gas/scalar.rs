//! Transport of a scalar φ carried by the gas (temperature, vapour concentration) on the gas grid:
//!
//! ∂(ερφ)/∂t + ∇·(ερuφ) = ∇·(εΓ∇φ) + S,
//!
//! at cell centres, implicit in time, with the momentum solver's convection scheme (upwind or hybrid) and central
//! diffusion; Γ is a diffusivity times the density (kg/(m·s)). Faces carry the gas mass fluxes ρ ε u A.

use serde::{Deserialize, Serialize};

use super::grid::{Grid, side};
use super::linsolve::{SolveReport, StencilSystem, bicgstab};
use super::simple::Convection;

/// The scalar's condition on one side (periodic sides follow the grid).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ScalarBoundary {
    /// φ fixed on the side (an inlet's value, a wall's temperature).
    Fixed { value: f64 },
    /// No diffusive flux; gas leaving carries the cell's value out.
    ZeroFlux,
}

/// The scalar equation's data for one step.
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
    let (rho, gamma) = (problem.density_kg_per_m3, problem.diffusion_kg_per_m_s);
    let eps = problem.porosity;
    let u = problem.velocity_m_per_s;
    let volume = grid.cell_volume_m3();
    let mut sys = StencilSystem::new(grid.cells());
    let coefficient = |flux_into: f64, diff: f64| -> f64 {
        match problem.convection {
            Convection::Upwind => diff + flux_into.max(0.0),
            Convection::Hybrid => flux_into.max(diff + 0.5 * flux_into).max(0.0),
        }
    };
    for k in 0..grid.n[2] {
        for j in 0..grid.n[1] {
            for i in 0..grid.n[0] {
                let idx = [i, j, k];
                let p = grid.cell(idx);
                let (mut ap, mut b, mut net_out, mut slot) = (0.0, 0.0, 0.0, 0);
                for a in 0..grid.axes() {
                    let area = grid.face_area_m2(a);
                    for high in [false, true] {
                        let mut fi = idx;
                        fi[a] += usize::from(high);
                        let face = grid.face(a, fi);
                        let sign = if high { 1.0 } else { -1.0 };
                        let neighbour = {
                            let n = grid.n[a] as isize;
                            let jn = idx[a] as isize + if high { 1 } else { -1 };
                            if (0..n).contains(&jn) {
                                let mut c = idx;
                                c[a] = jn as usize;
                                Some(c)
                            } else if grid.periodic(a) {
                                let mut c = idx;
                                c[a] = jn.rem_euclid(n) as usize;
                                Some(c)
                            } else {
                                None
                            }
                        };
                        match neighbour {
                            Some(nb) => {
                                let q = grid.cell(nb);
                                let eps_f = 0.5 * (eps[p] + eps[q]);
                                let flux = rho * eps_f * u[a][face] * area;
                                let diff = gamma * eps_f * area / grid.h_m[a];
                                let a_nb = coefficient(-sign * flux, diff);
                                ap += a_nb;
                                sys.nb[p][slot] = q as u32;
                                sys.anb[p][slot] = a_nb;
                                slot += 1;
                                net_out += sign * flux;
                            }
                            None => {
                                let flux = rho * eps[p] * u[a][face] * area;
                                match problem.boundary[side(a, high)] {
                                    ScalarBoundary::Fixed { value } => {
                                        let diff = gamma * eps[p] * area / (0.5 * grid.h_m[a]);
                                        let a_b = coefficient(-sign * flux, diff);
                                        ap += a_b;
                                        b += a_b * value;
                                        net_out += sign * flux;
                                    }
                                    ScalarBoundary::ZeroFlux => {
                                        // Only outflow carries φ_P out; inflow through a zero-flux side brings none.
                                        net_out += (sign * flux).max(0.0);
                                    }
                                }
                            }
                        }
                    }
                }
                let a_p0 = rho * eps[p] * volume / dt_s;
                sys.ap[p] = ap + a_p0 + net_out;
                sys.b[p] = b + a_p0 * phi[p] + problem.source.get(p).copied().unwrap_or(0.0) * volume;
            }
        }
    }
    bicgstab(&sys, phi, tolerance, 10_000)
}
