//! Validation of a [`ScenarioSpec`] and construction of the engine's configuration and initial particles.
//!
//! Every check names the key path that failed and what was expected; nothing is built from a spec that fails one.
//! Non-SI inputs (rpm, degrees) are converted here and nowhere else.

use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

mod fill;
mod walls;

pub(super) use walls::walls_named;

use super::ConfigError;
use super::spec::{FillSpec, GravitySpec, ScenarioSpec, SpeciesSpec, WallSpec};
use crate::engine::Vec3;
use crate::engine::channels::ParticleChannels;
use crate::engine::cohesion::Cohesion;
use crate::engine::geometry::{Domain, Gravity, GravityFlip, Wall, WallShape};
use crate::engine::models::cohesion_law::CohesionModel;
use crate::engine::models::{ContactLaw, NormalModel, PairTable, TangentialModel};
use crate::engine::particles::{Particles, Species, SpeciesId, SpeciesTable};
use crate::engine::simulation::SimConfig;
use crate::engine::state::RngState;

/// A validated scenario, ready to run.
/// Most snapshots a run writes (`output.snapshots_every_s`): each holds every particle, so more would fill a disk
/// before it said anything the eye can follow.
pub const MAX_SNAPSHOTS: u64 = 10_000;

pub struct BuiltScenario {
    pub spec: ScenarioSpec,
    pub config: Arc<SimConfig>,
    pub particles: Particles,
    pub dt_s: f64,
    /// Shortest contact duration among the species pairs at the reference velocity (for reporting dt/t_c).
    pub contact_time_s: f64,
    pub rng: RngState,
    /// The gas of a coupled run.
    pub gas: Option<super::gas::GasSetup>,
}

struct Checker<'a> {
    path: &'a Path,
}

impl Checker<'_> {
    fn fail(&self, key: impl Into<String>, message: impl Into<String>) -> ConfigError {
        ConfigError::invalid(self.path, key, message)
    }

    fn positive(&self, key: &str, v: f64) -> Result<(), ConfigError> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(self.fail(key, format!("expected a finite value > 0, got {v}")))
        }
    }

    fn non_negative(&self, key: &str, v: f64) -> Result<(), ConfigError> {
        if v.is_finite() && v >= 0.0 {
            Ok(())
        } else {
            Err(self.fail(key, format!("expected a finite value >= 0, got {v}")))
        }
    }

    fn finite3(&self, key: &str, v: &[f64; 3]) -> Result<(), ConfigError> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(self.fail(key, format!("expected three finite numbers, got {v:?}")))
        }
    }

    fn unit3(&self, key: &str, v: &[f64; 3]) -> Result<Vec3, ConfigError> {
        self.finite3(key, v)?;
        let u = Vec3::from(*v);
        if u.norm() == 0.0 {
            return Err(self.fail(key, "expected a non-zero direction vector"));
        }
        Ok(u.normalize())
    }

    fn species(&self, key: &str, table: &SpeciesTable, name: &str) -> Result<SpeciesId, ConfigError> {
        table.find(name).ok_or_else(|| {
            let known: Vec<&str> = table.species.iter().map(|s| s.name.as_str()).collect();
            self.fail(key, format!("unknown species '{name}'; defined: {}", known.join(", ")))
        })
    }
}

/// Validates `spec` (read from `path`, used in messages) and builds the simulation inputs.
pub fn build(spec: ScenarioSpec, path: &Path) -> Result<BuiltScenario, ConfigError> {
    let c = Checker { path };

    if spec.name.trim().is_empty() {
        return Err(c.fail("name", "expected a non-empty scenario name"));
    }

    if spec.species.is_empty() {
        return Err(c.fail("species", "expected at least one species"));
    }
    let mut engine_species = Vec::with_capacity(spec.species.len());
    for (k, s) in spec.species.iter().enumerate() {
        if spec.species[..k].iter().any(|o| o.name == s.name) {
            return Err(c.fail(
                format!("species[{k}].name"),
                format!("species name '{}' is used twice", s.name),
            ));
        }
        engine_species.push(resolve_species(&c, k, s)?);
    }
    if matches!(spec.cohesion, Some(CohesionModel::LiquidBridge(_))) {
        for (k, s) in spec.species.iter().enumerate() {
            let key = |f: &str| format!("species[{k}].{f}");
            if !(s.liquid_content.is_finite() && s.liquid_content >= 0.0) {
                return Err(c.fail(
                    key("liquid_content"),
                    format!("expected a finite value >= 0, got {}", s.liquid_content),
                ));
            }
            if !(s.contact_angle_deg.is_finite() && (0.0..90.0).contains(&s.contact_angle_deg)) {
                return Err(c.fail(
                    key("contact_angle_deg"),
                    format!("expected 0 <= θ < 90 (a wetting liquid), got {}", s.contact_angle_deg),
                ));
            }
        }
    }
    let species = SpeciesTable {
        species: engine_species,
    };

    check_contact_law(&c, &spec.contact)?;

    c.finite3("domain.lo_m", &spec.domain.lo_m)?;
    c.finite3("domain.hi_m", &spec.domain.hi_m)?;
    for axis in 0..3 {
        if spec.domain.hi_m[axis] <= spec.domain.lo_m[axis] {
            return Err(c.fail(
                format!("domain.hi_m[{axis}]"),
                format!(
                    "expected hi > lo, got lo {} and hi {}",
                    spec.domain.lo_m[axis], spec.domain.hi_m[axis]
                ),
            ));
        }
    }
    let domain = Domain::new(
        Vec3::from(spec.domain.lo_m),
        Vec3::from(spec.domain.hi_m),
        spec.domain.periodic,
    );
    c.finite3("gravity.vector_m_per_s2", &spec.gravity.vector_m_per_s2)?;
    if let Some(flip) = spec.gravity.flip {
        c.positive("gravity.flip.frequency_hz", flip.frequency_hz)?;
    }

    check_memory(&c, &spec)?;
    let walls = walls::build_walls(&c, &spec, &species, &domain)?;
    let mut rng = RngState::from_seed_u64(spec.seed).restore();
    let (mut particles, fill_ends) = fill::fill(&c, &spec, &species, &domain, &walls, &mut rng)?;

    let skin_m = spec.neighbor.skin_m.unwrap_or(0.4 * particles.max_radius_m());
    c.positive("neighbor.skin_m", skin_m)?;
    let inner_skin_m = spec.neighbor.inner_skin_m.unwrap_or(0.25 * skin_m);
    if !(inner_skin_m.is_finite() && inner_skin_m > 0.0 && inner_skin_m <= skin_m) {
        return Err(c.fail(
            "neighbor.inner_skin_m",
            format!("expected 0 < value <= neighbor.skin_m ({skin_m} m), got {inner_skin_m}"),
        ));
    }
    if spec.neighbor.sort_every_steps == Some(0) {
        return Err(c.fail(
            "neighbor.sort_every_steps",
            "expected a number of steps of at least 1 (leave the key out to never sort)",
        ));
    }
    c.positive("time.end_time_s", spec.time.end_time_s)?;
    c.positive("time.reference_velocity_m_per_s", spec.time.reference_velocity_m_per_s)?;
    if !(spec.max_overlap_fraction.is_finite() && spec.max_overlap_fraction > 0.0 && spec.max_overlap_fraction <= 1.0) {
        return Err(c.fail(
            "max_overlap_fraction",
            format!("expected 0 < value <= 1, got {}", spec.max_overlap_fraction),
        ));
    }
    if spec.output.checkpoint_every_steps == 0 {
        return Err(c.fail("output.checkpoint_every_steps", "expected at least 1"));
    }
    if spec.output.series_every_steps == 0 {
        return Err(c.fail("output.series_every_steps", "expected at least 1"));
    }
    if spec.output.keep_checkpoints == 0 {
        return Err(c.fail("output.keep_checkpoints", "expected at least 1"));
    }
    if let Some(every_s) = spec.output.snapshots_every_s {
        c.positive("output.snapshots_every_s", every_s)?;
        let count = spec.time.end_time_s / every_s;
        if count > MAX_SNAPSHOTS as f64 {
            return Err(c.fail(
                "output.snapshots_every_s",
                format!(
                    "{every_s} s over an end time of {} s makes {count:.0} snapshots; at most {MAX_SNAPSHOTS} are \
                     written (choose at least {:e} s)",
                    spec.time.end_time_s,
                    spec.time.end_time_s / MAX_SNAPSHOTS as f64
                ),
            ));
        }
    }

    let pair_table = PairTable::new(&species, &spec.contact);
    let mut contact_time_s = f64::INFINITY;
    for (a, sa) in species.species.iter().enumerate() {
        for (b, sb) in species.species.iter().enumerate() {
            let ma = sa.density_kg_per_m3 * 4.0 / 3.0 * PI * sa.radius_m.powi(3);
            let mb = sb.density_kg_per_m3 * 4.0 / 3.0 * PI * sb.radius_m.powi(3);
            let mat = pair_table.get(SpeciesId(a as u16), SpeciesId(b as u16));
            let t = spec.contact.normal.contact_time_s(
                mat,
                sa.radius_m * sb.radius_m / (sa.radius_m + sb.radius_m),
                ma * mb / (ma + mb),
                spec.time.reference_velocity_m_per_s,
            );
            contact_time_s = contact_time_s.min(t);
        }
    }
    if !contact_time_s.is_finite() || contact_time_s <= 0.0 {
        return Err(c.fail(
            "contact.normal",
            format!(
                "the contact parameters give no finite contact duration ({contact_time_s} s): the dashpot is overdamped"
            ),
        ));
    }
    let dt_s = match (spec.time.dt_s, spec.time.dt_fraction_of_contact_time) {
        (Some(dt), None) => {
            c.positive("time.dt_s", dt)?;
            dt
        }
        (None, Some(fraction)) => {
            if !(fraction.is_finite() && fraction > 0.0 && fraction <= 0.5) {
                return Err(c.fail(
                    "time.dt_fraction_of_contact_time",
                    format!("expected 0 < value <= 0.5, got {fraction}"),
                ));
            }
            fraction * contact_time_s
        }
        _ => {
            return Err(c.fail("time", "give exactly one of dt_s and dt_fraction_of_contact_time"));
        }
    };

    check_step_reach(&c, &spec, &particles, dt_s)?;
    let heat = super::heat::build_heat(
        path,
        &spec,
        &species,
        &walls,
        &pair_table,
        &fill_ends,
        &mut particles,
        dt_s,
    )?;

    let mut gas = match &spec.gas {
        None => None,
        Some(g) => {
            if spec.gravity.flip.is_some() {
                return Err(c.fail("gas", "a gas with time-varying gravity (gravity.flip) is not supported"));
            }
            let fail = |key: String, message: String| c.fail(key, message);
            Some(super::gas::build_gas(
                g,
                spec.domain.lo_m,
                spec.domain.hi_m,
                spec.domain.periodic,
                spec.pseudo_2d,
                spec.gravity.vector_m_per_s2,
                &fail,
            )?)
        }
    };
    if spec.gas.as_ref().is_some_and(|g| g.vacuum) {
        // Checked as written, then switched off: the particles move in vacuum.
        gas = None;
    }
    if let (Some(g), Some(name)) = (gas.as_mut(), spec.gas.as_ref().and_then(|g| g.outside_drum.as_ref())) {
        block_outside_drum(&c, g, &walls, name)?;
    }
    if let Some(g) = gas.as_mut() {
        super::heat::build_gas_heat(path, &spec, g)?;
    }
    super::drying::build_drying(path, &spec, gas.as_mut())?;
    let wall_species: Vec<_> = walls.iter().map(|w| w.species).collect();
    let mut cohesion = match spec.cohesion {
        None => None,
        Some(model) => Some(
            Cohesion::new(model, &species, &wall_species, particles.max_radius_m())
                .map_err(|(key, message)| c.fail(key, message))?,
        ),
    };
    if let Some(cohesion) = cohesion.as_mut() {
        let bead_radius_m = walls.iter().filter_map(Wall::bead_radius_m).fold(0.0, f64::max);
        cohesion.reach_glued_beads(bead_radius_m, particles.max_radius_m());
    }
    if let Some(off) = &spec.cohesion_off {
        let Some(cohesion) = cohesion.as_mut() else {
            return Err(c.fail("cohesion_off", "expected a `cohesion` model to switch off"));
        };
        cohesion.between_particles = !off.between_particles;
        cohesion.wall_on = vec![cohesion.wall_range_m > 0.0; walls.len()];
        for (k, name) in off.walls.iter().enumerate() {
            let key = format!("cohesion_off.walls[{k}]");
            if cohesion.wall_range_m <= 0.0 {
                return Err(c.fail(key, "the cohesion model does not act on walls (its `walls` is false)"));
            }
            let Some(named) = walls_named(&walls, name) else {
                let names: Vec<&str> = walls.iter().map(|w| w.name.as_str()).collect();
                return Err(c.fail(
                    key,
                    format!("no wall named '{name}'; the walls are: {}", names.join(", ")),
                ));
            };
            for w in named {
                cohesion.wall_on[w] = false;
            }
        }
    }
    if !matches!(spec.cohesion, Some(CohesionModel::LiquidBridge(_)))
        && let Some(k) = spec.species.iter().position(|s| s.liquid_content != 0.0)
    {
        return Err(c.fail(
            format!("species[{k}].liquid_content"),
            "liquid on the particles needs `cohesion: { liquid_bridge: ... }`",
        ));
    }
    let config = SimConfig {
        domain,
        pseudo_2d: spec.pseudo_2d,
        rotation: spec.rotation,
        gravity: engine_gravity(&spec.gravity),
        species,
        pair_table,
        contact_law: spec.contact,
        walls,
        skin_m,
        inner_skin_m,
        inner_skin_auto: spec.neighbor.inner_skin_m.is_none(),
        sort_every_steps: spec.neighbor.sort_every_steps,
        max_overlap_fraction: spec.max_overlap_fraction,
        cohesion,
        contact_statistics: spec.output.contact_statistics,
        heat,
    };
    particles.channels = ParticleChannels::new(particles.len(), config.channel_groups());
    Ok(BuiltScenario {
        rng: RngState::capture(&rng),
        spec,
        config: Arc::new(config),
        particles,
        dt_s,
        contact_time_s,
        gas,
    })
}

/// The engine's species from the scenario's entry `k`: the named material's properties where the entry gives
/// none, each checked at its key, in SI units (the contact angle in radians).
fn resolve_species(c: &Checker, k: usize, s: &SpeciesSpec) -> Result<Species, ConfigError> {
    let key = |f: &str| format!("species[{k}].{f}");
    let material = s.material.map(|m| m.properties());
    let required = |field: &str, given: Option<f64>, from_material: Option<f64>| {
        given.or(from_material).ok_or_else(|| {
            c.fail(
                key(field),
                format!("expected `{field}` (or a `material` that gives it: glass, steel, aluminium)"),
            )
        })
    };
    let density_kg_per_m3 = required(
        "density_kg_per_m3",
        s.density_kg_per_m3,
        material.map(|m| m.density_kg_per_m3),
    )?;
    let youngs_modulus_pa = required(
        "youngs_modulus_pa",
        s.youngs_modulus_pa,
        material.map(|m| m.youngs_modulus_pa),
    )?;
    let poisson_ratio = required("poisson_ratio", s.poisson_ratio, material.map(|m| m.poisson_ratio))?;
    let friction_coefficient = required(
        "friction_coefficient",
        s.friction_coefficient,
        material.map(|m| m.friction_coefficient),
    )?;
    c.positive(&key("radius_m"), s.radius_m)?;
    c.positive(&key("density_kg_per_m3"), density_kg_per_m3)?;
    c.positive(&key("youngs_modulus_pa"), youngs_modulus_pa)?;
    if !(poisson_ratio.is_finite() && (0.0..0.5).contains(&poisson_ratio)) {
        return Err(c.fail(
            key("poisson_ratio"),
            format!("expected 0 <= ν < 0.5, got {poisson_ratio}"),
        ));
    }
    c.non_negative(&key("friction_coefficient"), friction_coefficient)?;
    c.non_negative(&key("rolling_friction_coefficient"), s.rolling_friction_coefficient)?;
    if let Some(fy) = s.yield_force_n {
        c.positive(&key("yield_force_n"), fy)?;
    }
    let real_youngs_modulus_pa = s.real_youngs_modulus_pa.or_else(|| {
        material
            .map(|m| m.youngs_modulus_pa)
            .filter(|&e| e != youngs_modulus_pa)
    });
    if let Some(e) = real_youngs_modulus_pa {
        c.positive(&key("real_youngs_modulus_pa"), e)?;
    }
    let thermal_conductivity_w_per_m_k = s
        .thermal_conductivity_w_per_m_k
        .or(material.map(|m| m.thermal_conductivity_w_per_m_k));
    if let Some(k_s) = s.thermal_conductivity_w_per_m_k {
        c.positive(&key("thermal_conductivity_w_per_m_k"), k_s)?;
    }
    let heat_capacity_j_per_kg_k = s
        .heat_capacity_j_per_kg_k
        .or(material.map(|m| m.heat_capacity_j_per_kg_k));
    if let Some(c_p) = s.heat_capacity_j_per_kg_k {
        c.positive(&key("heat_capacity_j_per_kg_k"), c_p)?;
    }
    Ok(Species {
        name: s.name.clone(),
        radius_m: s.radius_m,
        density_kg_per_m3,
        youngs_modulus_pa,
        poisson_ratio,
        friction_coefficient,
        yield_force_n: s.yield_force_n,
        rolling_friction_coefficient: s.rolling_friction_coefficient,
        contact_angle_rad: s.contact_angle_deg.to_radians(),
        liquid_content: s.liquid_content,
        real_youngs_modulus_pa,
        thermal_conductivity_w_per_m_k,
        heat_capacity_j_per_kg_k,
    })
}

/// Blocks the gas cells whose centres lie outside the drum `name` and makes their walls turn with it.
fn block_outside_drum(
    c: &Checker,
    gas: &mut super::gas::GasSetup,
    walls: &[Wall],
    name: &str,
) -> Result<(), ConfigError> {
    let key = "gas.outside_drum";
    let drum = fill::drum_named(c, key, walls, name)?;
    let WallShape::RotatingCylinder { frame, radius_m } = drum.shape() else {
        return Err(c.fail(key, format!("wall '{name}' is not a drum")));
    };
    let grid = &gas.config.grid;
    let mut blocked = if gas.config.blocked.is_empty() {
        vec![false; grid.cells()]
    } else {
        gas.config.blocked.clone()
    };
    for k in 0..grid.n[2] {
        for j in 0..grid.n[1] {
            for i in 0..grid.n[0] {
                let centre = Vec3::from(grid.cell_centre_m([i, j, k]));
                let r = centre - frame.axis_point_m;
                let off_axis = r - frame.axis * r.dot(&frame.axis);
                if off_axis.norm() > *radius_m {
                    blocked[grid.cell([i, j, k])] = true;
                }
            }
        }
    }
    if blocked.iter().all(|&b| b) {
        return Err(c.fail(key, format!("drum '{name}' holds no gas cell centre")));
    }
    // The reference pressure on top of the kiln (seed 000 §5.2): the open cell highest against gravity (the first in
    // cell order among equals).
    let up = -Vec3::from(gas.config.gravity_m_per_s2);
    let height = |cell: usize| {
        let n = grid.n;
        let idx = [cell % n[0], (cell / n[0]) % n[1], cell / (n[0] * n[1])];
        Vec3::from(grid.cell_centre_m(idx)).dot(&up)
    };
    let top = (0..grid.cells())
        .filter(|&cell| !blocked[cell])
        .fold(None, |best: Option<usize>, cell| match best {
            Some(b) if height(b) >= height(cell) => Some(b),
            _ => Some(cell),
        });
    gas.config.pressure_reference_cell = top;
    gas.config.blocked = blocked;
    gas.config.blocked_wall_motion = Some(crate::engine::gas::simple::BlockedWallMotion {
        axis_point_m: frame.axis_point_m.into(),
        axis: frame.axis.into(),
        angular_velocity_rad_per_s: frame.angular_velocity_rad_per_s,
    });
    Ok(())
}

/// The engine's gravity from the scenario's.
fn engine_gravity(g: &GravitySpec) -> Gravity {
    Gravity {
        vector_m_per_s2: g.vector_m_per_s2,
        flip: g.flip.map(|f| GravityFlip {
            axis: f.axis,
            frequency_hz: f.frequency_hz,
        }),
    }
}

fn check_contact_law(c: &Checker, law: &ContactLaw) -> Result<(), ConfigError> {
    law.normal
        .check()
        .map_err(|(key, message)| c.fail(format!("contact.normal.{key}"), message))?;
    let hertzian = !matches!(law.normal, NormalModel::LinearSpringDashpot { .. });
    match law.tangential {
        TangentialModel::LinearSpringCoulomb {
            stiffness_n_per_m,
            damping_kg_per_s,
        } => {
            c.non_negative(
                "contact.tangential.linear_spring_coulomb.stiffness_n_per_m",
                stiffness_n_per_m,
            )?;
            c.non_negative(
                "contact.tangential.linear_spring_coulomb.damping_kg_per_s",
                damping_kg_per_s,
            )?;
        }
        TangentialModel::LinearStepSpringCoulomb {
            stiffness_n_per_m,
            damping_kg_per_s,
        } => {
            c.non_negative(
                "contact.tangential.linear_step_spring_coulomb.stiffness_n_per_m",
                stiffness_n_per_m,
            )?;
            c.non_negative(
                "contact.tangential.linear_step_spring_coulomb.damping_kg_per_s",
                damping_kg_per_s,
            )?;
        }
        TangentialModel::Mindlin | TangentialModel::WaltonBraun { .. } if !hertzian => {
            return Err(c.fail(
                "contact.tangential",
                format!(
                    "{} needs a Hertzian normal model (hertz or thornton) for its contact radius; with linear_spring_dashpot use linear_spring_coulomb",
                    law.tangential.name()
                ),
            ));
        }
        TangentialModel::WaltonBraun { exponent } => {
            c.positive("contact.tangential.walton_braun.exponent", exponent)?
        }
        TangentialModel::Mindlin => {}
    }
    Ok(())
}

/// The most points a lattice fill may enumerate (most fall outside a drum or are cut by walls, so this is larger
/// than any particle count a run can afford; the memory budget bounds the particles themselves).
const MAX_LATTICE_POINTS: i128 = 50_000_000;

/// A lattice's index range per axis, (first, last), of points `origin + k spacing` in [lo, hi).
fn lattice_range(spacing_m: f64, lo_m: &[f64; 3], hi_m: &[f64; 3], origin_m: &[f64; 3]) -> [(i64, i64); 3] {
    // `as i64` saturates, so an absurd spacing gives a huge range, not an overflow.
    std::array::from_fn(|a| {
        let first = ((lo_m[a] - origin_m[a]) / spacing_m).ceil() as i64;
        let last = (((hi_m[a] - origin_m[a]) / spacing_m).ceil() as i64).saturating_sub(1);
        (first, last)
    })
}

/// The number of points of a lattice range (saturating).
fn lattice_points(range: &[(i64, i64); 3]) -> i128 {
    range
        .iter()
        .map(|&(a, b)| (b as i128 - a as i128 + 1).max(0))
        .fold(1i128, |n, k| n.saturating_mul(k))
}

/// Estimated memory of a run, per particle: the engine's arrays (about 300 bytes), neighbour lists, contact
/// history and the checkpoint writer's copies. Measured: 740 bytes per particle at the first checkpoint of the
/// settling column at 29,160 and 120,204 particles (peak resident memory); rounded up.
const BYTES_PER_PARTICLE: f64 = 1024.0;
/// Estimated memory of a run, per gas cell: the fields, the SIMPLE loop's coefficients and the linear solvers'
/// vectors. Measured: 590 bytes per cell in the pseudo-2-D bed at 256,000 and 1,024,000 cells; rounded up.
const BYTES_PER_GAS_CELL: f64 = 640.0;

/// The number of particles each fill entry makes, counted from the spec (a lattice's points before walls cut it),
/// with the key that sets it.
fn particles_per_fill(spec: &ScenarioSpec) -> Vec<(String, f64)> {
    let mut per_fill: Vec<(String, f64)> = Vec::new();
    for (k, f) in spec.fill.iter().enumerate() {
        let (key, n) = match f {
            FillSpec::Lattice {
                spacing_m,
                lo_m,
                hi_m,
                origin_m,
                ..
            } => {
                if !(spacing_m.is_finite() && *spacing_m > 0.0) {
                    continue; // reported by the fill's own checks
                }
                let n = lattice_points(&lattice_range(*spacing_m, lo_m, hi_m, origin_m));
                (format!("fill[{k}].lattice.spacing_m"), n as f64)
            }
            FillSpec::Random { count, .. } => (format!("fill[{k}].random.count"), *count as f64),
            FillSpec::Explicit { positions_m, .. } => {
                (format!("fill[{k}].explicit.positions_m"), positions_m.len() as f64)
            }
        };
        per_fill.push((key, n));
    }
    per_fill
}

/// The memory a run of `spec` is estimated to need, in bytes, from its particle and gas cell counts (before anything
/// is built); what [`build`] compares with the machine's budget, and the dispatcher with its parallel jobs.
pub fn estimated_memory_bytes(spec: &ScenarioSpec) -> f64 {
    let particles: f64 = particles_per_fill(spec).iter().map(|(_, n)| n).sum();
    let cells: f64 = spec
        .gas
        .as_ref()
        .map_or(0.0, |g| g.cells.iter().map(|&n| n as f64).product());
    particles * BYTES_PER_PARTICLE + cells * BYTES_PER_GAS_CELL
}

/// Refuses a scenario whose particles and gas cells, counted from the spec before anything is allocated, would need
/// more memory than the machine's budget ([`crate::machine::memory_budget_bytes`]). The key named is the fill entry
/// with the most particles or `gas.cells`, whichever needs more.
fn check_memory(c: &Checker, spec: &ScenarioSpec) -> Result<(), ConfigError> {
    let per_fill = particles_per_fill(spec);
    let particles: f64 = per_fill.iter().map(|(_, n)| n).sum();
    if particles >= u32::MAX as f64 {
        let (key, _) = per_fill
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .expect("a count this large has a fill entry");
        return Err(c.fail(
            key.clone(),
            format!(
                "the fills would make {particles:.3e} particles; expected fewer than {}",
                u32::MAX
            ),
        ));
    }
    let cells: f64 = spec
        .gas
        .as_ref()
        .map_or(0.0, |g| g.cells.iter().map(|&n| n as f64).product());
    let Some((budget, source)) = crate::machine::memory_budget_bytes() else {
        return Ok(());
    };
    let (particle_bytes, gas_bytes) = (particles * BYTES_PER_PARTICLE, cells * BYTES_PER_GAS_CELL);
    let need = particle_bytes + gas_bytes;
    if need <= budget as f64 {
        return Ok(());
    }
    let key = if gas_bytes > particle_bytes {
        "gas.cells".to_string()
    } else {
        per_fill
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or("fill".to_string(), |(k, _)| k.clone())
    };
    Err(c.fail(
        key,
        format!(
            "the run would need about {} of memory ({particles:.3e} particles at ~{BYTES_PER_PARTICLE} bytes, \
             {cells:.3e} gas cells at ~{BYTES_PER_GAS_CELL} bytes), more than this machine's budget of {} ({source})",
            crate::machine::bytes_text(need),
            crate::machine::bytes_text(budget as f64),
        ),
    ))
}

/// Refuses motions no time step of `dt_s` can resolve: anything that would carry a particle further than its own
/// radius in one step, where a contact would go from first touch to full overlap unseen.
///
/// CHOICE: the bound is one radius of the smallest particle per step. Contacts are resolved when an overlap grows
/// over many steps (dt is a small fraction of the contact time); a particle that crosses its radius in one step
/// overlaps by its whole radius before any force acts, and the run can only fail (max_overlap_fraction) or be
/// meaningless. The bound is far above any resolved motion (at dt = t_c/20 a collision at the reference velocity
/// moves a particle a few per cent of its radius per step), so no run that could work is refused. It applies to
/// what the engine can see before the run: a drum's surface speed, a gas inflow or jet (at its highest level: a
/// particle dragged along moves at most at about the gas's speed), a particle's initial velocity and spin, and the
/// distance gravity moves a particle from rest in one step.
fn check_step_reach(c: &Checker, spec: &ScenarioSpec, particles: &Particles, dt_s: f64) -> Result<(), ConfigError> {
    let r_min = particles.radius_m.iter().copied().fold(f64::INFINITY, f64::min);
    if !r_min.is_finite() {
        return Ok(());
    }
    let per_step = |v: f64| v.abs() * dt_s;
    let refuse = |key: String, what: String, v_m_per_s: f64| {
        c.fail(
            key,
            format!(
                "{what} moves {:.3e} m per time step (dt = {dt_s:e} s), more than the smallest particle radius \
                 {r_min:e} m: no contact could be resolved; expected a speed below {:.3e} m/s",
                per_step(v_m_per_s),
                r_min / dt_s
            ),
        )
    };
    for (k, w) in spec.walls.iter().enumerate() {
        if let WallSpec::Drum(d) = w {
            let surface_m_per_s = d.rotation_rpm * 2.0 * PI / 60.0 * d.radius_m;
            if per_step(surface_m_per_s) > r_min {
                return Err(c.fail(
                    format!("walls[{k}].drum.rotation_rpm"),
                    format!(
                        "the drum's surface speed ({:.3e} m/s at {:.3e} rpm) moves {:.3e} m per time step (dt = {dt_s:e} \
                         s), more than the smallest particle radius {r_min:e} m: no contact could be resolved; \
                         expected |rotation_rpm| below {:.3e}",
                        surface_m_per_s.abs(),
                        d.rotation_rpm,
                        per_step(surface_m_per_s),
                        r_min / dt_s / d.radius_m * 60.0 / (2.0 * PI)
                    ),
                ));
            }
        }
    }
    for (k, f) in spec.fill.iter().enumerate() {
        let FillSpec::Explicit {
            velocities_m_per_s,
            angular_velocities_rad_per_s,
            ..
        } = f
        else {
            continue;
        };
        for (n, v) in velocities_m_per_s.iter().enumerate() {
            let speed = Vec3::from(*v).norm();
            if per_step(speed) > r_min {
                return Err(refuse(
                    format!("fill[{k}].explicit.velocities_m_per_s[{n}]"),
                    format!("an initial velocity of {speed:.3e} m/s"),
                    speed,
                ));
            }
        }
        for (n, w) in angular_velocities_rad_per_s.iter().enumerate() {
            let spin = Vec3::from(*w).norm();
            // A point of the surface moves ω r per step, r ≥ r_min: more than r whenever ω dt > 1.
            if spin * dt_s > 1.0 {
                return Err(c.fail(
                    format!("fill[{k}].explicit.angular_velocities_rad_per_s[{n}]"),
                    format!(
                        "an initial spin of {spin:.3e} rad/s turns a particle by {:.3e} rad per time step (dt = \
                         {dt_s:e} s), moving its surface more than its radius: expected below {:.3e} rad/s",
                        spin * dt_s,
                        1.0 / dt_s
                    ),
                ));
            }
        }
    }
    let g = Vec3::from(spec.gravity.vector_m_per_s2).norm();
    if 0.5 * g * dt_s * dt_s > r_min {
        return Err(c.fail(
            "gravity.vector_m_per_s2",
            format!(
                "gravity of {g:.3e} m/s² moves a particle at rest {:.3e} m in one time step (dt = {dt_s:e} s), more \
                 than the smallest particle radius {r_min:e} m; expected below {:.3e} m/s²",
                0.5 * g * dt_s * dt_s,
                2.0 * r_min / (dt_s * dt_s)
            ),
        ));
    }
    if let Some(flip) = spec.gravity.flip
        && flip.frequency_hz * dt_s > 0.5
    {
        return Err(c.fail(
            "gravity.flip.frequency_hz",
            format!(
                "a flip at {} Hz changes sign more often than every time step (dt = {dt_s:e} s); expected at most \
                 {:.3e} Hz",
                flip.frequency_hz,
                0.5 / dt_s
            ),
        ));
    }
    if let Some(gas) = &spec.gas {
        let highest_level = gas
            .inflow_levels
            .as_ref()
            .map_or(1.0, |l| l.factors.iter().copied().fold(0.0, f64::max));
        let inlets = super::gas::inlet_velocities(gas);
        for (key, v) in inlets {
            let v = v * highest_level;
            if per_step(v) > r_min {
                return Err(refuse(
                    key,
                    format!("a gas inflow of {v:.3e} m/s (at its highest level)"),
                    v,
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const JITTERED: &str = r#"
name: jittered layer
seed: SEED
domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.03, 0.05, 0.0027], periodic: [true, false, false] }
pseudo_2d: true
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, radius_m: 0.00135, density_kg_per_m3: 2000.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.33, friction_coefficient: 0.3 }
contact: { normal: { hertz: { restitution: 0.9 } }, tangential: mindlin }
walls:
  - box: { species: glass }
fill:
  - lattice: { species: glass, spacing_m: 0.003, lo_m: [0.0, 0.0015, 0.0], hi_m: [0.03, 0.0315, 0.0027], origin_m: [0.0015, 0.0015, 0.00135], jitter_m: JITTER }
time: { dt_s: 1.0e-5, end_time_s: 0.001 }
"#;

    fn positions(seed: u64, jitter_m: f64) -> Vec<Vec3> {
        let text = JITTERED
            .replace("SEED", &seed.to_string())
            .replace("JITTER", &jitter_m.to_string());
        let path = Path::new("jittered.yaml");
        let built = build(crate::scenario::parse(&text, path).expect("parses"), path).expect("builds");
        built.particles.position_m.clone()
    }

    #[test]
    fn lattice_jitter_moves_points_in_plane_within_bounds_and_follows_the_seed() {
        let exact = positions(1, 0.0);
        let jitter_m = 1.5e-4;
        let a = positions(1, jitter_m);
        assert_eq!(exact.len(), 100, "10 x 10 points");
        assert_eq!(a.len(), exact.len());
        let mut largest = [0.0f64; 3];
        for (x, x0) in a.iter().zip(&exact) {
            for (axis, l) in largest.iter_mut().enumerate() {
                *l = l.max((x[axis] - x0[axis]).abs());
            }
        }
        assert!(largest[0] <= jitter_m && largest[1] <= jitter_m, "{largest:?}");
        assert!(
            largest[0] > 0.8 * jitter_m && largest[1] > 0.8 * jitter_m,
            "the offsets span the range: {largest:?}"
        );
        assert_eq!(largest[2], 0.0, "one point across z: the layer stays in its plane");
        for (i, x) in a.iter().enumerate() {
            for y in &a[i + 1..] {
                let mut d = x - y;
                d[0] -= 0.03 * (d[0] / 0.03).round();
                assert!(d.norm() >= 2.0 * 0.00135, "jittered neighbours overlap");
            }
        }
        assert_eq!(a, positions(1, jitter_m), "the same seed gives the same points");
        assert_ne!(a, positions(2, jitter_m), "another seed gives other points");
    }
}
