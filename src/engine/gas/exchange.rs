//! Gas–particle momentum exchange on the grid: the exchange coefficient β of a cell (N·s/m⁴), and cell values
//! carried to the staggered faces where the momentum equations live.

use std::f64::consts::PI;

use super::grid::Grid;
use crate::engine::models::drag::{DragInput, DragLaw};

/// β of a cell filled with equal spheres of diameter `diameter_m` at solids fraction 1 − ε, moving at the cell's
/// mean particle velocity: β = n K with n = (1 − ε)/V_p spheres per unit volume (seed 002 eq 33: the cell-averaged
/// form) and K from the drag law at the cell's slip speed.
pub fn cell_beta(
    law: DragLaw,
    porosity: f64,
    slip_speed_m_per_s: f64,
    diameter_m: f64,
    gas_density_kg_per_m3: f64,
    gas_viscosity_pa_s: f64,
) -> f64 {
    if porosity >= 1.0 {
        return 0.0;
    }
    let k = law.coefficient_n_s_per_m(&DragInput {
        porosity,
        slip_speed_m_per_s,
        diameter_m,
        gas_density_kg_per_m3,
        gas_viscosity_pa_s,
    });
    (1.0 - porosity) / (PI * diameter_m.powi(3) / 6.0) * k
}

/// A cell-centred field carried to the faces of the component along `axis`: the mean of the two cells beside a
/// face, the one cell at a boundary face, and wrapped on a periodic axis.
pub fn to_faces(grid: &Grid, cells: &[f64], axis: usize) -> Vec<f64> {
    let dims = grid.face_dims(axis);
    let mut out = vec![0.0; grid.faces(axis)];
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let idx = [i, j, k];
                let along = idx[axis];
                let n = grid.n[axis];
                let cell_at = |a: usize| {
                    let mut c = idx;
                    c[axis] = a;
                    cells[grid.cell(c)]
                };
                out[grid.face(axis, idx)] = if grid.periodic(axis) {
                    0.5 * (cell_at((along + n - 1) % n) + cell_at(along % n))
                } else if along == 0 {
                    cell_at(0)
                } else if along == n {
                    cell_at(n - 1)
                } else {
                    0.5 * (cell_at(along - 1) + cell_at(along))
                };
            }
        }
    }
    out
}

/// The gas velocity at cell centres: the mean of each component's two faces.
pub fn cell_velocity(grid: &Grid, velocity: &[Vec<f64>; 3]) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0; 3]; grid.cells()];
    for k in 0..grid.n[2] {
        for j in 0..grid.n[1] {
            for i in 0..grid.n[0] {
                let idx = [i, j, k];
                let c = grid.cell(idx);
                for a in 0..grid.axes() {
                    let mut hi = idx;
                    hi[a] += 1;
                    out[c][a] = 0.5 * (velocity[a][grid.face(a, idx)] + velocity[a][grid.face(a, hi)]);
                }
            }
        }
    }
    out
}
