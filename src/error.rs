//! The one error type of granflow and its mapping to process exit codes.
//!
//! Each subsystem has its own `thiserror` enum (scenario configuration, numerical failure, checkpoint I/O); this
//! module wraps them so that `main.rs` can map any failure to a documented exit code in one place. Messages are
//! lowercase fragments that read well after "failed to" and name the file, key, step or particle involved.

use std::path::PathBuf;

use crate::checkpoint::CheckpointError;
use crate::engine::NumericalError;
use crate::scenario::ConfigError;
use crate::store::StoreError;

/// Exit code for invalid input (configuration, YAML, CLI arguments), checked before anything is written.
pub const EXIT_CONFIG: i32 = 2;
/// Exit code for a numerical failure of the simulation (non-finite values, excessive overlap, lost particle).
pub const EXIT_NUMERICAL: i32 = 3;
/// Exit code for an unreadable, corrupt or unwritable checkpoint.
pub const EXIT_CHECKPOINT: i32 = 4;
/// Exit code for other I/O failures (the campaign store's among them) and failures of external programs (e.g.
/// LIGGGHTS in `bench`).
pub const EXIT_IO: i32 = 5;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error(transparent)]
    Numerical(#[from] NumericalError),
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// The campaign store (SQLite) could not be opened, read or written.
    #[error(transparent)]
    Store(#[from] StoreError),
    #[error("{action} {path}: {source}")]
    Io {
        action: &'static str,
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{0}")]
    External(String),
    /// A command used wrongly in a way clap cannot express.
    #[error("{0}")]
    Usage(String),
}

impl Error {
    /// The process exit code for this error (see the `EXIT_*` constants).
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Config(_) | Error::Usage(_) => EXIT_CONFIG,
            Error::Numerical(_) => EXIT_NUMERICAL,
            Error::Checkpoint(_) => EXIT_CHECKPOINT,
            Error::Io { .. } | Error::Store(_) | Error::External(_) => EXIT_IO,
        }
    }

    pub fn io(action: &'static str, path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            action,
            path: path.into(),
            source,
        }
    }
}

impl From<crate::util::AtomicWriteError> for Error {
    fn from(e: crate::util::AtomicWriteError) -> Self {
        Error::Io {
            action: e.action,
            path: e.path,
            source: e.source,
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    /// A store that cannot be opened is an I/O failure (exit 5), and its message still names the database file.
    #[test]
    fn a_store_error_exits_as_io_and_names_the_database() {
        let path = std::env::temp_dir()
            .join("granflow-no-such-dir")
            .join("campaign.sqlite");
        let e: Error = crate::store::Store::open_read_only(&path)
            .map(|_| ())
            .unwrap_err()
            .into();
        assert!(matches!(e, Error::Store(_)));
        assert_eq!(e.exit_code(), EXIT_IO);
        assert!(e.to_string().contains(&path.display().to_string()), "{e}");
    }
}
