//! From particles to the gas grid and back: porosity (seed 000 eq 2.66) and gas velocity at a particle.
//!
//! Porosity ε = 1 − Σ V_i / V_cell, with V_i the part of particle i's volume in the cell, by one of two methods:
//! - `centre_binning`: each particle's whole volume goes to the cell holding its centre (seeds 001/002 count whole
//!   particles per cell; neither says how, centre binning is the usual reading);
//! - `volume_split` (the default): the volume is split between the cells the sphere overlaps. Along each axis the
//!   fraction on each side of a cell face is the exact spherical-cap fraction; the 3-D split is the product of the
//!   three axis splits, exact when the sphere crosses faces normal to one axis only and an approximation in cell
//!   corners. Each particle's fractions sum to 1, so solid volume is conserved exactly.
//!
//! Positions outside a non-periodic grid are clamped into its edge cells; on a periodic axis they wrap.

use serde::{Deserialize, Serialize};

use super::grid::Grid;
use crate::engine::Vec3;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PorosityMethod {
    CentreBinning,
    #[default]
    VolumeSplit,
}

/// Fraction of a sphere's volume on the low side of a plane at signed distance `s` from its centre (in radii,
/// positive when the plane lies on the high side of the centre): the cap formula V(h)/V with h the cap height.
pub fn cap_fraction_below(s: f64) -> f64 {
    if s >= 1.0 {
        1.0
    } else if s <= -1.0 {
        0.0
    } else {
        // The part beyond the plane is a cap of height 1 − s (unit sphere): V_cap/V = (1 − s)²(2 + s)/4.
        1.0 - (1.0 - s) * (1.0 - s) * (2.0 + s) / 4.0
    }
}

/// Cell index along `axis` of coordinate `x` (clamped or wrapped).
fn cell_along(grid: &Grid, axis: usize, x: f64) -> isize {
    floor_to_isize((x - grid.origin_m[axis]) / grid.h_m[axis])
}

fn wrap_or_clamp(grid: &Grid, axis: usize, i: isize) -> usize {
    let n = grid.n[axis] as isize;
    if grid.periodic(axis) {
        i.rem_euclid(n) as usize
    } else {
        i.clamp(0, n - 1) as usize
    }
}

/// The cells a sphere overlaps along one axis with the fraction of its volume in each (at most a few entries), into
/// `out` (cleared first: one buffer serves every particle of a porosity pass).
fn axis_split(grid: &Grid, axis: usize, centre: f64, radius: f64, out: &mut Vec<(usize, f64)>) {
    out.clear();
    if grid.n[axis] == 1 && !grid.periodic(axis) {
        out.push((0, 1.0));
        return;
    }
    let h = grid.h_m[axis];
    let first = cell_along(grid, axis, centre - radius);
    let last = cell_along(grid, axis, centre + radius);
    let mut below_previous = 0.0;
    for i in first..=last {
        let top = grid.origin_m[axis] + (i + 1) as f64 * h;
        let below = if i == last {
            1.0
        } else {
            cap_fraction_below((top - centre) / radius)
        };
        let fraction = below - below_previous;
        below_previous = below;
        let cell = wrap_or_clamp(grid, axis, i);
        match out.iter_mut().find(|(c, _)| *c == cell) {
            Some(entry) => entry.1 += fraction,
            None => out.push((cell, fraction)),
        }
    }
}

/// Solid volume in each cell, m³.
pub fn solid_volume_m3(grid: &Grid, method: PorosityMethod, positions_m: &[Vec3], radii_m: &[f64]) -> Vec<f64> {
    let mut solid = vec![0.0; grid.cells()];
    let mut splits: [Vec<(usize, f64)>; 3] = Default::default();
    for (x, &r) in positions_m.iter().zip(radii_m) {
        let volume = 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        match method {
            PorosityMethod::CentreBinning => {
                let idx: [usize; 3] = std::array::from_fn(|a| wrap_or_clamp(grid, a, cell_along(grid, a, x[a])));
                solid[grid.cell(idx)] += volume;
            }
            PorosityMethod::VolumeSplit => {
                for (a, split) in splits.iter_mut().enumerate() {
                    axis_split(grid, a, x[a], r, split);
                }
                for &(i, fx) in &splits[0] {
                    for &(j, fy) in &splits[1] {
                        for &(k, fz) in &splits[2] {
                            solid[grid.cell([i, j, k])] += volume * fx * fy * fz;
                        }
                    }
                }
            }
        }
    }
    solid
}

/// Porosity of each cell, not below `minimum` (a cell over-filled by the split or by binning would otherwise reach
/// 0 or below).
pub fn porosity(grid: &Grid, method: PorosityMethod, positions_m: &[Vec3], radii_m: &[f64], minimum: f64) -> Vec<f64> {
    let v = grid.cell_volume_m3();
    solid_volume_m3(grid, method, positions_m, radii_m)
        .into_iter()
        .map(|s| (1.0 - s / v).max(minimum))
        .collect()
}

/// The lattice of one velocity component's faces (faces sit at i·h along their axis and at cell centres across
/// it), precomputed for fast trilinear stencils: interpolation and the spreading of the drag reaction use the same
/// weights.
#[derive(Debug, Clone, Copy)]
pub struct FaceLattice {
    axis: usize,
    dims: [usize; 3],
    stride: [usize; 3],
    origin_m: [f64; 3],
    inverse_h_per_m: [f64; 3],
    /// 0 along the axis, ½ across it (in cells).
    offset: [f64; 3],
    periodic: [bool; 3],
}

/// Up to 8 faces (flat indices into the component's array) with non-zero trilinear weights, in corner order.
#[derive(Debug, Clone, Copy, Default)]
pub struct Stencil {
    pub face: [usize; 8],
    pub weight: [f64; 8],
    pub count: usize,
}

impl Stencil {
    /// Σ w · values[face].
    #[inline]
    pub fn apply(&self, values: &[f64]) -> f64 {
        let mut sum = 0.0;
        for c in 0..self.count {
            sum += self.weight[c] * values[self.face[c]];
        }
        sum
    }
}

impl FaceLattice {
    pub fn new(grid: &Grid, axis: usize) -> Self {
        let dims = grid.face_dims(axis);
        FaceLattice {
            axis,
            dims,
            stride: [1, dims[0], dims[0] * dims[1]],
            origin_m: grid.origin_m,
            inverse_h_per_m: std::array::from_fn(|a| 1.0 / grid.h_m[a]),
            offset: std::array::from_fn(|a| if a == axis { 0.0 } else { 0.5 }),
            periodic: std::array::from_fn(|a| grid.periodic(a)),
        }
    }

    /// The trilinear stencil at `x`: clamped at non-periodic edges (a point beyond the last face takes that face),
    /// wrapped on periodic axes.
    ///
    /// The corners come in the order of a three-bit counter (axis 0 fastest), each with the weight
    /// ((1 · f_0) · f_1) · f_2 (f_a the axis's w or 1 − w), and a corner of weight 0 is left out: an axis whose upper
    /// weight is 0 (a clamped edge, a one-cell axis, a point exactly on a face) contributes its lower side alone, so a
    /// 2-D grid's stencil is built from four corners, not eight.
    #[inline]
    pub fn stencil(&self, x: &Vec3) -> Stencil {
        // Per axis: the lower and upper face's index times the stride, and their weights 1 − w and w.
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        let mut w = [0.0f64; 3];
        for a in 0..3 {
            let s = (x[a] - self.origin_m[a]) * self.inverse_h_per_m[a] - self.offset[a];
            let base = floor_to_isize(s);
            let frac = s - base as f64;
            let (l, h, weight) = if self.periodic[a] {
                // Faces across a periodic axis number n (the high side is the low side).
                let n = self.dims[a] as isize - isize::from(a == self.axis);
                (wrap(base, n), wrap(base + 1, n), frac)
            } else {
                let max = self.dims[a] as isize - 1;
                if base < 0 {
                    (0, 0, 0.0)
                } else if base >= max {
                    (max as usize, max as usize, 0.0)
                } else {
                    (base as usize, base as usize + 1, frac)
                }
            };
            (lo[a], hi[a], w[a]) = (l * self.stride[a], h * self.stride[a], weight);
        }
        let mut out = Stencil {
            face: [0; 8],
            weight: [0.0; 8],
            count: 0,
        };
        // Whether each axis has an upper corner of non-zero weight (1 − w is never 0: w < 1).
        let upper = w.map(|w| w != 0.0);
        for k in 0..=usize::from(upper[2]) {
            let (face_k, weight_k) = if k == 1 { (hi[2], w[2]) } else { (lo[2], 1.0 - w[2]) };
            for j in 0..=usize::from(upper[1]) {
                let (face_j, weight_j) = if j == 1 { (hi[1], w[1]) } else { (lo[1], 1.0 - w[1]) };
                for i in 0..=usize::from(upper[0]) {
                    let (face_i, weight_i) = if i == 1 { (hi[0], w[0]) } else { (lo[0], 1.0 - w[0]) };
                    let weight = 1.0 * weight_i * weight_j * weight_k;
                    if weight != 0.0 {
                        out.face[out.count] = face_i + face_j + face_k;
                        out.weight[out.count] = weight;
                        out.count += 1;
                    }
                }
            }
        }
        out
    }

    /// The component's value at `x` from its face values.
    #[inline]
    pub fn interpolate(&self, values: &[f64], x: &Vec3) -> f64 {
        self.stencil(x).apply(values)
    }
}

/// ⌊s⌋ as an integer, exactly `s.floor() as isize` for every `s` (0 for NaN, saturated beyond isize's range), without
/// the call to the C library's `floor` that the x86-64 baseline makes (it has no rounding instruction): that call
/// was 6 % of a coupled bed's run (`docs/performance.md`).
#[inline]
pub(crate) fn floor_to_isize(s: f64) -> isize {
    let truncated = s as isize;
    // Saturating, as the cast is: below isize::MIN the truncation already saturated.
    truncated.saturating_sub(isize::from((truncated as f64) > s))
}

/// `i` wrapped into [0, n) (positions on a periodic axis are within one period of the domain, so the division is
/// rarely needed).
#[inline]
fn wrap(i: isize, n: isize) -> usize {
    if (0..n).contains(&i) {
        i as usize
    } else if (n..2 * n).contains(&i) {
        (i - n) as usize
    } else if (-n..0).contains(&i) {
        (i + n) as usize
    } else {
        i.rem_euclid(n) as usize
    }
}

/// One velocity component at a point: trilinear interpolation between the component's face values
/// ([`FaceLattice`]).
pub fn interpolate_component(grid: &Grid, values: &[f64], axis: usize, x: &Vec3) -> f64 {
    FaceLattice::new(grid, axis).interpolate(values, x)
}

/// The gas velocity at a point (the z component is 0 on a 2-D grid).
pub fn gas_velocity_at(grid: &Grid, velocity: &[Vec<f64>; 3], x: &Vec3) -> Vec3 {
    let mut u = Vec3::zeros();
    for a in 0..grid.axes() {
        u[a] = interpolate_component(grid, &velocity[a], a, x);
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::gas::grid::Boundary;
    use rand::{RngExt, SeedableRng};

    fn grid(periodic_x: bool) -> Grid {
        let wall = Boundary::Wall {
            velocity_m_per_s: [0.0; 3],
        };
        let x = if periodic_x { Boundary::Periodic } else { wall };
        Grid {
            n: [5, 4, 3],
            h_m: [0.01, 0.012, 0.009],
            origin_m: [0.0, -0.02, 0.0],
            boundary: [x, x, wall, wall, wall, wall],
        }
    }

    #[test]
    fn the_integer_floor_is_the_library_floor() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.5,
            -1e-300,
            1e-300,
            4503599627370495.5,
            -4503599627370495.5,
            9.3e18,
            -9.3e18,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let random = (0..10_000).map(|_| rng.random_range(-1e6..1e6));
        for s in special.into_iter().chain(random) {
            assert_eq!(floor_to_isize(s), s.floor() as isize, "{s}");
        }
    }

    #[test]
    fn cap_fractions_are_the_sphere_volume_formula() {
        assert_eq!(cap_fraction_below(0.0), 0.5);
        assert_eq!(cap_fraction_below(1.0), 1.0);
        assert_eq!(cap_fraction_below(-1.0), 0.0);
        // A plane at half a radius above the centre leaves a cap of height 0.5: V_cap/V = 0.25·2.5/4 = 0.15625.
        assert!((cap_fraction_below(0.5) - (1.0 - 0.15625)).abs() < 1e-15);
    }

    #[test]
    fn both_methods_conserve_the_solid_volume() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for periodic in [false, true] {
            let g = grid(periodic);
            let positions: Vec<Vec3> = (0..300)
                .map(|_| {
                    Vec3::new(
                        rng.random_range(0.0..0.05),
                        rng.random_range(-0.02..0.028),
                        rng.random_range(0.0..0.027),
                    )
                })
                .collect();
            let radii: Vec<f64> = (0..300).map(|_| rng.random_range(0.0005..0.003)).collect();
            let total: f64 = radii.iter().map(|r| 4.0 / 3.0 * std::f64::consts::PI * r * r * r).sum();
            for method in [PorosityMethod::CentreBinning, PorosityMethod::VolumeSplit] {
                let s: f64 = solid_volume_m3(&g, method, &positions, &radii).iter().sum();
                assert!(
                    (s / total - 1.0).abs() < 1e-12,
                    "{method:?} periodic {periodic}: {s} vs {total}"
                );
            }
        }
    }

    #[test]
    fn a_sphere_across_one_face_is_split_by_the_cap_formula() {
        let g = grid(false);
        // Centre 0.3 radius below the face x = 0.02, away from the other faces.
        let r = 0.002;
        let x = Vec3::new(0.02 - 0.3 * r, -0.02 + 0.006, 0.0045);
        let s = solid_volume_m3(&g, PorosityMethod::VolumeSplit, &[x], &[r]);
        let v = 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        let below = s[g.cell([1, 0, 0])] / v;
        assert!((below - cap_fraction_below(0.3)).abs() < 1e-14, "{below}");
        assert!((s[g.cell([2, 0, 0])] / v - (1.0 - cap_fraction_below(0.3))).abs() < 1e-14);
    }

    #[test]
    fn interpolation_is_exact_for_a_linear_field() {
        for periodic in [false] {
            let g = grid(periodic);
            for axis in 0..3 {
                let dims = g.face_dims(axis);
                let mut values = vec![0.0; g.faces(axis)];
                let field = |p: [f64; 3]| 1.0 + 2.0 * p[0] - 3.0 * p[1] + 0.5 * p[2];
                for k in 0..dims[2] {
                    for j in 0..dims[1] {
                        for i in 0..dims[0] {
                            values[g.face(axis, [i, j, k])] = field(g.face_centre_m(axis, [i, j, k]));
                        }
                    }
                }
                // A point inside the lattice of this component's faces.
                let p = Vec3::new(0.023, -0.004, 0.0131);
                let got = interpolate_component(&g, &values, axis, &p);
                assert!((got - field([p.x, p.y, p.z])).abs() < 1e-12, "axis {axis}: {got}");
            }
        }
    }
}
