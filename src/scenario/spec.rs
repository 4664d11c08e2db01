//! The scenario file as the user writes it (YAML, serde, unknown keys rejected). Units are SI with suffixes, except
//! the few non-SI conveniences (`rotation_rpm`, `tilt_deg`) that `build.rs` converts in one place.

use serde::{Deserialize, Serialize};

use crate::engine::geometry::Axis;
use crate::engine::models::ContactLaw;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    /// Required in a scenario file; in a campaign's `base` the campaign fills it in.
    #[serde(default)]
    pub name: String,
    pub domain: DomainSpec,
    /// One particle layer, motion in x–y only.
    #[serde(default)]
    pub pseudo_2d: bool,
    /// Whether particles rotate (default true). `false`: angular velocities are never updated, so friction resists
    /// sliding only and nothing rolls, as LIGGGHTS's `fix nve` does instead of `fix nve/sphere` (seed 001 uses
    /// rotation rates in its slip velocity, eq 6.23, but gives no rotation update).
    #[serde(default = "rotation_default", skip_serializing_if = "rotates")]
    pub rotation: bool,
    pub gravity: GravitySpec,
    pub species: Vec<SpeciesSpec>,
    pub contact: ContactLaw,
    #[serde(default)]
    pub walls: Vec<WallSpec>,
    pub fill: Vec<FillSpec>,
    pub time: TimeSpec,
    #[serde(default)]
    pub neighbor: NeighborSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// Seed of the random generator (random fills; later: spray).
    #[serde(default)]
    pub seed: u64,
    /// Largest tolerated overlap as a fraction of the smaller radius before the run fails as numerically unstable.
    #[serde(default = "default_max_overlap_fraction")]
    pub max_overlap_fraction: f64,
    /// A gas coupled to the particles (fluidized beds); absent: particles in vacuum.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gas: Option<super::gas::GasSpec>,
    /// Forces at a distance between particles: liquid bridges, Hamaker van der Waals or the square well; absent:
    /// dry, cohesionless particles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cohesion: Option<crate::engine::models::cohesion_law::CohesionModel>,
    /// Interactions the cohesion model is switched off for (seed 001 ch. 8's exclusion runs: no particle–particle,
    /// no particle–sidewall or no particle–distributor cohesion); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cohesion_off: Option<CohesionOff>,
}

/// A particle material as the scenario writes it (`build.rs` turns it into the engine's `Species`). Walls are
/// species too.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpeciesSpec {
    pub name: String,
    /// Nominal radius of particles created from this species (walls ignore it).
    pub radius_m: f64,
    pub density_kg_per_m3: f64,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    /// Coulomb sliding friction coefficient μ.
    pub friction_coefficient: f64,
    /// Thornton yield force F_y (seed 000 eq. 2.7; "essentially a fitting parameter"). Only the Thornton normal
    /// model reads it; `None` means the material never yields.
    #[serde(default)]
    pub yield_force_n: Option<f64>,
    /// Rolling-resistance coefficient μ_r for the optional rolling slot (dimensionless).
    #[serde(default)]
    pub rolling_friction_coefficient: f64,
    /// Reserved for heat transfer: solid conductivity and heat capacity.
    #[serde(default)]
    pub thermal_conductivity_w_per_m_k: Option<f64>,
    #[serde(default)]
    pub heat_capacity_j_per_kg_k: Option<f64>,
    /// Contact angle θ of the cohesion model's liquid on this material, degrees (liquid bridges; default 0).
    #[serde(default)]
    pub contact_angle_deg: f64,
    /// Liquid each particle of this species carries at the start, as V̂ = V/R³ (liquid bridges; seed 000 sprays
    /// up to 0.02; default 0: dry).
    #[serde(default)]
    pub liquid_content: f64,
}

/// Gravity as the scenario writes it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GravitySpec {
    pub vector_m_per_s2: [f64; 3],
    /// One component flips sign periodically (seed 000's zig-zag chute).
    #[serde(default)]
    pub flip: Option<GravityFlipSpec>,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GravityFlipSpec {
    /// The component that flips sign.
    pub axis: Axis,
    /// Flip frequency f: the component keeps its sign for 1/(2f), then reverses.
    pub frequency_hz: f64,
}

fn rotation_default() -> bool {
    true
}

fn rotates(rotation: &bool) -> bool {
    *rotation
}

/// What `cohesion_off` switches the cohesion model off for.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CohesionOff {
    /// No cohesion between particles (default false).
    #[serde(default)]
    pub between_particles: bool,
    /// Walls, by name (`box_x_lo` … `box_z_hi` for a box), that particles feel no cohesion from; the model must act
    /// on walls (its `walls: true`).
    #[serde(default)]
    pub walls: Vec<String>,
}

fn default_max_overlap_fraction() -> f64 {
    // CHOICE: 0.25 of the smaller radius. Soft-sphere results are meaningless well before this (typical
    // overlaps are 0.1–1 %), so reaching it means the time step or stiffness is wrong, not that the bed is dense.
    0.25
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DomainSpec {
    pub lo_m: [f64; 3],
    pub hi_m: [f64; 3],
    #[serde(default)]
    pub periodic: [bool; 3],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum WallSpec {
    /// Plane walls on the faces of the domain along every non-periodic axis.
    Box { species: String },
    Plane {
        name: String,
        species: String,
        point_m: [f64; 3],
        /// Points into the particle side; normalised on load.
        normal: [f64; 3],
    },
    /// Inside of a rotating cylinder, with baffles turning with it.
    Drum(DrumSpec),
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DrumSpec {
    pub name: String,
    pub species: String,
    pub axis_point_m: [f64; 3],
    pub axis: [f64; 3],
    pub radius_m: f64,
    /// Rotation speed about `axis` (right-handed; negative turns the other way), revolutions per minute.
    pub rotation_rpm: f64,
    #[serde(default)]
    pub baffles: Vec<BaffleSpec>,
}

/// Baffle plates fixed to a drum (seed 000 §3.4, Fig. 23). Coordinates are in the plane normal to the drum axis,
/// relative to the axis, at drum angle 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum BaffleSpec {
    /// `count` plates attached to the wall at equal angles, reaching `length_m` inwards; `tilt_deg` = 0 is a
    /// straight (radial) baffle, otherwise the plate leans by that angle from the radial direction ("angled").
    Traditional {
        count: u32,
        length_m: f64,
        half_thickness_m: f64,
        #[serde(default)]
        tilt_deg: f64,
    },
    /// Plates near the axis, where the flowing layer is. One plate: a bar of `length_m` centred on the axis.
    /// Several: spokes at equal angles from `inner_radius_m` to `inner_radius_m + length_m`.
    Axial {
        count: u32,
        length_m: f64,
        half_thickness_m: f64,
        #[serde(default)]
        inner_radius_m: f64,
    },
    /// Any plate, given by its mid-section segment.
    Segment {
        start_m: [f64; 2],
        end_m: [f64; 2],
        half_thickness_m: f64,
    },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum FillSpec {
    /// Particles on a simple-cubic lattice: points `origin_m + k·spacing_m` inside [lo_m, hi_m) (the LAMMPS
    /// `lattice sc` + `create_atoms region` convention), optionally only those inside a drum.
    Lattice {
        species: String,
        spacing_m: f64,
        lo_m: [f64; 3],
        hi_m: [f64; 3],
        #[serde(default)]
        origin_m: [f64; 3],
        /// Keep only points whose particle fits inside this drum.
        #[serde(default)]
        inside_drum: Option<String>,
        /// Displace each point by a uniform random offset in [−jitter_m, jitter_m] (scenario seed) along every
        /// axis in which the lattice holds more than one point, so that replicates settle into different packings.
        /// At most half the gap between neighbours: 2·jitter_m ≤ spacing_m − particle diameter.
        #[serde(default)]
        jitter_m: f64,
    },
    /// Particles at given positions, optionally with initial velocities and angular velocities.
    Explicit {
        species: String,
        positions_m: Vec<[f64; 3]>,
        #[serde(default)]
        velocities_m_per_s: Vec<[f64; 3]>,
        #[serde(default)]
        angular_velocities_rad_per_s: Vec<[f64; 3]>,
    },
    /// `count` non-overlapping particles at random positions in [lo_m, hi_m] (random sequential insertion with the
    /// scenario seed), optionally only inside a drum.
    Random {
        species: String,
        count: u32,
        lo_m: [f64; 3],
        hi_m: [f64; 3],
        #[serde(default)]
        inside_drum: Option<String>,
    },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    pub end_time_s: f64,
    /// Fixed time step. Either this or `dt_fraction_of_contact_time`.
    #[serde(default)]
    pub dt_s: Option<f64>,
    /// Time step as a fraction of the contact duration of the smallest particle pair at
    /// `reference_velocity_m_per_s`.
    #[serde(default)]
    pub dt_fraction_of_contact_time: Option<f64>,
    #[serde(default = "default_reference_velocity")]
    pub reference_velocity_m_per_s: f64,
}

fn default_reference_velocity() -> f64 {
    1.0
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NeighborSpec {
    /// Neighbour-list skin. Default: 0.4 × the largest particle radius (0.6 mm for the 1.5 mm benchmark spheres,
    /// as in its LIGGGHTS input).
    #[serde(default)]
    pub skin_m: Option<f64>,
    /// Skin of the force pass's own list, refiltered from the candidates within `skin_m` each time a particle has
    /// moved half of it (the cells are searched only when a particle has moved (skin_m − inner_skin_m)/2).
    /// Results do not depend on it, only the speed. Default: skin_m / 4, used after a cell search only where it
    /// halves the pairs the force pass examines (dense, slow beds); given: always; equal to skin_m: one list.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_skin_m: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    #[serde(default = "default_checkpoint_every")]
    pub checkpoint_every_steps: u64,
    #[serde(default = "default_keep")]
    pub keep_checkpoints: usize,
    #[serde(default = "default_series_every")]
    pub series_every_steps: u64,
    /// Add the net force on the particles by mechanism to the series (seed 001 ch. 8, Figs 8.8–8.16): the weight,
    /// the gas's force, and each wall's contact and cohesion forces, as components against gravity (N), averaged
    /// over the steps since the previous row or checkpoint. Particle–particle forces cancel in the sum. Default:
    /// false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub net_forces: bool,
    /// Record every contact's duration and, per particle, the contacts that ended, their summed durations and the
    /// time spent touching a wall (the metrics `mean_collision_duration_s`, `mean_wall_contact_duration_s`,
    /// `wall_contact_time_fraction`). Adds the checkpoint's `particles/channels` datasets. Default: false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub contact_statistics: bool,
}

fn default_checkpoint_every() -> u64 {
    10_000
}
fn default_keep() -> usize {
    3
}
fn default_series_every() -> u64 {
    1000
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            checkpoint_every_steps: default_checkpoint_every(),
            keep_checkpoints: default_keep(),
            series_every_steps: default_series_every(),
            net_forces: false,
            contact_statistics: false,
        }
    }
}
