//! Shared preparations (`prepare` in a campaign file, `campaign::prepare`): a wet, gas-fluidized bed whose bridges
//! and inflow start at 0.01 s, swept over surface tension × inlet velocity (4 jobs) with the first 0.01 s prepared
//! once. Every job must end bit-identical to its own scenario run from the start by `granflow simulate`; a
//! preparation shared across a parameter that acts before its end must fail every job of the group as a
//! configuration error naming the parameters.

mod common;

use std::path::Path;
use std::time::Duration;

use common::{final_state, granflow, worker_killed_after};
use granflow::engine::state::first_difference;
use rand::{RngExt, SeedableRng};

/// The campaign: bridges and inflow from `start_s`, prepared to `until_s`, jobs ending at `end_time_s`.
fn campaign(start_s: f64, until_s: f64, end_time_s: f64) -> String {
    format!(
        r#"
name: prepared-bed
base:
  domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.03, 0.1, 0.0027], periodic: [true, false, false] }}
  pseudo_2d: true
  gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
  species:
    - {{ name: left, radius_m: 0.00135, density_kg_per_m3: 2000.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.33, friction_coefficient: 0.3, liquid_content: 0.01 }}
    - {{ name: right, radius_m: 0.00135, density_kg_per_m3: 2000.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.33, friction_coefficient: 0.3, liquid_content: 0.01 }}
  contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
  walls: [ {{ box: {{ species: left }} }} ]
  fill:
    - lattice: {{ species: left, spacing_m: 0.003, lo_m: [0.0, 0.0015, 0.0], hi_m: [0.015, 0.0315, 0.0027], origin_m: [0.0015, 0.0015, 0.00135] }}
    - lattice: {{ species: right, spacing_m: 0.003, lo_m: [0.015, 0.0015, 0.0], hi_m: [0.03, 0.0315, 0.0027], origin_m: [0.0015, 0.0015, 0.00135] }}
  cohesion:
    liquid_bridge: {{ surface_tension_n_per_m: 0.02, viscosity_pa_s: 0.001, bridges_from_s: {start_s} }}
  gas:
    density_kg_per_m3: 1.23
    viscosity_pa_s: 1.8e-5
    cells: [4, 12, 1]
    sides: {{ y_low: {{ inlet: {{ superficial_velocity_m_per_s: 1.0 }} }}, y_high: outlet }}
    dem_steps_per_gas_step: 5
    inflow_ramp: {{ start_s: {start_s}, duration_s: 0.005 }}
  time: {{ dt_s: 2.0e-5, end_time_s: {end_time_s} }}
  output: {{ series_every_steps: 10 }}
sweep:
  grid:
    - {{ param: cohesion.liquid_bridge.surface_tension_n_per_m, name: surface_tension_n_per_m, values: [0.02, 0.08] }}
    - {{ param: gas.sides.y_low.inlet.superficial_velocity_m_per_s, name: u_m_per_s, values: [0.5, 1.5] }}
metrics: [intensity_of_segregation, pressure_drop_mean_pa]
analysis: {{ mixing_species: left, mixing_every_steps: 100, average_from_s: 0.015 }}
prepare: {{ until_s: {until_s}, shared_across: [surface_tension_n_per_m, u_m_per_s] }}
checkpoint: {{ every_steps: 400 }}
executor: {{ local: {{ max_parallel: 2 }} }}
"#
    )
}

fn job_dirs(out: &Path) -> Vec<std::path::PathBuf> {
    let mut dirs: Vec<_> = std::fs::read_dir(out.join("jobs"))
        .expect("jobs directory")
        .map(|e| e.expect("entry").path())
        .collect();
    dirs.sort();
    dirs
}

#[test]
fn prepared_jobs_end_bit_identical_to_jobs_run_from_the_start() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("bed.yaml"), campaign(0.01, 0.01, 0.03)).expect("write");
    let out = granflow(&["run", "bed.yaml", "--out", "bed", "--quiet"], dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    // One preparation for the four jobs, run at both ends of the shared axes and found identical.
    let preparations: Vec<_> = std::fs::read_dir(dir.join("bed/preparations"))
        .expect("preparations directory")
        .map(|e| e.expect("entry").path())
        .collect();
    assert_eq!(preparations.len(), 1, "{preparations:?}");
    let verdict = std::fs::read_to_string(preparations[0].join("prepared.json")).expect("verdict");
    assert!(
        verdict.contains("\"difference\": null") && verdict.contains("\"step\": 500"),
        "{verdict}"
    );
    assert!(preparations[0].join("first").is_dir() && preparations[0].join("last").is_dir());

    let jobs = job_dirs(&dir.join("bed"));
    assert_eq!(jobs.len(), 4);
    let mut pressure_drops = Vec::new();
    for job in &jobs {
        let result = std::fs::read_to_string(job.join("result.json")).expect("result");
        assert!(result.contains("\"prepare\""), "{result}");
        let value: serde_json::Value = serde_json::from_str(&result).expect("json");
        let dp = value["metrics"]
            .as_array()
            .expect("metrics")
            .iter()
            .find(|m| m["name"] == "pressure_drop_mean_pa")
            .and_then(|m| m["value"].as_f64())
            .expect("pressure drop");
        pressure_drops.push(dp);

        // The same scenario from the start, in one process.
        let scratch = dir.join(format!("scratch-{}", job.file_name().unwrap().to_string_lossy()));
        let scenario = job.join("scenario.json");
        let run = granflow(
            &[
                "simulate",
                scenario.to_str().unwrap(),
                "--out",
                scratch.to_str().unwrap(),
                "--quiet",
            ],
            dir,
        );
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let (prepared, whole) = (final_state(job), final_state(&scratch));
        assert_eq!(prepared.step, 1500);
        assert_eq!(first_difference(&prepared, &whole), None, "{}", job.display());
        // Every series row, the prepared part included (the job's rows add the mixing columns).
        let job_rows = std::fs::read_to_string(job.join("series.csv")).expect("series");
        let whole_rows = std::fs::read_to_string(scratch.join("series.csv")).expect("series");
        assert_eq!(job_rows.lines().count(), whole_rows.lines().count());
        for (a, b) in job_rows.lines().zip(whole_rows.lines()).skip(1) {
            assert!(a.starts_with(&format!("{b},")), "{a}\n{b}");
        }
    }
    // The jobs do differ after the preparation: the inlet velocity sets the pressure drop.
    let spread = pressure_drops.iter().cloned().fold(f64::MIN, f64::max)
        - pressure_drops.iter().cloned().fold(f64::MAX, f64::min);
    assert!(spread > 1.0, "{pressure_drops:?}");
}

#[test]
fn a_preparation_shared_across_a_parameter_that_acts_before_its_end_fails_its_jobs() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // The bridges and the inflow start at 0.005 s, before the preparation ends: both swept parameters act.
    std::fs::write(dir.join("bed.yaml"), campaign(0.005, 0.01, 0.03)).expect("write");
    let out = granflow(&["run", "bed.yaml", "--out", "bed", "--quiet"], dir);
    assert!(!out.status.success());
    let status = granflow(&["status", "bed"], dir);
    let text = String::from_utf8_lossy(&status.stdout);
    assert!(text.contains("0 done") && text.contains("4 failed"), "{text}");
    assert_eq!(text.matches("config: ").count(), 4, "{text}");
    assert!(
        text.contains("key `prepare.shared_across`: the preparation to 0.01 s differs")
            && text.contains("gas.sides.y_low.inlet.superficial_velocity_m_per_s acts before then"),
        "{text}"
    );
    // No job ran past the preparation.
    for job in job_dirs(&dir.join("bed")) {
        assert!(!job.join("result.json").exists());
        assert!(!job.join("series.csv").exists(), "{}", job.display());
    }
}

#[test]
fn a_prepared_job_killed_at_random_moments_ends_as_the_uninterrupted_one() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // Long enough (a 0.2 s preparation of a 0.3 s job) for kills to land while preparing, adopting and running.
    std::fs::write(dir.join("bed.yaml"), campaign(0.2, 0.2, 0.3)).expect("write");
    let out = granflow(&["run", "bed.yaml", "--out", "reference", "--quiet"], dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let reference = job_dirs(&dir.join("reference")).remove(0);

    // The same job alone in a fresh campaign directory, its worker killed again and again.
    let job = dir.join("killed/jobs").join(reference.file_name().unwrap());
    std::fs::create_dir_all(&job).expect("job directory");
    std::fs::copy(reference.join("job.json"), job.join("job.json")).expect("copy job");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut kills = 0;
    let mut kills_while_preparing = 0;
    for _ in 0..60 {
        if job.join("result.json").exists() {
            break;
        }
        let preparing = !job.join("series.csv").exists();
        if !worker_killed_after(&job, Duration::from_millis(rng.random_range(20..250))) {
            kills += 1;
            kills_while_preparing += usize::from(preparing);
        }
    }
    for _ in 0..5 {
        if job.join("result.json").exists() {
            break;
        }
        worker_killed_after(&job, Duration::from_secs(60));
    }
    assert!(
        job.join("result.json").exists(),
        "the job did not finish: {}",
        std::fs::read_to_string(job.join("worker.log")).unwrap_or_default()
    );
    assert!(
        kills >= 5 && kills_while_preparing >= 2,
        "{kills} kills, {kills_while_preparing} while preparing: make the job longer"
    );
    eprintln!("{kills} kills, {kills_while_preparing} while preparing");
    let metrics = |d: &Path| -> serde_json::Value {
        let text = std::fs::read_to_string(d.join("result.json")).expect("result");
        serde_json::from_str::<serde_json::Value>(&text).expect("json")["metrics"].clone()
    };
    assert_eq!(metrics(&job), metrics(&reference), "metrics after {kills} kills");
    assert_eq!(
        first_difference(&final_state(&job), &final_state(&reference)),
        None,
        "final states after {kills} kills"
    );
    let series = |d: &Path| std::fs::read_to_string(d.join("series.csv")).expect("series");
    assert_eq!(series(&job), series(&reference), "series after {kills} kills");
}
