//! Analysis: reducers that turn a job's particle states and time series into metrics.
//!
//! - `mixing`: intensity of segregation, Lacey index and RSD of a two-species bed (seed 000 eqs 2.77–2.80), and seed
//!   001's height-based mixing index.
//! - `fit`: the mixing rate constant from an exponential fit of IS(t) (seed 000 §4.1.3) and the time to a fraction
//!   of a series' maximum (seed 000 Table 1).
//! - `granular`: granular temperature (seed 000 eq 3.1) and coordination numbers (seed 002).
//! - `knn`: the exact k-nearest-neighbour search behind the local concentrations of `mixing`.
//! - `dimensionless`: the granular Bond and capillary numbers of wet particles, single and binary, and the wet phase
//!   rule (seed 000 §4).
//! - `escape_velocity`: the head-on escape velocity of a Hamaker pair and the Hamaker constant matching a square
//!   well (seed 001 ch. 7).
//! - `drying_curve`: the drying curve's times to 50 % and 90 % dried and its constant-rate period (seed 000 §7.3).
//! - `shear_profile`: the shear rate of a chute flow from its layer-averaged velocity profile and the critical flip
//!   frequency of seed 000's zig-zag chute (§3.2, eqs 3.4-3.5).
//! - `wall_heat`: the wall-to-bed heat transfer coefficient h_w of a heated drum, its core temperature and contact
//!   arc (seed 000 §5.2.4).
//!
//! Everything here is a pure function of values passed in: nothing reads checkpoints, the store or the engine's
//! state directly, and nothing here is called while a simulation steps.

pub mod dimensionless;
pub mod drying_curve;
pub mod escape_velocity;
pub mod fit;
pub mod fluidization;
pub mod granular;
pub mod knn;
pub mod mixing;
pub mod shear_profile;
pub mod wall_heat;

pub use fit::{ExponentialFit, fit_exponential_decay, time_to_fraction_of_max};
pub use granular::{GranularTemperature, granular_temperature, mean_coordination_number};
pub use mixing::{MixingState, above_median_height, height_mixing_index, mixing_state};
