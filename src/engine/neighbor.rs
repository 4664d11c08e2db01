//! Neighbour search: cell lists with a skin, producing a half list of candidate pairs in a deterministic order.
//!
//! The list is compressed-sparse-row: the candidates of particle i are the partners j > i in
//! `partner[start[i]..start[i+1]]`, sorted ascending. Particle–wall candidates are a second CSR (`wall_*`) with wall
//! indices ascending. Both are built in parallel over chunks of particles; only the binning into cells is serial.
//!
//! This is workspace: it is rebuilt when any particle has moved more than half the skin (or a moving wall more
//! than half the skin) and is never checkpointed. What it finds does not depend on when it was built, so results do
//! not either.

use super::Vec3;
use super::contacts::split_at_ends;
use super::geometry::{Domain, Wall};
use super::team::{Team, map_indices};

/// Particles per work item in the build.
pub const BUILD_CHUNK: usize = 1024;

/// How far beyond contact particles interact with each other and with walls (a cohesion model's range): the list
/// holds every pair whose surfaces are closer than this plus the skin.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Reach {
    pub pair_gap_m: f64,
    pub wall_gap_m: f64,
}

#[derive(Debug, Clone, Default)]
pub struct NeighborList {
    pub start: Vec<u32>,
    pub partner: Vec<u32>,
    pub wall_start: Vec<u32>,
    pub wall_partner: Vec<u16>,
    /// Positions and wall angles when the list was built.
    reference_position: Vec<Vec3>,
    reference_wall_angle: Vec<f64>,
    skin_m: f64,
    pub builds: u64,
}

/// Particles sorted into cubic-ish cells of at least the interaction range.
struct CellGrid {
    dims: [usize; 3],
    /// Cell coordinates of each particle.
    cell: Vec<[u32; 3]>,
    /// Particles of cell c are `particle[start[c]..start[c+1]]`, ascending.
    start: Vec<u32>,
    particle: Vec<u32>,
}

impl CellGrid {
    /// The most cells a grid of n particles has: 27 per particle, and at least 2^20 (4 MB of cell starts). A
    /// domain far larger than its particles (a few beads in a kilometre box) gets coarser cells instead of an
    /// allocation the size of the domain; the lists found are the same (they are sorted), only the search is slower.
    fn max_cells(particles: usize) -> f64 {
        (27.0 * particles as f64).max((1u64 << 20) as f64)
    }

    fn new(domain: &Domain, position: &[Vec3], cell_size_m: f64, team: &Team) -> Self {
        let length = domain.length_m();
        let max_cells = Self::max_cells(position.len());
        let mut size_m = cell_size_m;
        let mut per_axis = [1.0f64; 3];
        for _ in 0..64 {
            per_axis = std::array::from_fn(|axis| (length[axis] / size_m).floor().max(1.0));
            let cells = per_axis[0] * per_axis[1] * per_axis[2];
            if cells <= max_cells {
                break;
            }
            size_m *= (cells / max_cells).cbrt().max(1.01);
        }
        let dims: [usize; 3] = per_axis.map(|n| n as usize);
        let cell: Vec<[u32; 3]> = map_indices(team, position.len(), BUILD_CHUNK, |i| {
            let x = &position[i];
            let mut c = [0u32; 3];
            for axis in 0..3 {
                let f = (x[axis] - domain.lo_m[axis]) / length[axis] * dims[axis] as f64;
                c[axis] = (f.floor().max(0.0) as usize).min(dims[axis] - 1) as u32;
            }
            c
        });
        let n_cells = dims[0] * dims[1] * dims[2];
        let mut grid = CellGrid {
            dims,
            cell,
            start: vec![0u32; n_cells + 1],
            particle: vec![0u32; position.len()],
        };
        // Counting sort; stable, so each cell lists its particles in ascending index.
        for k in 0..grid.cell.len() {
            let f = grid.flat(grid.cell[k]);
            grid.start[f + 1] += 1;
        }
        for k in 0..n_cells {
            grid.start[k + 1] += grid.start[k];
        }
        let mut fill = grid.start.clone();
        for i in 0..grid.cell.len() {
            let f = grid.flat(grid.cell[i]);
            grid.particle[fill[f] as usize] = i as u32;
            fill[f] += 1;
        }
        grid
    }

    #[inline]
    fn flat(&self, c: [u32; 3]) -> usize {
        (c[2] as usize * self.dims[1] + c[1] as usize) * self.dims[0] + c[0] as usize
    }

    /// The distinct cell coordinates next to `c` along `axis` (itself included), wrapped on periodic axes.
    #[inline]
    fn adjacent(&self, c: u32, axis: usize, periodic: bool) -> ([u32; 3], usize) {
        let m = self.dims[axis] as i64;
        let mut out = [0u32; 3];
        let mut len = 0;
        for d in -1i64..=1 {
            let mut v = c as i64 + d;
            if v < 0 || v >= m {
                if !periodic {
                    continue;
                }
                v = v.rem_euclid(m);
            }
            if !out[..len].contains(&(v as u32)) {
                out[len] = v as u32;
                len += 1;
            }
        }
        (out, len)
    }
}

/// What a list holds, for particles of radius `radius` at `position`: pairs whose surfaces are closer than
/// `range.pair_gap_m + skin_m`, and particle–wall pairs likewise (with `range.wall_gap_m`), except that in a
/// `pseudo_2d` run a plane normal to z is a candidate only if the particle already overlaps it (its gap cannot
/// change: in a one-layer bed every particle just touches the front and back planes, which never push).
#[derive(Clone, Copy)]
pub struct Criteria<'a> {
    pub domain: &'a Domain,
    pub position: &'a [Vec3],
    pub radius: &'a [f64],
    pub skin_m: f64,
    pub range: Reach,
    pub walls: &'a [Wall],
    pub wall_angle: &'a [f64],
    /// (sine, cosine) of each `wall_angle` ([`crate::engine::geometry::turns`]).
    pub wall_turn: &'a [(f64, f64)],
    pub pseudo_2d: bool,
}

impl Criteria<'_> {
    #[inline(always)]
    fn pair(&self, i: usize, j: usize) -> bool {
        let reach = self.radius[i] + self.radius[j] + self.range.pair_gap_m + self.skin_m;
        self.domain
            .separation(&self.position[i], &self.position[j])
            .norm_squared()
            < reach * reach
    }

    #[inline(always)]
    fn wall(&self, i: usize, w: u16) -> bool {
        let (wall, ri) = (&self.walls[w as usize], self.radius[i]);
        let reach = if self.pseudo_2d && wall.is_plane_normal_to_z() {
            ri
        } else {
            ri + self.range.wall_gap_m + self.skin_m
        };
        // The bound first: the bed's interior is far from a drum's beads and baffles (the same decisions).
        wall.gap_lower_bound_m(&self.position[i]) < reach
            && wall
                .proximity_turned(&self.position[i], self.wall_turn[w as usize])
                .gap_m
                < reach
    }
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

    /// True when some particle has moved more than `allowance_m` from where it was at the build, or a moving
    /// wall's surface has. [`NeighborList::refilter`] asks it of the list it filters. The particles are scanned in
    /// chunks on `team`.
    pub fn displaced_beyond(
        &self,
        domain: &Domain,
        position: &[Vec3],
        walls: &[Wall],
        wall_angle: &[f64],
        allowance_m: f64,
        team: &Team,
    ) -> bool {
        if self.reference_position.len() != position.len() || self.builds == 0 {
            return true;
        }
        let limit2 = allowance_m * allowance_m;
        let moved = |particles: std::ops::Range<usize>| {
            position[particles.clone()]
                .iter()
                .zip(&self.reference_position[particles])
                .any(|(x, x0)| domain.separation(x, x0).norm_squared() > limit2)
        };
        team.map_chunks(position.len(), BUILD_CHUNK, moved).contains(&true)
            || walls
                .iter()
                .zip(wall_angle.iter().zip(&self.reference_wall_angle))
                .any(|(w, (a, a0))| w.max_lever_m() * (a - a0).abs() > allowance_m)
    }

    /// Rebuilds the lists by searching the cells for what `criteria` holds, on `team`.
    pub fn build(&mut self, criteria: &Criteria, team: &Team) {
        let Criteria {
            domain,
            position,
            radius,
            skin_m,
            range,
            walls,
            ..
        } = *criteria;
        let max_radius = radius.iter().copied().fold(0.0, f64::max);
        let grid = CellGrid::new(domain, position, 2.0 * max_radius + range.pair_gap_m + skin_m, team);
        self.assemble(criteria, team, |i, partners, near_walls| {
            let ci = grid.cell[i];
            let (xs, nx) = grid.adjacent(ci[0], 0, domain.periodic[0]);
            let (ys, ny) = grid.adjacent(ci[1], 1, domain.periodic[1]);
            let (zs, nz) = grid.adjacent(ci[2], 2, domain.periodic[2]);
            let before = partners.len();
            for &cz in &zs[..nz] {
                for &cy in &ys[..ny] {
                    for &cx in &xs[..nx] {
                        let c = grid.flat([cx, cy, cz]);
                        for &j in &grid.particle[grid.start[c] as usize..grid.start[c + 1] as usize] {
                            if j as usize > i && criteria.pair(i, j as usize) {
                                partners.push(j);
                            }
                        }
                    }
                }
            }
            partners[before..].sort_unstable();
            near_walls.extend((0..walls.len() as u16).filter(|&w| criteria.wall(i, w)));
        });
    }

    /// Rebuilds the lists as [`NeighborList::build`] would for `criteria`, taking the candidates from `outer` (a
    /// list with a larger skin) instead of the cells: the two-level scheme of the force pass. Complete only while no
    /// particle has moved more than (outer skin − `criteria.skin_m`)/2 since `outer` was built
    /// ([`NeighborList::displaced_beyond`]); the caller checks that first.
    pub fn refilter(&mut self, outer: &NeighborList, criteria: &Criteria, team: &Team) {
        debug_assert!(criteria.skin_m <= outer.skin_m);
        self.assemble(criteria, team, |i, partners, near_walls| {
            partners.extend(
                outer.partner[outer.pairs_of(i)]
                    .iter()
                    .filter(|&&j| criteria.pair(i, j as usize)),
            );
            near_walls.extend(
                outer.wall_partner[outer.walls_of(i)]
                    .iter()
                    .filter(|&&w| criteria.wall(i, w)),
            );
        });
    }

    /// Becomes a copy of `other` (lists, reference state and skin), counting as a build.
    pub fn adopt(&mut self, other: &NeighborList) {
        let builds = self.builds;
        self.clone_from(other);
        self.builds = builds + 1;
    }

    /// Fills the lists from `candidates(i, partners, walls)`, which appends particle i's partners (ascending, all
    /// greater than i) and walls (ascending), and records the reference state. Chunks of particles are searched on
    /// `team`, and then each chunk's results are copied to their places in the lists, also on `team`.
    fn assemble(
        &mut self,
        criteria: &Criteria,
        team: &Team,
        candidates: impl Fn(usize, &mut Vec<u32>, &mut Vec<u16>) + Sync,
    ) {
        let n = criteria.position.len();
        struct Chunk {
            partners: Vec<u32>,
            counts: Vec<u32>,
            walls: Vec<u16>,
            wall_counts: Vec<u32>,
        }
        let chunks: Vec<Chunk> = team.map_chunks(n, BUILD_CHUNK, |particles| {
            let mut out = Chunk {
                partners: Vec::with_capacity(particles.len() * 8),
                counts: Vec::with_capacity(particles.len()),
                walls: Vec::new(),
                wall_counts: Vec::with_capacity(particles.len()),
            };
            for i in particles {
                let (before, walls_before) = (out.partners.len(), out.walls.len());
                candidates(i, &mut out.partners, &mut out.walls);
                out.counts.push((out.partners.len() - before) as u32);
                out.wall_counts.push((out.walls.len() - walls_before) as u32);
            }
            out
        });

        // Where each chunk's results go.
        let particle_ends: Vec<usize> = (1..=chunks.len()).map(|c| (c * BUILD_CHUNK).min(n)).collect();
        let (mut pair_ends, mut wall_ends) = (Vec::with_capacity(chunks.len()), Vec::with_capacity(chunks.len()));
        let (mut total, mut wall_total) = (0usize, 0usize);
        for chunk in &chunks {
            total += chunk.partners.len();
            wall_total += chunk.walls.len();
            pair_ends.push(total);
            wall_ends.push(wall_total);
        }
        assert!(
            total <= u32::MAX as usize && wall_total <= u32::MAX as usize,
            "more than 2^32 neighbour pairs"
        );
        self.start.resize(n + 1, 0);
        self.start[0] = 0;
        self.partner.resize(total, 0);
        self.wall_start.resize(n + 1, 0);
        self.wall_start[0] = 0;
        self.wall_partner.resize(wall_total, 0);
        self.reference_position.resize(n, Vec3::zeros());
        let parts: Vec<_> = chunks
            .into_iter()
            .zip(split_at_ends(&mut self.start[1..], &particle_ends))
            .zip(split_at_ends(&mut self.partner, &pair_ends))
            .zip(split_at_ends(&mut self.wall_start[1..], &particle_ends))
            .zip(split_at_ends(&mut self.wall_partner, &wall_ends))
            .zip(split_at_ends(&mut self.reference_position, &particle_ends))
            .collect();
        let place = |c: usize, (((((chunk, start), partner), wall_start), wall_partner), reference): Placed| {
            let lo = c * BUILD_CHUNK;
            let mut end = if c == 0 { 0 } else { pair_ends[c - 1] as u32 };
            for (s, count) in start.iter_mut().zip(&chunk.counts) {
                end += count;
                *s = end;
            }
            let mut end = if c == 0 { 0 } else { wall_ends[c - 1] as u32 };
            for (s, count) in wall_start.iter_mut().zip(&chunk.wall_counts) {
                end += count;
                *s = end;
            }
            partner.copy_from_slice(&chunk.partners);
            wall_partner.copy_from_slice(&chunk.walls);
            reference.copy_from_slice(&criteria.position[lo..lo + reference.len()]);
        };
        type Placed<'a> = (
            ((((Chunk, &'a mut [u32]), &'a mut [u32]), &'a mut [u32]), &'a mut [u16]),
            &'a mut [Vec3],
        );
        if team.size() > 1 && parts.len() > 1 {
            team.map_parts(parts, place);
        } else {
            parts.into_iter().enumerate().for_each(|(c, part)| place(c, part));
        }

        self.reference_wall_angle.clear();
        self.reference_wall_angle.extend_from_slice(criteria.wall_angle);
        self.skin_m = criteria.skin_m;
        self.builds += 1;
    }

    /// Approximate heap bytes held by the lists.
    pub fn heap_bytes(&self) -> usize {
        (self.start.capacity() + self.partner.capacity() + self.wall_start.capacity()) * 4
            + self.wall_partner.capacity() * 2
            + self.reference_position.capacity() * std::mem::size_of::<Vec3>()
            + self.reference_wall_angle.capacity() * 8
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::geometry::turns;

    /// Uniform numbers in [0, 1) from a 64-bit LCG seeded with `seed` (reproducible test positions and radii).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The two-level scheme: a list refiltered with a smaller skin from a list built earlier (particles moved by
    /// less than half the difference of the skins since) equals the list built directly with the smaller skin, for
    /// pairs across a periodic axis and for walls.
    #[test]
    fn refiltered_list_equals_a_direct_build_with_the_inner_skin() {
        use crate::engine::geometry::{Wall, WallShape};
        use crate::engine::particles::SpeciesId;
        let domain = Domain::new(Vec3::zeros(), Vec3::new(0.3, 0.3, 0.3), [true, false, false]);
        let plane = |point: Vec3, normal: Vec3| {
            Wall::new(
                "plane".into(),
                SpeciesId(0),
                WallShape::Plane { point_m: point, normal },
            )
        };
        let walls = [
            plane(Vec3::zeros(), Vec3::y()),
            plane(Vec3::new(0.0, 0.3, 0.0), -Vec3::y()),
            plane(Vec3::zeros(), Vec3::z()),
        ];
        let angles = [0.0; 3];
        let mut rnd = uniform(99);
        let n = 600;
        let start: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(0.3 * rnd(), 0.3 * rnd(), 0.3 * rnd()))
            .collect();
        let radius: Vec<f64> = (0..n).map(|_| 0.01 + 0.01 * rnd()).collect();
        let (skin, inner) = (0.02, 0.005);
        let reach = Reach {
            pair_gap_m: 0.002,
            wall_gap_m: 0.001,
        };
        let at_start = Criteria {
            domain: &domain,
            position: &start,
            radius: &radius,
            skin_m: skin,
            range: reach,
            walls: &walls,
            wall_angle: &angles,
            wall_turn: &turns(&angles),
            pseudo_2d: false,
        };
        let mut outer = NeighborList::default();
        let one = Team::new(1);
        outer.build(&at_start, &one);
        // Everyone moves by just under (skin − inner)/2, in random directions.
        let allowance = 0.5 * (skin - inner);
        let moved: Vec<Vec3> = start
            .iter()
            .map(|x| {
                let d = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize() * (0.999 * allowance);
                let mut y = x + d;
                domain.wrap(&mut y);
                y
            })
            .collect();
        assert!(!outer.displaced_beyond(&domain, &moved, &walls, &angles, allowance, &one));
        let mut refiltered = NeighborList::default();
        let moved_inner = Criteria {
            position: &moved,
            skin_m: inner,
            ..at_start
        };
        refiltered.refilter(&outer, &moved_inner, &Team::new(2));
        let mut direct = NeighborList::default();
        direct.build(&moved_inner, &one);
        assert_eq!(refiltered.start, direct.start);
        assert_eq!(refiltered.partner, direct.partner);
        assert_eq!(refiltered.wall_start, direct.wall_start);
        assert_eq!(refiltered.wall_partner, direct.wall_partner);
        assert!(
            direct.pair_count() > 100 && direct.wall_partner.len() > 20,
            "the test must have pairs and walls"
        );
        assert!(direct.pair_count() < outer.pair_count());
        // Moving one particle a little further is what `displaced_beyond` reports.
        let mut far = moved.clone();
        far[7] = start[7] + Vec3::new(0.0, 1.01 * allowance, 0.0);
        assert!(outer.displaced_beyond(&domain, &far, &walls, &angles, allowance, &one));
    }

    /// `displaced_beyond` on a team scans every chunk: a move past the allowance in the last chunk is seen.
    #[test]
    fn displacement_is_seen_in_any_chunk_on_a_team() {
        let domain = Domain::new(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [false; 3]);
        let n = 3 * BUILD_CHUNK + 5;
        let mut rnd = uniform(7);
        let position: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
        let radius = vec![0.001; n];
        let criteria = Criteria {
            domain: &domain,
            position: &position,
            radius: &radius,
            skin_m: 0.002,
            range: Reach::default(),
            walls: &[],
            wall_angle: &[],
            wall_turn: &[],
            pseudo_2d: false,
        };
        let team = Team::new(2);
        let mut list = NeighborList::default();
        list.build(&criteria, &team);
        assert!(!list.displaced_beyond(&domain, &position, &[], &[], 1e-4, &team));
        for i in [0, BUILD_CHUNK, n - 1] {
            let mut moved = position.clone();
            moved[i].x += 2e-4;
            assert!(
                list.displaced_beyond(&domain, &moved, &[], &[], 1e-4, &team),
                "particle {i}"
            );
        }
    }

    /// The cell-list half list equals the brute-force one, on periodic boxes with many cells per axis and with only
    /// one or two (where the adjacent cells on both sides are the same cell).
    #[test]
    fn matches_brute_force_with_periodic_axes() {
        for (hi, periodic) in [
            (Vec3::new(1.0, 0.5, 0.3), [true, false, true]),
            (Vec3::new(0.1, 0.2, 0.5), [true, true, false]),
        ] {
            let domain = Domain::new(Vec3::zeros(), hi, periodic);
            let mut rnd = uniform(12345);
            // Several build chunks, so that the two-thread build splits the work.
            let n = 2 * BUILD_CHUNK + 300;
            let position: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(hi.x * rnd(), hi.y * rnd(), hi.z * rnd()))
                .collect();
            let radius: Vec<f64> = (0..n).map(|_| 0.02 + 0.02 * rnd()).collect();
            let criteria = Criteria {
                domain: &domain,
                position: &position,
                radius: &radius,
                skin_m: 0.01,
                range: Reach::default(),
                walls: &[],
                wall_angle: &[],
                wall_turn: &[],
                pseudo_2d: false,
            };
            let mut list = NeighborList::default();
            list.build(&criteria, &Team::new(1));
            let mut on_team = NeighborList::default();
            on_team.build(&criteria, &Team::new(2));
            assert_eq!((&on_team.start, &on_team.partner), (&list.start, &list.partner));
            for i in 0..n {
                let mut expected = vec![];
                for j in i + 1..n {
                    let reach = radius[i] + radius[j] + 0.01;
                    if domain.separation(&position[i], &position[j]).norm_squared() < reach * reach {
                        expected.push(j as u32);
                    }
                }
                assert_eq!(
                    &list.partner[list.pairs_of(i)],
                    expected.as_slice(),
                    "particle {i} in {hi:?}"
                );
            }
        }
    }
}
