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
