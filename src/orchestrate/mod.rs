//! Running a campaign: the dispatcher (the only database writer), its Slurm executor (`slurm.rs`), progress display
//! and the campaign log.
//!
//! What does not live here: the protocol the workers speak (`crate::worker::protocol`), the campaign directory's
//! layout (`crate::campaign_dir`) and the database (`crate::store`).

pub mod dispatcher;
mod log;
mod progress;
pub mod slurm;
