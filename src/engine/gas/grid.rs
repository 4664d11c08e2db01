//! The gas grid: uniform, structured, staggered (scalars at cell centres, each velocity component on the faces
//! normal to it), 3-D or 2-D (one cell deep: no z velocity, no z fluxes — seed 000's "pseudo-3-D" bed).

use serde::{Deserialize, Serialize};

/// What bounds the grid on one side.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Boundary {
    /// No-slip wall moving with `velocity_m_per_s` in its own plane (a lid); the normal component is ignored.
    Wall { velocity_m_per_s: [f64; 3] },
    /// The opposite side continues here (both sides must say so).
    Periodic,
    /// Gas enters (or leaves) with this velocity; tangential components act as a moving wall.
    Inlet { velocity_m_per_s: [f64; 3] },
    /// Gas leaves with zero normal gradient of velocity; the pressure there is the reference (0). The outflow is
    /// scaled so that the domain conserves mass (inflow minus the change of gas volume inside); faces where gas
    /// flows back in keep their zero-gradient value and are not scaled.
    Outlet,
}

/// Index of a side: 2·axis for the low side, 2·axis + 1 for the high side.
pub fn side(axis: usize, high: bool) -> usize {
    2 * axis + usize::from(high)
}

#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Cells along x, y, z (z = 1 for a 2-D grid).
    pub n: [usize; 3],
    /// Cell size along each axis, m.
    pub h_m: [f64; 3],
    pub origin_m: [f64; 3],
    /// Boundaries on sides x−, x+, y−, y+, z−, z+ (see [`side`]); z sides are ignored on a 2-D grid.
    pub boundary: [Boundary; 6],
}

impl Grid {
    pub fn two_d(&self) -> bool {
        self.n[2] == 1
    }

    /// Axes carrying a velocity component and fluxes: x, y (and z in 3-D).
    pub fn axes(&self) -> usize {
        if self.two_d() { 2 } else { 3 }
    }

    pub fn periodic(&self, axis: usize) -> bool {
        matches!(self.boundary[side(axis, false)], Boundary::Periodic)
    }

    pub fn cells(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    pub fn cell(&self, i: [usize; 3]) -> usize {
        i[0] + self.n[0] * (i[1] + self.n[1] * i[2])
    }

    pub fn cell_volume_m3(&self) -> f64 {
        self.h_m[0] * self.h_m[1] * self.h_m[2]
    }

    /// Area of a face normal to `axis`, m².
    pub fn face_area_m2(&self, axis: usize) -> f64 {
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        self.h_m[a] * self.h_m[b]
    }

    /// Face counts of the component along `axis`: n + 1 along the axis, n across.
    pub fn face_dims(&self, axis: usize) -> [usize; 3] {
        let mut d = self.n;
        d[axis] += 1;
        d
    }

    pub fn faces(&self, axis: usize) -> usize {
        let d = self.face_dims(axis);
        d[0] * d[1] * d[2]
    }

    pub fn face(&self, axis: usize, i: [usize; 3]) -> usize {
        let d = self.face_dims(axis);
        i[0] + d[0] * (i[1] + d[1] * i[2])
    }

    /// Centre of cell `i`.
    pub fn cell_centre_m(&self, i: [usize; 3]) -> [f64; 3] {
        std::array::from_fn(|a| self.origin_m[a] + (i[a] as f64 + 0.5) * self.h_m[a])
    }

    /// Centre of face `i` of the component along `axis`.
    pub fn face_centre_m(&self, axis: usize, i: [usize; 3]) -> [f64; 3] {
        std::array::from_fn(|a| {
            let offset = if a == axis { 0.0 } else { 0.5 };
            self.origin_m[a] + (i[a] as f64 + offset) * self.h_m[a]
        })
    }

    /// Checks the grid: positive sizes, periodic sides paired.
    pub fn check(&self) -> Result<(), String> {
        for a in 0..3 {
            if self.n[a] == 0 {
                return Err(format!("cells along axis {a}: expected at least 1"));
            }
            if !(self.h_m[a].is_finite() && self.h_m[a] > 0.0) {
                return Err(format!("cell size along axis {a}: expected > 0, got {}", self.h_m[a]));
            }
            let (lo, hi) = (self.boundary[side(a, false)], self.boundary[side(a, true)]);
            if matches!(lo, Boundary::Periodic) != matches!(hi, Boundary::Periodic) && !(a == 2 && self.two_d()) {
                return Err(format!("axis {a}: a periodic side needs a periodic opposite side"));
            }
        }
        Ok(())
    }
}
