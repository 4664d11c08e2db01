//! [`CheckpointError`]: every way reading or writing a checkpoint can fail.
//!
//! Each variant names the checkpoint file involved, so that a message read on its own (e.g. in the list of rejected
//! checkpoints of [`super::LoadedCheckpoint`]) says which file it is about. Messages are lowercase fragments.

use std::path::{Path, PathBuf};

/// A checkpoint could not be written, or a checkpoint file could not be read or failed verification.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The HDF5 library reported an error (unreadable or truncated file, missing permissions, ...).
    #[error("hdf5 error on checkpoint {path} while {context}: {source}")]
    Hdf5 {
        path: PathBuf,
        /// What was being done, e.g. "opening the file" or "reading /particles/position_m".
        context: String,
        #[source]
        source: hdf5::Error,
    },
    /// The file is readable HDF5 but its content fails verification (checksum, shapes, types, values).
    #[error("checkpoint {path} is corrupt: {reason}")]
    Corrupt { path: PathBuf, reason: String },
    /// The file was written with a different checkpoint format version.
    #[error("checkpoint {path} has format version {found}, this build reads version {expected}")]
    Version { path: PathBuf, found: u32, expected: u32 },
    /// A file-system operation (fsync, rename, directory listing, removal) failed.
    #[error("i/o error on checkpoint {path} while {action}: {source}")]
    Io {
        path: PathBuf,
        /// What was being done, e.g. "renaming the temporary file into place".
        action: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// The state handed to the writer is inconsistent (array lengths differ, a contact names a missing particle or
    /// wall); nothing was written, since the file could not be read back.
    #[error("refusing to write checkpoint {path}: inconsistent state: {reason}")]
    InvalidState { path: PathBuf, reason: String },
}

impl CheckpointError {
    /// The checkpoint file (or, for directory listings, the directory) the error is about.
    pub fn path(&self) -> &Path {
        match self {
            CheckpointError::Hdf5 { path, .. }
            | CheckpointError::Corrupt { path, .. }
            | CheckpointError::Version { path, .. }
            | CheckpointError::Io { path, .. }
            | CheckpointError::InvalidState { path, .. } => path,
        }
    }

    pub(crate) fn hdf5(path: &Path, context: impl Into<String>, source: hdf5::Error) -> Self {
        CheckpointError::Hdf5 {
            path: path.to_path_buf(),
            context: context.into(),
            source,
        }
    }

    pub(crate) fn corrupt(path: &Path, reason: impl Into<String>) -> Self {
        CheckpointError::Corrupt {
            path: path.to_path_buf(),
            reason: reason.into(),
        }
    }

    pub(crate) fn io(path: &Path, action: &'static str, source: std::io::Error) -> Self {
        CheckpointError::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    }
}
