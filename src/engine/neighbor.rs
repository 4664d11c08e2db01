//! Neighbour search: cell lists with a skin, producing a half list of candidate pairs in a deterministic order.
//!
//! The list is compressed-sparse-row: the candidates of particle i are the partners j > i in
//! `partner[start[i]..start[i+1]]`, sorted ascending. The transpose (`reverse_*`) lists, for each j, the pair slots
//! whose partner is j in ascending i, which is the order the parallel force gather needs to reproduce the serial
//! scatter bit for bit. Particle–wall candidates are a second CSR (`wall_*`) with wall indices ascending.
//!
//! This is workspace: it is rebuilt when any particle has moved more than half the skin (or a moving wall more
//! than half the skin) and is never checkpointed. What it finds does not depend on when it was built, so results do
//! not either.

use rayon::prelude::*;

use super::Vec3;
use super::geometry::{Domain, Wall};

/// Particles per parallel work item in the build.
const BUILD_CHUNK: usize = 512;

#[derive(Debug, Clone, Default)]
pub struct NeighborList {
    pub start: Vec<u32>,
    pub partner: Vec<u32>,
    pub reverse_start: Vec<u32>,
    /// Pair slot indices (into `partner`) grouped by partner, ascending in the first particle.
    pub reverse_slot: Vec<u32>,
    /// The first particle of each `reverse_slot` entry.
    pub reverse_first: Vec<u32>,
    pub wall_start: Vec<u32>,
    pub wall_partner: Vec<u16>,
    /// Positions and wall angles when the list was built.
    reference_position: Vec<Vec3>,
    reference_wall_angle: Vec<f64>,
    skin_m: f64,
    pub builds: u64,
}

impl NeighborList {
    pub fn pair_count(&self) -> usize {
        self.partner.len()
    }

    /// Range of pair slots whose first particle is `i`.
    #[inline]
    pub fn pairs_of(&self, i: usize) -> std::ops::Range<usize> {
        self.start[i] as usize..self.start[i + 1] as usize
    }

    #[inline]
    pub fn walls_of(&self, i: usize) -> std::ops::Range<usize> {
        self.wall_start[i] as usize..self.wall_start[i + 1] as usize
    }

    /// Positions at the last build (empty before the first), for the integrator's displacement check.
    pub fn reference_positions(&self) -> &[Vec3] {
        &self.reference_position
    }

    /// True when the list may miss a contact: some particle moved more than skin/2 since the build
    /// (`max_displacement2_m2` is the largest squared displacement; two particles closing on each other use up the
    /// skin), a moving wall's surface moved more than skin/2, or the particle count changed.
    pub fn needs_rebuild(
        &self,
        n_particles: usize,
        max_displacement2_m2: f64,
        walls: &[Wall],
        wall_angle: &[f64],
    ) -> bool {
        if self.reference_position.len() != n_particles || self.builds == 0 {
            return true;
        }
        if max_displacement2_m2 > (0.5 * self.skin_m).powi(2) {
            return true;
        }
        walls
            .iter()
            .zip(wall_angle.iter().zip(&self.reference_wall_angle))
            .any(|(w, (a, a0))| w.max_lever_m() * (a - a0).abs() > 0.5 * self.skin_m)
    }

    /// Rebuilds the lists for particles of radius `radius` at `position`. Pairs are candidates when their surfaces
    /// are closer than `skin_m`; particle–wall pairs likewise.
    pub fn build(
        &mut self,
        domain: &Domain,
        position: &[Vec3],
        radius: &[f64],
        skin_m: f64,
        walls: &[Wall],
        wall_angle: &[f64],
    ) {
        let n = position.len();
        let max_radius = radius.iter().copied().fold(0.0, f64::max);
        let cell_size = 2.0 * max_radius + skin_m;
        let length = domain.length_m();
        let mut dims = [1usize; 3];
        for axis in 0..3 {
            dims[axis] = ((length[axis] / cell_size).floor() as usize).max(1);
        }
        let cell_of = |x: &Vec3| -> [usize; 3] {
            let mut c = [0usize; 3];
            for axis in 0..3 {
                let f = (x[axis] - domain.lo_m[axis]) / length[axis] * dims[axis] as f64;
                c[axis] = (f.floor().max(0.0) as usize).min(dims[axis] - 1);
            }
            c
        };
        let flat = |c: [usize; 3]| (c[2] * dims[1] + c[1]) * dims[0] + c[0];
        let n_cells = dims[0] * dims[1] * dims[2];

        // Counting sort of particles into cells; stable, so each cell lists particles in ascending index.
        let cells: Vec<[usize; 3]> = position.iter().map(cell_of).collect();
        let mut cell_start = vec![0u32; n_cells + 1];
        for c in &cells {
            cell_start[flat(*c) + 1] += 1;
        }
        for k in 0..n_cells {
            cell_start[k + 1] += cell_start[k];
        }
        let mut fill = cell_start.clone();
        let mut cell_particle = vec![0u32; n];
        for (i, c) in cells.iter().enumerate() {
            let f = flat(*c);
            cell_particle[fill[f] as usize] = i as u32;
            fill[f] += 1;
        }

        let chunks: Vec<(Vec<u32>, Vec<u32>)> = (0..n.div_ceil(BUILD_CHUNK))
            .into_par_iter()
            .map(|chunk| {
                let lo = chunk * BUILD_CHUNK;
                let hi = (lo + BUILD_CHUNK).min(n);
                let mut partners = Vec::with_capacity((hi - lo) * 8);
                let mut counts = Vec::with_capacity(hi - lo);
                let mut neighbor_cells: Vec<usize> = Vec::with_capacity(27);
                for i in lo..hi {
                    let before = partners.len();
                    let ci = cells[i];
                    neighbor_cells.clear();
                    for dz in -1i64..=1 {
                        for dy in -1i64..=1 {
                            for dx in -1i64..=1 {
                                let mut c = [0usize; 3];
                                let mut inside = true;
                                for (axis, d) in [dx, dy, dz].into_iter().enumerate() {
                                    let v = ci[axis] as i64 + d;
                                    let m = dims[axis] as i64;
                                    if v < 0 || v >= m {
                                        if domain.periodic[axis] {
                                            c[axis] = v.rem_euclid(m) as usize;
                                        } else {
                                            inside = false;
                                        }
                                    } else {
                                        c[axis] = v as usize;
                                    }
                                }
                                if inside {
                                    neighbor_cells.push(flat(c));
                                }
                            }
                        }
                    }
                    neighbor_cells.sort_unstable();
                    neighbor_cells.dedup();
                    let xi = position[i];
                    let ri = radius[i];
                    for &cell in &neighbor_cells {
                        for &j in &cell_particle[cell_start[cell] as usize..cell_start[cell + 1] as usize] {
                            let j = j as usize;
                            if j <= i {
                                continue;
                            }
                            let reach = ri + radius[j] + skin_m;
                            if domain.separation(&xi, &position[j]).norm_squared() < reach * reach {
                                partners.push(j as u32);
                            }
                        }
                    }
                    partners[before..].sort_unstable();
                    counts.push((partners.len() - before) as u32);
                }
                (partners, counts)
            })
            .collect();

        self.start.clear();
        self.start.reserve(n + 1);
        self.start.push(0);
        self.partner.clear();
        let mut total = 0u32;
        for (partners, counts) in &chunks {
            for c in counts {
                total += c;
                self.start.push(total);
            }
            self.partner.extend_from_slice(partners);
        }

        // Transpose by counting sort over slots in ascending first particle: ascending i within each j.
        self.reverse_start.clear();
        self.reverse_start.resize(n + 1, 0);
        for &j in &self.partner {
            self.reverse_start[j as usize + 1] += 1;
        }
        for k in 0..n {
            self.reverse_start[k + 1] += self.reverse_start[k];
        }
        let mut fill = self.reverse_start.clone();
        self.reverse_slot.clear();
        self.reverse_slot.resize(self.partner.len(), 0);
        self.reverse_first.clear();
        self.reverse_first.resize(self.partner.len(), 0);
        for i in 0..n {
            for slot in self.pairs_of(i) {
                let f = &mut fill[self.partner[slot] as usize];
                self.reverse_slot[*f as usize] = slot as u32;
                self.reverse_first[*f as usize] = i as u32;
                *f += 1;
            }
        }

        self.wall_start.clear();
        self.wall_start.reserve(n + 1);
        self.wall_start.push(0);
        self.wall_partner.clear();
        for i in 0..n {
            for (w, wall) in walls.iter().enumerate() {
                if wall.proximity(&position[i], wall_angle[w]).gap_m < radius[i] + skin_m {
                    self.wall_partner.push(w as u16);
                }
            }
            self.wall_start.push(self.wall_partner.len() as u32);
        }

        self.reference_position.clear();
        self.reference_position.extend_from_slice(position);
        self.reference_wall_angle.clear();
        self.reference_wall_angle.extend_from_slice(wall_angle);
        self.skin_m = skin_m;
        self.builds += 1;
    }

    /// Approximate heap bytes held by the lists.
    pub fn heap_bytes(&self) -> usize {
        (self.start.capacity()
            + self.partner.capacity()
            + self.reverse_start.capacity()
            + self.reverse_slot.capacity()
            + self.reverse_first.capacity()
            + self.wall_start.capacity())
            * 4
            + self.wall_partner.capacity() * 2
            + self.reference_position.capacity() * std::mem::size_of::<Vec3>()
            + self.reference_wall_angle.capacity() * 8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cell-list half list equals the brute-force one, on a periodic box with few cells per axis.
    #[test]
    fn matches_brute_force_with_periodic_axes() {
        let domain = Domain::new(Vec3::zeros(), Vec3::new(1.0, 0.5, 0.3), [true, false, true]);
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = 400;
        let position: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), 0.5 * rnd(), 0.3 * rnd())).collect();
        let radius: Vec<f64> = (0..n).map(|_| 0.02 + 0.02 * rnd()).collect();
        let mut list = NeighborList::default();
        list.build(&domain, &position, &radius, 0.01, &[], &[]);
        for i in 0..n {
            let mut expected = vec![];
            for j in i + 1..n {
                let reach = radius[i] + radius[j] + 0.01;
                if domain.separation(&position[i], &position[j]).norm_squared() < reach * reach {
                    expected.push(j as u32);
                }
            }
            assert_eq!(&list.partner[list.pairs_of(i)], expected.as_slice(), "particle {i}");
        }
        // The transpose lists every slot once, grouped by partner, ascending in the first particle.
        for j in 0..n {
            let slots = &list.reverse_slot[list.reverse_start[j] as usize..list.reverse_start[j + 1] as usize];
            let mut last_i = None;
            for &s in slots {
                assert_eq!(list.partner[s as usize] as usize, j);
                let i = list.start.partition_point(|&st| st as usize <= s as usize) - 1;
                assert!(last_i.is_none_or(|l| l < i));
                last_i = Some(i);
            }
        }
    }
}
