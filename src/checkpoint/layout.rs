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

use xxhash_rust::xxh3::Xxh3Default;

use super::CheckpointMeta;
use crate::engine::Vec3;
use crate::engine::channels::{CHANNELS, ChannelInfo, ParticleChannels};
use crate::engine::models::ContactHistory;
use crate::engine::models::history::{FieldKind, FieldValue, HISTORY_FIELDS, HistoryField};

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

impl Arrays {
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

mod seal;
mod state;

pub(crate) use seal::{SEAL_BYTES, seal, verify_seal};
