//! Helpers shared by the integration tests: build scenarios from YAML text, run the real binary.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

use granflow::engine::Simulation;
use granflow::scenario::{self, BuiltScenario};

pub fn built(yaml: &str) -> BuiltScenario {
    let path = Path::new("test-scenario.yaml");
    scenario::build(scenario::parse(yaml, path).expect("test YAML parses"), path).expect("test scenario is valid")
}

pub fn simulation(b: &BuiltScenario, threads: usize) -> Simulation {
    Simulation::new(b.config.clone(), b.particles.clone(), b.dt_s, b.rng, threads).expect("initial state is sound")
}

/// Runs the granflow binary built for this test run.
pub fn granflow(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("the granflow binary runs")
}

/// What a granflow run that succeeded printed.
pub struct Printed {
    pub stdout: String,
    pub stderr: String,
}

/// Runs the granflow binary and fails the test unless it succeeds.
pub fn granflow_ok(args: &[&str], cwd: &Path) -> Printed {
    let out = granflow(args, cwd);
    assert!(
        out.status.success(),
        "granflow {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Printed {
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Runs the granflow binary and fails the test unless it exits with 2 (bad input) and its stderr holds `message`.
pub fn granflow_fails_with_2(args: &[&str], cwd: &Path, message: &str) {
    let out = granflow(args, cwd);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "granflow {args:?}: {stderr}");
    assert!(
        stderr.contains(message),
        "granflow {args:?}: expected `{message}` in: {stderr}"
    );
}

/// The newest valid checkpoint's state in a run directory.
pub fn final_state(dir: &Path) -> granflow::engine::state::SimState {
    granflow::checkpoint::CheckpointSeries::new(dir, 2)
        .latest_valid()
        .expect("lists")
        .expect("a checkpoint exists")
        .state
}

/// Runs the scenario `yaml` through the binary in `dir`: uninterrupted into `whole/`, and into `split/` stopped at
/// `stop_step` on two threads then resumed in a fresh process; returns the final states (whole, split).
pub fn whole_and_resumed(
    dir: &Path,
    yaml: &str,
    stop_step: u64,
) -> (granflow::engine::state::SimState, granflow::engine::state::SimState) {
    std::fs::write(dir.join("scenario.yaml"), yaml).expect("write scenario");
    let run = |args: &[&str]| {
        let out = granflow(args, dir);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let stop = stop_step.to_string();
    run(&["simulate", "scenario.yaml", "--out", "whole", "--quiet"]);
    run(&[
        "simulate",
        "scenario.yaml",
        "--out",
        "split",
        "--max-steps",
        &stop,
        "--threads",
        "2",
        "--quiet",
    ]);
    run(&["simulate", "scenario.yaml", "--out", "split", "--quiet"]);
    (final_state(&dir.join("whole")), final_state(&dir.join("split")))
}

/// The particles' thermal energy Σ m c T of a state whose particles share one heat capacity, J.
pub fn thermal_energy_j(s: &granflow::engine::state::SimState, heat_capacity_j_per_kg_k: f64) -> f64 {
    s.particles
        .mass_kg
        .iter()
        .zip(&s.particles.temperature_k)
        .map(|(m, t)| m * heat_capacity_j_per_kg_k * t)
        .sum()
}

/// A wet rotating drum: two species of 3 mm beads (contact angles 20° and 50°) carrying V̂ = 0.01 of water each,
/// the lattice collapsing into the drum's bed while it turns, the bed's surface sprayed up to V̂ = 0.02 every 50
/// steps, with bridges to the drum and its baffles as well.
pub const WET_DRUM: &str = r#"
name: wet-drum
domain: { lo_m: [-0.041, -0.041, 0.0], hi_m: [0.041, 0.041, 0.012], periodic: [false, false, true] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: a, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.3, friction_coefficient: 0.4, contact_angle_deg: 20.0, liquid_content: 0.01 }
  - { name: b, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.3, friction_coefficient: 0.4, contact_angle_deg: 50.0, liquid_content: 0.01 }
contact: { normal: { hertz: { restitution: 0.6 } }, tangential: mindlin }
cohesion: { liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.001, walls: true, spray: { max_liquid_content: 0.02, every_steps: 50 } } }
walls:
  - drum:
      name: drum
      species: a
      axis_point_m: [0.0, 0.0, 0.0]
      axis: [0.0, 0.0, 1.0]
      radius_m: 0.04
      rotation_rpm: 120.0
      baffles:
        - traditional: { count: 4, length_m: 0.01, half_thickness_m: 0.001, tilt_deg: 0.0 }
fill:
  - lattice: { species: a, spacing_m: 0.0032, lo_m: [-0.04, -0.04, 0.0], hi_m: [-0.001, 0.01, 0.0105], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }
  - lattice: { species: b, spacing_m: 0.0032, lo_m: [0.0, -0.04, 0.0], hi_m: [0.04, 0.01, 0.0105], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }
time: { dt_s: 1.0e-5, end_time_s: 0.08 }
output: { checkpoint_every_steps: 2000, keep_checkpoints: 2, series_every_steps: 500 }
seed: 5
"#;

/// The scenario's simulation with its gas attached.
pub fn with_gas(b: &BuiltScenario) -> Simulation {
    with_gas_on(b, 1)
}

/// The scenario's simulation on `threads` with its gas attached and its ledgers started, as a new run starts.
pub fn with_gas_on(b: &BuiltScenario, threads: usize) -> Simulation {
    let mut sim = simulation(b, threads);
    if let Some(setup) = &b.gas {
        let p = &sim.particles;
        let gas = setup.coupling(&p.position_m, &p.radius_m).expect("the gas builds");
        sim.attach_gas(gas);
        sim.start_drying_ledger();
    }
    sim.start_heat_ledger();
    sim
}

/// The `fill:` entries placing one sphere of species `s` at each position with its own temperature.
pub fn explicit_fills(fills: &[(f64, [f64; 3])]) -> String {
    fills
        .iter()
        .map(|(t, x)| {
            format!(
                "  - explicit: {{ species: s, positions_m: [[{}, {}, {}]], temperature_k: {t} }}\n",
                x[0], x[1], x[2]
            )
        })
        .collect()
}

/// A small kiln (seed 000 §5.1.1, §5.2): the gas is solved only inside the drum (cells whose centres lie outside it
/// are blocked) with the reference pressure on top, its wall drags the gas round with it, and the wall heats neither
/// particles nor gas before `from_s`, then both.
pub const KILN: &str = r#"
name: kiln
domain: { lo_m: [-0.021, -0.021, 0.0], hi_m: [0.021, 0.021, 0.006], periodic: [false, false, true] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, material: glass, radius_m: 0.0015, youngs_modulus_pa: 1.0e7 }
contact: { normal: { hertz: { restitution: 0.5 } }, tangential: mindlin }
walls:
  - drum: { name: drum, species: glass, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: 0.02, rotation_rpm: 30.0 }
fill:
  - lattice: { species: glass, spacing_m: 0.0031, lo_m: [-0.02, -0.02, 0.0], hi_m: [0.02, -0.005, 0.006], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }
time: { dt_s: 2.0e-5, end_time_s: 0.2 }
gas:
  density_kg_per_m3: 1.23
  viscosity_pa_s: 1.8e-5
  cells: [10, 10, 1]
  dem_steps_per_gas_step: 20
  outside_drum: drum
  drag_coupling: semi_implicit
heat:
  initial_temperature_k: 300.0
  walls: { drum: { temperature_k: 400.0, from_s: 0.02 } }
"#;

/// [`KILN`] with wet beads (V/R³ = 0.02, bridges to each other and to the wall), the wall hot from the start, gas
/// lenses and drying: every particle and gas field a run can carry.
pub fn wet_drying_kiln() -> String {
    KILN.replace(
        "youngs_modulus_pa: 1.0e7 }",
        "youngs_modulus_pa: 1.0e7, contact_angle_deg: 0.0, liquid_content: 0.02 }",
    )
    .replace(
        "walls:\n  - drum",
        "cohesion: { liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.001, walls: true } }\nwalls:\n  - drum",
    )
    .replace("from_s: 0.02 } }", "from_s: 0.0 } }\n  gas: { lens_conduction: {} }")
        + "drying: { evaporation_coefficient: 1.0 }\n"
}

/// The number of distinct colours of the 1200 × 900 PNG at `path` (fails on another size).
pub fn png_colours(path: &Path) -> usize {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().expect("a PNG");
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).expect("its pixels");
    assert_eq!((info.width, info.height), (1200, 900), "{}", path.display());
    let stride = info.line_size / info.width as usize;
    let mut colours = std::collections::HashSet::new();
    for px in pixels[..info.buffer_size()].chunks(stride) {
        colours.insert(px.to_vec());
    }
    colours.len()
}

/// Whether the SVG text at `svg` holds `text` as a text element's content (plotters writes each on its own line).
pub fn svg_has(svg: &str, text: &str) -> bool {
    svg.lines().any(|l| l.trim() == text)
}

/// Runs `granflow worker <dir>` and kills it with SIGKILL after `delay`, unless it finishes first; returns whether
/// it had finished.
pub fn worker_killed_after(dir: &Path, delay: std::time::Duration) -> bool {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(["worker", dir.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(delay);
    let finished = matches!(child.try_wait(), Ok(Some(_)));
    let _ = child.kill();
    let _ = child.wait();
    finished
}

/// The `base:` section (with its key) of the small drum campaigns of the campaign tests: a slice of a 40 mm drum at
/// 30 rpm, red beads on the left and blue on the right of a lattice filled up to the height `fill_top_m`, run to
/// `end_time_s` at dt = 20 µs with a series row every `series_every_steps`.
pub fn drum_slice_base(fill_top_m: f64, end_time_s: f64, series_every_steps: u64) -> String {
    format!(
        r#"base:
  domain: {{ lo_m: [-0.021, -0.021, 0.0], hi_m: [0.021, 0.021, 0.0064], periodic: [false, false, true] }}
  gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
  species:
    - {{ name: red, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e6, poisson_ratio: 0.3, friction_coefficient: 0.4 }}
    - {{ name: blue, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e6, poisson_ratio: 0.3, friction_coefficient: 0.4 }}
  contact: {{ normal: {{ hertz: {{ restitution: 0.7 }} }}, tangential: mindlin }}
  walls:
    - drum: {{ name: drum, species: red, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: 0.02, rotation_rpm: 30.0 }}
  fill:
    - lattice: {{ species: red, spacing_m: 0.0032, lo_m: [-0.02, -0.02, 0.0], hi_m: [0.0, {fill_top_m:?}, 0.0064], origin_m: [0.0016, 0.0016, 0.0016], inside_drum: drum }}
    - lattice: {{ species: blue, spacing_m: 0.0032, lo_m: [0.0, -0.02, 0.0], hi_m: [0.02, {fill_top_m:?}, 0.0064], origin_m: [0.0016, 0.0016, 0.0016], inside_drum: drum }}
  time: {{ dt_s: 2.0e-5, end_time_s: {end_time_s:?} }}
  output: {{ series_every_steps: {series_every_steps} }}
"#
    )
}

/// The series of a campaign's only job (in `out`) as columns by name.
pub fn only_job_series(out: &Path) -> std::collections::BTreeMap<String, Vec<f64>> {
    let job = std::fs::read_dir(out.join("jobs"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let text = std::fs::read_to_string(job.join("series.csv")).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(str::to_string).collect();
    let mut columns: std::collections::BTreeMap<String, Vec<f64>> =
        names.iter().map(|n| (n.clone(), Vec::new())).collect();
    for line in lines {
        for (name, field) in names.iter().zip(line.split(',')) {
            columns.get_mut(name).unwrap().push(field.parse().unwrap());
        }
    }
    columns
}
