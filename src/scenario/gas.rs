//! The `gas:` section of a scenario (a coupled gas–particle run: fluidized beds) and its validation into the gas
//! solver's configuration.
//!
//! The gas grid covers the particle domain: `cells` along x, y, z; with `pseudo_2d: true` the grid is one cell deep
//! (z = 1) and the cell depth is the domain's z extent — seed 000 §2.3.1's "pseudo-3-D" bed, whose depth should be
//! one particle diameter (seed 000 prints 1 mm for 3 mm beads; seed 002 says one diameter).

use serde::{Deserialize, Serialize};

use super::ConfigError;
use crate::engine::Vec3;
use crate::engine::gas::GasScalarSpec;
use crate::engine::gas::coupled::GasCoupling;
use crate::engine::gas::coupling::PorosityMethod;
use crate::engine::gas::fluid_forces::{DragCoupling, DragVelocities};
use crate::engine::gas::grid::side;
use crate::engine::gas::heat::GasThermal;
use crate::engine::gas::held_drag::DragUpdate;
use crate::engine::gas::linsolve::PressureSolver;
use crate::engine::gas::piso::PressureVelocity;
use crate::engine::gas::simple::{InflowLevels, InflowRamp, InletFace};
use crate::engine::gas::{Boundary, Convection, GasConfig, Grid};
use crate::engine::models::drag::DragLaw;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GasSpec {
    /// Keep the section but simulate no gas: the particles move in vacuum (no drag, no convection), to separate
    /// conduction from convection (seed 000 Fig. 72). Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub vacuum: bool,
    pub density_kg_per_m3: f64,
    pub viscosity_pa_s: f64,
    /// Gas cells along x, y, z (z = 1 for a pseudo-2-D bed). Seed 000: cells about 3 particle diameters wide.
    pub cells: [usize; 3],
    /// What bounds the gas on each side; an unset side is periodic where the domain is, else a no-slip wall.
    #[serde(default)]
    pub sides: SidesSpec,
    /// Jets: boundary faces whose centres lie in a box get their own inflow velocity (seed 002's central jet).
    #[serde(default)]
    pub jets: Vec<JetSpec>,
    /// Blocked cells: those whose centres lie in any of these boxes are outside the gas (no-slip walls around
    /// them). Particles need their own walls there.
    #[serde(default)]
    pub blocked: Vec<BoxSpec>,
    /// A rotary kiln: the cells whose centres lie outside this drum (by name, a `drum` wall) are blocked too, and
    /// their walls turn with the drum (no slip on the moving wall; seed 000 §5.1.1's kiln, with the circle as a
    /// staircase of cell faces).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outside_drum: Option<String>,
    #[serde(default = "default_drag")]
    pub drag: DragLaw,
    /// Which velocities drag is computed from: `instantaneous` (each particle's own, gas interpolated to it) or
    /// `cell_averaged` (seed 002's method 1: the cell's mean particle velocity and centre gas velocity).
    #[serde(default)]
    pub drag_velocities: DragVelocities,
    /// How the gas receives the drag: `explicit` (exactly what the particles got; needs gas steps below about
    /// 2 ρ_g ε / β) or `semi_implicit` (−β u_new + β v: stable for dense beds and strong jets).
    #[serde(default)]
    pub drag_coupling: DragCoupling,
    /// When each particle's drag coefficient, the gas velocity and the pressure gradient at it are evaluated:
    /// `every_dem_step` (default) or `every_gas_step` (held over the gas step, CFDEM's coupling interval: the drag
    /// law and the interpolation run once per gas step).
    #[serde(default)]
    pub drag_update: DragUpdate,
    /// How particle volume becomes cell porosity (default `volume_split`).
    #[serde(default)]
    pub porosity: PorosityMethod,
    /// Porosity is clamped to at least this.
    #[serde(default = "default_min_porosity")]
    pub min_porosity: f64,
    /// DEM steps per gas step (seed 001: 20).
    pub dem_steps_per_gas_step: u64,
    /// Default `upwind` (seed 000 §2.2.2).
    #[serde(default = "default_convection")]
    pub convection: Convection,
    #[serde(default)]
    pub solver: GasSolverSpec,
    /// Inflow off until `start_s`, then rising linearly to full over `duration_s`, on every inlet side and jet: the
    /// particles settle before the gas starts, so that all runs of a velocity sweep start from one packing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inflow_ramp: Option<InflowRamp>,
    /// Inflow held at a sequence of levels, `hold_s` each from `start_s` (seed 001's defluidization/fluidization
    /// cycle); multiplies the ramp.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inflow_levels: Option<InflowLevels>,
    /// Height above the inlet where the pressure-drop probe sits (seed 002 Fig. 3: 20 cm). The series always has
    /// the whole-column drop too.
    #[serde(default)]
    pub pressure_probe_height_m: Option<f64>,
}

fn default_drag() -> DragLaw {
    DragLaw::DiFelice
}
fn default_min_porosity() -> f64 {
    // CHOICE: 0.2, below random close packing's 0.36 even for a bidisperse volume split in one cell.
    0.2
}
fn default_convection() -> Convection {
    Convection::Upwind
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SidesSpec {
    #[serde(default)]
    pub x_low: Option<SideSpec>,
    #[serde(default)]
    pub x_high: Option<SideSpec>,
    #[serde(default)]
    pub y_low: Option<SideSpec>,
    #[serde(default)]
    pub y_high: Option<SideSpec>,
    #[serde(default)]
    pub z_low: Option<SideSpec>,
    #[serde(default)]
    pub z_high: Option<SideSpec>,
}

impl SidesSpec {
    fn get(&self, axis: usize, high: bool) -> Option<SideSpec> {
        [
            self.x_low,
            self.x_high,
            self.y_low,
            self.y_high,
            self.z_low,
            self.z_high,
        ][side(axis, high)]
    }
}

const SIDE_NAMES: [&str; 6] = ["x_low", "x_high", "y_low", "y_high", "z_low", "z_high"];

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SideSpec {
    /// No-slip wall at rest.
    Wall,
    Periodic,
    /// Zero-gradient outflow; the pressure there is the reference 0.
    Outlet,
    /// Uniform inflow into the domain at this superficial velocity (the distributor of a fluidized bed).
    Inlet {
        superficial_velocity_m_per_s: f64,
    },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JetSpec {
    /// The side the jet enters through (`y_low` for a bed's bottom).
    pub side: String,
    /// Faces of that side whose centres lie in [lo_m, hi_m] (the coordinate along the side's axis is ignored).
    pub lo_m: [f64; 3],
    pub hi_m: [f64; 3],
    /// Inflow velocity into the domain, m/s.
    pub superficial_velocity_m_per_s: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    pub lo_m: [f64; 3],
    pub hi_m: [f64; 3],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GasSolverSpec {
    #[serde(default = "d_relax_velocity")]
    pub relax_velocity: f64,
    #[serde(default = "d_relax_pressure")]
    pub relax_pressure: f64,
    #[serde(default = "d_outer")]
    pub max_outer_iterations: usize,
    #[serde(default = "d_mass_tol")]
    pub mass_tolerance: f64,
    #[serde(default = "d_velocity_tol")]
    pub velocity_tolerance: f64,
    #[serde(default = "d_linear_tol")]
    pub linear_tolerance: f64,
    #[serde(default = "d_linear_iter")]
    pub max_linear_iterations: usize,
    /// `auto` (default: a banded direct factorisation on small grids, conjugate gradients otherwise), `direct` or
    /// `conjugate_gradient`. Not written when `auto`, so existing job ids stay as they were.
    #[serde(default, skip_serializing_if = "is_auto")]
    pub pressure_solver: PressureSolver,
    /// `simple` (default: outer iterations to the tolerances) or `{ piso: { correctors: 2 } }` (one momentum
    /// predictor and that many pressure corrections per gas step, no outer iterations; CFDEM's transient coupling).
    /// Not written when `simple`, so existing job ids stay as they were.
    #[serde(default, skip_serializing_if = "is_simple")]
    pub pressure_velocity: PressureVelocity,
}

fn is_simple(p: &PressureVelocity) -> bool {
    *p == PressureVelocity::Simple
}

fn is_auto(s: &PressureSolver) -> bool {
    *s == PressureSolver::Auto
}

fn d_relax_velocity() -> f64 {
    0.8
}
fn d_relax_pressure() -> f64 {
    0.5
}
fn d_outer() -> usize {
    50
}
fn d_mass_tol() -> f64 {
    1e-5
}
fn d_velocity_tol() -> f64 {
    1e-4
}
fn d_linear_tol() -> f64 {
    1e-8
}
fn d_linear_iter() -> usize {
    500
}

impl Default for GasSolverSpec {
    fn default() -> Self {
        GasSolverSpec {
            relax_velocity: d_relax_velocity(),
            relax_pressure: d_relax_pressure(),
            max_outer_iterations: d_outer(),
            mass_tolerance: d_mass_tol(),
            velocity_tolerance: d_velocity_tol(),
            linear_tolerance: d_linear_tol(),
            max_linear_iterations: d_linear_iter(),
            pressure_solver: PressureSolver::Auto,
            pressure_velocity: PressureVelocity::Simple,
        }
    }
}

/// A validated gas section: everything needed to attach a gas to a simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct GasSetup {
    pub config: GasConfig,
    pub drag: DragLaw,
    pub drag_velocities: DragVelocities,
    pub drag_coupling: DragCoupling,
    pub drag_update: DragUpdate,
    pub porosity_method: PorosityMethod,
    pub min_porosity: f64,
    pub dem_steps_per_gas_step: u64,
    pub pressure_probe_height_m: Option<f64>,
    /// For each entry of `gas.jets`, one past its last face in `config.inlet_faces`.
    pub jet_face_ends: Vec<usize>,
    /// The gas's energy and convection, in a run with heat transfer (set by `scenario/heat.rs`).
    pub heat: Option<(GasThermal, GasScalarSpec)>,
    /// Evaporation and the vapour field, in a run with drying (set by `scenario/drying.rs`).
    pub drying: Option<(crate::engine::drying::DryingConfig, GasScalarSpec)>,
}

impl GasSetup {
    /// The gas around particles at `positions_m`.
    pub fn coupling(&self, positions_m: &[Vec3], radii_m: &[f64]) -> Result<GasCoupling, String> {
        let mut coupling = GasCoupling::new(
            self.config.clone(),
            self.drag,
            self.drag_velocities,
            self.porosity_method,
            self.min_porosity,
            self.dem_steps_per_gas_step,
            positions_m,
            radii_m,
        )?;
        coupling.drag_coupling = self.drag_coupling;
        coupling.fluid.drag_update = self.drag_update;
        if let Some((thermal, spec)) = &self.heat {
            coupling.attach_heat(*thermal, spec.clone())?;
        }
        if let Some((config, spec)) = &self.drying {
            coupling.attach_drying(*config, spec.clone())?;
        }
        Ok(coupling)
    }
}

/// Every inflow velocity the spec gives, with its key: inlet sides, then jets (before any ramp or level).
pub fn inlet_velocities(spec: &GasSpec) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    for (k, name) in SIDE_NAMES.iter().enumerate() {
        if let Some(SideSpec::Inlet {
            superficial_velocity_m_per_s,
        }) = spec.sides.get(k / 2, k % 2 == 1)
        {
            out.push((
                format!("gas.sides.{name}.inlet.superficial_velocity_m_per_s"),
                superficial_velocity_m_per_s,
            ));
        }
    }
    for (k, jet) in spec.jets.iter().enumerate() {
        out.push((
            format!("gas.jets[{k}].superficial_velocity_m_per_s"),
            jet.superficial_velocity_m_per_s,
        ));
    }
    out
}

type Fail<'a> = &'a dyn Fn(String, String) -> ConfigError;

/// Checks the gas section against the domain and builds its configuration.
pub fn build_gas(
    spec: &GasSpec,
    domain_lo_m: [f64; 3],
    domain_hi_m: [f64; 3],
    domain_periodic: [bool; 3],
    pseudo_2d: bool,
    gravity_m_per_s2: [f64; 3],
    fail: Fail,
) -> Result<GasSetup, ConfigError> {
    let positive = |key: &str, v: f64| -> Result<(), ConfigError> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(fail(
                format!("gas.{key}"),
                format!("expected a positive number, got {v}"),
            ))
        }
    };
    positive("density_kg_per_m3", spec.density_kg_per_m3)?;
    positive("viscosity_pa_s", spec.viscosity_pa_s)?;
    for a in 0..3 {
        if spec.cells[a] == 0 {
            return Err(fail(format!("gas.cells[{a}]"), "expected at least 1 cell".into()));
        }
    }
    if pseudo_2d && spec.cells[2] != 1 {
        return Err(fail(
            "gas.cells[2]".into(),
            format!("a pseudo-2-D bed has one gas cell in z, got {}", spec.cells[2]),
        ));
    }
    if spec.cells.iter().fold(1u128, |n, &k| n.saturating_mul(k as u128)) > 50_000_000 {
        return Err(fail(
            "gas.cells".into(),
            "more than 5e7 cells: expected a smaller grid".into(),
        ));
    }
    if spec.dem_steps_per_gas_step == 0 {
        return Err(fail("gas.dem_steps_per_gas_step".into(), "expected at least 1".into()));
    }
    if !(spec.min_porosity.is_finite() && spec.min_porosity > 0.0 && spec.min_porosity < 1.0) {
        return Err(fail(
            "gas.min_porosity".into(),
            format!("expected 0 < value < 1, got {}", spec.min_porosity),
        ));
    }
    let s = &spec.solver;
    if let PressureVelocity::Piso { correctors } = s.pressure_velocity
        && !(1..=20).contains(&correctors)
    {
        return Err(fail(
            "gas.solver.pressure_velocity.piso.correctors".into(),
            format!("expected 1 to 20 pressure corrections per gas step, got {correctors}"),
        ));
    }
    for (key, v) in [
        ("relax_velocity", s.relax_velocity),
        ("relax_pressure", s.relax_pressure),
    ] {
        if !(v.is_finite() && v > 0.0 && v <= 1.0) {
            return Err(fail(
                format!("gas.solver.{key}"),
                format!("expected 0 < value <= 1, got {v}"),
            ));
        }
    }
    for (key, v) in [
        ("mass_tolerance", s.mass_tolerance),
        ("velocity_tolerance", s.velocity_tolerance),
        ("linear_tolerance", s.linear_tolerance),
    ] {
        positive(&format!("solver.{key}"), v)?;
    }
    for (key, v) in [
        ("max_outer_iterations", s.max_outer_iterations),
        ("max_linear_iterations", s.max_linear_iterations),
    ] {
        if v == 0 {
            return Err(fail(format!("gas.solver.{key}"), "expected at least 1".into()));
        }
    }
    // A grid one cell deep carries no z velocity and has no z sides (Grid::two_d).
    let two_d = spec.cells[2] == 1;
    let mut boundary = [Boundary::Wall {
        velocity_m_per_s: [0.0; 3],
    }; 6];
    for a in 0..3 {
        for high in [false, true] {
            let name = SIDE_NAMES[side(a, high)];
            let given = spec.sides.get(a, high);
            if two_d && a == 2 {
                if given.is_some() {
                    return Err(fail(
                        format!("gas.sides.{name}"),
                        "a pseudo-2-D gas has no z sides (it is one cell deep)".into(),
                    ));
                }
                continue;
            }
            let side_spec = given.unwrap_or(if domain_periodic[a] {
                SideSpec::Periodic
            } else {
                SideSpec::Wall
            });
            if matches!(side_spec, SideSpec::Periodic) != domain_periodic[a] {
                return Err(fail(
                    format!("gas.sides.{name}"),
                    format!(
                        "the gas is periodic along an axis exactly when the particle domain is (domain.periodic[{a}] is {})",
                        domain_periodic[a]
                    ),
                ));
            }
            let inward = if high { -1.0 } else { 1.0 };
            boundary[side(a, high)] = match side_spec {
                SideSpec::Wall => Boundary::Wall {
                    velocity_m_per_s: [0.0; 3],
                },
                SideSpec::Periodic => Boundary::Periodic,
                SideSpec::Outlet => Boundary::Outlet,
                SideSpec::Inlet {
                    superficial_velocity_m_per_s: v,
                } => {
                    if !v.is_finite() || v < 0.0 {
                        return Err(fail(
                            format!("gas.sides.{name}.inlet.superficial_velocity_m_per_s"),
                            format!("expected a velocity >= 0 into the domain, got {v}"),
                        ));
                    }
                    let mut u = [0.0; 3];
                    u[a] = inward * v;
                    Boundary::Inlet { velocity_m_per_s: u }
                }
            };
        }
    }
    let h_m: [f64; 3] = std::array::from_fn(|a| (domain_hi_m[a] - domain_lo_m[a]) / spec.cells[a] as f64);
    let grid = Grid {
        n: spec.cells,
        h_m,
        origin_m: domain_lo_m,
        boundary,
    };
    if let Some(ramp) = spec.inflow_ramp {
        if !ramp.start_s.is_finite() || ramp.start_s < 0.0 {
            return Err(fail(
                "gas.inflow_ramp.start_s".into(),
                format!("expected a time >= 0 s, got {}", ramp.start_s),
            ));
        }
        if !ramp.duration_s.is_finite() || ramp.duration_s < 0.0 {
            return Err(fail(
                "gas.inflow_ramp.duration_s".into(),
                format!("expected a duration >= 0 s, got {}", ramp.duration_s),
            ));
        }
    }
    if let Some(levels) = &spec.inflow_levels {
        if !levels.start_s.is_finite() || levels.start_s < 0.0 {
            return Err(fail(
                "gas.inflow_levels.start_s".into(),
                format!("expected a time >= 0 s, got {}", levels.start_s),
            ));
        }
        if !levels.hold_s.is_finite() || levels.hold_s <= 0.0 {
            return Err(fail(
                "gas.inflow_levels.hold_s".into(),
                format!("expected a duration > 0 s, got {}", levels.hold_s),
            ));
        }
        if levels.factors.is_empty() {
            return Err(fail(
                "gas.inflow_levels.factors".into(),
                "expected at least one level".into(),
            ));
        }
        if let Some(k) = levels.factors.iter().position(|f| !f.is_finite() || *f < 0.0) {
            return Err(fail(
                format!("gas.inflow_levels.factors[{k}]"),
                format!("expected a finite factor >= 0, got {}", levels.factors[k]),
            ));
        }
    }
    let mut inlet_faces = Vec::new();
    let mut jet_face_ends = Vec::with_capacity(spec.jets.len());
    for (k, jet) in spec.jets.iter().enumerate() {
        let key = |f: &str| format!("gas.jets[{k}].{f}");
        let Some(index) = SIDE_NAMES.iter().position(|n| *n == jet.side) else {
            return Err(fail(
                key("side"),
                format!("unknown side `{}`; expected one of {}", jet.side, SIDE_NAMES.join(", ")),
            ));
        };
        let (axis, high) = (index / 2, index % 2 == 1);
        if axis >= grid.axes() || grid.periodic(axis) {
            return Err(fail(
                key("side"),
                format!("side `{}` is not a boundary of this gas grid", jet.side),
            ));
        }
        if !jet.superficial_velocity_m_per_s.is_finite() || jet.superficial_velocity_m_per_s < 0.0 {
            return Err(fail(
                key("superficial_velocity_m_per_s"),
                format!(
                    "expected a velocity >= 0 into the domain, got {}",
                    jet.superficial_velocity_m_per_s
                ),
            ));
        }
        let dims = grid.face_dims(axis);
        let along = if high { grid.n[axis] } else { 0 };
        let before = inlet_faces.len();
        for kk in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let idx = [i, j, kk];
                    if idx[axis] != along {
                        continue;
                    }
                    let c = grid.face_centre_m(axis, idx);
                    let inside = (0..3)
                        .filter(|&b| b != axis && !(two_d && b == 2))
                        .all(|b| c[b] >= jet.lo_m[b] && c[b] <= jet.hi_m[b]);
                    if inside {
                        inlet_faces.push(InletFace {
                            axis,
                            face: grid.face(axis, idx),
                            velocity_m_per_s: if high { -1.0 } else { 1.0 } * jet.superficial_velocity_m_per_s,
                        });
                    }
                }
            }
        }
        if inlet_faces.len() == before {
            return Err(fail(
                key("lo_m"),
                "the box holds no face centre of that side; widen it to at least one gas cell".into(),
            ));
        }
        jet_face_ends.push(inlet_faces.len());
    }
    if let Some(h) = spec.pressure_probe_height_m {
        positive("pressure_probe_height_m", h)?;
        if !boundary.iter().any(|b| matches!(b, Boundary::Inlet { .. })) && inlet_faces.is_empty() {
            return Err(fail(
                "gas.pressure_probe_height_m".into(),
                "the probe height is measured from an inlet side; no side is an inlet or has a jet".into(),
            ));
        }
    }
    let mut blocked = Vec::new();
    if !spec.blocked.is_empty() {
        blocked = vec![false; grid.cells()];
        for (k, b) in spec.blocked.iter().enumerate() {
            let before = blocked.iter().filter(|&&x| x).count();
            for kk in 0..grid.n[2] {
                for j in 0..grid.n[1] {
                    for i in 0..grid.n[0] {
                        let c = grid.cell_centre_m([i, j, kk]);
                        if (0..3).all(|a| c[a] >= b.lo_m[a] && c[a] <= b.hi_m[a]) {
                            blocked[grid.cell([i, j, kk])] = true;
                        }
                    }
                }
            }
            if blocked.iter().filter(|&&x| x).count() == before {
                return Err(fail(
                    format!("gas.blocked[{k}]"),
                    "the box holds no cell centre that is not already blocked".into(),
                ));
            }
        }
        if blocked.iter().all(|&x| x) {
            return Err(fail("gas.blocked".into(), "every gas cell is blocked".into()));
        }
    }
    let config = GasConfig {
        grid,
        density_kg_per_m3: spec.density_kg_per_m3,
        viscosity_pa_s: spec.viscosity_pa_s,
        gravity_m_per_s2,
        convection: spec.convection,
        relax_velocity: s.relax_velocity,
        relax_pressure: s.relax_pressure,
        max_outer_iterations: s.max_outer_iterations,
        mass_tolerance: s.mass_tolerance,
        velocity_tolerance: s.velocity_tolerance,
        linear_tolerance: s.linear_tolerance,
        max_linear_iterations: s.max_linear_iterations,
        pressure_solver: s.pressure_solver,
        pressure_velocity: s.pressure_velocity,
        inlet_faces,
        inflow_ramp: spec.inflow_ramp,
        inflow_levels: spec.inflow_levels.clone(),
        blocked,
        blocked_wall_motion: None,
        pressure_reference_cell: None,
    };
    config.grid.check().map_err(|m| fail("gas.cells".into(), m))?;
    crate::engine::gas::GasSolver::new(config.clone()).map_err(|m| fail("gas".into(), m))?;
    Ok(GasSetup {
        config,
        drag: spec.drag,
        drag_velocities: spec.drag_velocities,
        drag_coupling: spec.drag_coupling,
        drag_update: spec.drag_update,
        porosity_method: spec.porosity,
        min_porosity: spec.min_porosity,
        dem_steps_per_gas_step: spec.dem_steps_per_gas_step,
        pressure_probe_height_m: spec.pressure_probe_height_m,
        jet_face_ends,
        heat: None,
        drying: None,
    })
}
