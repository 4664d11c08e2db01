//! Running a campaign: the dispatcher (the only database writer), the protocol its workers speak, progress display
//! and the campaign log.

pub mod dispatcher;
mod log;
mod progress;
pub mod protocol;
