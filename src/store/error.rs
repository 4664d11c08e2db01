//! [`StoreError`]: every way opening, migrating, writing or querying the results database can fail.
//!
//! Each variant names the database file, so that a message read on its own (in a log line, after "failed to") says
//! which campaign it is about. Messages are lowercase fragments. Unknown parameter and metric names list the names
//! that do exist, so that a typo in `granflow query` is fixed without a second command.

use std::fmt::Display;
use std::path::{Path, PathBuf};

/// A results-database operation failed.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// SQLite reported an error (unreadable or locked file, constraint violation, malformed SQL, ...).
    #[error("sqlite error on results database {path} while {action}: {source}")]
    Sqlite {
        path: PathBuf,
        /// What was being done, e.g. "finishing job 3f2a..." or "applying migration 1".
        action: String,
        #[source]
        source: rusqlite::Error,
    },
    /// `open_read_only` was given a file that does not exist (a read-only open never creates one).
    #[error("results database {path} does not exist")]
    NotFound { path: PathBuf },
    /// The file was written by a newer granflow whose schema this build does not know.
    #[error(
        "results database {path} has schema version {found}, newer than version {supported} known to this build of \
         granflow; use a newer granflow to open it"
    )]
    TooNew { path: PathBuf, found: i64, supported: i64 },
    /// A read-only open found a database that needs migrating (or that is not a granflow database at all).
    #[error(
        "results database {path} has schema version {found}, this build needs version {expected}; {}",
        if *found == 0 { "it is not a granflow results database" } else { "open it read-write once to migrate it" }
    )]
    NeedsMigration { path: PathBuf, found: i64, expected: i64 },
    /// SQLite kept another journal mode (WAL needs shared memory, which some network filesystems lack).
    #[error("results database {path} cannot use WAL mode (journal_mode stayed `{mode}`); put it on a local filesystem")]
    WalUnavailable { path: PathBuf, mode: String },
    #[error("results database {path} has no campaign with id {campaign_id}")]
    UnknownCampaign { path: PathBuf, campaign_id: i64 },
    #[error("results database {path} has no job {job_id}")]
    UnknownJob { path: PathBuf, job_id: String },
    /// A job id is already stored under another campaign; job ids identify jobs across the whole database.
    #[error(
        "results database {path} already holds job {job_id} in campaign {existing_campaign_id}, cannot add it to \
         campaign {campaign_id}"
    )]
    JobInOtherCampaign {
        path: PathBuf,
        job_id: String,
        campaign_id: i64,
        existing_campaign_id: i64,
    },
    /// A job result or a new job is malformed (duplicate metric names, negative timings, ...); nothing was written.
    #[error("refusing to store job {job_id} in results database {path}: {reason}")]
    InvalidJobData {
        path: PathBuf,
        job_id: String,
        reason: String,
    },
    #[error(
        "campaign {campaign_id} in results database {path} has no parameter `{name}`; available parameters: {}",
        list_or_none(available, "none")
    )]
    UnknownParameter {
        path: PathBuf,
        campaign_id: i64,
        name: String,
        available: Vec<String>,
    },
    #[error(
        "campaign {campaign_id} in results database {path} has no metric `{name}`; available metrics: {}",
        list_or_none(available, "none (no job has finished yet)")
    )]
    UnknownMetric {
        path: PathBuf,
        campaign_id: i64,
        name: String,
        available: Vec<String>,
    },
    /// The jobs of a campaign report one metric in several units, so averaging them would be meaningless.
    #[error("metric `{name}` has several units in results database {path}: {}", units.join(", "))]
    MixedUnits {
        path: PathBuf,
        name: String,
        units: Vec<String>,
    },
    /// A pivot or query request is malformed (same parameter on both axes, several statements, ...).
    #[error("invalid query on results database {path}: {reason}")]
    InvalidQuery { path: PathBuf, reason: String },
    /// A query tried to modify the database; queries run on a read-only connection.
    #[error("refusing to run `{sql}` on results database {path}: queries are read-only (SELECT, WITH, EXPLAIN)")]
    WriteInQuery { path: PathBuf, sql: String },
}

impl StoreError {
    /// The database file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            StoreError::Sqlite { path, .. }
            | StoreError::NotFound { path }
            | StoreError::TooNew { path, .. }
            | StoreError::NeedsMigration { path, .. }
            | StoreError::WalUnavailable { path, .. }
            | StoreError::UnknownCampaign { path, .. }
            | StoreError::UnknownJob { path, .. }
            | StoreError::JobInOtherCampaign { path, .. }
            | StoreError::InvalidJobData { path, .. }
            | StoreError::UnknownParameter { path, .. }
            | StoreError::UnknownMetric { path, .. }
            | StoreError::MixedUnits { path, .. }
            | StoreError::InvalidQuery { path, .. }
            | StoreError::WriteInQuery { path, .. } => path,
        }
    }

    pub(crate) fn sqlite(path: &Path, action: impl Display, source: rusqlite::Error) -> Self {
        StoreError::Sqlite {
            path: path.to_path_buf(),
            action: action.to_string(),
            source,
        }
    }
}

fn list_or_none(names: &[String], none: &str) -> String {
    if names.is_empty() {
        none.to_string()
    } else {
        names.join(", ")
    }
}

/// Attaches the database path and the action to a rusqlite error: `conn.execute(..).context(path, "marking ...")?`.
pub(crate) trait Context<T> {
    fn context(self, path: &Path, action: impl Display) -> Result<T, StoreError>;
}

impl<T> Context<T> for rusqlite::Result<T> {
    fn context(self, path: &Path, action: impl Display) -> Result<T, StoreError> {
        self.map_err(|source| StoreError::sqlite(path, action, source))
    }
}
