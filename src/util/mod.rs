//! Small helpers that know nothing about particles, scenarios or campaigns, shared by the modules that do:
//! `atomic_file` (writing a file so that a reader sees the old content or the new, never a part) and `did_you_mean`
//! (the closest known name to a misspelt one, for error messages).
//!
//! What does not live here: anything with a physical unit, a file format of granflow's own (those live with the
//! module that owns the format), or the layout of a campaign directory (`crate::campaign_dir`).

pub mod atomic_file;
pub mod did_you_mean;

pub use atomic_file::{AtomicWriteError, write_atomic};
pub use did_you_mean::did_you_mean;
