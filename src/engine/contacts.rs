//! Contact history: a sorted store keyed by (particle id, particle-or-wall id) and its working copy aligned with
//! the neighbour list's slots.
//!
//! While stepping, each candidate slot of the neighbour list owns one [`ContactHistory`] (inactive when the pair does
//! not touch), so the force loop reads and writes history without lookups. Whenever the list is rebuilt, the active
//! entries are carried over by key in one merge pass; a checkpoint stores exactly the active entries in key order
//! ([`ContactStore`]), and a restored simulation merges that store into its first list. Both paths use the same
//! merge, so a restart cannot lose or reorder a contact.

use super::Vec3;
use super::models::ContactHistory;
use super::neighbor::{BUILD_CHUNK, NeighborList};
use super::particles::ParticleId;
use super::team::Team;

/// Index of a wall in the scenario's wall list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WallId(pub u16);

/// The active contacts of a simulation in key order: everything about contacts that a checkpoint must hold.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactStore {
    /// Particle–particle contacts, sorted by (i, j), i < j.
    pub pairs: Vec<(ParticleId, ParticleId, ContactHistory)>,
    /// Particle–wall contacts, sorted by (i, wall).
    pub walls: Vec<(ParticleId, WallId, ContactHistory)>,
}

/// Which history fields a contact law needs; storage holds only those columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HistoryLayout {
    /// `tangential` (every tangential model).
    pub tangential: bool,
    /// `reversal_force_n`, `increment_direction` (Walton-Braun).
    pub walton_braun: bool,
    /// `max_overlap_m`, `max_normal_force_n`, `yielded` (Thornton).
    pub thornton: bool,
}

/// Thornton's per-contact state, one column.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ThorntonState {
    pub max_overlap_m: f64,
    pub max_normal_force_n: f64,
    pub yielded: bool,
}

/// Contact histories as columns aligned with neighbour-list slots. `touching[k]` says whether slot k is an active
/// contact; the other columns exist only when the layout asks for them (Hertz-Mindlin keeps 25 bytes per slot
/// instead of a 100-byte struct), because the force loop streams through them every step.
#[derive(Debug, Clone, Default)]
pub struct HistoryColumns {
    layout: HistoryLayout,
    pub touching: Vec<bool>,
    tangential: Vec<Vec3>,
    reversal: Vec<Vec3>,
    direction: Vec<Vec3>,
    thornton: Vec<ThorntonState>,
}

/// Mutable view of a range of [`HistoryColumns`] (the parallel force loop works on disjoint views).
pub struct ColumnsMut<'a> {
    layout: HistoryLayout,
    pub touching: &'a mut [bool],
    tangential: &'a mut [Vec3],
    reversal: &'a mut [Vec3],
    direction: &'a mut [Vec3],
    thornton: &'a mut [ThorntonState],
}

fn column<T: Clone + Default>(present: bool, len: usize) -> Vec<T> {
    if present { vec![T::default(); len] } else { Vec::new() }
}

/// Splits `data` (either empty, giving empty pieces, or as long as the last end) into consecutive mutable pieces
/// ending at `ends`.
pub fn split_at_ends<'a, T>(mut data: &'a mut [T], ends: &[usize]) -> Vec<&'a mut [T]> {
    if data.is_empty() {
        return ends.iter().map(|_| <&mut [T]>::default()).collect();
    }
    let mut out = Vec::with_capacity(ends.len());
    let mut consumed = 0;
    for &end in ends {
        let (head, tail) = data.split_at_mut(end - consumed);
        out.push(head);
        data = tail;
        consumed = end;
    }
    out
}

impl HistoryColumns {
    pub fn new(len: usize, layout: HistoryLayout) -> Self {
        HistoryColumns {
            layout,
            touching: vec![false; len],
            tangential: column(layout.tangential, len),
            reversal: column(layout.walton_braun, len),
            direction: column(layout.walton_braun, len),
            thornton: column(layout.thornton, len),
        }
    }

    pub fn len(&self) -> usize {
        self.touching.len()
    }

    pub fn is_empty(&self) -> bool {
        self.touching.is_empty()
    }

    pub fn view(&mut self) -> ColumnsMut<'_> {
        ColumnsMut {
            layout: self.layout,
            touching: &mut self.touching,
            tangential: &mut self.tangential,
            reversal: &mut self.reversal,
            direction: &mut self.direction,
            thornton: &mut self.thornton,
        }
    }

    /// Disjoint views ending at the given slot offsets.
    pub fn split(&mut self, ends: &[usize]) -> Vec<ColumnsMut<'_>> {
        let layout = self.layout;
        let mut touching = split_at_ends(&mut self.touching, ends).into_iter();
        let mut tangential = split_at_ends(&mut self.tangential, ends).into_iter();
        let mut reversal = split_at_ends(&mut self.reversal, ends).into_iter();
        let mut direction = split_at_ends(&mut self.direction, ends).into_iter();
        let mut thornton = split_at_ends(&mut self.thornton, ends).into_iter();
        ends.iter()
            .map(|_| ColumnsMut {
                layout,
                touching: touching.next().expect("one piece per end"),
                tangential: tangential.next().expect("one piece per end"),
                reversal: reversal.next().expect("one piece per end"),
                direction: direction.next().expect("one piece per end"),
                thornton: thornton.next().expect("one piece per end"),
            })
            .collect()
    }

    /// The full history of slot k (zero fields for columns the layout does not keep).
    pub fn get(&self, k: usize) -> ContactHistory {
        let mut h = ContactHistory {
            active: self.touching[k],
            ..ContactHistory::INACTIVE
        };
        if self.layout.tangential {
            h.tangential = self.tangential[k];
        }
        if self.layout.walton_braun {
            h.reversal_force_n = self.reversal[k];
            h.increment_direction = self.direction[k];
        }
        if self.layout.thornton {
            let t = self.thornton[k];
            h.max_overlap_m = t.max_overlap_m;
            h.max_normal_force_n = t.max_normal_force_n;
            h.yielded = t.yielded;
        }
        h
    }

    pub fn heap_bytes(&self) -> usize {
        self.touching.capacity()
            + (self.tangential.capacity() + self.reversal.capacity() + self.direction.capacity())
                * std::mem::size_of::<Vec3>()
            + self.thornton.capacity() * std::mem::size_of::<ThorntonState>()
    }
}

impl ColumnsMut<'_> {
    /// A view of the same slots for a shorter borrow (to hand to a function by value and use again after).
    pub fn reborrow(&mut self) -> ColumnsMut<'_> {
        ColumnsMut {
            layout: self.layout,
            touching: self.touching,
            tangential: self.tangential,
            reversal: self.reversal,
            direction: self.direction,
            thornton: self.thornton,
        }
    }

    /// The history of local slot k with the layout known at compile time (`WB`: Walton-Braun columns, `TH`: Thornton
    /// columns), so that the fields a law does not use never touch memory. Must match the view's layout.
    #[inline(always)]
    pub fn load_as<const WB: bool, const TH: bool>(&self, k: usize) -> ContactHistory {
        debug_assert!(self.layout.walton_braun == WB && self.layout.thornton == TH);
        let mut h = ContactHistory {
            active: self.touching[k],
            tangential: self.tangential[k],
            ..ContactHistory::INACTIVE
        };
        if WB {
            h.reversal_force_n = self.reversal[k];
            h.increment_direction = self.direction[k];
        }
        if TH {
            let t = self.thornton[k];
            h.max_overlap_m = t.max_overlap_m;
            h.max_normal_force_n = t.max_normal_force_n;
            h.yielded = t.yielded;
        }
        h
    }

    /// [`ColumnsMut::save`] with the layout known at compile time.
    #[inline(always)]
    pub fn save_as<const WB: bool, const TH: bool>(&mut self, k: usize, h: &ContactHistory) {
        debug_assert!(self.layout.walton_braun == WB && self.layout.thornton == TH);
        self.touching[k] = h.active;
        self.tangential[k] = h.tangential;
        if WB {
            self.reversal[k] = h.reversal_force_n;
            self.direction[k] = h.increment_direction;
        }
        if TH {
            self.thornton[k] = ThorntonState {
                max_overlap_m: h.max_overlap_m,
                max_normal_force_n: h.max_normal_force_n,
                yielded: h.yielded,
            };
        }
    }

    #[inline(always)]
    pub fn save(&mut self, k: usize, h: &ContactHistory) {
        self.touching[k] = h.active;
        if self.layout.tangential {
            self.tangential[k] = h.tangential;
        }
        if self.layout.walton_braun {
            self.reversal[k] = h.reversal_force_n;
            self.direction[k] = h.increment_direction;
        }
        if self.layout.thornton {
            self.thornton[k] = ThorntonState {
                max_overlap_m: h.max_overlap_m,
                max_normal_force_n: h.max_normal_force_n,
                yielded: h.yielded,
            };
        }
    }

    /// Marks local slot k as not touching and clears its history, if it was touching.
    #[inline(always)]
    pub fn release(&mut self, k: usize) {
        if self.touching[k] {
            self.save(k, &ContactHistory::INACTIVE);
        }
    }
}

/// Histories for the pair and wall slots of a [`NeighborList`].
#[derive(Debug, Clone, Default)]
pub struct AlignedHistory {
    pub pair: HistoryColumns,
    pub wall: HistoryColumns,
}

impl AlignedHistory {
    /// The active contacts in key order.
    pub fn to_store(&self, list: &NeighborList) -> ContactStore {
        let n = list.start.len().saturating_sub(1);
        let mut store = ContactStore::default();
        for i in 0..n {
            for k in list.pairs_of(i) {
                if self.pair.touching[k] {
                    store
                        .pairs
                        .push((ParticleId(i as u32), ParticleId(list.partner[k]), self.pair.get(k)));
                }
            }
            for k in list.walls_of(i) {
                if self.wall.touching[k] {
                    store
                        .walls
                        .push((ParticleId(i as u32), WallId(list.wall_partner[k]), self.wall.get(k)));
                }
            }
        }
        store
    }

    /// Histories for a freshly built `list`, taking every contact of `store` whose pair is a candidate of `list`.
    /// Returns how many active contacts of the store found no slot (a contact that should have been found: the
    /// caller treats a non-zero count as a bug).
    pub fn from_store(store: &ContactStore, list: &NeighborList, layout: HistoryLayout) -> (AlignedHistory, usize) {
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
                        Some(offset) => wall_view.save(slots.start + offset, h),
                        None => orphans += 1,
                    }
                }
            }
            orphans += next_pair.count() + next_wall.count();
        }
        (AlignedHistory { pair, wall }, orphans)
    }

    /// The histories of `old` (aligned with `old_list`) carried over to `new_list`, built from the same particles:
    /// each particle's old and new partner lists are both sorted, so one merge per particle moves every entry, in
    /// parallel over chunks of particles. Returns how many active contacts found no slot (a bug, as in
    /// [`AlignedHistory::from_store`]).
    pub fn remap(
        &self,
        old_list: &NeighborList,
        new_list: &NeighborList,
        layout: HistoryLayout,
        team: &Team,
    ) -> (AlignedHistory, usize) {
        if old_list.start.len() != new_list.start.len() {
            // A different particle set (or no list yet): go through the keyed store.
            return AlignedHistory::from_store(&self.to_store(old_list), new_list, layout);
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

/// Copies the active entries of one particle's old slots to its new slots (partners sorted ascending in both);
/// `base` is the first slot of the `to` view. Returns the number of active entries whose partner is gone.
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
        if !from.touching[k] {
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
