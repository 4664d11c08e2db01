//! The gas phase: a finite-volume solver of the volume-averaged gas equations on a staggered grid (SIMPLE), with
//! its sparse linear solvers. Coupling to the particles (porosity, drag, two-way momentum exchange) builds on it, and
//! scalars the gas carries (temperature, vapour) are transported with its flow and exchanged with the particles.

pub(crate) mod boundary_velocities;
pub mod coupled;
pub mod coupling;
pub mod exchange;
pub mod exchange_accumulator;
pub mod field;
pub mod fluid_forces;
pub mod grid;
pub mod heat;
pub mod held_drag;
pub mod linsolve;
pub(crate) mod momentum_rows;
pub mod piso;
pub(crate) mod pressure_sides;
pub mod scalar;
pub mod simple;
pub mod transported_scalar;

pub use exchange_accumulator::ExchangeAccumulator;
pub use field::{FieldLocation, GasField, GasFieldView};
pub use grid::{Boundary, Grid};
pub use piso::PressureVelocity;
pub use simple::{Convection, GasConfig, GasSolver, GasState, StepReport};
pub use transported_scalar::{GasScalarSpec, ScalarExchange, ScalarWall, TransportedScalar};
