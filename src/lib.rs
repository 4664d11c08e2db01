//! granflow: campaigns of coupled soft-sphere DEM + gas-phase simulations for particle-process engineering.
//!
//! This crate is the library behind the `granflow` binary. The engine (`engine`) knows nothing about campaigns;
//! `scenario` turns a YAML description of one simulation into the engine's configuration; `checkpoint` writes and
//! verifies complete HDF5 states; `simulate` and `bench` are the commands built on them. A campaign (`campaign`:
//! the file, its sweep, jobs and metrics) is run by the dispatcher (`orchestrate`) in worker processes (`worker`,
//! which also holds the protocol they speak), into a campaign directory (`campaign_dir`: its layout) whose database
//! is `store`; `inspect` and `report` read it. `util` holds helpers that know none of this (atomic file writes, the
//! closest name to a misspelt one).

pub mod analysis;
pub mod bench;
pub mod bench_campaign;
pub mod campaign;
pub mod campaign_dir;
pub mod checkpoint;
pub mod cli;
pub mod engine;
pub mod error;
pub mod heated_drum;
pub mod inspect;
pub mod machine;
mod models_doc;
pub mod orchestrate;
pub mod plot;
pub mod provenance;
pub mod report;
pub mod scenario;
pub mod simulate;
pub mod snapshot;
pub mod store;
pub mod units;
pub mod util;
pub mod worker;

pub use error::{Error, Result};
