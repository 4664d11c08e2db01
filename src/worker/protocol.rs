//! The messages a worker sends its dispatcher: one JSON object per line on the worker's stdout, each carrying the
//! protocol version `v`. Everything else a worker has to say goes to stderr (kept in the job's `worker.log`).
//!
//! The worker's exit code tells how it ended (see the `EXIT_*` constants here and in `error.rs`, and
//! [`exit_class`]); the dispatcher trusts `result.json`, not messages, to decide that a job is done. The protocol
//! lives with the worker, which speaks it; the dispatcher (`crate::orchestrate`) listens.

use serde::{Deserialize, Serialize};

use crate::error::{EXIT_CONFIG, EXIT_IO, EXIT_NUMERICAL};
use crate::store::FailureClass;

/// Version of the message format; a dispatcher ignores lines of another version.
pub const PROTOCOL_VERSION: u32 = 1;

/// The worker stopped on request (SIGTERM/SIGINT) after writing a checkpoint; the job should be requeued.
pub const EXIT_PREEMPTED: i32 = 10;
/// Another worker holds the job directory's lock.
pub const EXIT_LOCKED: i32 = 11;
/// The dispatcher went away (the worker's stdin closed); the worker stopped at once.
pub const EXIT_ORPHANED: i32 = 12;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    Started {
        job_id: String,
        step: u64,
        total_steps: u64,
        resumed_from_step: Option<u64>,
        pid: u32,
    },
    Progress {
        step: u64,
        total_steps: u64,
        time_s: f64,
        steps_per_s: f64,
    },
    Checkpointed {
        step: u64,
    },
    Finished {
        wall_time_s: f64,
    },
    Stopped {
        step: u64,
    },
    Failed {
        /// Serialised as [`FailureClass::as_str`] (`"numerical"`), as in every version-1 message.
        class: FailureClass,
        error: String,
    },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Message {
    pub v: u32,
    #[serde(flatten)]
    pub event: Event,
}

impl Message {
    pub fn new(event: Event) -> Self {
        Message {
            v: PROTOCOL_VERSION,
            event,
        }
    }

    pub fn to_line(&self) -> String {
        serde_json::to_string(self).expect("messages serialise")
    }

    /// Parses one line; `None` for lines that are not messages of this protocol version.
    pub fn parse(line: &str) -> Option<Message> {
        serde_json::from_str::<Message>(line)
            .ok()
            .filter(|m| m.v == PROTOCOL_VERSION)
    }
}

/// Exit code → failure class, for a worker that ended without a result (`None`: killed by a signal).
pub fn exit_class(code: Option<i32>) -> FailureClass {
    match code {
        Some(EXIT_CONFIG) => FailureClass::Config,
        Some(EXIT_NUMERICAL) => FailureClass::Numerical,
        Some(EXIT_PREEMPTED) => FailureClass::Preempted,
        Some(EXIT_LOCKED) => FailureClass::Locked,
        Some(EXIT_ORPHANED) => FailureClass::Killed,
        Some(EXIT_IO) => FailureClass::Crash,
        Some(_) => FailureClass::Crash,
        None => FailureClass::Killed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `failed` message reads as it did when its class was a string: no protocol version bump.
    #[test]
    fn a_failed_message_carries_the_class_name() {
        let line = Message::new(Event::Failed {
            class: FailureClass::Numerical,
            error: "non-finite velocity".into(),
        })
        .to_line();
        assert_eq!(
            line,
            r#"{"v":1,"event":"failed","class":"numerical","error":"non-finite velocity"}"#
        );
        for class in FailureClass::ALL {
            let line = format!(r#"{{"v":1,"event":"failed","class":"{}","error":""}}"#, class.as_str());
            assert_eq!(
                Message::parse(&line).map(|m| m.event),
                Some(Event::Failed {
                    class,
                    error: String::new()
                })
            );
        }
    }

    #[test]
    fn exit_codes_map_to_classes() {
        assert_eq!(exit_class(None), FailureClass::Killed);
        assert_eq!(exit_class(Some(EXIT_CONFIG)), FailureClass::Config);
        assert_eq!(exit_class(Some(EXIT_NUMERICAL)), FailureClass::Numerical);
        assert_eq!(exit_class(Some(EXIT_PREEMPTED)), FailureClass::Preempted);
        assert_eq!(exit_class(Some(EXIT_LOCKED)), FailureClass::Locked);
        assert_eq!(exit_class(Some(EXIT_ORPHANED)), FailureClass::Killed);
        assert_eq!(exit_class(Some(EXIT_IO)), FailureClass::Crash);
        assert_eq!(exit_class(Some(101)), FailureClass::Crash);
    }

    #[test]
    fn messages_round_trip_and_other_versions_are_ignored() {
        let m = Message::new(Event::Progress {
            step: 10,
            total_steps: 100,
            time_s: 1e-3,
            steps_per_s: 5.0,
        });
        let line = m.to_line();
        assert!(
            line.contains("\"v\":1") && line.contains("\"event\":\"progress\""),
            "{line}"
        );
        assert_eq!(Message::parse(&line), Some(m));
        assert_eq!(Message::parse(&line.replace("\"v\":1", "\"v\":2")), None);
        assert_eq!(Message::parse("warning: something"), None);
    }
}
