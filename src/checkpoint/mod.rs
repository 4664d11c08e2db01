//! HDF5 checkpoints: writing a [`SimState`] with its [`CheckpointMeta`] to one self-describing file, reading it
//! back bit for bit, and keeping a rotating series of them per run ([`CheckpointSeries`]).
//!
//! A checkpoint is written atomically (temporary file, fsync, rename, fsync of the directory). It carries two
//! checksums: an xxh3-64 over its content (attribute `checksum_xxh3_64`), and a seal in the HDF5 userblock holding
//! the length and xxh3-64 of the file bytes, checked before libhdf5 parses the file. A reader therefore gets exactly
//! the state that was written or a [`CheckpointError`] naming the file; truncated, bit-flipped or foreign files are
//! errors, never panics or crashes. The layout (names, element types, units, checksum order, seal) is documented in
//! `schemas/checkpoint.md` and defined in `layout.rs`. What does *not* live here: deciding when to checkpoint,
//! checking that a restored state matches the scenario being resumed (the caller compares [`CheckpointMeta`]), and
//! rebuilding the engine from a state (`engine::Simulation::restore`).

mod error;
mod layout;
mod series;

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;
use hdf5::{Datatype, H5Type, Location};

pub use error::CheckpointError;
use layout::{
    Arrays, DatasetSpec, Element, FORMAT_NAME, GROUPS, Header, Rows, SEAL_BYTES, Visitor, VisitorMut, checksum, seal,
    verify_seal,
};
pub use series::{CheckpointSeries, LoadedCheckpoint};

use crate::engine::SimState;

/// Version of the file layout. Bump it whenever a name, type, shape or the checksum definition changes; readers
/// reject any other version with [`CheckpointError::Version`].
pub const CHECKPOINT_FORMAT_VERSION: u32 = 10;

/// Metadata stored beside the state.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckpointMeta {
    /// Version of the engine that wrote the file, e.g. `env!("CARGO_PKG_VERSION")`.
    pub engine_version: String,
    /// Contact-law slot names (normal, tangential, rolling), e.g. `["thornton", "walton_braun", "none"]`.
    pub model_names: Vec<String>,
    /// Names of the scenario's walls, in wall-id order.
    pub wall_names: Vec<String>,
    /// The fully resolved scenario, so that a restore can check it matches.
    pub scenario_json: String,
}

/// The temporary file a checkpoint is written to before being renamed over `path`: `<path>.tmp`.
fn tmp_path(path: &Path) -> PathBuf {
    let mut s = OsString::from(path.as_os_str());
    s.push(".tmp");
    PathBuf::from(s)
}

/// Writes `state` and `meta` to `path` atomically: to `<path>.tmp`, flush and close, seal (file checksum in the
/// userblock) and fsync the file, rename it over `path`, fsync the directory. On failure the temporary file is
/// removed and an existing `path` is left untouched.
pub fn write_checkpoint(path: &Path, state: &SimState, meta: &CheckpointMeta) -> Result<(), CheckpointError> {
    let invalid = |reason: String| CheckpointError::InvalidState {
        path: path.to_path_buf(),
        reason,
    };
    let arrays = Arrays::from_state(state);
    arrays.check().map_err(invalid)?;
    let strings = [
        ("engine_version", &meta.engine_version),
        ("scenario_json", &meta.scenario_json),
    ]
    .into_iter()
    .chain(meta.model_names.iter().map(|s| ("model_names", s)))
    .chain(meta.wall_names.iter().map(|s| ("wall_names", s)));
    for (name, s) in strings {
        if s.contains('\0') {
            return Err(invalid(format!("{name} contains a NUL character")));
        }
    }
    let header = Header {
        format_version: CHECKPOINT_FORMAT_VERSION,
        step: state.step,
        time_s: state.time_s,
        dt_s: state.dt_s,
        meta,
    };
    let sum = checksum(&header, &arrays);

    let tmp = tmp_path(path);
    let result = write_hdf5(&tmp, &header, &arrays, sum).and_then(|()| commit(&tmp, path));
    if result.is_err() {
        // Best effort: the error being returned is the one worth reporting.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Seals and fsyncs `tmp`, renames it over `path` and fsyncs the directory.
fn commit(tmp: &Path, path: &Path) -> Result<(), CheckpointError> {
    seal(tmp)?;
    std::fs::rename(tmp, path).map_err(|e| CheckpointError::io(path, "renaming the temporary file into place", e))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::File::open(dir)
        .and_then(|d| d.sync_all())
        .map_err(|e| CheckpointError::io(path, "syncing the directory", e))
}

/// Creates the HDF5 file `tmp` with the whole checkpoint, then flushes and closes it.
fn write_hdf5(tmp: &Path, header: &Header<'_>, arrays: &Arrays, sum: u64) -> Result<(), CheckpointError> {
    let err = |context: &'static str| move |e: hdf5::Error| CheckpointError::hdf5(tmp, context, e);
    let file = hdf5::File::with_options()
        .with_fcpl(|p| p.userblock(SEAL_BYTES))
        .create(tmp)
        .map_err(err("creating the file"))?;
    // Every handle opened below is dropped before `close`, which otherwise leaves the file open (weak close).
    write_contents(&file, tmp, header, arrays, sum)?;
    file.flush().map_err(err("flushing the file"))?;
    file.close().map_err(err("closing the file"))
}

fn write_contents(
    file: &hdf5::File,
    tmp: &Path,
    header: &Header<'_>,
    arrays: &Arrays,
    sum: u64,
) -> Result<(), CheckpointError> {
    let attr_err = |name: &str| {
        let context = format!("writing attribute {name}");
        move |e: hdf5::Error| CheckpointError::hdf5(tmp, context, e)
    };
    let meta = header.meta;
    put_str_attr(file, "format", FORMAT_NAME).map_err(attr_err("format"))?;
    put_scalar_attr(file, "format_version", header.format_version).map_err(attr_err("format_version"))?;
    put_str_attr(file, "engine_version", &meta.engine_version).map_err(attr_err("engine_version"))?;
    put_scalar_attr(file, "step", header.step).map_err(attr_err("step"))?;
    put_scalar_attr(file, "time_s", header.time_s).map_err(attr_err("time_s"))?;
    put_scalar_attr(file, "dt_s", header.dt_s).map_err(attr_err("dt_s"))?;
    put_str_list_attr(file, "model_names", &meta.model_names).map_err(attr_err("model_names"))?;
    put_str_list_attr(file, "wall_names", &meta.wall_names).map_err(attr_err("wall_names"))?;
    put_str_attr(file, "scenario_json", &meta.scenario_json).map_err(attr_err("scenario_json"))?;
    put_scalar_attr(file, "checksum_xxh3_64", sum).map_err(attr_err("checksum_xxh3_64"))?;
    for group in GROUPS {
        file.create_group(group)
            .map_err(|e| CheckpointError::hdf5(tmp, format!("creating group /{group}"), e))?;
    }
    arrays.visit(&mut Writer { file, path: tmp })
}

fn vlen(s: &str) -> hdf5::Result<VarLenUnicode> {
    s.parse::<VarLenUnicode>()
        .map_err(|_| hdf5::Error::from("string contains a NUL character"))
}

fn put_scalar_attr<T: H5Type>(loc: &Location, name: &str, value: T) -> hdf5::Result<()> {
    loc.new_attr::<T>().create(name)?.write_scalar(&value)
}

fn put_str_attr(loc: &Location, name: &str, value: &str) -> hdf5::Result<()> {
    put_scalar_attr(loc, name, vlen(value)?)
}

fn put_str_list_attr(loc: &Location, name: &str, values: &[String]) -> hdf5::Result<()> {
    let values = values.iter().map(|s| vlen(s)).collect::<hdf5::Result<Vec<_>>>()?;
    let attr = loc.new_attr::<VarLenUnicode>().shape([values.len()]).create(name)?;
    if values.is_empty() {
        Ok(())
    } else {
        attr.write_raw(values.as_slice())
    }
}

/// Writes each dataset of [`Arrays`] with its `units` attribute.
struct Writer<'a> {
    file: &'a hdf5::File,
    path: &'a Path,
}

impl Visitor for Writer<'_> {
    type Error = CheckpointError;

    fn visit<T: Element>(&mut self, spec: &DatasetSpec, data: &[T]) -> Result<(), CheckpointError> {
        let err = |e: hdf5::Error| CheckpointError::hdf5(self.path, format!("writing /{}", spec.path), e);
        let shape = spec.shape(data.len());
        let ds = self
            .file
            .new_dataset::<T>()
            .shape(shape.as_slice())
            .create(spec.path)
            .map_err(err)?;
        match data {
            [] => {}
            [value] if spec.rows == Rows::Scalar => ds.write_scalar(value).map_err(err)?,
            _ => ds.write_raw(data).map_err(err)?,
        }
        put_str_attr(&ds, "units", spec.units).map_err(err)
    }
}

/// Reads and verifies the checkpoint at `path`: the seal (length and file checksum, before libhdf5 parses the
/// file), format name and version, element types and shapes, content checksum, and the consistency of the arrays
/// (contacts refer to existing particles and walls). Returns exactly the state and metadata that were written.
pub fn read_checkpoint(path: &Path) -> Result<(SimState, CheckpointMeta), CheckpointError> {
    // Before libhdf5 parses anything: it does not survive every kind of damage (see `layout`).
    verify_seal(path)?;
    let file_len = std::fs::metadata(path)
        .map_err(|e| CheckpointError::io(path, "reading the file's metadata", e))?
        .len();
    let file = hdf5::File::open(path).map_err(|e| CheckpointError::hdf5(path, "opening the file", e))?;
    let mut reader = Reader {
        file: &file,
        path,
        file_len,
    };

    let format = reader.str_attr("format")?;
    if format != FORMAT_NAME {
        return Err(CheckpointError::corrupt(
            path,
            format!("root attribute format is {format:?}, expected {FORMAT_NAME:?}"),
        ));
    }
    let format_version = reader.scalar_attr::<u32>("format_version")?;
    if format_version != CHECKPOINT_FORMAT_VERSION {
        return Err(CheckpointError::Version {
            path: path.to_path_buf(),
            found: format_version,
            expected: CHECKPOINT_FORMAT_VERSION,
        });
    }
    let meta = CheckpointMeta {
        engine_version: reader.str_attr("engine_version")?,
        model_names: reader.str_list_attr("model_names")?,
        wall_names: reader.str_list_attr("wall_names")?,
        scenario_json: reader.str_attr("scenario_json")?,
    };
    let header = Header {
        format_version,
        step: reader.scalar_attr("step")?,
        time_s: reader.scalar_attr("time_s")?,
        dt_s: reader.scalar_attr("dt_s")?,
        meta: &meta,
    };
    let stored = reader.scalar_attr::<u64>("checksum_xxh3_64")?;
    let mut arrays = Arrays::default();
    arrays.visit_mut(&mut reader)?;
    drop(file);

    let computed = checksum(&header, &arrays);
    if computed != stored {
        return Err(CheckpointError::corrupt(
            path,
            format!("content checksum mismatch (stored {stored:#018x}, computed {computed:#018x})"),
        ));
    }
    arrays
        .check()
        .map_err(|reason| CheckpointError::corrupt(path, reason))?;
    let state = arrays.into_state(&header);
    Ok((state, meta))
}

/// Reads attributes and datasets, checking presence, element type and shape before reading any data.
struct Reader<'a> {
    file: &'a hdf5::File,
    path: &'a Path,
    /// Size of the file in bytes: no dataset can hold more, which bounds allocations on corrupt shapes.
    file_len: u64,
}

impl Reader<'_> {
    fn hdf5_err(&self, context: String) -> impl FnOnce(hdf5::Error) -> CheckpointError + '_ {
        move |e| CheckpointError::hdf5(self.path, context, e)
    }

    fn corrupt(&self, reason: String) -> CheckpointError {
        CheckpointError::corrupt(self.path, reason)
    }

    /// Fails unless `actual` is exactly the type `T` is written as.
    fn check_type<T: H5Type>(&self, actual: &Datatype, what: &str) -> Result<(), CheckpointError> {
        let expected = Datatype::from_type::<T>().map_err(self.hdf5_err(format!("building the type of {what}")))?;
        if *actual == expected {
            Ok(())
        } else {
            Err(self.corrupt(format!("{what} has type {actual:?}, expected {expected:?}")))
        }
    }

    /// Opens root attribute `name` after checking that it exists and has type `T` and rank `rank`.
    fn attr<T: H5Type>(&self, name: &str, rank: usize) -> Result<(hdf5::Attribute, Vec<usize>), CheckpointError> {
        let what = format!("root attribute {name}");
        let names = self
            .file
            .attr_names()
            .map_err(self.hdf5_err("listing the root attributes".to_string()))?;
        if !names.iter().any(|n| n == name) {
            return Err(self.corrupt(format!("missing {what}")));
        }
        let attr = self.file.attr(name).map_err(self.hdf5_err(format!("opening {what}")))?;
        let dtype = attr
            .dtype()
            .map_err(self.hdf5_err(format!("reading the type of {what}")))?;
        self.check_type::<T>(&dtype, &what)?;
        let shape = attr
            .get_shape()
            .map_err(self.hdf5_err(format!("reading the shape of {what}")))?;
        if shape.len() != rank {
            return Err(self.corrupt(format!("{what} has shape {shape:?}, expected rank {rank}")));
        }
        Ok((attr, shape))
    }

    fn scalar_attr<T: H5Type>(&self, name: &str) -> Result<T, CheckpointError> {
        let (attr, _) = self.attr::<T>(name, 0)?;
        attr.read_scalar::<T>()
            .map_err(self.hdf5_err(format!("reading root attribute {name}")))
    }

    fn utf8(&self, name: &str, v: &VarLenUnicode) -> Result<String, CheckpointError> {
        String::from_utf8(v.as_bytes().to_vec())
            .map_err(|_| self.corrupt(format!("root attribute {name} is not valid UTF-8")))
    }

    fn str_attr(&self, name: &str) -> Result<String, CheckpointError> {
        let v = self.scalar_attr::<VarLenUnicode>(name)?;
        self.utf8(name, &v)
    }

    fn str_list_attr(&self, name: &str) -> Result<Vec<String>, CheckpointError> {
        let (attr, shape) = self.attr::<VarLenUnicode>(name, 1)?;
        if shape[0] == 0 {
            return Ok(Vec::new());
        }
        let values = attr
            .read_raw::<VarLenUnicode>()
            .map_err(self.hdf5_err(format!("reading root attribute {name}")))?;
        values.iter().map(|v| self.utf8(name, v)).collect()
    }
}

impl VisitorMut for Reader<'_> {
    type Error = CheckpointError;

    fn visit<T: Element>(&mut self, spec: &DatasetSpec, data: &mut Vec<T>) -> Result<(), CheckpointError> {
        let what = format!("dataset /{}", spec.path);
        if !self.file.link_exists(spec.path) {
            return Err(self.corrupt(format!("missing {what}")));
        }
        let ds = self
            .file
            .dataset(spec.path)
            .map_err(self.hdf5_err(format!("opening {what}")))?;
        let dtype = ds
            .dtype()
            .map_err(self.hdf5_err(format!("reading the type of {what}")))?;
        self.check_type::<T>(&dtype, &what)?;
        let shape = ds
            .get_shape()
            .map_err(self.hdf5_err(format!("reading the shape of {what}")))?;
        let shape_ok = match (spec.rows, shape.as_slice()) {
            (Rows::Scalar, []) => true,
            (Rows::Fixed(n), [m]) => *m == n,
            (Rows::Scalar | Rows::Fixed(_), _) => false,
            (_, [_]) => spec.width == 1,
            (_, [_, w]) => spec.width > 1 && *w == spec.width,
            _ => false,
        };
        if !shape_ok {
            return Err(self.corrupt(format!("{what} has shape {shape:?}, expected {}", expected_shape(spec))));
        }
        let len = shape.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d));
        let bytes = len.and_then(|n| n.checked_mul(std::mem::size_of::<T>()));
        let len = match (len, bytes) {
            (Some(len), Some(bytes)) if bytes as u64 <= self.file_len => len,
            _ => {
                return Err(self.corrupt(format!(
                    "{what} has shape {shape:?}, larger than the file ({} bytes)",
                    self.file_len
                )));
            }
        };
        // The element type was checked equal above, so reading converts nothing.
        let reader = ds.as_reader();
        let context = format!("reading {what}");
        *data = if spec.rows == Rows::Scalar {
            vec![reader.read_scalar::<T>().map_err(self.hdf5_err(context))?]
        } else if len == 0 {
            Vec::new()
        } else {
            reader.read_raw::<T>().map_err(self.hdf5_err(context))?
        };
        if data.len() != len {
            return Err(self.corrupt(format!("{what} read {} elements, expected {len}", data.len())));
        }
        Ok(())
    }
}

/// The expected shape of a dataset, for error messages, e.g. `[N, 3]`.
fn expected_shape(spec: &DatasetSpec) -> String {
    let rows = match spec.rows {
        Rows::Particles => "N".to_string(),
        Rows::PairContacts => "pair contacts".to_string(),
        Rows::WallContacts => "wall contacts".to_string(),
        Rows::Walls => "walls".to_string(),
        Rows::Fixed(n) => n.to_string(),
        Rows::Scalar => return "scalar".to_string(),
        Rows::GasCells => "gas cells".to_string(),
        Rows::GasFaces(a) => format!("gas faces normal to axis {a}"),
        Rows::GasScalar => "0 or 1".to_string(),
        Rows::NetForce => "0 or 1".to_string(),
        Rows::NetForceWalls => "0 or walls".to_string(),
        Rows::ParticlesIfRecorded => "0 or N".to_string(),
        Rows::GasCellsIfHeat => "0 or gas cells".to_string(),
        Rows::GasScalarIfHeat => "0 or 1".to_string(),
        Rows::GasCellsIfDrying => "0 or gas cells".to_string(),
        Rows::GasScalarIfDrying => "0 or 1".to_string(),
        Rows::ScalarIfHeat => "0 or 1".to_string(),
    };
    if spec.width == 1 {
        format!("[{rows}]")
    } else {
        format!("[{rows}, {}]", spec.width)
    }
}

#[cfg(test)]
mod tests;
