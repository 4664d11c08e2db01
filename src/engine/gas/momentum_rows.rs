//! The index work of the momentum equations, done once: for each unknown face of a velocity component, the cells on
//! either side, its neighbours along and across the component, and what stands beyond a wall or inlet.
//!
//! `GasSolver::assemble_momentum` runs every outer iteration of every gas step; with its index arithmetic done there
//! (periodic wrapping, face and cell numbering, blocked-cell tests) it was the largest part of a coupled bed's gas
//! step (`docs/performance.md`). None of it changes after the solver is built: the grid, its blocked cells and the
//! boundaries are fixed; only an inlet's velocity may change (its ramp factor), which is why a ghost keeps its
//! [`Boundary`] rather than a velocity.

use super::grid::{Boundary, Grid, side};
use super::simple::{BlockedWallMotion, cell_blocked, face_index, step_cell};

/// A neighbouring face of the same component, as the momentum row sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NeighbourFace {
    /// Its index among the component's faces.
    pub face: usize,
    /// Its unknown's index in the component's system, or `linsolve::NONE` (a boundary face or a periodic alias,
    /// whose value goes to the right-hand side).
    pub unknown: u32,
}

/// What lies across the row's control volume along another axis, on one side.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Across {
    /// Open cells beyond both cells of the row: their flat indices, and the face of the component between them.
    Open {
        beyond_lo: usize,
        beyond_hi: usize,
        neighbour: NeighbourFace,
    },
    /// A wall, inlet or blocked cells: the ghost value half a cell away is this boundary's velocity (an inlet's
    /// times the ramp factor at the time of the step).
    Ghost(Boundary),
}

/// One side of the control volume across the component (axis `axis`, the high side or the low one).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CrossSide {
    pub axis: usize,
    pub high: bool,
    /// The faces of component `axis` on this side of the row's low and high cell, whose mean carries the flux.
    pub flux_face_lo: usize,
    pub flux_face_hi: usize,
    pub across: Across,
}

/// One row of a component's momentum system: unknown face `face`, between cells `cell_lo` and `cell_hi`.
#[derive(Debug, Clone)]
pub(crate) struct MomentumRow {
    pub face: usize,
    pub cell_lo: usize,
    pub cell_hi: usize,
    /// The faces of the same component one cell along it (wrapped on a periodic axis).
    pub east: NeighbourFace,
    pub west: NeighbourFace,
    /// The sides across the component, in the order the assembly adds them (axis ascending, low side first).
    pub cross: Vec<CrossSide>,
}

/// The rows of component `c`, one per unknown (`face_of[u]` is unknown u's face), for a grid with `blocked` cells
/// (empty: none) whose walls move with `wall_motion`.
pub(crate) fn momentum_rows(
    grid: &Grid,
    blocked: &[bool],
    wall_motion: Option<BlockedWallMotion>,
    unknown: &[u32],
    face_of: &[usize],
    c: usize,
) -> Vec<MomentumRow> {
    let neighbour = |face: usize| NeighbourFace {
        face,
        unknown: unknown[face],
    };
    face_of
        .iter()
        .map(|&f| {
            let idx = face_index(grid, c, f);
            let cell_hi = idx;
            let cell_lo = step_cell(grid, idx, c, -1).expect("solved faces have a cell on each side");
            let face_at = |along: isize| -> usize {
                let n = grid.n[c] as isize;
                let mut j = idx;
                j[c] = if grid.periodic(c) {
                    along.rem_euclid(n) as usize
                } else {
                    along as usize
                };
                grid.face(c, j)
            };
            let mut cross = Vec::new();
            for dax in (0..grid.axes()).filter(|&x| x != c) {
                for high in [false, true] {
                    let delta = if high { 1 } else { -1 };
                    let d_face_index = |cell: [usize; 3]| -> usize {
                        let mut j = cell;
                        j[dax] = cell[dax] + usize::from(high);
                        grid.face(dax, j)
                    };
                    let neighbour_hi = step_cell(grid, cell_hi, dax, delta);
                    let neighbour_lo = step_cell(grid, cell_lo, dax, delta);
                    let open = |c: Option<[usize; 3]>| c.filter(|c| !cell_blocked(grid, blocked, *c));
                    let across = match (open(neighbour_lo), open(neighbour_hi)) {
                        (Some(nl), Some(nh)) => {
                            let mut j = idx;
                            j[dax] = nh[dax];
                            Across::Open {
                                beyond_lo: grid.cell(nl),
                                beyond_hi: grid.cell(nh),
                                neighbour: neighbour(grid.face(c, j)),
                            }
                        }
                        // Blocked cells beyond: a wall at rest or turning with `wall_motion`, its velocity taken
                        // at the wall, half a cell from the face's centre.
                        _ if neighbour_lo.is_some() && neighbour_hi.is_some() => {
                            let mut wall = grid.face_centre_m(c, idx);
                            let sign = if high { 1.0 } else { -1.0 };
                            wall[dax] += sign * 0.5 * grid.h_m[dax];
                            Across::Ghost(Boundary::Wall {
                                velocity_m_per_s: wall_motion.map_or([0.0; 3], |m| m.velocity_at(wall)),
                            })
                        }
                        _ => Across::Ghost(grid.boundary[side(dax, high)]),
                    };
                    cross.push(CrossSide {
                        axis: dax,
                        high,
                        flux_face_lo: d_face_index(cell_lo),
                        flux_face_hi: d_face_index(cell_hi),
                        across,
                    });
                }
            }
            MomentumRow {
                face: f,
                cell_lo: grid.cell(cell_lo),
                cell_hi: grid.cell(cell_hi),
                east: neighbour(face_at(idx[c] as isize + 1)),
                west: neighbour(face_at(idx[c] as isize - 1)),
                cross,
            }
        })
        .collect()
}
