//! The engine's force loop runs either its x86-64 baseline compilation or its x86-64-v3 one (AVX2, FMA, BMI),
//! chosen at run time; `GRANFLOW_CPU=baseline` forces the first. Both must give the same bits: the same short runs
//! through the real binary, one each way, end in identical states (every array, contact history included).

mod common;

use std::path::Path;
use std::process::Command;

use granflow::checkpoint::CheckpointSeries;
use granflow::engine::state::{SimState, first_difference};

/// A drum with Thornton + Walton-Braun contacts and baffles, and a Hertz + Mindlin drum with rolling resistance
/// (the Hertz kernel holds the one explicit fused multiply-add).
const SCENARIOS: &[(&str, &str)] = &[
    (
        "thornton-drum",
        r#"
name: thornton-drum
domain: { lo_m: [-0.041, -0.041, 0.0], hi_m: [0.041, 0.041, 0.012], periodic: [false, false, true] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.3, friction_coefficient: 0.4, yield_force_n: 0.02 }
contact: { normal: { thornton: {} }, tangential: { walton_braun: {} } }
walls:
  - drum:
      name: drum
      species: glass
      axis_point_m: [0.0, 0.0, 0.0]
      axis: [0.0, 0.0, 1.0]
      radius_m: 0.04
      rotation_rpm: 120.0
      baffles:
        - traditional: { count: 4, length_m: 0.01, half_thickness_m: 0.001, tilt_deg: 20.0 }
fill:
  - lattice: { species: glass, spacing_m: 0.003, lo_m: [-0.04, -0.04, 0.0], hi_m: [0.04, 0.002, 0.012], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }
time: { dt_s: 1.0e-5, end_time_s: 0.02 }
output: { checkpoint_every_steps: 1000, keep_checkpoints: 1, series_every_steps: 100 }
seed: 3
"#,
    ),
    (
        "hertz-drum",
        r#"
name: hertz-drum
domain: { lo_m: [-0.021, -0.021, 0.0], hi_m: [0.021, 0.021, 0.0064], periodic: [false, false, true] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: red, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e6, poisson_ratio: 0.3, friction_coefficient: 0.4, rolling_friction_coefficient: 0.05 }
contact: { normal: { hertz: { restitution: 0.7 } }, tangential: mindlin, rolling: constant_directional_torque }
walls:
  - drum: { name: drum, species: red, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: 0.02, rotation_rpm: 60.0 }
fill:
  - lattice: { species: red, spacing_m: 0.0032, lo_m: [-0.02, -0.02, 0.0], hi_m: [0.02, 0.0, 0.0064], origin_m: [0.0016, 0.0016, 0.0016], inside_drum: drum }
time: { dt_s: 2.0e-5, end_time_s: 0.04 }
output: { checkpoint_every_steps: 1000, keep_checkpoints: 1, series_every_steps: 100 }
seed: 5
"#,
    ),
];

fn run(dir: &Path, scenario: &str, out: &str, threads: &str, baseline: bool) -> SimState {
    let mut command = Command::new(env!("CARGO_BIN_EXE_granflow"));
    command
        .args(["simulate", scenario, "--out", out, "--threads", threads, "--quiet"])
        .current_dir(dir);
    if baseline {
        command.env(granflow::machine::CPU_ENV, "baseline");
    } else {
        command.env_remove(granflow::machine::CPU_ENV);
    }
    let output = command.output().expect("granflow runs");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    // The summary names the path taken: the forced baseline, or the fast path wherever the CPU has it.
    let summary: serde_json::Value = serde_json::from_slice(&output.stdout).expect("the summary is JSON");
    let expected = if baseline || !granflow::machine::cpu_fast_path() {
        "x86-64"
    } else {
        "x86-64-v3"
    };
    assert_eq!(summary["cpu_path"], expected, "{out}");
    CheckpointSeries::new(dir.join(out), 1)
        .latest_valid()
        .expect("lists")
        .expect("a checkpoint")
        .state
}

#[test]
fn baseline_and_fast_path_give_the_same_bits() {
    if !granflow::machine::cpu_fast_path() {
        eprintln!("this CPU has no x86-64-v3 instructions: both runs take the baseline path");
    }
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    for (name, yaml) in SCENARIOS {
        let file = format!("{name}.yaml");
        std::fs::write(dir.join(&file), yaml).expect("write");
        for threads in ["1", "2"] {
            let fast = run(dir, &file, &format!("{name}-fast-{threads}"), threads, false);
            let base = run(dir, &file, &format!("{name}-baseline-{threads}"), threads, true);
            assert!(fast.step > 0);
            if let Some(diff) = first_difference(&fast, &base) {
                panic!("{name} on {threads} thread(s): the baseline and fast paths differ: {diff}");
            }
        }
    }
}
