//! Where particles live: the box and its periodic axes, gravity, and walls (planes, rotating drum, baffles).
//! Scenario builders that fill these with particles live in `crate::scenario`.

pub mod domain;
pub mod walls;

pub use domain::{Axis, Domain, Gravity, GravityFlip};
pub use walls::{RotatingFrame, Wall, WallProximity, WallShape, turns};
