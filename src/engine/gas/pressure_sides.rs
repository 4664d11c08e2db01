//! The index work of the pressure-correction equation, done once: each cell's faces along each axis and, where a
//! face's velocity is solved, the cell beyond it (see `momentum_rows.rs` for the momentum equations' share).

use super::grid::Grid;
use super::linsolve::NONE;
use super::simple::{all_indices, step_cell};

/// One face of a cell in the pressure-correction equation: the face (of the component along its axis) and, where
/// the face's velocity is solved and a cell lies beyond it, the solved copy of the face (the first face stands for
/// the last on a periodic axis) and that cell.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PressureSide {
    pub face: usize,
    pub solved: Option<(usize, usize)>,
}

/// The faces of every cell for [`PressureSide`], computed once.
pub(crate) fn pressure_sides(grid: &Grid, unknown: &[Vec<u32>; 3]) -> Vec<PressureSide> {
    let mut sides = Vec::with_capacity(grid.cells() * 2 * grid.axes());
    for idx in all_indices(grid.n) {
        for a in 0..grid.axes() {
            for high in [false, true] {
                let mut fi = idx;
                fi[a] += usize::from(high);
                let face = grid.face(a, fi);
                let solved_face = if grid.periodic(a) && fi[a] == grid.n[a] {
                    let mut first = fi;
                    first[a] = 0;
                    grid.face(a, first)
                } else {
                    face
                };
                let solved = if unknown[a][solved_face] != NONE {
                    step_cell(grid, idx, a, if high { 1 } else { -1 }).map(|nb| (solved_face, grid.cell(nb)))
                } else {
                    None
                };
                sides.push(PressureSide { face, solved });
            }
        }
    }
    sides
}
