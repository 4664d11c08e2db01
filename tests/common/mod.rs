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
