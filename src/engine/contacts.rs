//! Contact history: a sorted store keyed by (particle id, particle-or-wall id) and its working copy aligned with
//! the neighbour list's slots.
//!
//! While stepping, each candidate slot of the neighbour list owns one [`ContactHistory`] (inactive when the pair does
//! not touch), so the force loop reads and writes history without lookups. Whenever the list is rebuilt, the active
//! entries are carried over by key in one merge pass; a checkpoint stores exactly the active entries in key order
//! ([`ContactStore`]), and a restored simulation merges that store into its first list. Both paths use the same
//! merge, so a restart cannot lose or reorder a contact.

use super::models::ContactHistory;
use super::neighbor::NeighborList;
use super::particles::ParticleId;

/// Index of a wall in the scenario's wall list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WallId(pub u16);

/// The key of a contact: a particle and its partner, a particle of larger id or a wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Partner {
    Particle(ParticleId),
    Wall(WallId),
}

/// The active contacts of a simulation in key order: everything about contacts that a checkpoint must hold.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactStore {
    /// Particle–particle contacts, sorted by (i, j), i < j.
    pub pairs: Vec<(ParticleId, ParticleId, ContactHistory)>,
    /// Particle–wall contacts, sorted by (i, wall).
    pub walls: Vec<(ParticleId, WallId, ContactHistory)>,
}

/// Histories aligned with a [`NeighborList`]: `pair[k]` belongs to slot k of `partner`, `wall[k]` to slot k of
/// `wall_partner`. `pair_touching[k]` mirrors `pair[k].active` in a dense array: the force loop examines every
/// candidate each step but touches the (large) history only for contacts, which keeps it out of cache otherwise.
#[derive(Debug, Clone, Default)]
pub struct AlignedHistory {
    pub pair: Vec<ContactHistory>,
    pub wall: Vec<ContactHistory>,
    pub pair_touching: Vec<bool>,
    pub wall_touching: Vec<bool>,
}

impl AlignedHistory {
    /// The active contacts in key order.
    pub fn to_store(&self, list: &NeighborList) -> ContactStore {
        let n = list.start.len().saturating_sub(1);
        let mut store = ContactStore::default();
        for i in 0..n {
            for k in list.pairs_of(i) {
                if self.pair_touching[k] {
                    store
                        .pairs
                        .push((ParticleId(i as u32), ParticleId(list.partner[k]), self.pair[k]));
                }
            }
            for k in list.walls_of(i) {
                if self.wall_touching[k] {
                    store
                        .walls
                        .push((ParticleId(i as u32), WallId(list.wall_partner[k]), self.wall[k]));
                }
            }
        }
        store
    }

    /// Histories for a freshly built `list`, taking every contact of `store` whose pair is a candidate of `list`.
    /// Returns how many active contacts of the store found no slot (a contact that should have been found: the
    /// caller treats a non-zero count as a bug).
    pub fn from_store(store: &ContactStore, list: &NeighborList) -> (AlignedHistory, usize) {
        let n = list.start.len().saturating_sub(1);
        let mut pair = vec![ContactHistory::INACTIVE; list.partner.len()];
        let mut wall = vec![ContactHistory::INACTIVE; list.wall_partner.len()];
        let mut orphans = 0;
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
                    Some(offset) => pair[slots.start + offset] = *h,
                    None => orphans += 1,
                }
            }
            let slots = list.walls_of(i);
            let partners = &list.wall_partner[slots.clone()];
            while let Some((pi, w, h)) = next_wall.next_if(|(pi, _, _)| pi.index() <= i) {
                match (pi.index() == i)
                    .then(|| partners.binary_search(&w.0))
                    .and_then(Result::ok)
                {
                    Some(offset) => wall[slots.start + offset] = *h,
                    None => orphans += 1,
                }
            }
        }
        orphans += next_pair.count() + next_wall.count();
        let pair_touching = pair.iter().map(|h| h.active).collect();
        let wall_touching = wall.iter().map(|h| h.active).collect();
        (
            AlignedHistory {
                pair,
                wall,
                pair_touching,
                wall_touching,
            },
            orphans,
        )
    }

    pub fn heap_bytes(&self) -> usize {
        (self.pair.capacity() + self.wall.capacity()) * std::mem::size_of::<ContactHistory>()
            + self.pair_touching.capacity()
            + self.wall_touching.capacity()
    }
}
