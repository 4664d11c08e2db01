//! The engine's run configuration: everything about a simulation that does not change while it runs, in SI units
//! and engine types (built from the scenario by `scenario/build.rs`, which owns every unit conversion). The driver
//! (`simulation.rs`) holds it behind an `Arc`; kernels read the parts they need.

use super::channels::ChannelGroups;
use super::cohesion::Cohesion;
use super::geometry::{Domain, Gravity, Wall};
use super::heat::HeatConfig;
use super::models::history::HistoryLayout;
use super::models::{ContactLaw, PairTable};
use super::neighbor::Reach;
use super::particles::SpeciesTable;

/// Everything about a simulation that does not change while it runs.
#[derive(Debug, Clone)]
pub struct SimConfig {
    pub domain: Domain,
    /// One particle layer moving in x–y only (seeds' 2-D beds and kilns): z velocity, z force and x/y rotation are
    /// held at zero.
    pub pseudo_2d: bool,
    /// Particles rotate; `false`: their angular velocities are never updated (inverse moments of inertia zero).
    pub rotation: bool,
    pub gravity: Gravity,
    pub species: SpeciesTable,
    pub pair_table: PairTable,
    pub contact_law: ContactLaw,
    pub walls: Vec<Wall>,
    /// Neighbour-list skin: candidates are pairs whose surfaces are closer than this.
    pub skin_m: f64,
    /// Skin of the force pass's own list when smaller than `skin_m` (the two-level scheme): that list is refiltered
    /// from the candidates within `skin_m` whenever a particle has moved half of it, and the cells are searched
    /// again only when the candidates themselves may be incomplete. Equal to `skin_m`: one level.
    pub inner_skin_m: f64,
    /// The inner skin was not chosen by the scenario: use two levels only after cell searches where it halves the
    /// force pass's candidates (otherwise one level until the next search).
    pub inner_skin_auto: bool,
    /// Sort the particles by place after every step whose number is a multiple of this (`engine::particle_order`);
    /// `None`: never (the particles keep the order they were filled in).
    pub sort_every_steps: Option<u64>,
    /// Largest tolerated overlap as a fraction of the smaller radius; beyond it the step fails.
    pub max_overlap_fraction: f64,
    /// Forces at a distance (liquid bridges, van der Waals, square well); `None`: dry, cohesionless particles.
    pub cohesion: Option<Cohesion>,
    /// Record each contact's duration and the particles' contact statistics (`engine::channels`;
    /// `output.contact_statistics`).
    pub contact_statistics: bool,
    /// Heat transfer (particle temperatures, conduction); `None`: no temperatures.
    pub heat: Option<HeatConfig>,
}

impl SimConfig {
    /// The history columns the run's models use: the contact law's, the cohesion slot's when there is a cohesion
    /// model, and the duration slot's when the run records contact statistics.
    pub fn history_layout(&self) -> HistoryLayout {
        HistoryLayout {
            cohesion: self.cohesion.is_some(),
            contact_duration: self.contact_statistics,
            ..self.contact_law.history_layout()
        }
    }

    /// The scalar channel groups the run records.
    pub fn channel_groups(&self) -> ChannelGroups {
        ChannelGroups {
            statistics: self.contact_statistics,
            heat: self.heat.is_some(),
        }
    }

    /// How far beyond contact the neighbour list must reach for the cohesion model and the gas lens's conduction.
    pub fn reach(&self) -> Reach {
        let cohesion = self.cohesion.as_ref().map_or(Reach::default(), |c| Reach {
            pair_gap_m: c.range_m,
            wall_gap_m: c.wall_range_m,
        });
        let lens = self.heat.as_ref().map_or(0.0, |h| h.lens_reach_m);
        Reach {
            pair_gap_m: cohesion.pair_gap_m.max(lens),
            wall_gap_m: cohesion.wall_gap_m.max(lens),
        }
    }
}
