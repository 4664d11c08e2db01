//! [`FailureClass`]: why an attempt at a job ended without a result. The worker names the class of its own errors,
//! the dispatcher the class of an exit or of a stop it caused; the class is stored with the attempt
//! (`jobs.exit_class`, `attempts.exit_class`), carried by the worker's `failed` message, and chooses the retry
//! budget.
//!
//! What does not live here: which class an exit code or an error is (`crate::worker::protocol`, `crate::worker`)
//! and what happens after each class (the dispatcher's retry policy).

use std::fmt;

use rusqlite::ToSql;
use rusqlite::types::{FromSql, FromSqlError, FromSqlResult, ToSqlOutput, ValueRef};
use serde::{Deserialize, Serialize};

/// Why an attempt ended without a result. Stored, and sent in worker messages, as the lowercase name of
/// [`FailureClass::as_str`]; those names are part of the database and of the worker protocol, and never change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureClass {
    /// The job's configuration is invalid (found by the worker); never retried.
    Config,
    /// Non-finite values, excessive overlap or a lost particle.
    Numerical,
    /// The worker failed otherwise (I/O, an unreadable checkpoint, a panic, an unknown exit code).
    Crash,
    /// The worker was killed by a signal it did not handle (`kill -9`, out of memory), or stopped because its
    /// dispatcher went away.
    Killed,
    /// The job ran longer than the executor's `job_timeout_s`; the dispatcher asked it to checkpoint and stop.
    Timeout,
    /// The worker sent no heartbeat for `heartbeat_timeout_s`; the dispatcher killed it.
    Lost,
    /// The worker checkpointed and stopped on a signal that did not come from the dispatcher.
    Preempted,
    /// The dispatcher was interrupted (Ctrl-C, SIGTERM) and asked its workers to checkpoint and stop.
    Interrupted,
    /// Another worker holds the job directory's lock.
    Locked,
}

impl FailureClass {
    /// Every class.
    pub const ALL: [FailureClass; 9] = [
        FailureClass::Config,
        FailureClass::Numerical,
        FailureClass::Crash,
        FailureClass::Killed,
        FailureClass::Timeout,
        FailureClass::Lost,
        FailureClass::Preempted,
        FailureClass::Interrupted,
        FailureClass::Locked,
    ];

    /// The name stored in the database, sent in worker messages and shown to users.
    pub fn as_str(self) -> &'static str {
        match self {
            FailureClass::Config => "config",
            FailureClass::Numerical => "numerical",
            FailureClass::Crash => "crash",
            FailureClass::Killed => "killed",
            FailureClass::Timeout => "timeout",
            FailureClass::Lost => "lost",
            FailureClass::Preempted => "preempted",
            FailureClass::Interrupted => "interrupted",
            FailureClass::Locked => "locked",
        }
    }

    /// The class named `name`, as stored by [`FailureClass::as_str`].
    pub fn from_name(name: &str) -> Option<FailureClass> {
        FailureClass::ALL.into_iter().find(|class| class.as_str() == name)
    }
}

impl fmt::Display for FailureClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl ToSql for FailureClass {
    fn to_sql(&self) -> rusqlite::Result<ToSqlOutput<'_>> {
        Ok(ToSqlOutput::from(self.as_str()))
    }
}

impl FromSql for FailureClass {
    fn column_result(value: ValueRef<'_>) -> FromSqlResult<Self> {
        let name = value.as_str()?;
        FailureClass::from_name(name)
            .ok_or_else(|| FromSqlError::Other(format!("unknown failure class `{name}`").into()))
    }
}

#[cfg(test)]
mod tests {
    use super::FailureClass;

    /// The stored names, exactly as every earlier granflow wrote them.
    #[test]
    fn every_class_round_trips_through_its_name() {
        let names: Vec<&str> = FailureClass::ALL.iter().map(|c| c.as_str()).collect();
        assert_eq!(
            names,
            [
                "config",
                "numerical",
                "crash",
                "killed",
                "timeout",
                "lost",
                "preempted",
                "interrupted",
                "locked"
            ]
        );
        for class in FailureClass::ALL {
            assert_eq!(FailureClass::from_name(class.as_str()), Some(class));
            assert_eq!(class.to_string(), class.as_str());
            let json = serde_json::to_string(&class).unwrap();
            assert_eq!(json, format!("\"{}\"", class.as_str()));
            assert_eq!(serde_json::from_str::<FailureClass>(&json).unwrap(), class);
        }
        assert_eq!(FailureClass::from_name("Numerical"), None);
        assert_eq!(FailureClass::from_name("unknown"), None);
    }

    #[test]
    fn every_class_round_trips_through_sqlite() {
        let conn = rusqlite::Connection::open_in_memory().unwrap();
        for class in FailureClass::ALL {
            let (text, back): (String, FailureClass) = conn
                .query_row("SELECT ?1, ?1", [class], |row| Ok((row.get(0)?, row.get(1)?)))
                .unwrap();
            assert_eq!((text.as_str(), back), (class.as_str(), class));
        }
        let err = conn
            .query_row("SELECT 'fried'", [], |row| row.get::<_, FailureClass>(0))
            .unwrap_err();
        assert!(err.to_string().contains("unknown failure class `fried`"), "{err}");
    }
}
