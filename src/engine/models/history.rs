//! Per-contact history: the state each model slot carries from one step to the next, declared once.
//!
//! The [`contact_history!`] declaration below is the only list of history fields. Each slot owns a struct of its
//! fields (the normal slot's kernels see only `NormalHistory`, the tangential slot's only `TangentialHistory`, the
//! cohesion slot's only `CohesionHistory`), and the same declaration generates:
//! - [`ContactHistory`], one record per pair or particle–wall slot (`active` while the pair touches, then the slots);
//! - [`HistoryColumns`] / [`ColumnsMut`], the structure-of-arrays store the force loop streams through, with a column
//!   only for the fields the run's models use ([`HistoryLayout`]) and loads specialised at compile time
//!   ([`StaticLayout`]);
//! - [`HISTORY_FIELDS`], the table that the checkpoint's datasets (`checkpoint/layout.rs`) and the restart
//!   comparison (`state::first_difference`) are built from, so a new field cannot be forgotten in either.
//!
//! Contact slots (normal, tangential, duration) are cleared when the pair separates: a new contact starts from zero, which is
//! what all three seed models assume. Persistent slots (cohesion: a liquid bridge outlives the contact, a pair stays
//! in a square well at a gap) keep their state until their own model clears it. What does not live here: the keyed
//! store of records and its alignment with the neighbour list (`engine::contacts`), and the kernels (`normal.rs`,
//! `tangential.rs`, `engine::cohesion`).

use crate::engine::Vec3;

/// Which optional history columns a run's models use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HistoryLayout {
    /// The tangential slot's shear history (every tangential model: always true).
    pub tangential: bool,
    /// `reversal_force_n`, `increment_direction` (Walton-Braun).
    pub walton_braun: bool,
    /// The normal slot's plastic state (Thornton).
    pub thornton: bool,
    /// The cohesion slot (liquid bridges, the square well).
    pub cohesion: bool,
    /// The duration slot (`output.contact_statistics`).
    pub contact_duration: bool,
}

impl HistoryLayout {
    /// No optional column: the base that layouts name their columns against (`..HistoryLayout::NONE`), so that a
    /// new column's flag is written only where a run turns it on.
    pub const NONE: HistoryLayout = HistoryLayout {
        tangential: false,
        walton_braun: false,
        thornton: false,
        cohesion: false,
        contact_duration: false,
    };
}

/// A history layout known at compile time: loads and stores of the fields it leaves out compile to nothing.
pub trait StaticLayout {
    const LAYOUT: HistoryLayout;
}

/// The layouts of the contact pass: the contact law's columns (`WB`: Walton-Braun, `TH`: Thornton); the cohesion
/// slot is left to the cohesion kernels (`engine::cohesion`), which read and write it field by field.
pub struct ContactLayout<const WB: bool, const TH: bool>;

impl<const WB: bool, const TH: bool> StaticLayout for ContactLayout<WB, TH> {
    const LAYOUT: HistoryLayout = HistoryLayout {
        tangential: true,
        walton_braun: WB,
        thornton: TH,
        ..HistoryLayout::NONE
    };
}

/// The element kinds a history field can have, as stored in checkpoints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldKind {
    /// A flag, stored as u8 0/1.
    Flag,
    /// A scalar, f64.
    Scalar,
    /// A vector, three f64.
    Vector,
}

/// A field's value, for the generic walkers (checkpoint, restart comparison).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FieldValue {
    Flag(bool),
    Scalar(f64),
    Vector(Vec3),
}

/// A type a history field can have.
pub trait HistoryValue: Copy + Default + PartialEq {
    const ZERO: Self;
    const KIND: FieldKind;
    fn to_value(self) -> FieldValue;
    fn from_value(v: FieldValue) -> Self;
}

impl HistoryValue for bool {
    const ZERO: bool = false;
    const KIND: FieldKind = FieldKind::Flag;
    fn to_value(self) -> FieldValue {
        FieldValue::Flag(self)
    }
    fn from_value(v: FieldValue) -> Self {
        matches!(v, FieldValue::Flag(true))
    }
}

impl HistoryValue for f64 {
    const ZERO: f64 = 0.0;
    const KIND: FieldKind = FieldKind::Scalar;
    fn to_value(self) -> FieldValue {
        FieldValue::Scalar(self)
    }
    fn from_value(v: FieldValue) -> Self {
        match v {
            FieldValue::Scalar(x) => x,
            _ => 0.0,
        }
    }
}

impl HistoryValue for Vec3 {
    const ZERO: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    const KIND: FieldKind = FieldKind::Vector;
    fn to_value(self) -> FieldValue {
        FieldValue::Vector(self)
    }
    fn from_value(v: FieldValue) -> Self {
        match v {
            FieldValue::Vector(x) => x,
            _ => Vec3::zeros(),
        }
    }
}

/// One history field: where it lives, how it is stored, and how to read and write it in a record.
#[derive(Clone, Copy)]
pub struct HistoryField {
    /// The slot that owns it (`normal`, `tangential`, `cohesion`).
    pub slot: &'static str,
    /// Its name, also its dataset's last path component.
    pub name: &'static str,
    /// Units of its checkpoint dataset.
    pub units: &'static str,
    pub kind: FieldKind,
    /// Its checkpoint datasets for particle pairs and particle–wall pairs.
    pub pair_path: &'static str,
    pub wall_path: &'static str,
    /// Whether a run of this layout has the field.
    pub present: fn(&HistoryLayout) -> bool,
    pub get: fn(&ContactHistory) -> FieldValue,
    pub set: fn(&mut ContactHistory, FieldValue),
}

impl std::fmt::Debug for HistoryField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.slot, self.name)
    }
}

/// Whether a slot is cleared when its contact separates.
macro_rules! persistent {
    (contact) => {
        false
    };
    (persistent) => {
        true
    };
}

/// Declares the history slots and their fields; see the module documentation for what it generates.
macro_rules! contact_history {
    ($(
        $(#[$slot_doc:meta])*
        $kind:ident $slot:ident: $Slot:ident, $Columns:ident, $ColumnsMut:ident {
            $( $(#[$doc:meta])* $field:ident: $ty:ty, $units:expr, if $present:ident; )*
        }
    )*) => {
        $(
            $(#[$slot_doc])*
            #[derive(Debug, Clone, Copy, PartialEq, Default)]
            pub struct $Slot {
                $( $(#[$doc])* pub $field: $ty, )*
            }

            impl $Slot {
                pub const ZERO: $Slot = $Slot { $( $field: <$ty as HistoryValue>::ZERO, )* };
            }

            /// The columns of one slot (empty where the layout leaves a field out).
            #[derive(Debug, Clone, Default)]
            pub struct $Columns {
                $( pub $field: Vec<$ty>, )*
            }

            /// A mutable view of a range of one slot's columns.
            pub struct $ColumnsMut<'a> {
                $( pub $field: &'a mut [$ty], )*
            }
        )*

        /// One record: whether the pair touches, then every slot's history.
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        pub struct ContactHistory {
            /// True while the pair overlaps.
            pub active: bool,
            $( pub $slot: $Slot, )*
        }

        impl ContactHistory {
            /// Nothing: no contact, no persistent state.
            pub const INACTIVE: ContactHistory = ContactHistory { active: false, $( $slot: $Slot::ZERO, )* };

            /// Whether the record holds nothing a checkpoint must keep (no contact and every persistent slot zero).
            pub fn is_empty(&self) -> bool {
                !self.active $( && (!persistent!($kind) || self.$slot == $Slot::ZERO) )*
            }

            /// The record after its contact separated: contact slots cleared, persistent slots kept.
            pub fn released(&self) -> ContactHistory {
                ContactHistory {
                    active: false,
                    $( $slot: if persistent!($kind) { self.$slot } else { $Slot::ZERO }, )*
                }
            }
        }

        /// Every history field, slot by slot in declaration order (the checkpoint's dataset order).
        pub const HISTORY_FIELDS: &[HistoryField] = &[
            $( $(
                HistoryField {
                    slot: stringify!($slot),
                    name: stringify!($field),
                    units: $units,
                    kind: <$ty as HistoryValue>::KIND,
                    pair_path: concat!("contacts/pairs/", stringify!($field)),
                    wall_path: concat!("contacts/walls/", stringify!($field)),
                    present: |l: &HistoryLayout| l.$present,
                    get: |h: &ContactHistory| h.$slot.$field.to_value(),
                    set: |h: &mut ContactHistory, v: FieldValue| h.$slot.$field = <$ty as HistoryValue>::from_value(v),
                },
            )* )*
        ];

        /// Records as columns aligned with neighbour-list slots. `touching[k]` says whether slot k is an active
        /// contact; a field has a column only when the layout uses it (Hertz-Mindlin keeps 25 bytes per slot),
        /// because the force loop streams through them every step.
        #[derive(Debug, Clone, Default)]
        pub struct HistoryColumns {
            layout: HistoryLayout,
            pub touching: Vec<bool>,
            $( pub $slot: $Columns, )*
        }

        /// A mutable view of a range of [`HistoryColumns`] (the parallel force loop works on disjoint views).
        pub struct ColumnsMut<'a> {
            layout: HistoryLayout,
            pub touching: &'a mut [bool],
            $( pub $slot: $ColumnsMut<'a>, )*
        }

        impl HistoryColumns {
            pub fn new(len: usize, layout: HistoryLayout) -> Self {
                HistoryColumns {
                    layout,
                    touching: vec![false; len],
                    $( $slot: $Columns { $( $field: column(layout.$present, len), )* }, )*
                }
            }

            pub fn layout(&self) -> HistoryLayout {
                self.layout
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
                    $( $slot: $ColumnsMut { $( $field: &mut self.$slot.$field, )* }, )*
                }
            }

            /// Disjoint views ending at the given slot offsets.
            pub fn split(&mut self, ends: &[usize]) -> Vec<ColumnsMut<'_>> {
                let layout = self.layout;
                let mut touching = split_at_ends(&mut self.touching, ends).into_iter();
                $( $( let mut $field = split_at_ends(&mut self.$slot.$field, ends).into_iter(); )* )*
                ends.iter()
                    .map(|_| ColumnsMut {
                        layout,
                        touching: touching.next().expect("one piece per end"),
                        $( $slot: $ColumnsMut {
                            $( $field: $field.next().expect("one piece per end"), )*
                        }, )*
                    })
                    .collect()
            }

            /// The full record of slot k (zero fields for columns the layout does not keep).
            pub fn get(&self, k: usize) -> ContactHistory {
                let mut h = ContactHistory { active: self.touching[k], ..ContactHistory::INACTIVE };
                $( $( if self.layout.$present { h.$slot.$field = self.$slot.$field[k]; } )* )*
                h
            }

            /// Whether slot k holds anything to keep: an active contact or a persistent slot's state.
            pub fn occupied(&self, k: usize) -> bool {
                self.touching[k] || (self.layout.cohesion && !self.get(k).is_empty())
            }

            pub fn heap_bytes(&self) -> usize {
                self.touching.capacity()
                    $( $( + self.$slot.$field.capacity() * std::mem::size_of::<$ty>() )* )*
            }
        }

        impl ColumnsMut<'_> {
            /// A view of the same slots for a shorter borrow (to hand to a function by value and use again after).
            pub fn reborrow(&mut self) -> ColumnsMut<'_> {
                ColumnsMut {
                    layout: self.layout,
                    touching: self.touching,
                    $( $slot: $ColumnsMut { $( $field: self.$slot.$field, )* }, )*
                }
            }

            /// The record of local slot k with the layout `L` known at compile time, so that the fields it leaves
            /// out never touch memory (they read as zero). `L`'s fields must be columns of the view.
            #[inline(always)]
            pub fn load_as<L: StaticLayout>(&self, k: usize) -> ContactHistory {
                let mut h = ContactHistory { active: self.touching[k], ..ContactHistory::INACTIVE };
                $( $( if L::LAYOUT.$present { h.$slot.$field = self.$slot.$field[k]; } )* )*
                h
            }

            /// Stores the fields of `L` (and the touching flag) of `h` in local slot k.
            #[inline(always)]
            pub fn save_as<L: StaticLayout>(&mut self, k: usize, h: &ContactHistory) {
                self.touching[k] = h.active;
                $( $( if L::LAYOUT.$present { self.$slot.$field[k] = h.$slot.$field; } )* )*
            }

            /// Marks local slot k as not touching and clears the contact fields of `L`, if it was touching.
            #[inline(always)]
            pub fn release_as<L: StaticLayout>(&mut self, k: usize) {
                if self.touching[k] {
                    self.touching[k] = false;
                    $( if !persistent!($kind) {
                        $( if L::LAYOUT.$present { self.$slot.$field[k] = <$ty as HistoryValue>::ZERO; } )*
                    } )*
                }
            }

            /// Stores every field the view's layout keeps.
            #[inline(always)]
            pub fn save(&mut self, k: usize, h: &ContactHistory) {
                self.touching[k] = h.active;
                $( $( if self.layout.$present { self.$slot.$field[k] = h.$slot.$field; } )* )*
            }

            /// The record of local slot k (every field the view's layout keeps).
            #[inline(always)]
            pub fn get(&self, k: usize) -> ContactHistory {
                let mut h = ContactHistory { active: self.touching[k], ..ContactHistory::INACTIVE };
                $( $( if self.layout.$present { h.$slot.$field = self.$slot.$field[k]; } )* )*
                h
            }
        }
    };
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

/// Units of the tangential slot's shear history, which depend on the model.
const SHEAR_UNITS: &str = "m (linear_spring_coulomb, mindlin: displacement) or N (walton_braun: force)";

contact_history! {
    /// The normal slot: Thornton's plastic state (the other normal models keep none).
    contact normal: NormalHistory, NormalColumns, NormalColumnsMut {
        /// The normal force has passed the yield force during this contact.
        yielded: bool, "1", if thornton;
        /// Maximum overlap α_max reached in this contact, m.
        max_overlap_m: f64, "m", if thornton;
        /// Normal force F_max at α_max, N.
        max_normal_force_n: f64, "N", if thornton;
    }
    /// The tangential slot.
    contact tangential: TangentialHistory, TangentialColumns, TangentialColumnsMut {
        /// Linear spring and Mindlin: the elastic tangential displacement u_t (m). Walton-Braun: the tangential
        /// force F_t on particle i (N).
        shear: Vec3, SHEAR_UNITS, if tangential;
        /// Walton-Braun: the tangential force at the last reversal of the slip direction, F_t* (N).
        reversal_force_n: Vec3, "N", if walton_braun;
        /// Walton-Braun: unit direction of the last tangential force increment (zero before the first one).
        increment_direction: Vec3, "1", if walton_braun;
    }
    /// The duration slot: how long the contact has lasted (`output.contact_statistics`; the pair pass adds the
    /// duration of each contact that ends to the particles' contact-statistics channels, `engine::channels`).
    contact duration: DurationHistory, DurationColumns, DurationColumnsMut {
        /// Time since the contact began, s.
        duration_s: f64, "s", if contact_duration;
    }
    /// The cohesion slot: the state a cohesion model carries beyond contact.
    persistent cohesion: CohesionHistory, CohesionColumns, CohesionColumnsMut {
        /// Liquid bridge volume, m³ (0: no bridge).
        bridge_volume_m3: f64, "m3", if cohesion;
        /// Square well: the pair is inside the well.
        in_well: bool, "1", if cohesion;
    }
}

impl ContactHistory {
    /// The record of the same pair with its particles exchanged (the particles were reordered and the pair is now
    /// kept under its other particle, `engine::particle_order`): every vector field negated, scalars and flags as
    /// they are. A vector field is particle i's side of the contact (the tangential displacement of i relative to j,
    /// the tangential force on i, their directions), which exchanging i and j reverses; a scalar or flag belongs to
    /// the pair. A new vector field that is not i's side must say so here.
    pub fn mirrored(&self) -> ContactHistory {
        let mut h = *self;
        for field in HISTORY_FIELDS {
            if let FieldValue::Vector(v) = (field.get)(self) {
                (field.set)(&mut h, FieldValue::Vector(-v));
            }
        }
        h
    }
}

impl CohesionHistory {
    /// No bridge and not in a well.
    pub fn is_empty(&self) -> bool {
        self.bridge_volume_m3 == 0.0 && !self.in_well
    }
}

/// Brings a history vector into the current tangent plane (normal `n`) by removing its normal component: contacts
/// roll and the pair rotates, so a vector stored in the previous step's tangent plane must follow it.
///
/// CHOICE: projection without restoring the length, as LIGGGHTS `tangential history` and LAMMPS `gran/hertz/history`
/// do. The length lost is second order in the rotation per step (relative (θ dt)²/2); restoring it would cost a
/// square root and a division per contact per step, a tenth of the contact kernel.
#[inline]
pub fn rotate_into_tangent_plane(v: Vec3, n: &Vec3) -> Vec3 {
    v - n * v.dot(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exchanging a pair's particles negates every vector field (i's side of the contact) and keeps the rest.
    #[test]
    fn a_mirrored_record_negates_its_vectors_and_keeps_its_scalars_and_flags() {
        let mut h = ContactHistory::INACTIVE;
        h.active = true;
        for (k, f) in HISTORY_FIELDS.iter().enumerate() {
            let value = match f.kind {
                FieldKind::Flag => FieldValue::Flag(true),
                FieldKind::Scalar => FieldValue::Scalar(k as f64 + 0.5),
                FieldKind::Vector => FieldValue::Vector(Vec3::new(k as f64 + 1.0, -2.0, 3.5)),
            };
            (f.set)(&mut h, value);
        }
        let m = h.mirrored();
        assert_eq!(m.active, h.active);
        for f in HISTORY_FIELDS {
            match ((f.get)(&h), (f.get)(&m)) {
                (FieldValue::Vector(a), FieldValue::Vector(b)) => assert_eq!(b, -a, "{}", f.name),
                (a, b) => assert_eq!(a, b, "{}", f.name),
            }
        }
        assert_eq!(m.mirrored(), h);
    }

    /// Every field is listed once, reads back what is set through the table, and lives in the slot it names.
    #[test]
    fn the_field_table_covers_every_field_of_every_slot() {
        let mut h = ContactHistory::INACTIVE;
        for (k, f) in HISTORY_FIELDS.iter().enumerate() {
            let value = match f.kind {
                FieldKind::Flag => FieldValue::Flag(true),
                FieldKind::Scalar => FieldValue::Scalar(k as f64 + 0.5),
                FieldKind::Vector => FieldValue::Vector(Vec3::new(k as f64, 1.0, 2.0)),
            };
            (f.set)(&mut h, value);
            assert_eq!((f.get)(&h), value, "{f:?}");
            assert!(f.pair_path.ends_with(f.name) && f.wall_path.ends_with(f.name));
        }
        // Every slot's every field was set: none is left at zero.
        assert_ne!(h.normal, NormalHistory::ZERO);
        assert!(h.normal.yielded && h.normal.max_overlap_m != 0.0 && h.normal.max_normal_force_n != 0.0);
        assert!(h.tangential.reversal_force_n.x != 0.0 && h.tangential.increment_direction.x != 0.0);
        assert!(h.cohesion.in_well && h.cohesion.bridge_volume_m3 != 0.0);
        let names: Vec<&str> = HISTORY_FIELDS.iter().map(|f| f.name).collect();
        let mut unique = names.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{names:?}");
    }

    /// A separating contact loses its contact slots and keeps its persistent ones; an empty record is empty.
    #[test]
    fn release_keeps_persistent_slots_only() {
        let mut h = ContactHistory::INACTIVE;
        assert!(h.is_empty());
        h.active = true;
        h.normal.max_overlap_m = 1e-6;
        h.tangential.shear = Vec3::new(1e-7, 0.0, 0.0);
        h.cohesion.bridge_volume_m3 = 1e-12;
        let r = h.released();
        assert!(!r.active && r.normal == NormalHistory::ZERO && r.tangential == TangentialHistory::ZERO);
        assert_eq!(r.cohesion.bridge_volume_m3, 1e-12);
        assert!(!r.is_empty());
        let layout = HistoryLayout {
            tangential: true,
            walton_braun: false,
            thornton: true,
            cohesion: true,
            contact_duration: false,
        };
        let mut columns = HistoryColumns::new(2, layout);
        columns.view().save(1, &h);
        assert_eq!(columns.get(1), h);
        columns.view().release_as::<ContactLayout<false, true>>(1);
        assert_eq!(columns.get(1), r);
        assert!(columns.occupied(1) && !columns.occupied(0));
    }
}
