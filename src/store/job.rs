//! The plain-data types of jobs as the store sees them: what goes in ([`NewJob`], [`JobResult`]), what comes out
//! ([`JobRow`]) and the closed vocabularies ([`JobStatus`], [`AfterFailure`], [`ParamValue`]).
//!
//! What does not live here: how job ids are computed, and the failure classes of `exit_class`
//! ([`FailureClass`](super::FailureClass), in its own file).

use std::cmp::Ordering;
use std::fmt;

use rusqlite::ToSql;
use rusqlite::types::{FromSql, FromSqlError, FromSqlResult, ToSqlOutput, ValueRef};

use super::render::{format_real, json_real};

/// Where a job is in its life. Stored as lowercase text (`jobs.status`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum JobStatus {
    /// Not started, or put back for a retry or after a dispatcher crash.
    Pending,
    /// A worker has been started for it.
    Running,
    /// Its result has been ingested.
    Done,
    /// Failed for good (no retry left, or a failure class that is never retried).
    Failed,
}

impl JobStatus {
    /// Every status, in life-cycle order.
    pub const ALL: [JobStatus; 4] = [
        JobStatus::Pending,
        JobStatus::Running,
        JobStatus::Done,
        JobStatus::Failed,
    ];

    /// The name stored in the database and shown to users.
    pub fn as_str(self) -> &'static str {
        match self {
            JobStatus::Pending => "pending",
            JobStatus::Running => "running",
            JobStatus::Done => "done",
            JobStatus::Failed => "failed",
        }
    }

    /// The status named `name`, as stored by [`JobStatus::as_str`].
    pub fn from_name(name: &str) -> Option<JobStatus> {
        JobStatus::ALL.into_iter().find(|status| status.as_str() == name)
    }
}

impl fmt::Display for JobStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl ToSql for JobStatus {
    fn to_sql(&self) -> rusqlite::Result<ToSqlOutput<'_>> {
        Ok(ToSqlOutput::from(self.as_str()))
    }
}

impl FromSql for JobStatus {
    fn column_result(value: ValueRef<'_>) -> FromSqlResult<Self> {
        let name = value.as_str()?;
        JobStatus::from_name(name).ok_or_else(|| FromSqlError::Other(format!("unknown job status `{name}`").into()))
    }
}

/// The value of one resolved parameter. Numbers (integers included) are `Real`; everything else (model names,
/// booleans, ...) is `Text`.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    Real(f64),
    Text(String),
}

impl ParamValue {
    /// The value as JSON (a number or a string).
    pub fn to_json(&self) -> serde_json::Value {
        match self {
            ParamValue::Real(value) => json_real(*value),
            ParamValue::Text(text) => serde_json::Value::String(text.clone()),
        }
    }

    /// Axis order for pivots: numbers first, numerically; then texts, lexicographically.
    pub fn axis_cmp(&self, other: &ParamValue) -> Ordering {
        match (self, other) {
            (ParamValue::Real(a), ParamValue::Real(b)) => a.total_cmp(b),
            (ParamValue::Text(a), ParamValue::Text(b)) => a.cmp(b),
            (ParamValue::Real(_), ParamValue::Text(_)) => Ordering::Less,
            (ParamValue::Text(_), ParamValue::Real(_)) => Ordering::Greater,
        }
    }

    /// The value stored in a `params` row (exactly one of the two columns is set, by a CHECK constraint).
    pub(crate) fn from_columns(real: Option<f64>, text: Option<String>) -> Option<ParamValue> {
        match (real, text) {
            (Some(value), _) => Some(ParamValue::Real(value)),
            (None, Some(text)) => Some(ParamValue::Text(text)),
            (None, None) => None,
        }
    }
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Real(value) => f.write_str(&format_real(*value)),
            ParamValue::Text(text) => f.write_str(text),
        }
    }
}

/// A job of the sweep, as [`Store::insert_jobs`](super::Store::insert_jobs) stores it.
#[derive(Debug, Clone, PartialEq)]
pub struct NewJob {
    /// Hash of the canonical resolved parameters.
    pub job_id: String,
    /// Position in the sweep.
    pub ordinal: i64,
    /// The resolved parameters as JSON.
    pub params_json: String,
    /// The same parameters flattened to (dotted name, value), for `params` (WHERE clauses, pivots, exports).
    pub params: Vec<(String, ParamValue)>,
}

/// One reduced metric of a job.
#[derive(Debug, Clone, PartialEq)]
pub struct Metric {
    pub name: String,
    /// SI value; NaN is stored as NULL.
    pub value: f64,
    /// SI unit, `""` for dimensionless.
    pub unit: String,
}

/// The outcome of a successful job (its `result.json`), ingested by [`Store::finish_job`](super::Store::finish_job).
#[derive(Debug, Clone, PartialEq)]
pub struct JobResult {
    pub metrics: Vec<Metric>,
    /// Wall-clock seconds per engine stage, as (stage, seconds).
    pub timings: Vec<(String, f64)>,
    pub sim_time_s: f64,
    pub wall_time_s: f64,
    pub steps: u64,
    /// Unix seconds.
    pub finished_at: f64,
    /// The build that finished the job (`result.json`'s `build`; empty when unknown).
    pub build: String,
}

/// What happens to a job after a failed attempt; the retry policy that chooses it lives with the dispatcher.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AfterFailure {
    /// Back to `pending`, to be started again.
    Retry,
    /// `failed` for good.
    Final,
}

/// One attempt of a job: when it started and ended, unix s (`ended_s` is `None` while it runs, or when the
/// dispatcher stopped before seeing its end).
#[derive(Debug, Clone, PartialEq)]
pub struct AttemptSpan {
    pub job_id: String,
    pub started_s: f64,
    pub ended_s: Option<f64>,
}

/// One job as stored, for status displays and reconciliation.
#[derive(Debug, Clone, PartialEq)]
pub struct JobRow {
    pub job_id: String,
    pub ordinal: i64,
    pub params_json: String,
    pub status: JobStatus,
    /// Current or last attempt; 0 = never started.
    pub attempt: u32,
    /// Why the last attempt ended without a result (cleared when the job starts again or finishes).
    pub exit_class: Option<super::FailureClass>,
    pub error: Option<String>,
    pub host: Option<String>,
    pub started_at: Option<f64>,
    pub finished_at: Option<f64>,
    pub last_heartbeat: Option<f64>,
    pub sim_time_s: Option<f64>,
    pub wall_time_s: Option<f64>,
    pub steps: Option<u64>,
    /// The Slurm array task of the current or last submission (`<array>_<index>`), and its state as last seen.
    pub slurm_task: Option<String>,
    pub slurm_state: Option<String>,
}
