//! The heated drum of a run (a rotating cylinder wall held at a temperature: a kiln) and the series columns it gets
//! for the wall heat transfer coefficient h_w (seed 000 §5.2.4): the bed's core and inner-core temperatures, the
//! arc of wall the bed touches and the gas's mean temperature. The reducer (`worker`'s `reduce.rs`) fits h_w from
//! them with [`crate::analysis::wall_heat`].

use crate::analysis::wall_heat::{DrumAxis, bed_core, wall_contact_arc_rad};
use crate::engine::Simulation;
use crate::engine::config::SimConfig;
use crate::engine::geometry::WallShape;

/// A drum whose wall is held at a temperature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatedDrum {
    /// Its index among the walls.
    pub wall: usize,
    pub axis: DrumAxis,
    /// T_w, K.
    pub temperature_k: f64,
    /// The wall heats from this time, s.
    pub heated_from_s: f64,
    /// The radius of the beads glued to it (`walls[].drum.glued_beads`), m; 0 for a smooth wall.
    pub bead_radius_m: f64,
    /// |ω|, rad/s.
    pub angular_speed_rad_per_s: f64,
    /// L: the domain's extent along the axis (the drum slice's length), m; NaN when the axis is not along one of
    /// the domain's axes.
    pub length_m: f64,
}

/// The run's heated drum: the one rotating-cylinder wall with a temperature (`None` with none or several, or
/// without heat transfer).
pub fn heated_drum(config: &SimConfig) -> Option<HeatedDrum> {
    let heat = config.heat.as_ref()?;
    let mut drums = config.walls.iter().enumerate().filter_map(|(w, wall)| {
        let WallShape::RotatingCylinder { frame, radius_m } = wall.shape() else {
            return None;
        };
        let temperature_k = heat.wall_temperature_k[w]?;
        let axis = frame.axis.normalize();
        let along = (0..3).find(|&k| (axis[k].abs() - 1.0).abs() < 1e-12);
        Some(HeatedDrum {
            wall: w,
            axis: DrumAxis {
                axis_point_m: frame.axis_point_m,
                axis,
                radius_m: *radius_m,
            },
            temperature_k,
            heated_from_s: heat.wall_heated_from_s[w],
            bead_radius_m: config
                .walls
                .iter()
                .filter(|other| other.glued_to.as_deref() == Some(wall.name.as_str()))
                .filter_map(|other| other.bead_radius_m())
                .fold(0.0, f64::max),
            angular_speed_rad_per_s: frame.angular_velocity_rad_per_s.abs(),
            length_m: along.map_or(f64::NAN, |k| config.domain.hi_m[k] - config.domain.lo_m[k]),
        })
    });
    let drum = drums.next()?;
    drums.next().is_none().then_some(drum)
}

/// The series columns of a run with a heated drum: the mass-weighted mean temperature of the bed's core (the disc
/// of `heat.bed_core_radius_fraction`, [`bed_core`]) and of its inner core (half that radius), K (`nan` when
/// empty); the particles in the core; the arc of wall the bed touches ([`wall_contact_arc_rad`]), rad; and the
/// gas's mass-weighted mean temperature, K (`nan` without a gas).
pub const DRUM_HEAT_COLUMNS: &str =
    ",core_temperature_k,inner_core_temperature_k,core_particles,drum_contact_arc_rad,gas_mean_temperature_k";

/// The [`DRUM_HEAT_COLUMNS`] of the current state.
pub fn drum_heat_columns(sim: &Simulation, drum: &HeatedDrum, core_radius_fraction: f64) -> String {
    let p = &sim.particles;
    let core = bed_core(
        &drum.axis,
        &p.position_m,
        &p.mass_kg,
        &p.temperature_k,
        core_radius_fraction,
    );
    let inner = bed_core(
        &drum.axis,
        &p.position_m,
        &p.mass_kg,
        &p.temperature_k,
        0.5 * core_radius_fraction,
    );
    let arc = wall_contact_arc_rad(&drum.axis, &p.position_m, &p.radius_m, drum.bead_radius_m);
    let gas = sim
        .gas
        .as_ref()
        .and_then(|g| g.mean_temperature_k())
        .unwrap_or(f64::NAN);
    format!(
        ",{:e},{:e},{},{arc:e},{gas:e}",
        core.temperature_k, inner.temperature_k, core.particles
    )
}
