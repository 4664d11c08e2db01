//! What a checkpoint file contains: the dataset table (names, element types, shapes, units, checksum order), the
//! flat arrays that mirror it, their conversion from and to a [`SimState`], their consistency checks, the content
//! checksum, and the seal (the file checksum kept in the HDF5 userblock).
//!
//! The table is written once, in the `datasets!` invocation below, and everything else (writing, reading, shape
//! checks, checksum) walks it through [`Arrays::visit`] / [`Arrays::visit_mut`], so the order of the checksum is
//! the order of that table by construction. `schemas/checkpoint.md` documents the same table; keep them in step.
//! HDF5 itself is handled in `super` (the parent module), not here.
//!
//! The seal exists because libhdf5 (1.10) trusts its own metadata: a flipped bit in an object header can crash the
//! process (SIGSEGV) instead of returning an error. So the writer hashes every byte after the userblock once the
//! HDF5 file is closed and records the length and hash in the userblock, and the reader checks both before
//! libhdf5 sees the file. A damaged or truncated file is thus rejected in plain Rust.

use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

use xxhash_rust::xxh3::Xxh3Default;

use super::{CheckpointError, CheckpointMeta};
use crate::engine::Vec3;
use crate::engine::channels::{CHANNELS, ChannelInfo, ParticleChannels};
use crate::engine::contacts::{ContactStore, WallId};
use crate::engine::gas::ExchangeAccumulator;
use crate::engine::gas::coupled::{GasScalarSnapshot, GasSnapshot, GasStepStats};
use crate::engine::gas::held_drag::HeldDragSnapshot;
use crate::engine::heat_ledger::HeatLedger;
use crate::engine::models::ContactHistory;
use crate::engine::models::history::{FieldKind, FieldValue, HISTORY_FIELDS, HistoryField};
use crate::engine::net_force::NetForceTally;
use crate::engine::particles::{ParticleId, Particles, SpeciesId};
use crate::engine::state::{RngState, SimState};

/// The name of the gas temperature among the gas's transported scalars.
const GAS_TEMPERATURE: &str = "temperature_k";

/// The name of the vapour among the gas's transported scalars (a run with drying).
const GAS_VAPOUR: &str = crate::engine::drying::VAPOUR_FIELD;

/// Value of the root attribute `format`.
pub(crate) const FORMAT_NAME: &str = "granflow-checkpoint";

/// Which count the first dimension of a dataset follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum Rows {
    /// N, the number of particles.
    Particles,
    /// The number of particle–particle history records (active contacts and pairs with a cohesion state).
    PairContacts,
    /// The number of particle–wall history records.
    WallContacts,
    /// The number of walls.
    Walls,
    /// A fixed length (the RNG seed).
    Fixed(usize),
    /// A scalar (rank-0) dataset.
    Scalar,
    /// The number of gas cells (0 without a gas).
    GasCells,
    /// The number of gas faces normal to axis 0, 1 or 2 (0 without a gas, and for z on a 2-D grid: all faces).
    GasFaces(u8),
    /// One value with a gas, none without (a 1-D dataset of length 0 or 1).
    GasScalar,
    /// One row when the run sums net forces by mechanism, none otherwise.
    NetForce,
    /// The number of walls when the run sums net forces by mechanism, 0 otherwise.
    NetForceWalls,
    /// N when the run has what the dataset holds (a scalar channel's group, temperatures), 0 otherwise.
    ParticlesIfRecorded,
    /// The number of gas cells when the gas carries a temperature, 0 otherwise.
    GasCellsIfHeat,
    /// One value when the gas carries a temperature, none otherwise.
    GasScalarIfHeat,
    /// The number of gas cells when the gas carries vapour (a run with drying), 0 otherwise.
    GasCellsIfDrying,
    /// One value when the gas carries vapour, none otherwise.
    GasScalarIfDrying,
    /// One value when the run has heat transfer (an energy ledger), none otherwise.
    ScalarIfHeat,
}

/// One dataset of the layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct DatasetSpec {
    /// Path below the root, without the leading slash, e.g. `particles/position_m`.
    pub path: &'static str,
    pub rows: Rows,
    /// 1 for a one-dimensional dataset, 3 for a rows × 3 dataset of vectors.
    pub width: usize,
    /// Value of the dataset's `units` attribute.
    pub units: &'static str,
    /// Element type, as named in `schemas/checkpoint.md`.
    pub dtype: &'static str,
}

impl DatasetSpec {
    /// The HDF5 shape of this dataset when it holds `len` elements.
    pub(crate) fn shape(&self, len: usize) -> Vec<usize> {
        match (self.rows, self.width) {
            (Rows::Scalar, _) => Vec::new(),
            (_, 1) => vec![len],
            (_, w) => vec![len / w, w],
        }
    }
}

/// An element type of a checkpoint dataset, with its little-endian encoding for the checksum.
pub(crate) trait Element: hdf5::H5Type + Copy + Default + 'static {
    /// Type name used in the documentation and in error messages.
    const NAME: &'static str;
    /// Appends the little-endian bytes of `self` to `out`.
    fn put_le(self, out: &mut Vec<u8>);
}

macro_rules! element {
    ($($ty:ty),*) => {$(
        impl Element for $ty {
            const NAME: &'static str = stringify!($ty);
            #[inline]
            fn put_le(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    )*};
}
element!(u8, u16, u32, u64, f64);

/// Walks the datasets of [`Arrays`] in table order, read-only.
pub(crate) trait Visitor {
    type Error;
    fn visit<T: Element>(&mut self, spec: &DatasetSpec, data: &[T]) -> Result<(), Self::Error>;
}

/// Walks the datasets of [`Arrays`] in table order, filling them (the reader).
pub(crate) trait VisitorMut {
    type Error;
    fn visit<T: Element>(&mut self, spec: &DatasetSpec, data: &mut Vec<T>) -> Result<(), Self::Error>;
}

/// Declares the dataset table: the [`Arrays`] struct (one flat, row-major `Vec` per dataset), [`DATASETS`], and
/// the two visitors. The order of the entries is the checksum order.
macro_rules! datasets {
    ($( $field:ident : $ty:ty => $path:literal, $rows:expr, $width:literal, $units:expr; )*) => {
        /// The datasets of a checkpoint as flat row-major arrays, one field per dataset.
        #[derive(Debug, Clone, Default, PartialEq)]
        pub(crate) struct Arrays {
            $( pub $field: Vec<$ty>, )*
            /// The history fields of the pair records and of the wall records (`models::history`), visited after
            /// the table's datasets.
            pub pair_history: HistoryArrays,
            pub wall_history: HistoryArrays,
            /// The particles' scalar channels (`engine::channels`), visited after the history.
            pub channels: ParticleChannels,
        }

        /// Every dataset of the layout, in checksum order.
        pub(crate) const DATASETS: &[DatasetSpec] = &[$(
            DatasetSpec {
                path: $path,
                rows: $rows,
                width: $width,
                units: $units,
                dtype: <$ty as Element>::NAME,
            },
        )*];

        impl Arrays {
            /// Calls `v` on every dataset in table order, then on the history datasets.
            pub(crate) fn visit<V: Visitor>(&self, v: &mut V) -> Result<(), V::Error> {
                let mut specs = DATASETS.iter();
                $(
                    let spec = specs.next().expect("DATASETS has one entry per field");
                    v.visit(spec, &self.$field)?;
                )*
                self.pair_history.visit(HistoryTable::Pairs, v)?;
                self.wall_history.visit(HistoryTable::Walls, v)?;
                for info in CHANNELS {
                    v.visit(&channel_spec(info), (info.get)(&self.channels))?;
                }
                Ok(())
            }

            /// Calls `v` on every dataset in table order, then on the history datasets, letting it fill the arrays.
            pub(crate) fn visit_mut<V: VisitorMut>(&mut self, v: &mut V) -> Result<(), V::Error> {
                let mut specs = DATASETS.iter();
                $(
                    let spec = specs.next().expect("DATASETS has one entry per field");
                    v.visit(spec, &mut self.$field)?;
                )*
                self.pair_history.visit_mut(HistoryTable::Pairs, v)?;
                self.wall_history.visit_mut(HistoryTable::Walls, v)?;
                for info in CHANNELS {
                    v.visit(&channel_spec(info), (info.get_mut)(&mut self.channels))?;
                }
                Ok(())
            }
        }
    };
}

/// The two tables of history records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum HistoryTable {
    Pairs,
    Walls,
}

impl HistoryTable {
    /// The dataset of `field` in this table.
    pub(crate) fn spec(self, field: &HistoryField) -> DatasetSpec {
        let (path, rows) = match self {
            HistoryTable::Pairs => (field.pair_path, Rows::PairContacts),
            HistoryTable::Walls => (field.wall_path, Rows::WallContacts),
        };
        let (width, dtype) = match field.kind {
            FieldKind::Flag => (1, <u8 as Element>::NAME),
            FieldKind::Scalar => (1, <f64 as Element>::NAME),
            FieldKind::Vector => (3, <f64 as Element>::NAME),
        };
        DatasetSpec {
            path,
            rows,
            width,
            units: field.units,
            dtype,
        }
    }
}

/// The dataset of one scalar channel.
fn channel_spec(info: &ChannelInfo) -> DatasetSpec {
    DatasetSpec {
        path: info.path,
        rows: Rows::ParticlesIfRecorded,
        width: 1,
        units: info.unit,
        dtype: <f64 as Element>::NAME,
    }
}

/// Every dataset of a checkpoint: the table's, then the history fields' of pairs and of walls, then the channels'.
#[cfg(test)]
pub(crate) fn all_datasets() -> Vec<DatasetSpec> {
    let history = |t: HistoryTable| HISTORY_FIELDS.iter().map(move |f| t.spec(f));
    DATASETS
        .iter()
        .copied()
        .chain(history(HistoryTable::Pairs))
        .chain(history(HistoryTable::Walls))
        .chain(CHANNELS.iter().map(channel_spec))
        .collect()
}

/// One history field's column: flags as u8, scalars and vectors (three per row) as f64.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum HistoryColumn {
    Flags(Vec<u8>),
    Values(Vec<f64>),
}

/// The history columns of one table of records, one per entry of `HISTORY_FIELDS`, in its order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct HistoryArrays {
    pub columns: Vec<HistoryColumn>,
}

impl Default for HistoryArrays {
    fn default() -> Self {
        HistoryArrays {
            columns: HISTORY_FIELDS
                .iter()
                .map(|f| match f.kind {
                    FieldKind::Flag => HistoryColumn::Flags(Vec::new()),
                    FieldKind::Scalar | FieldKind::Vector => HistoryColumn::Values(Vec::new()),
                })
                .collect(),
        }
    }
}

impl HistoryArrays {
    /// The columns of `records`.
    fn of<'a>(records: impl Iterator<Item = &'a ContactHistory>) -> HistoryArrays {
        let mut out = HistoryArrays::default();
        for h in records {
            for (field, column) in HISTORY_FIELDS.iter().zip(&mut out.columns) {
                match ((field.get)(h), column) {
                    (FieldValue::Flag(b), HistoryColumn::Flags(c)) => c.push(u8::from(b)),
                    (FieldValue::Scalar(x), HistoryColumn::Values(c)) => c.push(x),
                    (FieldValue::Vector(x), HistoryColumn::Values(c)) => c.extend_from_slice(&[x.x, x.y, x.z]),
                    _ => unreachable!("a column has its field's kind"),
                }
            }
        }
        out
    }

    /// Sets every field of `h` from row `k`. The arrays must have passed [`Arrays::check`].
    fn fill(&self, k: usize, h: &mut ContactHistory) {
        for (field, column) in HISTORY_FIELDS.iter().zip(&self.columns) {
            let value = match (field.kind, column) {
                (FieldKind::Flag, HistoryColumn::Flags(c)) => FieldValue::Flag(c[k] != 0),
                (FieldKind::Scalar, HistoryColumn::Values(c)) => FieldValue::Scalar(c[k]),
                (FieldKind::Vector, HistoryColumn::Values(c)) => {
                    FieldValue::Vector(Vec3::new(c[3 * k], c[3 * k + 1], c[3 * k + 2]))
                }
                _ => unreachable!("a column has its field's kind"),
            };
            (field.set)(h, value);
        }
    }

    /// The first flag that is neither 0 nor 1, as (dataset path, row, value).
    fn bad_flag(&self, table: HistoryTable) -> Option<(&'static str, usize, u8)> {
        HISTORY_FIELDS
            .iter()
            .zip(&self.columns)
            .find_map(|(field, column)| match column {
                HistoryColumn::Flags(c) => c.iter().position(|&v| v > 1).map(|k| (table.spec(field).path, k, c[k])),
                HistoryColumn::Values(_) => None,
            })
    }

    fn visit<V: Visitor>(&self, table: HistoryTable, v: &mut V) -> Result<(), V::Error> {
        for (field, column) in HISTORY_FIELDS.iter().zip(&self.columns) {
            let spec = table.spec(field);
            match column {
                HistoryColumn::Flags(c) => v.visit(&spec, c)?,
                HistoryColumn::Values(c) => v.visit(&spec, c)?,
            }
        }
        Ok(())
    }

    fn visit_mut<V: VisitorMut>(&mut self, table: HistoryTable, v: &mut V) -> Result<(), V::Error> {
        for (field, column) in HISTORY_FIELDS.iter().zip(&mut self.columns) {
            let spec = table.spec(field);
            match column {
                HistoryColumn::Flags(c) => v.visit(&spec, c)?,
                HistoryColumn::Values(c) => v.visit(&spec, c)?,
            }
        }
        Ok(())
    }
}

datasets! {
    particle_id: u32 => "particles/id", Rows::Particles, 1, "1";
    particle_species: u16 => "particles/species", Rows::Particles, 1, "1";
    radius_m: f64 => "particles/radius_m", Rows::Particles, 1, "m";
    mass_kg: f64 => "particles/mass_kg", Rows::Particles, 1, "kg";
    inertia_kg_m2: f64 => "particles/inertia_kg_m2", Rows::Particles, 1, "kg m2";
    position_m: f64 => "particles/position_m", Rows::Particles, 3, "m";
    velocity_m_per_s: f64 => "particles/velocity_m_per_s", Rows::Particles, 3, "m/s";
    angular_velocity_rad_per_s: f64 => "particles/angular_velocity_rad_per_s", Rows::Particles, 3, "rad/s";
    force_n: f64 => "particles/force_n", Rows::Particles, 3, "N";
    torque_n_m: f64 => "particles/torque_n_m", Rows::Particles, 3, "N m";

    pair_i: u32 => "contacts/pairs/i", Rows::PairContacts, 1, "1";
    pair_j: u32 => "contacts/pairs/j", Rows::PairContacts, 1, "1";
    pair_active: u8 => "contacts/pairs/active", Rows::PairContacts, 1, "1";

    wall_i: u32 => "contacts/walls/i", Rows::WallContacts, 1, "1";
    wall_wall: u16 => "contacts/walls/wall", Rows::WallContacts, 1, "1";
    wall_active: u8 => "contacts/walls/active", Rows::WallContacts, 1, "1";

    wall_angle_rad: f64 => "walls/angle_rad", Rows::Walls, 1, "rad";

    rng_seed: u8 => "rng/seed", Rows::Fixed(32), 1, "1";
    rng_stream: u64 => "rng/stream", Rows::Scalar, 1, "1";
    rng_word_pos_hi: u64 => "rng/word_pos_hi", Rows::Scalar, 1, "1";
    rng_word_pos_lo: u64 => "rng/word_pos_lo", Rows::Scalar, 1, "1";

    gas_pressure_pa: f64 => "gas/pressure_pa", Rows::GasCells, 1, "Pa";
    gas_porosity: f64 => "gas/porosity", Rows::GasCells, 1, "1";
    gas_velocity_x: f64 => "gas/velocity_x_m_per_s", Rows::GasFaces(0), 1, "m/s";
    gas_velocity_y: f64 => "gas/velocity_y_m_per_s", Rows::GasFaces(1), 1, "m/s";
    gas_velocity_z: f64 => "gas/velocity_z_m_per_s", Rows::GasFaces(2), 1, "m/s";
    gas_reaction_x: f64 => "gas/drag_reaction_sum_x_n_per_m3", Rows::GasFaces(0), 1, "N/m3";
    gas_reaction_y: f64 => "gas/drag_reaction_sum_y_n_per_m3", Rows::GasFaces(1), 1, "N/m3";
    gas_reaction_z: f64 => "gas/drag_reaction_sum_z_n_per_m3", Rows::GasFaces(2), 1, "N/m3";
    gas_beta_x: f64 => "gas/drag_beta_sum_x_n_s_per_m4", Rows::GasFaces(0), 1, "N s/m4";
    gas_beta_y: f64 => "gas/drag_beta_sum_y_n_s_per_m4", Rows::GasFaces(1), 1, "N s/m4";
    gas_beta_z: f64 => "gas/drag_beta_sum_z_n_s_per_m4", Rows::GasFaces(2), 1, "N s/m4";
    gas_beta_v_x: f64 => "gas/drag_beta_velocity_sum_x_n_per_m3", Rows::GasFaces(0), 1, "N/m3";
    gas_beta_v_y: f64 => "gas/drag_beta_velocity_sum_y_n_per_m3", Rows::GasFaces(1), 1, "N/m3";
    gas_beta_v_z: f64 => "gas/drag_beta_velocity_sum_z_n_per_m3", Rows::GasFaces(2), 1, "N/m3";
    gas_time_s: f64 => "gas/time_s", Rows::GasScalar, 1, "s";
    gas_reaction_steps: u32 => "gas/drag_reaction_steps", Rows::GasScalar, 1, "1";
    gas_last_outer_iterations: u64 => "gas/last_step/outer_iterations", Rows::GasScalar, 1, "1";
    gas_last_linear_iterations: u64 => "gas/last_step/linear_iterations", Rows::GasScalar, 1, "1";
    gas_last_mass_imbalance: f64 => "gas/last_step/mass_imbalance", Rows::GasScalar, 1, "1";
    gas_last_converged: u8 => "gas/last_step/converged", Rows::GasScalar, 1, "1";
    gas_temperature_k: f64 => "gas/temperature_k", Rows::GasCellsIfHeat, 1, "K";
    gas_heat_transfer_sum: f64 => "gas/heat_transfer_sum_k_kg_per_m3_s", Rows::GasCellsIfHeat, 1, "K kg/(m3 s)";
    gas_heat_exchange_steps: u32 => "gas/heat_exchange_steps", Rows::GasScalarIfHeat, 1, "1";
    gas_vapour_mass_fraction: f64 => "gas/vapour_mass_fraction", Rows::GasCellsIfDrying, 1, "kg/kg";
    drying_initial_liquid_kg: f64 => "gas/drying/initial_liquid_kg", Rows::GasScalarIfDrying, 1, "kg";
    drying_initial_vapour_kg: f64 => "gas/drying/initial_vapour_kg", Rows::GasScalarIfDrying, 1, "kg";
    drying_sprayed_kg: f64 => "gas/drying/sprayed_kg", Rows::GasScalarIfDrying, 1, "kg";
    drying_evaporated_kg: f64 => "gas/drying/evaporated_kg", Rows::GasScalarIfDrying, 1, "kg";
    drying_vapour_in_kg: f64 => "gas/drying/vapour_in_kg", Rows::GasScalarIfDrying, 1, "kg";
    drying_vapour_out_kg: f64 => "gas/drying/vapour_out_kg", Rows::GasScalarIfDrying, 1, "kg";
    held_drag_position_m: f64 => "gas/held_drag/position_m", Rows::ParticlesIfRecorded, 3, "m";
    held_drag_velocity: f64 => "gas/held_drag/velocity_m_per_s", Rows::ParticlesIfRecorded, 3, "m/s";
    held_drag_velocity_sum: f64 => "gas/held_drag/velocity_sum_m_per_s", Rows::ParticlesIfRecorded, 3, "m/s";

    liquid_m3: f64 => "particles/liquid_m3", Rows::Particles, 1, "m3";
    sprayed_m3: f64 => "particles/sprayed_m3", Rows::Particles, 1, "m3";
    temperature_k: f64 => "particles/temperature_k", Rows::ParticlesIfRecorded, 1, "K";

    heat_initial_energy_j: f64 => "heat_ledger/initial_energy_j", Rows::ScalarIfHeat, 1, "J";
    heat_wall_to_particles_j: f64 => "heat_ledger/wall_to_particles_j", Rows::ScalarIfHeat, 1, "J";
    heat_gas_boundary_in_j: f64 => "heat_ledger/gas_boundary_in_j", Rows::ScalarIfHeat, 1, "J";
    heat_gas_boundary_out_j: f64 => "heat_ledger/gas_boundary_out_j", Rows::ScalarIfHeat, 1, "J";
    heat_gas_continuity_j: f64 => "heat_ledger/gas_continuity_j", Rows::ScalarIfHeat, 1, "J";

    net_force_steps: u64 => "net_force/steps", Rows::NetForce, 1, "1";
    net_force_fluid_n: f64 => "net_force/fluid_sum_n", Rows::NetForce, 3, "N";
    net_force_wall_contact_n: f64 => "net_force/wall_contact_sum_n", Rows::NetForceWalls, 3, "N";
    net_force_wall_cohesion_n: f64 => "net_force/wall_cohesion_sum_n", Rows::NetForceWalls, 3, "N";
}

/// Groups to create before the datasets, parents first.
pub(crate) const GROUPS: &[&str] = &[
    "particles",
    "contacts",
    "contacts/pairs",
    "contacts/walls",
    "walls",
    "rng",
    "gas",
    "gas/last_step",
    "gas/held_drag",
    "gas/drying",
    "net_force",
    "particles/channels",
    "heat_ledger",
];

/// The scalar part of a checkpoint: the root attributes other than `format` and the checksum.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Header<'a> {
    pub format_version: u32,
    pub step: u64,
    pub time_s: f64,
    pub dt_s: f64,
    pub meta: &'a CheckpointMeta,
}

fn flatten(v: &[Vec3]) -> Vec<f64> {
    v.iter().flat_map(|x| [x.x, x.y, x.z]).collect()
}

fn unflatten(v: &[f64]) -> Vec<Vec3> {
    v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
}

impl Arrays {
    /// The datasets of `state`. Call [`Arrays::check`] on the result before writing it.
    pub(crate) fn from_state(state: &SimState) -> Arrays {
        let p = &state.particles;
        let gas = state.gas.as_ref();
        // The one transported scalar a checkpoint holds today: the gas temperature of a run with heat transfer.
        let gas_temperature = gas.and_then(|g| g.scalars.iter().find(|s| s.name == GAS_TEMPERATURE));
        let held = gas.and_then(|g| g.held_drag.as_ref());
        let vapour = gas.and_then(|g| g.scalars.iter().find(|s| s.name == GAS_VAPOUR));
        let ledger = gas.and_then(|g| g.drying.as_ref());
        let ledger_value = |f: fn(&crate::engine::drying::DryingLedger) -> f64| ledger.map(f).into_iter().collect();
        let heat_value = |f: fn(&HeatLedger) -> f64| state.heat_ledger.as_ref().map(f).into_iter().collect();
        Arrays {
            particle_id: p.id.iter().map(|id| id.0).collect(),
            particle_species: p.species.iter().map(|s| s.0).collect(),
            radius_m: p.radius_m.clone(),
            mass_kg: p.mass_kg.clone(),
            inertia_kg_m2: p.inertia_kg_m2.clone(),
            position_m: flatten(&p.position_m),
            velocity_m_per_s: flatten(&p.velocity_m_per_s),
            angular_velocity_rad_per_s: flatten(&p.angular_velocity_rad_per_s),
            force_n: flatten(&p.force_n),
            torque_n_m: flatten(&p.torque_n_m),

            pair_i: state.contacts.pairs.iter().map(|(i, _, _)| i.0).collect(),
            pair_j: state.contacts.pairs.iter().map(|(_, j, _)| j.0).collect(),
            pair_active: state
                .contacts
                .pairs
                .iter()
                .map(|(_, _, h)| u8::from(h.active))
                .collect(),

            wall_i: state.contacts.walls.iter().map(|(i, _, _)| i.0).collect(),
            wall_wall: state.contacts.walls.iter().map(|(_, w, _)| w.0).collect(),
            wall_active: state
                .contacts
                .walls
                .iter()
                .map(|(_, _, h)| u8::from(h.active))
                .collect(),

            wall_angle_rad: state.wall_angle_rad.clone(),

            rng_seed: state.rng.seed.to_vec(),
            rng_stream: vec![state.rng.stream],
            rng_word_pos_hi: vec![(state.rng.word_pos >> 64) as u64],
            rng_word_pos_lo: vec![state.rng.word_pos as u64],

            gas_pressure_pa: gas.map(|g| g.pressure_pa.clone()).unwrap_or_default(),
            gas_porosity: gas.map(|g| g.porosity.clone()).unwrap_or_default(),
            gas_velocity_x: gas.map(|g| g.velocity_m_per_s[0].clone()).unwrap_or_default(),
            gas_velocity_y: gas.map(|g| g.velocity_m_per_s[1].clone()).unwrap_or_default(),
            gas_velocity_z: gas.map(|g| g.velocity_m_per_s[2].clone()).unwrap_or_default(),
            gas_reaction_x: gas.map(|g| g.reaction_n_per_m3[0].clone()).unwrap_or_default(),
            gas_reaction_y: gas.map(|g| g.reaction_n_per_m3[1].clone()).unwrap_or_default(),
            gas_reaction_z: gas.map(|g| g.reaction_n_per_m3[2].clone()).unwrap_or_default(),
            gas_beta_x: gas.map(|g| g.beta_sum[0].clone()).unwrap_or_default(),
            gas_beta_y: gas.map(|g| g.beta_sum[1].clone()).unwrap_or_default(),
            gas_beta_z: gas.map(|g| g.beta_sum[2].clone()).unwrap_or_default(),
            gas_beta_v_x: gas.map(|g| g.beta_velocity_sum[0].clone()).unwrap_or_default(),
            gas_beta_v_y: gas.map(|g| g.beta_velocity_sum[1].clone()).unwrap_or_default(),
            gas_beta_v_z: gas.map(|g| g.beta_velocity_sum[2].clone()).unwrap_or_default(),
            gas_time_s: gas.map(|g| g.time_s).into_iter().collect(),
            gas_reaction_steps: gas.map(|g| g.reaction_steps).into_iter().collect(),
            gas_last_outer_iterations: gas.map(|g| g.last.outer_iterations).into_iter().collect(),
            gas_last_linear_iterations: gas.map(|g| g.last.linear_iterations).into_iter().collect(),
            gas_last_mass_imbalance: gas.map(|g| g.last.mass_imbalance).into_iter().collect(),
            gas_last_converged: gas.map(|g| u8::from(g.last.converged)).into_iter().collect(),
            gas_temperature_k: gas_temperature.map(|s| s.value.clone()).unwrap_or_default(),
            gas_heat_transfer_sum: gas_temperature
                .map(|s| s.exchange.transfer_sum.clone())
                .unwrap_or_default(),
            gas_heat_exchange_steps: gas_temperature.map(|s| s.exchange.steps).into_iter().collect(),
            gas_vapour_mass_fraction: vapour.map(|s| s.value.clone()).unwrap_or_default(),
            drying_initial_liquid_kg: ledger_value(|l| l.initial_liquid_kg),
            drying_initial_vapour_kg: ledger_value(|l| l.initial_vapour_kg),
            drying_sprayed_kg: ledger_value(|l| l.sprayed_kg),
            drying_evaporated_kg: ledger_value(|l| l.evaporated_kg),
            drying_vapour_in_kg: ledger_value(|l| l.vapour_in_kg),
            drying_vapour_out_kg: ledger_value(|l| l.vapour_out_kg),
            held_drag_position_m: held.map(|h| flatten(&h.position_m)).unwrap_or_default(),
            held_drag_velocity: held.map(|h| flatten(&h.velocity_m_per_s)).unwrap_or_default(),
            held_drag_velocity_sum: held.map(|h| flatten(&h.velocity_sum_m_per_s)).unwrap_or_default(),

            liquid_m3: p.liquid_m3.clone(),
            sprayed_m3: p.sprayed_m3.clone(),
            temperature_k: p.temperature_k.clone(),

            heat_initial_energy_j: heat_value(|l| l.initial_energy_j),
            heat_wall_to_particles_j: heat_value(|l| l.wall_to_particles_j),
            heat_gas_boundary_in_j: heat_value(|l| l.gas_boundary_in_j),
            heat_gas_boundary_out_j: heat_value(|l| l.gas_boundary_out_j),
            heat_gas_continuity_j: heat_value(|l| l.gas_continuity_j),
            net_force_steps: state.net_force.as_ref().map(|t| t.steps).into_iter().collect(),
            net_force_fluid_n: state
                .net_force
                .as_ref()
                .map(|t| flatten(&[t.fluid_n]))
                .unwrap_or_default(),
            net_force_wall_contact_n: state
                .net_force
                .as_ref()
                .map(|t| flatten(&t.wall_contact_n))
                .unwrap_or_default(),
            net_force_wall_cohesion_n: state
                .net_force
                .as_ref()
                .map(|t| flatten(&t.wall_cohesion_n))
                .unwrap_or_default(),

            pair_history: HistoryArrays::of(state.contacts.pairs.iter().map(|(_, _, h)| h)),
            wall_history: HistoryArrays::of(state.contacts.walls.iter().map(|(_, _, h)| h)),
            channels: p.channels.clone(),
        }
    }

    /// Checks that the arrays describe a consistent state: every dataset has the shape its [`Rows`] demand (all
    /// particle datasets the same number of rows, and so on), flags are 0 or 1, and every contact refers to an
    /// existing particle and wall. Returns the first problem found.
    pub(crate) fn check(&self) -> Result<(), String> {
        let mut shapes = ShapeCheck::default();
        self.visit(&mut shapes)?;
        let n = self.particle_id.len();
        let n_walls = self.wall_angle_rad.len();
        let flags = [
            ("contacts/pairs/active", &self.pair_active),
            ("contacts/walls/active", &self.wall_active),
        ];
        for (path, values) in flags {
            if let Some(k) = values.iter().position(|&v| v > 1) {
                return Err(format!("/{path}[{k}] is {}, expected 0 or 1", values[k]));
            }
        }
        for (arrays, table) in [
            (&self.pair_history, HistoryTable::Pairs),
            (&self.wall_history, HistoryTable::Walls),
        ] {
            if let Some((path, k, v)) = arrays.bad_flag(table) {
                return Err(format!("/{path}[{k}] is {v}, expected 0 or 1"));
            }
        }
        let particles = [
            ("contacts/pairs/i", &self.pair_i),
            ("contacts/pairs/j", &self.pair_j),
            ("contacts/walls/i", &self.wall_i),
        ];
        for (path, values) in particles {
            if let Some(k) = values.iter().position(|&v| v as usize >= n) {
                return Err(format!(
                    "/{path}[{k}] = {} is not a particle (there are {n})",
                    values[k]
                ));
            }
        }
        let gas_scalars = self.gas_time_s.len();
        if gas_scalars > 1 {
            return Err(format!("/gas/time_s has {gas_scalars} elements, expected 0 or 1"));
        }
        let gas_lengths = [
            ("gas/pressure_pa", self.gas_pressure_pa.len()),
            ("gas/velocity_x_m_per_s", self.gas_velocity_x.len()),
            ("gas/velocity_y_m_per_s", self.gas_velocity_y.len()),
        ];
        for (path, len) in gas_lengths {
            if (len > 0) != (gas_scalars == 1) {
                return Err(format!("/{path} has {len} values but /gas/time_s has {gas_scalars}"));
            }
        }
        let gas_cells = self.gas_pressure_pa.len();
        let heat_cells = self.gas_temperature_k.len();
        if heat_cells != 0
            && (heat_cells != gas_cells
                || self.gas_heat_transfer_sum.len() != gas_cells
                || self.gas_heat_exchange_steps.len() != 1)
        {
            return Err(format!(
                "/gas/temperature_k has {heat_cells} values, /gas/heat_transfer_sum_k_kg_per_m3_s {} and \
                 /gas/heat_exchange_steps {}, expected one per gas cell ({gas_cells}) and one",
                self.gas_heat_transfer_sum.len(),
                self.gas_heat_exchange_steps.len()
            ));
        }
        let vapour_cells = self.gas_vapour_mass_fraction.len();
        let ledger = [
            self.drying_initial_liquid_kg.len(),
            self.drying_initial_vapour_kg.len(),
            self.drying_sprayed_kg.len(),
            self.drying_evaporated_kg.len(),
            self.drying_vapour_in_kg.len(),
            self.drying_vapour_out_kg.len(),
        ];
        let drying = vapour_cells != 0;
        if (drying && (vapour_cells != gas_cells || heat_cells != gas_cells))
            || ledger.iter().any(|&len| len != usize::from(drying))
        {
            return Err(format!(
                "/gas/vapour_mass_fraction has {vapour_cells} values and the /gas/drying datasets {ledger:?}, \
                 expected none, or one per gas cell ({gas_cells}, with a gas temperature) and one each"
            ));
        }
        let heat_ledger = [
            self.heat_initial_energy_j.len(),
            self.heat_wall_to_particles_j.len(),
            self.heat_gas_boundary_in_j.len(),
            self.heat_gas_boundary_out_j.len(),
            self.heat_gas_continuity_j.len(),
        ];
        if heat_ledger.iter().any(|&len| len > 1 || len != heat_ledger[0]) {
            return Err(format!(
                "the /heat_ledger datasets have {heat_ledger:?} elements, expected one each (a run with heat \
                 transfer) or none"
            ));
        }
        let optional = CHANNELS
            .iter()
            .map(|info| (info.path, (info.get)(&self.channels).len()))
            .chain([("particles/temperature_k", self.temperature_k.len())])
            .chain([
                ("gas/held_drag/position_m", self.held_drag_position_m.len() / 3),
                ("gas/held_drag/velocity_m_per_s", self.held_drag_velocity.len() / 3),
                (
                    "gas/held_drag/velocity_sum_m_per_s",
                    self.held_drag_velocity_sum.len() / 3,
                ),
            ]);
        for (path, rows) in optional {
            if rows != 0 && rows != n {
                return Err(format!("/{path} has {rows} rows, expected 0 or one per particle ({n})"));
            }
        }
        let tallies = self.net_force_steps.len();
        let tally_walls = self.net_force_wall_contact_n.len() / 3;
        if tallies > 1 || tally_walls != tallies * n_walls {
            return Err(format!(
                "/net_force/steps has {tallies} elements and /net_force/wall_contact_sum_n {tally_walls} rows, \
                 expected none, or 1 and one row per wall ({n_walls})"
            ));
        }
        if let Some(&v) = self.gas_last_converged.first().filter(|&&v| v > 1) {
            return Err(format!("/gas/last_step/converged is {v}, expected 0 or 1"));
        }
        for (path, values) in [("contacts/walls/wall", &self.wall_wall)] {
            if let Some(k) = values.iter().position(|&w| w as usize >= n_walls) {
                return Err(format!(
                    "/{path}[{k}] = {} is not a wall (there are {n_walls})",
                    values[k]
                ));
            }
        }
        Ok(())
    }

    /// The state these arrays describe. The arrays must have passed [`Arrays::check`].
    pub(crate) fn into_state(self, header: &Header<'_>) -> SimState {
        let particles = Particles {
            id: self.particle_id.iter().map(|&i| ParticleId(i)).collect(),
            species: self.particle_species.iter().map(|&s| SpeciesId(s)).collect(),
            radius_m: self.radius_m,
            mass_kg: self.mass_kg,
            inertia_kg_m2: self.inertia_kg_m2,
            position_m: unflatten(&self.position_m),
            velocity_m_per_s: unflatten(&self.velocity_m_per_s),
            angular_velocity_rad_per_s: unflatten(&self.angular_velocity_rad_per_s),
            force_n: unflatten(&self.force_n),
            torque_n_m: unflatten(&self.torque_n_m),
            liquid_m3: self.liquid_m3,
            sprayed_m3: self.sprayed_m3,
            temperature_k: self.temperature_k,
            channels: self.channels,
        };
        let record = |active: u8, history: &HistoryArrays, k: usize| {
            let mut h = ContactHistory {
                active: active != 0,
                ..ContactHistory::INACTIVE
            };
            history.fill(k, &mut h);
            h
        };
        let pairs = (0..self.pair_i.len())
            .map(|k| {
                (
                    ParticleId(self.pair_i[k]),
                    ParticleId(self.pair_j[k]),
                    record(self.pair_active[k], &self.pair_history, k),
                )
            })
            .collect();
        let walls = (0..self.wall_i.len())
            .map(|k| {
                (
                    ParticleId(self.wall_i[k]),
                    WallId(self.wall_wall[k]),
                    record(self.wall_active[k], &self.wall_history, k),
                )
            })
            .collect();
        let mut seed = [0u8; 32];
        seed.copy_from_slice(&self.rng_seed);
        let word_pos = (u128::from(self.rng_word_pos_hi[0]) << 64) | u128::from(self.rng_word_pos_lo[0]);
        let cells = self.gas_pressure_pa.len();
        let gas = (self.gas_time_s.len() == 1).then(|| GasSnapshot {
            pressure_pa: self.gas_pressure_pa,
            velocity_m_per_s: [self.gas_velocity_x, self.gas_velocity_y, self.gas_velocity_z],
            porosity: self.gas_porosity,
            time_s: self.gas_time_s[0],
            reaction_n_per_m3: [self.gas_reaction_x, self.gas_reaction_y, self.gas_reaction_z],
            beta_sum: [self.gas_beta_x, self.gas_beta_y, self.gas_beta_z],
            beta_velocity_sum: [self.gas_beta_v_x, self.gas_beta_v_y, self.gas_beta_v_z],
            reaction_steps: self.gas_reaction_steps[0],
            last: GasStepStats {
                outer_iterations: self.gas_last_outer_iterations[0],
                linear_iterations: self.gas_last_linear_iterations[0],
                mass_imbalance: self.gas_last_mass_imbalance[0],
                converged: self.gas_last_converged[0] == 1,
            },
            held_drag: (!self.held_drag_position_m.is_empty()).then(|| HeldDragSnapshot {
                position_m: unflatten(&self.held_drag_position_m),
                velocity_m_per_s: unflatten(&self.held_drag_velocity),
                velocity_sum_m_per_s: unflatten(&self.held_drag_velocity_sum),
            }),
            scalars: (self.gas_temperature_k.len() == cells && cells > 0)
                .then(|| GasScalarSnapshot {
                    name: GAS_TEMPERATURE.into(),
                    unit: "K".into(),
                    value: self.gas_temperature_k,
                    exchange: ExchangeAccumulator {
                        coefficient_sum: vec![0.0; cells],
                        coefficient_value_sum: vec![0.0; cells],
                        transfer_sum: self.gas_heat_transfer_sum,
                        steps: self.gas_heat_exchange_steps.first().copied().unwrap_or(0),
                    },
                })
                .into_iter()
                .chain(
                    (self.gas_vapour_mass_fraction.len() == cells && cells > 0).then(|| GasScalarSnapshot {
                        name: GAS_VAPOUR.into(),
                        unit: "kg/kg".into(),
                        value: self.gas_vapour_mass_fraction,
                        exchange: ExchangeAccumulator::new(cells),
                    }),
                )
                .collect(),
            drying: (self.drying_evaporated_kg.len() == 1).then(|| crate::engine::drying::DryingLedger {
                initial_liquid_kg: self.drying_initial_liquid_kg[0],
                initial_vapour_kg: self.drying_initial_vapour_kg[0],
                sprayed_kg: self.drying_sprayed_kg[0],
                evaporated_kg: self.drying_evaporated_kg[0],
                vapour_in_kg: self.drying_vapour_in_kg[0],
                vapour_out_kg: self.drying_vapour_out_kg[0],
            }),
        });
        let net_force = (self.net_force_steps.len() == 1).then(|| NetForceTally {
            steps: self.net_force_steps[0],
            fluid_n: unflatten(&self.net_force_fluid_n)[0],
            wall_contact_n: unflatten(&self.net_force_wall_contact_n),
            wall_cohesion_n: unflatten(&self.net_force_wall_cohesion_n),
        });
        let heat_ledger = (self.heat_initial_energy_j.len() == 1).then(|| HeatLedger {
            initial_energy_j: self.heat_initial_energy_j[0],
            wall_to_particles_j: self.heat_wall_to_particles_j[0],
            gas_boundary_in_j: self.heat_gas_boundary_in_j[0],
            gas_boundary_out_j: self.heat_gas_boundary_out_j[0],
            gas_continuity_j: self.heat_gas_continuity_j[0],
        });
        SimState {
            gas,
            net_force,
            heat_ledger,
            step: header.step,
            time_s: header.time_s,
            dt_s: header.dt_s,
            particles,
            wall_angle_rad: self.wall_angle_rad,
            contacts: ContactStore { pairs, walls },
            rng: RngState {
                seed,
                stream: self.rng_stream[0],
                word_pos,
            },
        }
    }
}

/// Checks every dataset's length against its [`Rows`]: the first dataset of each kind fixes the count.
#[derive(Default)]
struct ShapeCheck {
    rows: HashMap<Rows, (usize, &'static str)>,
}

impl Visitor for ShapeCheck {
    type Error = String;

    fn visit<T: Element>(&mut self, spec: &DatasetSpec, data: &[T]) -> Result<(), String> {
        let len = data.len();
        match spec.rows {
            Rows::Scalar if len != 1 => Err(format!("/{} must be a scalar, has {len} elements", spec.path)),
            Rows::Fixed(n) if len != n * spec.width => Err(format!(
                "/{} must have {} elements, has {len}",
                spec.path,
                n * spec.width
            )),
            Rows::Scalar | Rows::Fixed(_) => Ok(()),
            // Each of these is 0 or N rows on its own ([`Arrays::check`]).
            Rows::ParticlesIfRecorded
            | Rows::GasCellsIfHeat
            | Rows::GasScalarIfHeat
            | Rows::GasCellsIfDrying
            | Rows::GasScalarIfDrying
            | Rows::ScalarIfHeat => Ok(()),
            _ if !len.is_multiple_of(spec.width) => Err(format!(
                "/{} has {len} elements, not a multiple of {}",
                spec.path, spec.width
            )),
            kind => {
                let rows = len / spec.width;
                let (expected, first) = *self.rows.entry(kind).or_insert((rows, spec.path));
                if rows == expected {
                    Ok(())
                } else {
                    Err(format!("/{} has {rows} rows but /{first} has {expected}", spec.path))
                }
            }
        }
    }
}

/// Feeds the checksum: the byte stream documented in `schemas/checkpoint.md`.
struct Hasher {
    h: Xxh3Default,
    buf: Vec<u8>,
}

impl Hasher {
    fn u32(&mut self, v: u32) {
        self.h.update(&v.to_le_bytes());
    }

    fn u64(&mut self, v: u64) {
        self.h.update(&v.to_le_bytes());
    }

    fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.h.update(s.as_bytes());
    }

    fn strs(&mut self, v: &[String]) {
        self.u64(v.len() as u64);
        for s in v {
            self.str(s);
        }
    }
}

impl Visitor for Hasher {
    type Error = std::convert::Infallible;

    fn visit<T: Element>(&mut self, spec: &DatasetSpec, data: &[T]) -> Result<(), Self::Error> {
        self.str(spec.path);
        let shape = spec.shape(data.len());
        self.u64(shape.len() as u64);
        for d in shape {
            self.u64(d as u64);
        }
        for chunk in data.chunks(4096) {
            self.buf.clear();
            for &x in chunk {
                x.put_le(&mut self.buf);
            }
            self.h.update(&self.buf);
        }
        Ok(())
    }
}

/// The xxh3-64 checksum of a checkpoint: the header fields, then every dataset in table order.
pub(crate) fn checksum(header: &Header<'_>, arrays: &Arrays) -> u64 {
    let mut h = Hasher {
        h: Xxh3Default::new(),
        buf: Vec::with_capacity(4096 * 8),
    };
    h.str(FORMAT_NAME);
    h.u32(header.format_version);
    h.str(&header.meta.engine_version);
    h.u64(header.step);
    h.u64(header.time_s.to_bits());
    h.u64(header.dt_s.to_bits());
    h.strs(&header.meta.model_names);
    h.strs(&header.meta.wall_names);
    h.str(&header.meta.scenario_json);
    match arrays.visit(&mut h) {
        Ok(()) => {}
        Err(never) => match never {},
    }
    h.h.digest()
}

/// Size of the HDF5 userblock at the start of every checkpoint, which holds the seal.
pub(crate) const SEAL_BYTES: u64 = 512;
const SEAL_MAGIC: &str = "granflow-checkpoint seal v1\n";

/// The userblock: magic line, `hdf5_bytes=<decimal>`, `file_xxh3_64=0x<16 hex digits>`, zero padding.
fn seal_block(hdf5_bytes: u64, hash: u64) -> Vec<u8> {
    let mut block = format!("{SEAL_MAGIC}hdf5_bytes={hdf5_bytes}\nfile_xxh3_64={hash:#018x}\n").into_bytes();
    block.resize(SEAL_BYTES as usize, 0);
    block
}

/// The length and hash recorded in a seal block, given the bytes after the magic line.
fn parse_seal(rest: &[u8]) -> Option<(u64, u64)> {
    let text = std::str::from_utf8(rest.split(|&b| b == 0).next()?).ok()?;
    let mut lines = text.lines();
    let len = lines.next()?.strip_prefix("hdf5_bytes=")?.parse().ok()?;
    let hash = u64::from_str_radix(lines.next()?.strip_prefix("file_xxh3_64=0x")?, 16).ok()?;
    Some((len, hash))
}

/// The xxh3-64 of everything from the current position of `file` to its end, and the number of bytes hashed.
fn hash_rest(file: &mut File) -> std::io::Result<(u64, u64)> {
    let mut hasher = Xxh3Default::new();
    let mut buf = vec![0u8; 1 << 20];
    let mut len = 0u64;
    loop {
        match file.read(&mut buf) {
            Ok(0) => return Ok((hasher.digest(), len)),
            Ok(k) => {
                hasher.update(&buf[..k]);
                len += k as u64;
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
}

/// Seals the closed HDF5 file at `path` (created with a [`SEAL_BYTES`] userblock): hashes everything after the
/// userblock, writes the seal into it and fsyncs the file.
pub(crate) fn seal(path: &Path) -> Result<(), CheckpointError> {
    let io = |e: std::io::Error| CheckpointError::io(path, "sealing the file", e);
    let mut file = OpenOptions::new().read(true).write(true).open(path).map_err(io)?;
    file.seek(SeekFrom::Start(SEAL_BYTES)).map_err(io)?;
    let (hash, len) = hash_rest(&mut file).map_err(io)?;
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    file.write_all(&seal_block(len, hash)).map_err(io)?;
    file.sync_all().map_err(io)
}

/// Checks the seal of the file at `path`: a well-formed seal block, the recorded length and the recorded hash.
pub(crate) fn verify_seal(path: &Path) -> Result<(), CheckpointError> {
    let io = |e: std::io::Error| CheckpointError::io(path, "reading the file", e);
    let corrupt = |reason: String| CheckpointError::corrupt(path, reason);
    let mut file = File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    if len < SEAL_BYTES {
        return Err(corrupt(format!(
            "truncated ({len} bytes, shorter than the {SEAL_BYTES}-byte seal block)"
        )));
    }
    let mut block = vec![0u8; SEAL_BYTES as usize];
    file.read_exact(&mut block).map_err(io)?;
    let Some(rest) = block.strip_prefix(SEAL_MAGIC.as_bytes()) else {
        return Err(corrupt(
            "no checkpoint seal at the start of the file (not a granflow checkpoint, or rewritten by another tool)"
                .to_string(),
        ));
    };
    let (hdf5_bytes, stored) = parse_seal(rest)
        .filter(|&(n, h)| seal_block(n, h) == block)
        .ok_or_else(|| corrupt("the seal block is damaged".to_string()))?;
    let expected = SEAL_BYTES.saturating_add(hdf5_bytes);
    if len < expected {
        return Err(corrupt(format!("truncated ({len} bytes, {expected} written)")));
    }
    if len > expected {
        return Err(corrupt(format!(
            "{} bytes longer than the {expected} written",
            len - expected
        )));
    }
    let (computed, _) = hash_rest(&mut file).map_err(io)?;
    if computed != stored {
        return Err(corrupt(format!(
            "file checksum mismatch (stored {stored:#018x}, computed {computed:#018x})"
        )));
    }
    Ok(())
}
