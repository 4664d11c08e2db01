//! The gas phase: a finite-volume solver of the volume-averaged gas equations on a staggered grid (SIMPLE), with
//! its sparse linear solvers. Coupling to the particles (porosity, drag, two-way momentum exchange) builds on it.

pub mod coupled;
pub mod coupling;
pub mod exchange;
pub mod fluid_forces;
pub mod grid;
pub mod linsolve;
pub mod scalar;
pub mod simple;

pub use grid::{Boundary, Grid};
pub use simple::{Convection, GasConfig, GasSolver, GasState, StepReport};
