//! The messages a worker sends its dispatcher: one JSON object per line on the worker's stdout, each carrying the
//! protocol version `v`. Everything else a worker has to say goes to stderr (kept in the job's `worker.log`).
//!
//! The worker's exit code tells how it ended (see the `EXIT_*` constants here and in `error.rs`); the dispatcher
//! trusts `result.json`, not messages, to decide that a job is done.

use serde::{Deserialize, Serialize};

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
        class: String,
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

#[cfg(test)]
mod tests {
    use super::*;

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
