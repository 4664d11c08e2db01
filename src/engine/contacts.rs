//! Contact history records: a sorted store keyed by (particle id, particle-or-wall id) and its working copy aligned
//! with the neighbour list's slots.
//!
//! While stepping, each candidate slot of the neighbour list owns one [`ContactHistory`] record (empty when the pair
//! neither touches nor carries a persistent state such as a liquid bridge), so the force loop reads and writes
//! history without lookups. Whenever the list is rebuilt, the occupied records are carried over by key in one merge
//! pass; a checkpoint stores exactly the occupied records in key order ([`ContactStore`]), and a restored simulation
//! merges that store into its first list. Both paths use the same merge, so a restart cannot lose or reorder a
//! contact. What a record holds is declared in `models::history`.

use super::models::ContactHistory;
use super::models::history::CohesionHistory;
pub use super::models::history::{ColumnsMut, HistoryColumns, HistoryLayout, split_at_ends};
use super::neighbor::{BUILD_CHUNK, NeighborList};
use super::particles::ParticleId;
use super::team::Team;

/// Index of a wall in the scenario's wall list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WallId(pub u16);

/// The occupied records of a simulation in key order (active contacts, and pairs with a persistent state such as a
/// liquid bridge): everything about pairs that a checkpoint must hold.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactStore {
    /// Particle–particle records, sorted by (i, j), i < j. The keys are the particles' array indices (their ids
    /// only until the run sorts its particles, `engine::particle_order`).
    pub pairs: Vec<(ParticleId, ParticleId, ContactHistory)>,
    /// Particle–wall records, sorted by (i, wall), i an array index.
    pub walls: Vec<(ParticleId, WallId, ContactHistory)>,
}

/// The records of a [`ContactStore`] that hold a cohesion state, with that state.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CohesionView {
    pub pairs: Vec<(ParticleId, ParticleId, CohesionHistory)>,
    pub walls: Vec<(ParticleId, WallId, CohesionHistory)>,
}

impl ContactStore {
    /// The records with a liquid bridge or a square-well state.
    pub fn cohesion(&self) -> CohesionView {
        CohesionView {
            pairs: self
                .pairs
                .iter()
                .filter(|(_, _, h)| !h.cohesion.is_empty())
                .map(|&(i, j, h)| (i, j, h.cohesion))
                .collect(),
            walls: self
                .walls
                .iter()
                .filter(|(_, _, h)| !h.cohesion.is_empty())
                .map(|&(i, w, h)| (i, w, h.cohesion))
                .collect(),
        }
    }

    /// Total liquid held in bridges, m³.
    pub fn bridge_liquid_m3(&self) -> f64 {
        self.pairs
            .iter()
            .map(|(_, _, h)| h.cohesion.bridge_volume_m3)
            .sum::<f64>()
            + self
                .walls
                .iter()
                .map(|(_, _, h)| h.cohesion.bridge_volume_m3)
                .sum::<f64>()
    }
}

/// Histories for the pair and wall slots of a [`NeighborList`].
#[derive(Debug, Clone, Default)]
pub struct AlignedHistory {
    pub pair: HistoryColumns,
    pub wall: HistoryColumns,
}

impl AlignedHistory {
    /// The occupied records in key order.
    pub fn to_store(&self, list: &NeighborList) -> ContactStore {
        let n = list.start.len().saturating_sub(1);
        let mut store = ContactStore::default();
        for i in 0..n {
            for k in list.pairs_of(i) {
                if self.pair.occupied(k) {
                    store
                        .pairs
                        .push((ParticleId(i as u32), ParticleId(list.partner[k]), self.pair.get(k)));
                }
            }
            for k in list.walls_of(i) {
                if self.wall.occupied(k) {
                    store
                        .walls
                        .push((ParticleId(i as u32), WallId(list.wall_partner[k]), self.wall.get(k)));
                }
            }
        }
        store
    }

    /// Histories for a freshly built `list`, taking every record of `store` whose pair is a candidate of `list`.
    /// Returns how many records of the store found no slot (a record that should have been found: the caller
    /// treats a non-zero count as a bug). A record dropped so gives its bridge's liquid back to the particles (half
    /// each; all to i for a wall) through `liquid_m3`, so that liquid stays conserved.
    pub fn from_store(
        store: &ContactStore,
        list: &NeighborList,
        layout: HistoryLayout,
        liquid_m3: &mut [f64],
    ) -> (AlignedHistory, usize) {
        let n = list.start.len().saturating_sub(1);
        let mut pair = HistoryColumns::new(list.partner.len(), layout);
        let mut wall = HistoryColumns::new(list.wall_partner.len(), layout);
        let mut orphans = 0;
        {
            let mut pair_view = pair.view();
            let mut wall_view = wall.view();
            let mut next_pair = store.pairs.iter().peekable();
            let mut next_wall = store.walls.iter().peekable();
            for i in 0..n {
                let slots = list.pairs_of(i);
                let partners = &list.partner[slots.clone()];
                while let Some((pi, pj, h)) = next_pair.next_if(|(pi, _, _)| pi.index() <= i) {
                    match (pi.index() == i)
                        .then(|| partners.binary_search(&pj.0))
                        .and_then(Result::ok)
                    {
                        Some(offset) => pair_view.save(slots.start + offset, h),
                        None => {
                            orphans += 1;
                            let volume = h.cohesion.bridge_volume_m3;
                            if let (Some(_), Some(_)) = (liquid_m3.get(pi.index()), liquid_m3.get(pj.index())) {
                                liquid_m3[pi.index()] += 0.5 * volume;
                                liquid_m3[pj.index()] += volume - 0.5 * volume;
                            }
                        }
                    }
                }
                let slots = list.walls_of(i);
                let partners = &list.wall_partner[slots.clone()];
                while let Some((pi, w, h)) = next_wall.next_if(|(pi, _, _)| pi.index() <= i) {
                    match (pi.index() == i)
                        .then(|| partners.binary_search(&w.0))
                        .and_then(Result::ok)
                    {
                        Some(offset) => wall_view.save(slots.start + offset, h),
                        None => {
                            orphans += 1;
                            if let Some(l) = liquid_m3.get_mut(pi.index()) {
                                *l += h.cohesion.bridge_volume_m3;
                            }
                        }
                    }
                }
            }
            // Records of particles beyond the list (a store of another particle set) have nowhere to go.
            orphans += next_pair.count() + next_wall.count();
        }
        (AlignedHistory { pair, wall }, orphans)
    }

    /// The histories of `old` (aligned with `old_list`) carried over to `new_list`, built from the same particles:
    /// each particle's old and new partner lists are both sorted, so one merge per particle moves every record, in
    /// parallel over chunks of particles. Returns how many occupied records found no slot (a bug, as in
    /// [`AlignedHistory::from_store`]).
    pub fn remap(
        &self,
        old_list: &NeighborList,
        new_list: &NeighborList,
        layout: HistoryLayout,
        liquid_m3: &mut [f64],
        team: &Team,
    ) -> (AlignedHistory, usize) {
        if old_list.start.len() != new_list.start.len() {
            // A different particle set (or no list yet): go through the keyed store.
            return AlignedHistory::from_store(&self.to_store(old_list), new_list, layout, liquid_m3);
        }
        let n = new_list.start.len().saturating_sub(1);
        let mut pair = HistoryColumns::new(new_list.partner.len(), layout);
        let mut wall = HistoryColumns::new(new_list.wall_partner.len(), layout);
        let chunk_ends: Vec<usize> = (1..=n.div_ceil(BUILD_CHUNK))
            .map(|c| (c * BUILD_CHUNK).min(n))
            .collect();
        let pair_ends: Vec<usize> = chunk_ends.iter().map(|&e| new_list.start[e] as usize).collect();
        let wall_ends: Vec<usize> = chunk_ends.iter().map(|&e| new_list.wall_start[e] as usize).collect();
        let merge = |(c, (mut pairs, mut walls)): (usize, (ColumnsMut, ColumnsMut))| {
            let lo = c * BUILD_CHUNK;
            let hi = chunk_ends[c];
            let (pair_base, wall_base) = (new_list.start[lo] as usize, new_list.wall_start[lo] as usize);
            let mut orphans = 0;
            for i in lo..hi {
                orphans += merge_slots(
                    &self.pair,
                    old_list.pairs_of(i),
                    &old_list.partner,
                    &mut pairs,
                    new_list.pairs_of(i),
                    &new_list.partner,
                    pair_base,
                );
                orphans += merge_slots(
                    &self.wall,
                    old_list.walls_of(i),
                    &old_list.wall_partner,
                    &mut walls,
                    new_list.walls_of(i),
                    &new_list.wall_partner,
                    wall_base,
                );
            }
            orphans
        };
        let chunks = pair
            .split(&pair_ends)
            .into_iter()
            .zip(wall.split(&wall_ends))
            .enumerate();
        let orphans: usize = if team.size() > 1 {
            team.map_parts(chunks.collect(), |_, c| merge(c)).into_iter().sum()
        } else {
            chunks.map(merge).sum()
        };
        (AlignedHistory { pair, wall }, orphans)
    }

    pub fn heap_bytes(&self) -> usize {
        self.pair.heap_bytes() + self.wall.heap_bytes()
    }
}

/// Copies the occupied records of one particle's old slots to its new slots (partners sorted ascending in both);
/// `base` is the first slot of the `to` view. Returns the number of occupied records whose partner is gone.
fn merge_slots<P: Ord + Copy>(
    from: &HistoryColumns,
    old_slots: std::ops::Range<usize>,
    old_partner: &[P],
    to: &mut ColumnsMut,
    new_slots: std::ops::Range<usize>,
    new_partner: &[P],
    base: usize,
) -> usize {
    let mut orphans = 0;
    let mut next = new_slots.start;
    for k in old_slots {
        if !from.occupied(k) {
            continue;
        }
        let key = old_partner[k];
        while next < new_slots.end && new_partner[next] < key {
            next += 1;
        }
        if next < new_slots.end && new_partner[next] == key {
            to.save(next - base, &from.get(k));
        } else {
            orphans += 1;
        }
    }
    orphans
}
