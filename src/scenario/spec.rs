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
    /// Heat transfer: particle temperatures and conduction; absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heat: Option<HeatSpec>,
    /// Drying (seed 000 chapter 7): the particles' liquid evaporates into the gas, which carries the vapour;
    /// needs `heat` and a `gas` (not in vacuum); absent: nothing evaporates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drying: Option<super::drying::DryingSpec>,
}

/// A particle material as the scenario writes it (`build.rs` turns it into the engine's `Species`). Walls are
/// species too. A named `material` (seed 000's Table 7) supplies every property the entry leaves out; a property
/// given explicitly wins, and a Young's modulus given beside a material is the simulation's (softened) one, the
/// material's being the real one (`real_youngs_modulus_pa`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpeciesSpec {
    pub name: String,
    /// A named material whose properties fill in those not given here.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<Material>,
    /// Nominal radius of particles created from this species (walls ignore it).
    pub radius_m: f64,
    /// Required unless `material` gives it (as are the Young's modulus, Poisson ratio and friction coefficient).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_kg_per_m3: Option<f64>,
    /// The modulus the contact law uses (may be softened to allow a longer time step).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_modulus_pa: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<f64>,
    /// Coulomb sliding friction coefficient μ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_coefficient: Option<f64>,
    /// Thornton yield force F_y (seed 000 eq. 2.7; "essentially a fitting parameter"). Only the Thornton normal
    /// model reads it; `None` means the material never yields.
    #[serde(default)]
    pub yield_force_n: Option<f64>,
    /// Rolling-resistance coefficient μ_r for the optional rolling slot (dimensionless).
    #[serde(default)]
    pub rolling_friction_coefficient: f64,
    /// The material's real Young's modulus where `youngs_modulus_pa` is softened: heat conduction scales the
    /// contact radius back to the real material's (`heat.soft_contact_correction`). Default: the `material`'s when
    /// it differs from `youngs_modulus_pa`, else none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub real_youngs_modulus_pa: Option<f64>,
    /// Solid thermal conductivity k_s, W/(m K) (heat transfer; default: the `material`'s).
    #[serde(default)]
    pub thermal_conductivity_w_per_m_k: Option<f64>,
    /// Specific heat capacity c_p, J/(kg K) (heat transfer; default: the `material`'s).
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

/// The named materials of seed 000's Table 7 (the rotary kiln, §5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Material {
    /// ρ 2700 kg/m³ (the seed's value), E 69 GPa, ν 0.33, μ 0.3, k 1.7 W/(m K), c 800 J/(kg K).
    Glass,
    /// ρ 7900 kg/m³, E 193 GPa, ν 0.29, μ 0.3, k 15 W/(m K), c 477 J/(kg K).
    Steel,
    /// ρ 2700 kg/m³, E 110 GPa, ν 0.33, μ 0.3, k 180 W/(m K), c 900 J/(kg K). Also spelt `aluminum`.
    #[serde(alias = "aluminum")]
    Aluminium,
}

/// The properties of a named [`Material`], SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialProperties {
    pub density_kg_per_m3: f64,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    pub friction_coefficient: f64,
    pub thermal_conductivity_w_per_m_k: f64,
    pub heat_capacity_j_per_kg_k: f64,
}

impl Material {
    /// Seed 000, Table 7.
    pub fn properties(self) -> MaterialProperties {
        let (
            density_kg_per_m3,
            youngs_modulus_pa,
            poisson_ratio,
            thermal_conductivity_w_per_m_k,
            heat_capacity_j_per_kg_k,
        ) = match self {
            Material::Glass => (2700.0, 69.0e9, 0.33, 1.7, 800.0),
            Material::Steel => (7900.0, 193.0e9, 0.29, 15.0, 477.0),
            Material::Aluminium => (2700.0, 110.0e9, 0.33, 180.0, 900.0),
        };
        MaterialProperties {
            density_kg_per_m3,
            youngs_modulus_pa,
            poisson_ratio,
            friction_coefficient: 0.3,
            thermal_conductivity_w_per_m_k,
            heat_capacity_j_per_kg_k,
        }
    }
}

/// Heat transfer (seed 000 chapter 5): particle temperatures, conduction through contacts, walls and liquid
/// bridges. Absent: no temperatures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HeatSpec {
    /// Temperature of the particles whose fill states none, K.
    pub initial_temperature_k: f64,
    /// Walls by name (`box_x_lo` … for a box) with a fixed temperature or adiabatic; a wall not listed is
    /// adiabatic.
    #[serde(default)]
    pub walls: std::collections::BTreeMap<String, WallHeatSpec>,
    /// Scale the contact radius of a softened species back to its real modulus's for conduction (where a species
    /// states or its material gives a real modulus). Default true.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub soft_contact_correction: bool,
    /// The gas's thermal properties and convection, used when the scenario has a `gas` (not in `vacuum`).
    #[serde(default)]
    pub gas: GasHeatSpec,
    /// In a drum with a heated wall, the bed's core (whose temperature gives h_w, seed 000 eq. 5.21) is the disc
    /// round the bed's centroid of this fraction of the centroid's distance to the wall; the series also holds an
    /// inner core of half the radius (Fig. 69: the core changes h_w). Default 0.5.
    #[serde(default = "half", skip_serializing_if = "is_half")]
    pub bed_core_radius_fraction: f64,
    /// k_l of the liquid in liquid bridges, W/(m K): bridges conduct H_l = k_l V/d² (seed 000 eqs 7.8–7.11).
    /// Default 0.61, water near 300 K (the seed gives no value).
    #[serde(default = "water_conductivity", skip_serializing_if = "is_water_conductivity")]
    pub liquid_conductivity_w_per_m_k: f64,
}

fn water_conductivity() -> f64 {
    0.61
}

fn is_water_conductivity(x: &f64) -> bool {
    *x == 0.61
}

fn half() -> f64 {
    0.5
}

fn is_half(x: &f64) -> bool {
    *x == 0.5
}

/// The gas's energy (seed 000 eq. 5.8) and its convection with the particles (eqs. 5.5–5.7). Defaults: Table 7's
/// air and seed 000's correlation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GasHeatSpec {
    /// k_g, W/(m K) (default 0.0261, air).
    #[serde(default = "air_conductivity")]
    pub conductivity_w_per_m_k: f64,
    /// c_g, J/(kg K) (default 1000.7, air).
    #[serde(default = "air_heat_capacity")]
    pub heat_capacity_j_per_kg_k: f64,
    /// The Nusselt correlation of h_gp (default `seed000` with coefficient 1.8).
    #[serde(default)]
    pub nusselt: crate::engine::models::convection::NusseltCorrelation,
    /// The gas's temperature at the start, K (default `heat.initial_temperature_k`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_temperature_k: Option<f64>,
    /// Temperature of the gas entering through inlet sides and jets, K (default the gas's initial temperature).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inlet_temperature_k: Option<f64>,
    /// Each jet's own inlet temperature, K, in the order of `gas.jets` (default: `inlet_temperature_k`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub jet_temperatures_k: Vec<f64>,
    /// Conduction through the gas between nearly touching surfaces (particle–fluid–particle and particle–fluid–wall,
    /// Rong & Horio 1999 as in MFIX-DEM); absent: off, as in seed 000's model. Acts only with a gas (not in
    /// `vacuum`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lens_conduction: Option<LensConductionSpec>,
}

/// The gas lens's parameters (`engine::models::gas_lens`): `lens_conduction: {}` takes MFIX's defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LensConductionSpec {
    /// f: the lens of gas round the larger particle has radius (1 + f) R (MFIX's FLPC; default 0.2).
    #[serde(default = "lens_fraction")]
    pub lens_radius_fraction: f64,
    /// s, m: the smallest gap the gas conducts across (MFIX's DES_MIN_COND_DIST; default 4e-10).
    #[serde(default = "lens_min_gap")]
    pub min_gap_m: f64,
}

fn lens_fraction() -> f64 {
    0.2
}

fn lens_min_gap() -> f64 {
    4e-10
}

fn air_conductivity() -> f64 {
    0.0261
}

fn air_heat_capacity() -> f64 {
    1000.7
}

impl Default for GasHeatSpec {
    fn default() -> Self {
        GasHeatSpec {
            conductivity_w_per_m_k: air_conductivity(),
            heat_capacity_j_per_kg_k: air_heat_capacity(),
            nusselt: Default::default(),
            initial_temperature_k: None,
            inlet_temperature_k: None,
            jet_temperatures_k: Vec::new(),
            lens_conduction: None,
        }
    }
}

/// A wall's thermal condition: `temperature_k` (fixed) or `adiabatic: true`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallHeatSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_k: Option<f64>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub adiabatic: bool,
    /// A heated wall is adiabatic until this time, s (the bed settles first; default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub from_s: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn yes() -> bool {
    true
}

fn is_true(b: &bool) -> bool {
    *b
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
        /// Beads glued to the plane: a rough floor or roof (seed 000 §3.2's "particle-roughened walls").
        #[serde(default, skip_serializing_if = "Option::is_none")]
        glued_beads: Option<PlaneBeadsSpec>,
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
    /// Beads glued to the inside of the drum, turning with it: a rough wall (seed 000 §3.4 builds its tumbler wall
    /// from particles). Without them the wall is a smooth cylinder, on which a bed of free-rolling spheres slides.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub glued_beads: Option<GluedBeadsSpec>,
}

/// Spheres of `radius_m` centred on a plane at `point_m + i·spacing_m[0]·e1 + j·spacing_m[1]·e2` for all integers i,
/// j, where e1 is the first of x, y, z not along the normal made normal to it and e2 = normal × e1 (for a floor of
/// normal +y: e1 = x, e2 = −z). Along a periodic axis an even number of beads per period.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlaneBeadsSpec {
    pub radius_m: f64,
    pub spacing_m: [f64; 2],
}

/// Spheres of `radius_m` centred on the drum's surface, `count_around` of them equally spaced around it (even) in
/// rings `axial_spacing_m` apart along the axis (from the axis point; along a periodic axis an even number of rings
/// per period). A bead contact is a wall contact (the bead does not move but with the drum).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GluedBeadsSpec {
    pub radius_m: f64,
    pub count_around: u32,
    pub axial_spacing_m: f64,
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
        /// Initial temperature of these particles, K (a run with `heat`; default `heat.initial_temperature_k`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        temperature_k: Option<f64>,
    },
    /// Particles at given positions, optionally with initial velocities and angular velocities.
    Explicit {
        species: String,
        positions_m: Vec<[f64; 3]>,
        #[serde(default)]
        velocities_m_per_s: Vec<[f64; 3]>,
        #[serde(default)]
        angular_velocities_rad_per_s: Vec<[f64; 3]>,
        /// Initial temperature of these particles, K (a run with `heat`; default `heat.initial_temperature_k`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        temperature_k: Option<f64>,
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
        /// Initial temperature of these particles, K (a run with `heat`; default `heat.initial_temperature_k`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        temperature_k: Option<f64>,
    },
}

impl FillSpec {
    /// The fill's own initial temperature, K, if it states one.
    pub fn temperature_k(&self) -> Option<f64> {
        match self {
            FillSpec::Lattice { temperature_k, .. }
            | FillSpec::Explicit { temperature_k, .. }
            | FillSpec::Random { temperature_k, .. } => *temperature_k,
        }
    }

    /// The species it places.
    pub fn species(&self) -> &str {
        match self {
            FillSpec::Lattice { species, .. }
            | FillSpec::Explicit { species, .. }
            | FillSpec::Random { species, .. } => species,
        }
    }

    /// Its key in the scenario's `fill` list entry (`lattice`, `explicit`, `random`).
    pub fn kind(&self) -> &'static str {
        match self {
            FillSpec::Lattice { .. } => "lattice",
            FillSpec::Explicit { .. } => "explicit",
            FillSpec::Random { .. } => "random",
        }
    }
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
    /// Sort the particles by place every this many steps (cells of one largest diameter, slabs across the bed's
    /// widest spread), as LAMMPS' `atom_modify sort` does: a bed that mixes otherwise scatters neighbours through
    /// memory, and on several threads nearly every pair then crosses between the threads' ranges (a bubbling bed of
    /// 2,400 beads ran its contact pass 1.75× slower on two threads than on one). Results stay independent of the
    /// thread count and restarts stay exact; a sorted run's bits differ from an unsorted one's (forces are summed in
    /// another order), its physics does not. Default: never (the particles keep their fill order). 1000 suits most
    /// beds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sort_every_steps: Option<u64>,
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
    /// Write particle (and gas) snapshots for ParaView every this many seconds of simulated time, and at the run's
    /// start and end, into `snapshots/` of the run's directory (VTK XML: `particles.pvd`, `gas.pvd`; `snapshot`
    /// module). At most 10,000 over the run. Default: none (`granflow snapshots <dir>` makes them from the
    /// checkpoints afterwards).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub snapshots_every_s: Option<f64>,
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
            snapshots_every_s: None,
        }
    }
}
