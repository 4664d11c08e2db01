//! `granflow simulate`: run one scenario to its end time in an output directory, with checkpoints and a time series,
//! resuming from the newest valid checkpoint when the directory already holds a run of the same scenario.
//!
//! Directory layout: `scenario.json` (the resolved spec, written once), `ckpt-<step>.h5` (atomic, checksummed, the
//! newest N kept), `series.csv` (one row per sample, rewritten up to the restored step on resume) and
//! `summary.json` (written atomically at the end; its presence means the run finished).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::checkpoint::{CheckpointMeta, CheckpointSeries};
use crate::engine::{Simulation, Vec3};
use crate::error::{Error, Result};
use crate::scenario::{self, BuiltScenario};
use crate::util::write_atomic;

/// Options of one `simulate` invocation.
#[derive(Debug, Clone)]
pub struct SimulateOptions {
    pub scenario_path: PathBuf,
    pub out_dir: Option<PathBuf>,
    pub threads: usize,
    /// Stop after this many steps in this invocation (for tests of interrupted runs); the run stays resumable.
    pub max_steps: Option<u64>,
    pub quiet: bool,
}

/// What a finished (or stopped) invocation reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Summary {
    pub scenario: String,
    pub particles: usize,
    pub step: u64,
    pub time_s: f64,
    pub dt_s: f64,
    pub dt_over_contact_time: f64,
    pub finished: bool,
    /// The run was asked to stop (signal) and checkpointed before its end.
    pub stopped: bool,
    pub kinetic_energy_j: f64,
    pub bed_top_m: f64,
    pub mean_height_m: f64,
    pub wall_time_s: f64,
    /// Time spent writing checkpoints in this invocation (included in wall_time_s).
    pub checkpoint_time_s: f64,
    pub checkpoints_written: u64,
    pub steps_per_s: f64,
    pub resumed_from_step: Option<u64>,
    /// This invocation's wall time per engine stage, seconds (see `Simulation::stage_timings`).
    pub stage_timings_s: Vec<(String, f64)>,
    /// Neighbour-list builds (cell searches) in this invocation.
    pub neighbor_builds: u64,
    /// Refilters of the force pass's list from the candidates (the two-level scheme) in this invocation.
    #[serde(default)]
    pub neighbor_refilters: u64,
    /// The build that ran this invocation ([`crate::provenance::build_id`]).
    pub build: String,
    /// The compilation of the force loop it ran ([`crate::provenance::cpu_path`]).
    pub cpu_path: String,
    /// In a run with heat transfer, the lumped-particle check at the end ([`biot_numbers`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub biot_numbers: Option<BiotNumbers>,
}

/// Seed 000 §5.1.3's Biot numbers at the end of a run: a lumped particle temperature needs both ≪ 1.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct BiotNumbers {
    /// The largest (2/π) √(δ/R) over touching pairs and wall contacts (eq. 5.15: contact conductance against the
    /// particle's internal conduction; R the smaller radius, δ the overlap); 0 without contacts.
    pub contact_max: f64,
    /// The largest h_gp R / k_s over the particles (eq. 5.13); 0 without a gas.
    pub convection_max: f64,
    /// The largest H R/(k_s π R²) of the gas lens (`heat.gas.lens_conduction`) over touching pairs and wall
    /// contacts, eq. 5.15's form with the lens's conductance (R the smaller radius); 0 without the lens. The lens
    /// puts its heat near the contact point: where this is not ≪ 1 (glass in air at the wall, about 0.4) the lumped
    /// temperature is an approximation.
    pub lens_max: f64,
}

/// The [`BiotNumbers`] of the current state, `None` without heat transfer.
pub fn biot_numbers(sim: &Simulation) -> Option<BiotNumbers> {
    let p = &sim.particles;
    if p.temperature_k.is_empty() {
        return None;
    }
    let contacts = sim.snapshot().contacts;
    let biot = |overlap: f64, radius: f64| 2.0 / std::f64::consts::PI * (overlap.max(0.0) / radius).sqrt();
    let pairs = contacts.pairs.iter().filter(|(_, _, h)| h.active).map(|(i, j, _)| {
        let (i, j) = (i.index(), j.index());
        let separation = sim.config.domain.separation(&p.position_m[i], &p.position_m[j]).norm();
        biot(
            p.radius_m[i] + p.radius_m[j] - separation,
            p.radius_m[i].min(p.radius_m[j]),
        )
    });
    let walls = contacts.walls.iter().filter(|(_, _, h)| h.active).map(|(i, w, _)| {
        let (i, w) = (i.index(), w.0 as usize);
        let gap = sim.config.walls[w]
            .proximity(&p.position_m[i], sim.wall_angle_rad[w])
            .gap_m;
        biot(p.radius_m[i] - gap, p.radius_m[i])
    });
    let contact_max = pairs.chain(walls).fold(0.0, f64::max);
    let lens = sim.config.heat.as_ref().and_then(|h| h.lens);
    let k_s = |i: usize| sim.config.species.get(p.species[i]).thermal_conductivity_w_per_m_k;
    let lens_max = lens.map_or(0.0, |lens| {
        let pairs = contacts
            .pairs
            .iter()
            .filter(|(_, _, h)| h.active)
            .filter_map(|(i, j, _)| {
                let (i, j) = (i.index(), j.index());
                let separation = sim.config.domain.separation(&p.position_m[i], &p.position_m[j]).norm();
                let h = lens.pair_conductance_w_per_k(p.radius_m[i], p.radius_m[j], separation);
                let r = p.radius_m[i].min(p.radius_m[j]);
                Some(h / (std::f64::consts::PI * r * k_s(i)?.min(k_s(j)?)))
            });
        let walls = contacts
            .walls
            .iter()
            .filter(|(_, _, h)| h.active)
            .filter_map(|(i, w, _)| {
                let (i, w) = (i.index(), w.0 as usize);
                let gap = sim.config.walls[w]
                    .proximity(&p.position_m[i], sim.wall_angle_rad[w])
                    .gap_m
                    - p.radius_m[i];
                let h = lens.wall_conductance_w_per_k(p.radius_m[i], gap);
                Some(h / (std::f64::consts::PI * p.radius_m[i] * k_s(i)?))
            });
        pairs.chain(walls).fold(0.0, f64::max)
    });
    let convection_max = sim.gas.as_ref().map_or(0.0, |gas| {
        (0..p.len())
            .filter_map(|i| {
                let (_, conductance) =
                    gas.convection_conductance(&p.position_m[i], &p.velocity_m_per_s[i], p.radius_m[i])?;
                let r = p.radius_m[i];
                let h = conductance / (4.0 * std::f64::consts::PI * r * r);
                let k_s = sim.config.species.get(p.species[i]).thermal_conductivity_w_per_m_k?;
                Some(h * r / k_s)
            })
            .fold(0.0, f64::max)
    });
    Some(BiotNumbers {
        contact_max,
        convection_max,
        lens_max,
    })
}

const SERIES_HEADER: &str = "step,time_s,kinetic_energy_j,translational_kinetic_energy_j,bed_top_m,mean_height_m,pair_contacts,wall_contacts,mean_coordination";

pub fn checkpoint_meta(built: &BuiltScenario) -> CheckpointMeta {
    CheckpointMeta {
        engine_version: env!("CARGO_PKG_VERSION").to_string(),
        model_names: built
            .config
            .contact_law
            .model_names()
            .iter()
            .map(|s| s.to_string())
            .collect(),
        wall_names: built.config.walls.iter().map(|w| w.name.clone()).collect(),
        scenario_json: serde_json::to_string(&built.spec).expect("a validated spec always serialises"),
    }
}

/// Series columns of a run with a gas: the pressure drop from the inlet layer of cells to the far layer and to the
/// probe height (`nan` without a probe); seed 001's reading, the pressure at the first node (the inlet layer's
/// centre) minus the outlet's, with W'/A, the weight of the particles beyond that node over the inlet side's area;
/// and how the last gas step converged.
pub const GAS_SERIES_COLUMNS: &str = ",column_pressure_drop_pa,probe_pressure_drop_pa,node_pressure_drop_pa,\
node_weight_per_area_pa,gas_outer_iterations,gas_linear_iterations,gas_mass_imbalance";

/// The series columns of a run with heat transfer: the particles' mass-weighted mean temperature and the coldest and
/// hottest particle's, K; the energy ledger's heat from the walls into the particles and into the gas across its
/// boundary (net) since the start, and the gas temperature equation's continuity term, J; and the ledger's closure
/// ([`Simulation::energy_closure`], `engine::heat_ledger`).
const HEAT_SERIES_COLUMNS: &str = ",mean_temperature_k,min_temperature_k,max_temperature_k,wall_heat_to_particles_j,\
gas_boundary_heat_j,gas_continuity_heat_j,energy_closure";

/// The heat columns ([`HEAT_SERIES_COLUMNS`]), empty without heat transfer.
fn heat_columns(sim: &Simulation) -> String {
    let p = &sim.particles;
    if p.temperature_k.is_empty() {
        return String::new();
    }
    let mass: f64 = p.mass_kg.iter().sum();
    let mean = p.mass_kg.iter().zip(&p.temperature_k).map(|(m, t)| m * t).sum::<f64>() / mass;
    let (lo, hi) = p
        .temperature_k
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
            (lo.min(t), hi.max(t))
        });
    let (to_particles, to_gas, continuity) = sim.heat_ledger.as_ref().map_or((f64::NAN, f64::NAN, f64::NAN), |l| {
        (
            l.wall_to_particles_j,
            l.gas_boundary_in_j - l.gas_boundary_out_j,
            l.gas_continuity_j,
        )
    });
    let closure = sim.energy_closure().unwrap_or(f64::NAN);
    format!(",{mean:e},{lo:e},{hi:e},{to_particles:e},{to_gas:e},{continuity:e},{closure:e}")
}

/// The drying columns of a run with `drying`: the liquid on particles and in bridges (and in bridges alone), kg; the
/// moisture content X (that liquid over the particles' dry mass, kg/kg); the vapour in the gas, gone out through
/// its boundary and evaporated since the start, kg; the gas's mean relative humidity; and the ledger's closure
/// ([`Simulation::drying_closure`]).
const DRYING_SERIES_COLUMNS: &str = ",liquid_kg,bridge_liquid_kg,moisture_content,vapour_kg,vapour_out_kg,evaporated_kg,gas_relative_humidity,drying_closure";

/// The [`DRYING_SERIES_COLUMNS`], empty without drying.
fn drying_columns(sim: &Simulation) -> String {
    let Some((gas, drying)) = sim.gas.as_ref().and_then(|g| Some((g, g.drying.as_ref()?))) else {
        return String::new();
    };
    let density = drying.config.liquid_density_kg_per_m3;
    let liquid_kg = sim.total_liquid_m3() * density;
    let bridge_kg = (sim.total_liquid_m3() - sim.particles.liquid_m3.iter().sum::<f64>()) * density;
    let solid_kg: f64 = sim.particles.mass_kg.iter().sum();
    let l = &drying.ledger;
    format!(
        ",{liquid_kg:e},{bridge_kg:e},{:e},{:e},{:e},{:e},{:e},{:e}",
        liquid_kg / solid_kg,
        gas.vapour_kg().unwrap_or(f64::NAN),
        l.vapour_out_kg,
        l.evaporated_kg,
        gas.mean_relative_humidity().unwrap_or(f64::NAN),
        sim.drying_closure().unwrap_or(f64::NAN)
    )
}

/// The series columns of a run with a spray: the liquid sprayed onto the particles since the start, m³, and the
/// coating variability CV_m of the particles' coating mass gain (seed 000 eq. 6.45, `Simulation::coating_gain_m3`;
/// `nan` before the first spray).
const SPRAY_SERIES_COLUMNS: &str = ",sprayed_m3,coating_variability";

fn sprays(built: &BuiltScenario) -> bool {
    matches!(
        built.spec.cohesion,
        Some(crate::engine::models::cohesion_law::CohesionModel::LiquidBridge(
            crate::engine::models::cohesion_law::LiquidBridge { spray: Some(_), .. }
        ))
    )
}

/// The [`SPRAY_SERIES_COLUMNS`], empty without a spray.
fn spray_columns(sim: &Simulation, built: &BuiltScenario) -> String {
    if !sprays(built) {
        return String::new();
    }
    format!(
        ",{:e},{:e}",
        sim.particles.sprayed_m3.iter().sum::<f64>(),
        crate::engine::spray::coating_variability(&sim.coating_gain_m3())
    )
}

/// The series header of a scenario (before any observer columns).
pub fn series_header(built: &BuiltScenario) -> String {
    let mut header = SERIES_HEADER.to_string();
    if built.gas.is_some() {
        header.push_str(GAS_SERIES_COLUMNS);
    }
    if built.config.heat.is_some() {
        header.push_str(HEAT_SERIES_COLUMNS);
    }
    if crate::heated_drum::heated_drum(&built.config).is_some() {
        header.push_str(crate::heated_drum::DRUM_HEAT_COLUMNS);
    }
    if built.gas.as_ref().is_some_and(|g| g.drying.is_some()) {
        header.push_str(DRYING_SERIES_COLUMNS);
    }
    if sprays(built) {
        header.push_str(SPRAY_SERIES_COLUMNS);
    }
    if built.spec.output.net_forces {
        header.push_str(",weight_n,fluid_force_up_n");
        for wall in &built.config.walls {
            header.push_str(&format!(
                ",wall_{0}_contact_up_n,wall_{0}_cohesion_up_n,wall_{0}_contact_across_n,wall_{0}_cohesion_across_n",
                wall.name
            ));
        }
    }
    header
}

/// The net-force columns (`output.net_forces`): the weight, and the components against gravity of the gas's force
/// and of each wall's contact and cohesion forces on all particles, then for each wall the size of those two
/// forces' part across gravity (for a vertical sidewall its normal load and its pull, plus its horizontal friction
/// in a 3-D bed; for a distributor its net friction), averaged over the steps since the previous reading (`nan`
/// before any step). Reading restarts the sums.
fn net_force_columns(sim: &mut Simulation, built: &BuiltScenario) -> String {
    if !built.spec.output.net_forces {
        return String::new();
    }
    let g = sim.config.gravity.at(sim.time_s);
    let weight_n = sim.particles.mass_kg.iter().sum::<f64>() * g.norm();
    let means = sim.net_force.as_mut().and_then(|t| t.take_means());
    let walls = sim.config.walls.len();
    let across = |f: &Vec3, up: &Vec3| (f - up * f.dot(up)).norm();
    let (fluid, per_wall): (f64, Vec<[f64; 4]>) = match (means, (-g).try_normalize(0.0)) {
        (Some(m), Some(up)) => (
            m.fluid_n.dot(&up),
            m.wall_contact_n
                .iter()
                .zip(&m.wall_cohesion_n)
                .map(|(c, h)| [c.dot(&up), h.dot(&up), across(c, &up), across(h, &up)])
                .collect(),
        ),
        _ => (f64::NAN, vec![[f64::NAN; 4]; walls]),
    };
    let mut out = format!(",{weight_n:e},{fluid:e}");
    for [contact, cohesion, contact_across, cohesion_across] in per_wall {
        out.push_str(&format!(
            ",{contact:e},{cohesion:e},{contact_across:e},{cohesion_across:e}"
        ));
    }
    out
}

fn gas_columns(sim: &Simulation, probe_height_m: Option<f64>) -> String {
    let Some(gas) = sim.gas.as_ref() else {
        return String::new();
    };
    let column = gas.column_pressure_drop_pa().unwrap_or(f64::NAN);
    let probe = probe_height_m
        .and_then(|h| gas.pressure_drop_to_pa(h))
        .unwrap_or(f64::NAN);
    let node = gas.first_node_pressure_drop_pa().unwrap_or(f64::NAN);
    let weight = weight_beyond_first_node_per_area_pa(sim).unwrap_or(f64::NAN);
    format!(
        ",{column:e},{probe:e},{node:e},{weight:e},{},{},{:e}",
        gas.last.outer_iterations, gas.last.linear_iterations, gas.last.mass_imbalance
    )
}

/// W'/A (seed 001 notes §4.1): the weight of the particles whose centres lie beyond the first gas node (the centre
/// of the inlet layer of cells, seen from the inlet) over the inlet side's area, Pa; `None` without a gas inlet.
fn weight_beyond_first_node_per_area_pa(sim: &Simulation) -> Option<f64> {
    let gas = sim.gas.as_ref()?;
    let (axis, node_m, inlet_high) = gas.first_node_plane()?;
    let area_m2 = gas.inlet_side_area_m2()?;
    let g = sim.config.gravity.at(sim.time_s).norm();
    let p = &sim.particles;
    let mass_kg: f64 = (0..p.len())
        .filter(|&i| {
            if inlet_high {
                p.position_m[i][axis] < node_m
            } else {
                p.position_m[i][axis] > node_m
            }
        })
        .map(|i| p.mass_kg[i])
        .sum();
    Some(mass_kg * g / area_m2)
}

/// Attaches the scenario's gas to a new or restored simulation (with the checkpointed gas state when restored).
pub fn attach_gas(
    built: &BuiltScenario,
    sim: &mut Simulation,
    restored: Option<&crate::engine::gas::coupled::GasSnapshot>,
) -> Result<()> {
    match (&built.gas, restored) {
        (None, None) => Ok(()),
        (None, Some(_)) => Err(Error::External(
            "the checkpoint holds a gas state but the scenario has no gas".into(),
        )),
        (Some(setup), restored) => {
            let p = &sim.particles;
            let coupling = setup
                .coupling(&p.position_m, &p.radius_m)
                .map_err(|m| Error::External(format!("gas: {m}")))?;
            sim.attach_gas(coupling);
            match restored {
                Some(snap) => sim.restore_gas(snap).map_err(Error::External),
                // A checkpoint of a gas run always holds the gas; only a new run starts without one.
                None => {
                    sim.start_drying_ledger();
                    Ok(())
                }
            }
        }
    }
}

fn series_row(sim: &mut Simulation, built: &BuiltScenario) -> String {
    let net = net_force_columns(sim, built);
    let (top, mean) = sim.bed_height_m();
    let (pairs, walls) = sim.contact_counts();
    let n = sim.particles.len().max(1) as f64;
    let gas = gas_columns(sim, built.gas.as_ref().and_then(|g| g.pressure_probe_height_m));
    let mut heat = heat_columns(sim);
    if let (Some(drum), Some(spec)) = (crate::heated_drum::heated_drum(&sim.config), &built.spec.heat) {
        heat.push_str(&crate::heated_drum::drum_heat_columns(
            sim,
            &drum,
            spec.bed_core_radius_fraction,
        ));
    }
    heat.push_str(&drying_columns(sim));
    heat.push_str(&spray_columns(sim, built));
    format!(
        "{},{:e},{:e},{:e},{:e},{:e},{},{},{:.6}{gas}{heat}{net}",
        sim.step,
        sim.time_s,
        sim.particles.kinetic_energy_j(),
        sim.particles.translational_kinetic_energy_j(),
        top,
        mean,
        pairs,
        walls,
        2.0 * pairs as f64 / n
    )
}

/// When `resuming` from the checkpoint at `step`, keeps the header and the rows up to `step` of an existing series
/// file, and refuses (leaving it as it is) a file whose header differs from `header` (written by another granflow
/// version): its rows would not fit the header, and dropping them would lose finished work silently. Otherwise (a
/// run starting from its initial state) keeps no row: a run killed after writing its first row but before its first
/// checkpoint would otherwise start with that row twice.
fn truncate_series(path: &Path, header: &str, step: u64, resuming: bool) -> Result<()> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => return Err(Error::io("read", path, e)),
    };
    if let Some(existing) = text.lines().next().filter(|h| resuming && *h != header) {
        return Err(Error::External(format!(
            "{} has the columns `{existing}`, but this granflow writes `{header}` (was the run started by another \
             version?); finish it with that version or start it again in a new directory",
            path.display()
        )));
    }
    let mut out = String::from(header);
    out.push('\n');
    let fields = header.split(',').count();
    for line in text.lines().skip(1) {
        // A row cut short by a kill has fewer fields and is dropped.
        let complete = line.split(',').count() == fields;
        match line.split(',').next().and_then(|s| s.parse::<u64>().ok()) {
            Some(s) if resuming && s <= step && complete => {
                out.push_str(line);
                out.push('\n');
            }
            _ => {}
        }
    }
    Ok(write_atomic(path, out.as_bytes())?)
}

/// Runs (or resumes) a scenario. Returns the summary of this invocation.
pub fn simulate(opts: &SimulateOptions) -> Result<Summary> {
    let built = scenario::load(&opts.scenario_path)?;
    let out = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(&built.spec.name));
    let (summary, _) = run_in_dir(
        &built,
        &out,
        RunControl {
            threads: opts.threads,
            dt_halvings: 0,
            max_steps: opts.max_steps,
            quiet: opts.quiet,
            stop: None,
            observer: &mut NoObserver,
        },
    )?;
    Ok(summary)
}

/// What happens during a run, for callers that report it (the campaign worker).
#[derive(Debug, Clone, Copy)]
pub enum RunEvent {
    Started {
        step: u64,
        total_steps: u64,
        resumed_from_step: Option<u64>,
    },
    Progress {
        step: u64,
        time_s: f64,
        steps_per_s: f64,
    },
    Checkpointed {
        step: u64,
    },
}

/// Hooks into a run: extra series columns and events.
pub trait RunObserver {
    /// Names of extra series columns, each preceded by a comma (`",a,b"`), or empty.
    fn extra_columns(&self) -> String {
        String::new()
    }
    /// Values of the extra columns for the current state, each preceded by a comma.
    fn extra_row(&mut self, _sim: &Simulation) -> String {
        String::new()
    }
    fn event(&mut self, _event: RunEvent) {}
}

/// An observer that adds nothing.
pub struct NoObserver;
impl RunObserver for NoObserver {}

/// How to run: threads, an optional step budget, and an optional stop flag (set by a signal handler: the run
/// checkpoints at the next chunk boundary and returns with `finished = false`).
pub struct RunControl<'a> {
    pub threads: usize,
    /// When > 0, run with the scenario's time step halved this many times (from wherever the run resumes): how a
    /// campaign retries a job that failed numerically.
    pub dt_halvings: u32,
    pub max_steps: Option<u64>,
    pub quiet: bool,
    pub stop: Option<&'a AtomicBool>,
    pub observer: &'a mut dyn RunObserver,
}

/// Steps between checks of the stop flag and progress reports.
const CHUNK_STEPS: u64 = 500;

/// Runs (or resumes) a built scenario in `out`. Returns this invocation's summary and the final simulation.
pub fn run_in_dir(built: &BuiltScenario, out: &Path, ctl: RunControl) -> Result<(Summary, Simulation)> {
    let RunControl {
        threads,
        dt_halvings,
        max_steps,
        quiet,
        stop,
        observer,
    } = ctl;
    let meta = checkpoint_meta(built);
    std::fs::create_dir_all(out).map_err(|e| Error::io("create directory", out, e))?;
    let spec_path = out.join("scenario.json");
    match std::fs::read_to_string(&spec_path) {
        Ok(existing) if existing != meta.scenario_json => {
            return Err(Error::External(format!(
                "{} holds a run of a different scenario (its scenario.json differs); choose another --out",
                out.display()
            )));
        }
        Ok(_) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => write_atomic(&spec_path, meta.scenario_json.as_bytes())?,
        Err(e) => return Err(Error::io("read", &spec_path, e)),
    }

    let header = format!("{}{}", series_header(built), observer.extra_columns());
    let series = CheckpointSeries::new(out, built.spec.output.keep_checkpoints);
    let series_path = out.join("series.csv");
    let (mut sim, resumed_from_step) = match series.latest_valid()? {
        Some(loaded) => {
            for rejected in &loaded.rejected {
                eprintln!("warning: {rejected}; using {} instead", loaded.path.display());
            }
            if loaded.meta.scenario_json != meta.scenario_json {
                return Err(Error::External(format!(
                    "checkpoint {} was written for a different scenario",
                    loaded.path.display()
                )));
            }
            let step = loaded.state.step;
            truncate_series(&series_path, &header, step, true)?;
            if !quiet {
                eprintln!("resuming from {} (step {step})", loaded.path.display());
            }
            let mut state = loaded.state;
            let gas = state.gas.take();
            if built.gas.is_some() && gas.is_none() {
                return Err(Error::External(format!(
                    "checkpoint {} holds no gas state but the scenario has a gas",
                    loaded.path.display()
                )));
            }
            let mut sim = Simulation::restore(built.config.clone(), state, threads)?;
            attach_gas(built, &mut sim, gas.as_ref())?;
            (sim, Some(step))
        }
        None => {
            let mut sim = Simulation::new(
                built.config.clone(),
                built.particles.clone(),
                built.dt_s,
                built.rng,
                threads,
            )?;
            attach_gas(built, &mut sim, None)?;
            sim.start_heat_ledger();
            if built.spec.output.net_forces {
                sim.record_net_forces();
            }
            truncate_series(&series_path, &header, 0, false)?;
            let row = format!("{}{}", series_row(&mut sim, built), observer.extra_row(&sim));
            let mut f = std::fs::OpenOptions::new()
                .append(true)
                .open(&series_path)
                .map_err(|e| Error::io("open", &series_path, e))?;
            writeln!(f, "{row}").map_err(|e| Error::io("write", &series_path, e))?;
            f.flush().map_err(|e| Error::io("write", &series_path, e))?;
            series.write(&sim.snapshot(), &meta)?;
            (sim, None)
        }
    };

    if built.spec.output.net_forces {
        sim.record_net_forces();
    }
    if dt_halvings > 0 {
        let dt_s = built.dt_s / f64::from(1u32 << dt_halvings.min(30));
        if sim.dt_s != dt_s {
            if !quiet {
                eprintln!(
                    "time step {:.3e} s → {:.3e} s ({dt_halvings} halving(s))",
                    sim.dt_s, dt_s
                );
            }
            sim.dt_s = dt_s;
        }
    }
    // Steps to the end time from where the run is (the time step may have changed since the start).
    let total_steps = sim.step + ((built.spec.time.end_time_s - sim.time_s) / sim.dt_s).round().max(0.0) as u64;
    let mut series_file = std::fs::OpenOptions::new()
        .append(true)
        .open(&series_path)
        .map_err(|e| Error::io("open", &series_path, e))?;
    let start = Instant::now();
    let start_step = sim.step;
    let mut last_report = Instant::now();
    let mut last_event = Instant::now();
    let stop_at = max_steps.map_or(total_steps, |m| (start_step + m).min(total_steps));
    observer.event(RunEvent::Started {
        step: sim.step,
        total_steps,
        resumed_from_step,
    });
    if !quiet && resumed_from_step.is_none() {
        eprintln!(
            "{}: {} particles, dt = {:.3e} s = {:.4} t_c, {} steps to t = {} s, {} thread(s)",
            built.spec.name,
            sim.particles.len(),
            sim.dt_s,
            sim.dt_s / built.contact_time_s,
            total_steps,
            built.spec.time.end_time_s,
            sim.threads()
        );
    }
    let every = |n: u64, k: u64| (n / k + 1) * k;
    // Snapshots for ParaView: at the start of a new run, every `snapshots_every_s`, and at the end.
    let snapshot_dir = out.join(crate::snapshot::SNAPSHOT_DIR);
    let snapshot_every = built
        .spec
        .output
        .snapshots_every_s
        .map(|every_s| crate::snapshot::every_steps(every_s, sim.dt_s));
    if snapshot_every.is_some() && resumed_from_step.is_none() {
        crate::snapshot::write_snapshot(&sim, &snapshot_dir)?;
    }
    let mut checkpoint_time_s = 0.0;
    let mut checkpoints_written = 0u64;
    let mut write_checkpoint = |sim: &Simulation, observer: &mut dyn RunObserver| -> Result<()> {
        let t = Instant::now();
        series.write(&sim.snapshot(), &meta)?;
        checkpoint_time_s += t.elapsed().as_secs_f64();
        checkpoints_written += 1;
        observer.event(RunEvent::Checkpointed { step: sim.step });
        Ok(())
    };
    let stop_requested = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let mut stopped = false;
    while sim.step < stop_at {
        if stop_requested() {
            stopped = true;
            break;
        }
        let next = every(sim.step, built.spec.output.series_every_steps)
            .min(every(sim.step, built.spec.output.checkpoint_every_steps))
            .min(every(sim.step, CHUNK_STEPS))
            .min(snapshot_every.map_or(u64::MAX, |k| every(sim.step, k)))
            .min(stop_at);
        sim.run_steps(next - sim.step)?;
        if snapshot_every.is_some_and(|k| sim.step % k == 0 || sim.step == total_steps) {
            crate::snapshot::write_snapshot(&sim, &snapshot_dir)?;
        }
        if sim.step % built.spec.output.series_every_steps == 0 {
            let row = format!("{}{}", series_row(&mut sim, built), observer.extra_row(&sim));
            writeln!(series_file, "{row}").map_err(|e| Error::io("write", &series_path, e))?;
        }
        if sim.step % built.spec.output.checkpoint_every_steps == 0 || sim.step == total_steps {
            series_file.flush().map_err(|e| Error::io("write", &series_path, e))?;
            write_checkpoint(&sim, observer)?;
        }
        if last_event.elapsed().as_secs_f64() >= 1.0 {
            last_event = Instant::now();
            observer.event(RunEvent::Progress {
                step: sim.step,
                time_s: sim.time_s,
                steps_per_s: (sim.step - start_step) as f64 / start.elapsed().as_secs_f64(),
            });
        }
        if !quiet && last_report.elapsed().as_secs_f64() > 5.0 {
            last_report = Instant::now();
            let rate = (sim.step - start_step) as f64 / start.elapsed().as_secs_f64();
            eprintln!(
                "step {}/{} t = {:.4} s, {:.0} steps/s, KE = {:.3e} J",
                sim.step,
                total_steps,
                sim.time_s,
                rate,
                sim.particles.kinetic_energy_j()
            );
        }
    }
    if sim.step % built.spec.output.checkpoint_every_steps != 0 && sim.step != total_steps {
        // Stopped early (--max-steps or a stop request): keep everything computed so far.
        series_file.flush().map_err(|e| Error::io("write", &series_path, e))?;
        write_checkpoint(&sim, observer)?;
    }
    let wall = start.elapsed().as_secs_f64();
    let (top, mean) = sim.bed_height_m();
    let summary = Summary {
        scenario: built.spec.name.clone(),
        particles: sim.particles.len(),
        step: sim.step,
        time_s: sim.time_s,
        dt_s: sim.dt_s,
        dt_over_contact_time: sim.dt_s / built.contact_time_s,
        finished: sim.step >= total_steps,
        stopped,
        kinetic_energy_j: sim.particles.kinetic_energy_j(),
        bed_top_m: top,
        mean_height_m: mean,
        wall_time_s: wall,
        checkpoint_time_s,
        checkpoints_written,
        steps_per_s: (sim.step - start_step) as f64 / wall.max(1e-9),
        resumed_from_step,
        stage_timings_s: sim.stage_timings(),
        neighbor_builds: sim.neighbor_builds(),
        neighbor_refilters: sim.neighbor_refilters(),
        build: crate::provenance::build_id(),
        cpu_path: crate::provenance::cpu_path().to_string(),
        biot_numbers: biot_numbers(&sim),
    };
    if summary.finished {
        let json = serde_json::to_string_pretty(&summary).expect("summary serialises");
        write_atomic(&out.join("summary.json"), json.as_bytes())?;
    }
    Ok((summary, sim))
}

#[cfg(test)]
mod tests {
    use super::truncate_series;

    #[test]
    fn a_fresh_start_keeps_no_row_of_an_attempt_killed_before_its_first_checkpoint() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("series.csv");
        // An attempt killed after its step-0 row and before its step-0 checkpoint.
        std::fs::write(&path, "step,time_s\n0,0e0\n").expect("write");
        truncate_series(&path, "step,time_s", 0, false).expect("truncate");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "step,time_s\n");
        // Resuming from step 10 keeps the rows up to it and drops a row cut short.
        std::fs::write(&path, "step,time_s\n0,0e0\n10,1e0\n20,2e0\n30\n").expect("write");
        truncate_series(&path, "step,time_s", 10, true).expect("truncate");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "step,time_s\n0,0e0\n10,1e0\n");
    }
}
