//! The simulation engine: soft-sphere DEM with cohesion and liquid, coupled to the gas phase. It knows nothing about
//! campaigns; a [`Simulation`] is driven by `crate::simulate` (the `simulate` command and the workers).
//! `docs/ARCHITECTURE.md` maps its files and one time step through them.

pub mod channels;
pub mod cohesion;
pub mod config;
pub mod contacts;
pub mod drying;
pub mod error;
pub mod gas;
pub mod geometry;
pub mod heat;
pub mod heat_ledger;
pub mod integrate;
pub mod liquid;
pub mod models;
pub mod neighbor;
pub mod net_force;
pub mod pair_pass;
pub mod particle_order;
pub mod particles;
pub mod range_plan;
pub mod simulation;
pub mod spray;
pub mod state;
pub mod team;

/// Three-vector of f64 used everywhere in the engine.
pub type Vec3 = nalgebra::Vector3<f64>;

pub use error::NumericalError;
pub use simulation::{SimConfig, Simulation};
pub use state::SimState;
