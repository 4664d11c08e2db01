//! Exact k-nearest neighbours of a set of particle centres, found on a uniform cell grid.
//!
//! The mixing indices of seed 000 §2.5 (eqs 2.77–2.80) take the local concentration over each particle and its nearest
//! neighbours; this module finds those neighbours. The search is exact, not approximate, and deterministic: the
//! neighbours of a particle are ordered by distance with ties broken by the smaller particle index, so the answer
//! depends on the positions only, never on the grid. It runs in O(n·k) for beds of roughly uniform density.
//!
//! Not here: periodic images (a bed with periodic sides is measured as stored, without wrapping: neither seed says
//! whether its neighbourhoods wrap) and the contact neighbour list of the engine (`crate::engine::neighbor`), which
//! answers a different question (every pair within an interaction range).

use std::cmp::Ordering;

use crate::engine::Vec3;

/// Mean number of particles per search cell the grid is sized for.
///
/// CHOICE: 4. Measured with `cargo test --release --lib analysis::knn::tests::timing_100k -- --ignored --nocapture`
/// (100,000 uniform random points, k = 10, medians of 5, builds run in turn on a shared 2-core machine): 2 → 85–89 ms,
/// 3 → 69–72 ms, 4 → 67–75 ms, 6 → 83–90 ms; 1 and 8 were slower still. With 4, most queries end after the 27 cells
/// around their own.
const TARGET_PARTICLES_PER_CELL: f64 = 4.0;

/// The k nearest neighbours of every particle, self excluded, nearest first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NearestNeighbours {
    /// Neighbours per particle: the requested k, reduced to n − 1 when there are fewer other particles.
    k: usize,
    /// Neighbours of particle i are `index[i * k..(i + 1) * k]`.
    index: Vec<u32>,
}

impl NearestNeighbours {
    /// Neighbours per particle (the requested k, or n − 1 if that is smaller).
    pub fn k(&self) -> usize {
        self.k
    }

    /// The neighbours of particle `i`, nearest first; equal distances in ascending index.
    pub fn of(&self, i: usize) -> &[u32] {
        &self.index[i * self.k..(i + 1) * self.k]
    }
}

/// The `k` nearest other particles of every particle (exact; ties by index), on a uniform cell grid.
///
/// If there are fewer than k + 1 particles, every particle gets all the others (k becomes n − 1). Positions must be
/// finite for the answer to mean anything; a non-finite coordinate does not panic, its distances sort last.
///
/// # Panics
/// If there are more than `u32::MAX` particles.
pub fn k_nearest_neighbours(positions_m: &[Vec3], k: usize) -> NearestNeighbours {
    let n = positions_m.len();
    assert!(
        u32::try_from(n).is_ok(),
        "k_nearest_neighbours: {n} particles do not fit u32 indices"
    );
    let k = k.min(n.saturating_sub(1));
    let mut index = vec![0u32; n * k];
    if k == 0 {
        return NearestNeighbours { k, index };
    }
    let grid = SearchGrid::new(positions_m);
    let mut best: Vec<(f64, u32)> = Vec::with_capacity(k + 256);
    // Queries in cell order, so consecutive queries touch the same cells.
    for slot in 0..n {
        let i = grid.particle[slot];
        grid.nearest(grid.position[slot], i, k, &mut best);
        let out = &mut index[i as usize * k..(i as usize + 1) * k];
        for (o, &(_, j)) in out.iter_mut().zip(best.iter()) {
            *o = j;
        }
    }
    NearestNeighbours { k, index }
}

/// (squared distance, index) ordering: nearer first, then smaller index. A total order (NaN last), and no two
/// candidates are equal since indices differ.
#[inline]
fn order(a: &(f64, u32), b: &(f64, u32)) -> Ordering {
    a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
}

/// Particles binned into cubic cells of edge `cell_m` covering their bounding box.
struct SearchGrid {
    lo_m: [f64; 3],
    cell_m: f64,
    dims: [usize; 3],
    /// Particles of cell c are slots `start[c]..start[c + 1]`.
    start: Vec<u32>,
    /// Particle index of each slot; ascending within a cell.
    particle: Vec<u32>,
    /// Position of each slot's particle, stored next to the others of its cell for locality.
    position: Vec<[f64; 3]>,
}

impl SearchGrid {
    fn new(positions_m: &[Vec3]) -> Self {
        let n = positions_m.len();
        let mut lo_m = [f64::INFINITY; 3];
        let mut hi_m = [f64::NEG_INFINITY; 3];
        for p in positions_m {
            for axis in 0..3 {
                if p[axis].is_finite() {
                    lo_m[axis] = lo_m[axis].min(p[axis]);
                    hi_m[axis] = hi_m[axis].max(p[axis]);
                }
            }
        }
        let mut extent_m = [0.0f64; 3];
        for axis in 0..3 {
            if lo_m[axis] > hi_m[axis] {
                // No finite coordinate on this axis.
                lo_m[axis] = 0.0;
                hi_m[axis] = 0.0;
            }
            extent_m[axis] = hi_m[axis] - lo_m[axis];
        }
        let cell_m = cell_size_m(extent_m, n);
        let mut dims = [1usize; 3];
        for axis in 0..3 {
            // At most about n cells in all, so the ceil cannot overflow in practice; min() guards a degenerate box.
            let cells = (extent_m[axis] / cell_m).ceil();
            dims[axis] = if cells >= 1.0 {
                (cells as usize).clamp(1, n.max(1))
            } else {
                1
            };
        }
        let mut grid = SearchGrid {
            lo_m,
            cell_m,
            dims,
            start: vec![0u32; dims[0] * dims[1] * dims[2] + 1],
            particle: vec![0u32; n],
            position: vec![[0.0; 3]; n],
        };
        // Counting sort; stable, so each cell lists its particles in ascending index.
        let cell_of: Vec<usize> = positions_m.iter().map(|p| grid.flat(grid.cell_of(p))).collect();
        for &c in &cell_of {
            grid.start[c + 1] += 1;
        }
        for c in 0..grid.start.len() - 1 {
            grid.start[c + 1] += grid.start[c];
        }
        let mut fill = grid.start.clone();
        for (i, &c) in cell_of.iter().enumerate() {
            let slot = fill[c] as usize;
            grid.particle[slot] = i as u32;
            grid.position[slot] = [positions_m[i].x, positions_m[i].y, positions_m[i].z];
            fill[c] += 1;
        }
        grid
    }

    #[inline]
    fn cell_of(&self, p: &Vec3) -> [usize; 3] {
        [
            self.coordinate(p.x, 0),
            self.coordinate(p.y, 1),
            self.coordinate(p.z, 2),
        ]
    }

    #[inline]
    fn coordinate(&self, x: f64, axis: usize) -> usize {
        let f = ((x - self.lo_m[axis]) / self.cell_m).floor();
        // `as` saturates and maps NaN to 0.
        if f > 0.0 {
            (f as usize).min(self.dims[axis] - 1)
        } else {
            0
        }
    }

    #[inline]
    fn flat(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// The k nearest particles to `p` other than `me`, into `best` (sorted, nearest first).
    ///
    /// Visits cells in rings of growing Chebyshev distance r around p's cell, gathering every particle, and after
    /// each ring keeps only the k best (a selection, O(candidates)). A particle in a ring beyond r is at least r cells
    /// plus p's distance to its own cell's nearest face away, so once the k-th best is strictly nearer than that
    /// bound nothing unvisited can displace it, not even on a tie (which would need an equal distance).
    fn nearest(&self, p: [f64; 3], me: u32, k: usize, best: &mut Vec<(f64, u32)>) {
        best.clear();
        let c = [
            self.coordinate(p[0], 0),
            self.coordinate(p[1], 1),
            self.coordinate(p[2], 2),
        ];
        let mut face_m = f64::INFINITY;
        let mut last_ring = 0usize;
        for axis in 0..3 {
            last_ring = last_ring.max(c[axis]).max(self.dims[axis] - 1 - c[axis]);
            if self.dims[axis] > 1 {
                let cell_lo_m = self.lo_m[axis] + c[axis] as f64 * self.cell_m;
                let below = p[axis] - cell_lo_m;
                let above = cell_lo_m + self.cell_m - p[axis];
                face_m = face_m.min(below.min(above).max(0.0));
            }
        }
        if !face_m.is_finite() {
            face_m = 0.0;
        }
        // Rounding in the binning can put a particle a few ulps on the wrong side of a face.
        let margin_m = 1e-6 * self.cell_m;
        for r in 0..=last_ring {
            self.scan_ring(c, r, p, me, best);
            if best.len() > k {
                best.select_nth_unstable_by(k - 1, order);
                best.truncate(k);
            }
            if r == last_ring {
                break;
            }
            if best.len() == k {
                let kth = best
                    .iter()
                    .copied()
                    .reduce(|a, b| if order(&a, &b).is_lt() { b } else { a });
                let kth_sq = kth.expect("k > 0 candidates").0;
                let bound_m = r as f64 * self.cell_m + face_m - margin_m;
                if bound_m > 0.0 && kth_sq < bound_m * bound_m {
                    break;
                }
            }
        }
        best.sort_unstable_by(order);
    }

    /// Gathers every particle but `me` of the cells at Chebyshev distance exactly `r` from cell `c`.
    fn scan_ring(&self, c: [usize; 3], r: usize, p: [f64; 3], me: u32, out: &mut Vec<(f64, u32)>) {
        let range = |axis: usize| {
            let lo = c[axis].saturating_sub(r);
            let hi = (c[axis] + r).min(self.dims[axis] - 1);
            lo..=hi
        };
        for z in range(2) {
            let z_on_ring = z.abs_diff(c[2]) == r;
            for y in range(1) {
                if z_on_ring || y.abs_diff(c[1]) == r {
                    // The whole row is on the ring: its cells are consecutive slots.
                    let x = range(0);
                    let first = self.start[self.flat([*x.start(), y, z])] as usize;
                    let last = self.start[self.flat([*x.end(), y, z]) + 1] as usize;
                    self.gather(first..last, p, me, out);
                } else {
                    // Only the two x ends of this row are on the ring.
                    if c[0] >= r {
                        self.gather_cell([c[0] - r, y, z], p, me, out);
                    }
                    if r > 0 && c[0] + r < self.dims[0] {
                        self.gather_cell([c[0] + r, y, z], p, me, out);
                    }
                }
            }
        }
    }

    #[inline]
    fn gather_cell(&self, cell: [usize; 3], p: [f64; 3], me: u32, out: &mut Vec<(f64, u32)>) {
        let f = self.flat(cell);
        self.gather(self.start[f] as usize..self.start[f + 1] as usize, p, me, out);
    }

    #[inline]
    fn gather(&self, slots: std::ops::Range<usize>, p: [f64; 3], me: u32, out: &mut Vec<(f64, u32)>) {
        for (&j, q) in self.particle[slots.clone()].iter().zip(&self.position[slots]) {
            if j != me {
                let (dx, dy, dz) = (q[0] - p[0], q[1] - p[1], q[2] - p[2]);
                out.push((dx * dx + dy * dy + dz * dz, j));
            }
        }
    }
}

/// Edge of the cubic search cells for n particles in a box of the given extents.
///
/// Sized for `TARGET_PARTICLES_PER_CELL` on average. An axis thinner than a cell (a pseudo-2-D bed one particle
/// deep, or a line of particles) gets one cell, and the others share the particles among themselves.
fn cell_size_m(extent_m: [f64; 3], n: usize) -> f64 {
    let target_cells = (n as f64 / TARGET_PARTICLES_PER_CELL).max(1.0);
    let mut active: Vec<usize> = (0..3).filter(|&a| extent_m[a] > 0.0).collect();
    loop {
        if active.is_empty() {
            // All particles at one point: one cell; any positive size will do.
            return 1.0;
        }
        let volume: f64 = active.iter().map(|&a| extent_m[a]).product();
        let cell_m = (volume / target_cells).powf(1.0 / active.len() as f64);
        let thinnest = *active
            .iter()
            .min_by(|&&a, &&b| extent_m[a].total_cmp(&extent_m[b]))
            .expect("active is not empty");
        if extent_m[thinnest] >= cell_m || !cell_m.is_finite() {
            return if cell_m.is_finite() && cell_m > 0.0 {
                cell_m
            } else {
                extent_m[thinnest].max(f64::MIN_POSITIVE)
            };
        }
        active.retain(|&a| a != thinnest);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::RngExt;
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::SeedableRng;

    /// Reference: sort every other particle by (squared distance, index).
    fn brute_force(positions_m: &[Vec3], k: usize) -> Vec<Vec<u32>> {
        let n = positions_m.len();
        let k = k.min(n.saturating_sub(1));
        (0..n)
            .map(|i| {
                let p = positions_m[i];
                let mut all: Vec<(f64, u32)> = (0..n)
                    .filter(|&j| j != i)
                    .map(|j| {
                        let q = positions_m[j];
                        let (dx, dy, dz) = (q.x - p.x, q.y - p.y, q.z - p.z);
                        (dx * dx + dy * dy + dz * dz, j as u32)
                    })
                    .collect();
                all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                all.into_iter().take(k).map(|(_, j)| j).collect()
            })
            .collect()
    }

    fn assert_matches_brute_force(positions_m: &[Vec3], k: usize) {
        let fast = k_nearest_neighbours(positions_m, k);
        let slow = brute_force(positions_m, k);
        for (i, expected) in slow.iter().enumerate() {
            assert_eq!(fast.of(i), expected.as_slice(), "neighbours of particle {i} (k = {k})");
        }
    }

    fn random_points(n: usize, seed: u64, extent_m: [f64; 3]) -> Vec<Vec3> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                Vec3::new(
                    rng.random::<f64>() * extent_m[0],
                    rng.random::<f64>() * extent_m[1],
                    rng.random::<f64>() * extent_m[2],
                )
            })
            .collect()
    }

    #[test]
    fn matches_brute_force_on_uniform_points() {
        let points = random_points(3000, 1, [0.05, 0.03, 0.02]);
        for k in [1, 6, 10, 25] {
            assert_matches_brute_force(&points, k);
        }
    }

    #[test]
    fn matches_brute_force_on_a_pseudo_2d_bed_and_a_line() {
        // One particle deep in z, as in seed 000's fluidized bed.
        assert_matches_brute_force(&random_points(2000, 2, [0.03, 0.1, 0.0]), 10);
        assert_matches_brute_force(&random_points(500, 3, [0.0, 0.2, 0.0]), 10);
    }

    #[test]
    fn matches_brute_force_on_a_clustered_bed() {
        // A dense clump next to sparse outliers stresses the ring stopping rule.
        let mut points = random_points(1500, 4, [0.001, 0.001, 0.001]);
        points.extend(random_points(50, 5, [1.0, 1.0, 1.0]));
        assert_matches_brute_force(&points, 10);
    }

    #[test]
    fn ties_go_to_the_smaller_index() {
        // A cubic lattice: every interior particle has six neighbours at exactly the same distance, and more ties
        // further out; coordinates are exact in binary so the ties are exact.
        let mut points = Vec::new();
        for z in 0..6 {
            for y in 0..6 {
                for x in 0..6 {
                    points.push(Vec3::new(x as f64 * 0.5, y as f64 * 0.5, z as f64 * 0.5));
                }
            }
        }
        for k in [3, 6, 7, 10, 19] {
            assert_matches_brute_force(&points, k);
        }
        // Coincident particles: distance zero ties.
        let same = vec![Vec3::new(1.0, 2.0, 3.0); 8];
        let nn = k_nearest_neighbours(&same, 3);
        assert_eq!(nn.of(0), &[1, 2, 3]);
        assert_eq!(nn.of(5), &[0, 1, 2]);
    }

    #[test]
    fn fewer_particles_than_k_gives_all_the_others() {
        let points = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let nn = k_nearest_neighbours(&points, 10);
        assert_eq!(nn.k(), 2);
        assert_eq!(nn.of(0), &[2, 1]);
        assert_eq!(nn.of(1), &[2, 0]);
        assert_eq!(k_nearest_neighbours(&[], 10).k(), 0);
        assert_eq!(k_nearest_neighbours(&points[..1], 10).of(0), &[] as &[u32]);
    }

    #[test]
    fn non_finite_positions_do_not_panic() {
        let mut points = random_points(100, 6, [1.0, 1.0, 1.0]);
        points[7] = Vec3::new(f64::NAN, 0.5, 0.5);
        points[8] = Vec3::new(f64::INFINITY, 0.5, 0.5);
        let nn = k_nearest_neighbours(&points, 10);
        // The finite particles never pick the broken ones while finite candidates remain.
        assert!(!nn.of(0).contains(&7) && !nn.of(0).contains(&8));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Coordinates on a coarse integer lattice (many exact ties) or continuous, at various anisotropic scales.
        #[test]
        fn matches_brute_force_on_random_points(
            raw in prop::collection::vec((0u8..12, 0u8..12, 0u8..4), 0..300),
            scale in prop::array::uniform3(prop_oneof![Just(0.0), 1e-4..1.0f64]),
            jitter in any::<bool>(),
            k in 0usize..20,
        ) {
            let points: Vec<Vec3> = raw
                .iter()
                .enumerate()
                .map(|(i, &(x, y, z))| {
                    let j = if jitter { (i as f64 * 0.618_033_988_7).fract() * 0.3 } else { 0.0 };
                    Vec3::new((x as f64 + j) * scale[0], y as f64 * scale[1], (z as f64 - j) * scale[2])
                })
                .collect();
            let fast = k_nearest_neighbours(&points, k);
            let slow = brute_force(&points, k);
            for (i, expected) in slow.iter().enumerate() {
                prop_assert_eq!(fast.of(i), expected.as_slice(), "particle {}", i);
            }
        }
    }

    /// `cargo test --release --lib analysis::knn::tests::timing_100k -- --ignored --nocapture`
    #[test]
    #[ignore = "timing; run in release"]
    fn timing_100k() {
        let points = random_points(100_000, 7, [0.1, 0.1, 0.1]);
        let mut times = Vec::new();
        for _ in 0..5 {
            let start = std::time::Instant::now();
            let nn = k_nearest_neighbours(&points, 10);
            times.push(start.elapsed());
            assert_eq!(nn.k(), 10);
        }
        times.sort();
        println!(
            "k_nearest_neighbours: 100000 particles, k = 10: median {:?} (min {:?}, max {:?})",
            times[2], times[0], times[4]
        );
    }
}
