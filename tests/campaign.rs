//! Campaigns through the real binary, in temporary directories: a campaign runs to completion and its database
//! holds every job with its metrics; the pivot returns the expected grid; adding sweep values runs only the new
//! jobs; changing a parameter is refused without --force; a worker killed with `kill -9` at random moments is
//! resumed to a result bit-identical to an uninterrupted run; `kill -9` of the dispatcher loses nothing.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use common::{drum_slice_base, granflow, worker_killed_after};
use granflow::checkpoint::CheckpointSeries;
use granflow::engine::state::first_difference;
use rand::{RngExt, SeedableRng};

/// A small drum campaign: 2 speeds × 2 fill levels, a fraction of a second each.
fn campaign(speeds: &str, end_time_s: f64) -> String {
    let base = drum_slice_base(0.0, end_time_s, 500);
    format!(
        r#"
name: mini
seed: 7
{base}sweep:
  grid:
    - {{ param: walls.0.drum.rotation_rpm, name: rotation_rpm, values: {speeds} }}
    - zip:
        - {{ param: fill.0.lattice.hi_m.1, name: fill_top_m, values: [-0.006, 0.0] }}
        - {{ param: fill.1.lattice.hi_m.1, values: [-0.006, 0.0] }}
metrics: [lacey_index, intensity_of_segregation, kinetic_energy_j, coordination_number, height_mixing_index]
analysis: {{ mixing_species: red }}
executor: {{ local: {{ max_parallel: 2 }} }}
checkpoint: {{ every_steps: 1000, keep: 2 }}
"#
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn ok(args: &[&str], cwd: &Path) -> String {
    let out = granflow(args, cwd);
    assert!(
        out.status.success(),
        "granflow {args:?} exited {:?}: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn sql(dir: &Path, query: &str) -> String {
    ok(
        &["query", dir.to_str().unwrap(), "--sql", query, "--format", "csv"],
        dir,
    )
}

#[test]
fn a_campaign_runs_stores_every_job_and_pivots() {
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "mini.yaml", &campaign("[20.0, 60.0]", 0.06));
    let out = tmp.path().join("out");
    ok(
        &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
        tmp.path(),
    );

    let counts = sql(&out, "SELECT status, COUNT(*) FROM jobs GROUP BY status");
    assert!(counts.contains("done,4"), "{counts}");
    let metrics = sql(&out, "SELECT COUNT(*) FROM metrics WHERE value IS NOT NULL");
    assert!(metrics.contains("20"), "4 jobs × 5 metrics: {metrics}");
    for id in sql(&out, "SELECT job_id FROM jobs").lines().skip(1) {
        let dir = out.join("jobs").join(id.trim());
        assert!(
            dir.join("result.json").exists() && dir.join("series.h5").exists(),
            "{}",
            dir.display()
        );
    }

    // The Lacey index over speed and fill level as CSV, with `filters` (e.g. `--where PARAM=VALUE`).
    let lacey_pivot = |filters: &[&str]| {
        let mut args = vec![
            "query",
            out.to_str().unwrap(),
            "--pivot",
            "rotation_rpm",
            "fill_top_m",
            "--metric",
            "lacey_index",
            "--format",
            "csv",
        ];
        args.extend_from_slice(filters);
        ok(&args, tmp.path())
    };
    let pivot = lacey_pivot(&[]);
    let lines: Vec<&str> = pivot.lines().collect();
    assert_eq!(lines.len(), 3, "a header and one row per fill level:\n{pivot}");
    assert!(lines[0].contains("20") && lines[0].contains("60"), "{pivot}");
    for row in &lines[1..] {
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells.len(), 3, "{pivot}");
        for c in &cells[1..] {
            let v: f64 = c
                .trim()
                .parse()
                .unwrap_or_else(|_| panic!("a number in every cell: {pivot}"));
            assert!((-0.5..=1.01).contains(&v), "a Lacey index: {v}");
        }
    }

    // --where keeps one speed's jobs: its column filled, the other's empty.
    let filtered = lacey_pivot(&["--where", "rotation_rpm=20"]);
    for row in filtered.lines().skip(1) {
        let cells: Vec<&str> = row.split(',').collect();
        assert!(!cells[1].is_empty() && cells[2].is_empty(), "{filtered}");
    }
    let export = ok(&["export", out.to_str().unwrap(), "--format", "csv"], tmp.path());
    assert_eq!(export.lines().count(), 5, "{export}");
    // Parameters in the sweep's order, the zipped partner (no axis name: its path) beside its named axis.
    assert!(
        export.starts_with("job_id,status,param.rotation_rpm,param.fill_top_m,param.fill[1].lattice.hi_m[1],metric."),
        "{export}"
    );
    let status = ok(&["status", out.to_str().unwrap()], tmp.path());
    assert!(status.contains("4 done"), "{status}");

    // Adding a sweep value runs only the new jobs.
    std::fs::write(&file, campaign("[20.0, 60.0, 90.0]", 0.06)).unwrap();
    let before = sql(&out, "SELECT job_id, finished_at FROM jobs ORDER BY job_id");
    ok(
        &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
        tmp.path(),
    );
    let after = sql(&out, "SELECT job_id, finished_at FROM jobs ORDER BY job_id");
    for line in before.lines().skip(1) {
        assert!(after.contains(line), "job {line} was not touched again");
    }
    assert!(sql(&out, "SELECT COUNT(*) FROM jobs WHERE status = 'done'").contains('6'));
    let attempts = sql(&out, "SELECT MAX(attempt) FROM jobs");
    assert!(attempts.lines().nth(1) == Some("1"), "every job ran once: {attempts}");

    // Changing a parameter of existing jobs makes new jobs and is refused without --force.
    std::fs::write(&file, campaign("[20.0, 60.0, 90.0]", 0.08)).unwrap();
    let refused = granflow(
        &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
        tmp.path(),
    );
    assert_eq!(
        refused.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&refused.stderr)
    );
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--force"));
}

#[test]
fn workers_killed_at_random_moments_resume_bit_identically() {
    let tmp = tempfile::tempdir().unwrap();
    // GRANFLOW_KILL_TRIALS asks for more kills (scripts/kill-test.sh); the job is made long enough for them.
    let trials: usize = std::env::var("GRANFLOW_KILL_TRIALS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10);
    let file = write(
        tmp.path(),
        "mini.yaml",
        &campaign("[60.0]", (0.8 * trials as f64).max(8.0)),
    );
    let reference = tmp.path().join("reference");
    ok(
        &[
            "run",
            file.to_str().unwrap(),
            "--out",
            reference.to_str().unwrap(),
            "--quiet",
        ],
        tmp.path(),
    );
    let id = sql(&reference, "SELECT job_id FROM jobs ORDER BY ordinal LIMIT 1")
        .lines()
        .nth(1)
        .unwrap()
        .trim()
        .to_string();
    let ref_dir = reference.join("jobs").join(&id);

    let dir = tmp.path().join("killed");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(ref_dir.join("job.json"), dir.join("job.json")).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut kills = 0;
    for _ in 0..4 * trials.max(10) {
        if dir.join("result.json").exists() {
            break;
        }
        let delay = Duration::from_millis(rng.random_range(20..250));
        if !worker_killed_after(&dir, delay) {
            kills += 1;
        }
    }
    while !dir.join("result.json").exists() {
        worker_killed_after(&dir, Duration::from_secs(60));
    }
    assert!(
        kills >= 10,
        "only {kills} kills landed before the job finished; make it longer"
    );
    eprintln!("{kills} kills before the job finished");

    let read = |d: &Path| std::fs::read_to_string(d.join("result.json")).unwrap();
    let metrics = |text: &str| -> serde_json::Value {
        serde_json::from_str::<serde_json::Value>(text).unwrap()["metrics"].clone()
    };
    assert_eq!(
        metrics(&read(&dir)),
        metrics(&read(&ref_dir)),
        "metrics after {kills} kills"
    );
    let last = |d: &Path| CheckpointSeries::new(d, 2).latest_valid().unwrap().unwrap().state;
    let (a, b) = (last(&dir), last(&ref_dir));
    assert_eq!(first_difference(&a, &b), None, "final states after {kills} kills");
    let series = |d: &Path| std::fs::read_to_string(d.join("series.csv")).unwrap();
    assert_eq!(series(&dir), series(&ref_dir), "time series after {kills} kills");
}

/// Command lines of running processes that contain `needle` (read from /proc, so no procps is needed).
fn processes_mentioning(needle: &str) -> Vec<String> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        if let Ok(cmdline) = std::fs::read(entry.path().join("cmdline")) {
            let text = String::from_utf8_lossy(&cmdline).replace('\0', " ");
            if text.contains(needle) {
                found.push(text);
            }
        }
    }
    found
}

#[test]
fn killing_the_dispatcher_loses_nothing_and_resume_finishes() {
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "mini.yaml", &campaign("[20.0, 60.0]", 0.15));
    let out = tmp.path().join("out");
    let mut dispatcher = Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    dispatcher.kill().unwrap();
    dispatcher.wait().unwrap();
    // Its workers notice (their stdin closes) and stop at once.
    std::thread::sleep(Duration::from_millis(500));
    let left = processes_mentioning(out.join("jobs").to_str().unwrap());
    assert!(left.is_empty(), "workers outlived their dispatcher: {left:?}");
    ok(&["resume", out.to_str().unwrap(), "--quiet"], tmp.path());
    assert!(sql(&out, "SELECT COUNT(*) FROM jobs WHERE status = 'done'").contains('4'));
    assert!(
        sql(&out, "SELECT COUNT(*) FROM metrics").contains("20"),
        "no metric lost or duplicated"
    );
    assert!(sql(&out, "PRAGMA integrity_check").contains("ok"));
    let finished = sql(&out, "SELECT COUNT(*) FROM attempts WHERE outcome = 'done'");
    assert!(
        finished.lines().nth(1) == Some("4"),
        "no job finished twice: {finished}"
    );
}

#[test]
fn a_numerical_failure_is_retried_with_the_time_step_halved() {
    // Two spheres meeting head-on at 2 m/s: with dt = 3e-4 s they overlap by 0.27 radius within one step
    // (excessive overlap); with 1.5e-4 s the collision resolves.
    let yaml = r#"
name: numerical
base:
  domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.02, 0.02, 0.02] }
  gravity: { vector_m_per_s2: [0.0, 0.0, 0.0] }
  species:
    - { name: g, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3 }
  contact: { normal: { hertz: { restitution: 0.9 } }, tangential: mindlin }
  fill:
    - explicit: { species: g, positions_m: [[0.006, 0.01, 0.01], [0.014, 0.01, 0.01]], velocities_m_per_s: [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]] }
  time: { dt_s: 3.0e-4, end_time_s: 0.006 }
sweep: { param: contact.normal.hertz.restitution, values: [0.9, 0.5] }
retry: { numerical: 2 }
"#;
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "numerical.yaml", yaml);
    let out = tmp.path().join("out");
    ok(
        &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
        tmp.path(),
    );
    assert!(sql(&out, "SELECT COUNT(*) FROM jobs WHERE status = 'done'").contains('2'));
    let requeued = sql(
        &out,
        "SELECT COUNT(*) FROM attempts WHERE outcome = 'requeued' AND exit_class = 'numerical'",
    );
    assert_eq!(
        requeued.lines().nth(1),
        Some("2"),
        "one numerical retry per job: {requeued}"
    );
    for id in sql(&out, "SELECT job_id FROM jobs").lines().skip(1) {
        let state = CheckpointSeries::new(out.join("jobs").join(id.trim()), 2)
            .latest_valid()
            .unwrap()
            .unwrap()
            .state;
        assert_eq!(state.dt_s, 1.5e-4, "the retry ran with the time step halved");
    }
}

#[test]
fn ctrl_c_checkpoints_and_stops_then_resume_finishes_and_a_second_dispatcher_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "mini.yaml", &campaign("[20.0, 60.0]", 3.0));
    let out = tmp.path().join("out");
    let mut dispatcher = Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1200));

    // One dispatcher per campaign directory.
    let second = granflow(&["resume", out.to_str().unwrap(), "--quiet"], tmp.path());
    assert!(!second.status.success());
    assert!(
        String::from_utf8_lossy(&second.stderr).contains("another dispatcher"),
        "{}",
        String::from_utf8_lossy(&second.stderr)
    );

    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(dispatcher.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    )
    .unwrap();
    let status = dispatcher.wait().unwrap();
    assert_eq!(status.code(), Some(130), "interrupted");
    let states = sql(&out, "SELECT status, COUNT(*) FROM jobs GROUP BY status");
    assert!(!states.contains("failed") && !states.contains("running"), "{states}");
    let stopped = sql(&out, "SELECT COUNT(*) FROM attempts WHERE exit_class = 'interrupted'");
    assert_ne!(
        stopped.lines().nth(1),
        Some("0"),
        "running workers were stopped: {stopped}"
    );
    // The stopped workers kept their progress: a checkpoint beyond the start.
    let pending = sql(&out, "SELECT job_id FROM jobs WHERE status = 'pending'");
    let progressed = pending.lines().skip(1).any(|id| {
        CheckpointSeries::new(out.join("jobs").join(id.trim()), 2)
            .latest_valid()
            .unwrap()
            .is_some_and(|c| c.state.step > 0)
    });
    assert!(progressed, "an interrupted job checkpointed its progress: {pending}");
    ok(&["resume", out.to_str().unwrap(), "--quiet"], tmp.path());
    assert!(sql(&out, "SELECT COUNT(*) FROM jobs WHERE status = 'done'").contains('4'));
}

#[test]
fn a_job_over_its_time_limit_is_stopped_and_failed_as_a_timeout() {
    let tmp = tempfile::tempdir().unwrap();
    let text = campaign("[20.0]", 60.0).replace(
        "executor: { local: { max_parallel: 2 } }",
        "executor: { local: { max_parallel: 2, job_timeout_s: 0.5 } }",
    );
    let file = write(tmp.path(), "mini.yaml", &text);
    let out = tmp.path().join("out");
    let started = std::time::Instant::now();
    let run = granflow(
        &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
        tmp.path(),
    );
    assert_eq!(
        run.status.code(),
        Some(6),
        "some jobs failed: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        started.elapsed() < Duration::from_secs(30),
        "stopped long before its 60 s of simulated time"
    );
    let failed = sql(
        &out,
        "SELECT exit_class, COUNT(*) FROM jobs WHERE status = 'failed' GROUP BY exit_class",
    );
    assert!(failed.contains("timeout,2"), "{failed}");
}

/// `granflow reduce` recomputes every finished job's metrics from its final checkpoint and series: metrics spoiled in
/// the database and in a result.json come back bit for bit, the finish times stay, and it refuses to run beside a
/// dispatcher's lock.
#[test]
fn reducing_a_finished_campaign_again_recomputes_its_metrics_bit_for_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "mini.yaml", &campaign("[20.0, 60.0]", 0.03));
    let out = tmp.path().join("out");
    ok(
        &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
        tmp.path(),
    );
    // Hex of the bits, so the comparison is exact.
    let metrics_sql = "SELECT job_id, name, hex(value) FROM metrics ORDER BY job_id, name";
    let before = sql(&out, metrics_sql);
    let finished = sql(&out, "SELECT job_id, finished_at FROM jobs ORDER BY job_id");
    assert_eq!(before.lines().count(), 1 + 20, "{before}");

    let db = rusqlite::Connection::open(out.join("campaign.sqlite")).unwrap();
    db.execute("UPDATE metrics SET value = -1.0", []).unwrap();
    drop(db);
    let some_job = before.lines().nth(1).unwrap().split(',').next().unwrap().to_string();
    let result_path = out.join("jobs").join(&some_job).join("result.json");
    let result = std::fs::read_to_string(&result_path).unwrap();
    let mut spoiled: serde_json::Value = serde_json::from_str(&result).unwrap();
    for m in spoiled["metrics"].as_array_mut().unwrap() {
        m["value"] = serde_json::json!(-1.0);
    }
    std::fs::write(&result_path, serde_json::to_string_pretty(&spoiled).unwrap()).unwrap();

    let reduced = granflow(&["reduce", out.to_str().unwrap()], tmp.path());
    assert!(reduced.status.success(), "{}", String::from_utf8_lossy(&reduced.stderr));
    assert!(String::from_utf8_lossy(&reduced.stderr).contains("reduced 4 finished job(s) again"));
    assert_eq!(sql(&out, metrics_sql), before, "the metrics come back bit for bit");
    assert_eq!(
        sql(&out, "SELECT job_id, finished_at FROM jobs ORDER BY job_id"),
        finished
    );
    assert_eq!(
        std::fs::read_to_string(&result_path).unwrap(),
        result,
        "result.json rewritten the same"
    );

    // Not beside a dispatcher: the campaign lock is held here.
    let lock = std::fs::File::create(out.join("campaign.lock")).unwrap();
    lock.try_lock().unwrap();
    let refused = granflow(&["reduce", out.to_str().unwrap()], tmp.path());
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("is locked"));
}

/// The dispatcher runs fewer jobs at once than asked when that many would need more than the machine's memory
/// budget (`GRANFLOW_MEMORY_BYTES` stands in for a small machine), says so, and still finishes every job.
#[test]
fn parallel_jobs_are_limited_by_the_memory_budget() {
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "mini.yaml", &campaign("[20.0, 60.0]", 0.002));
    let loaded = granflow::campaign::load(&file).unwrap();
    let largest = loaded
        .jobs
        .iter()
        .map(|j| granflow::scenario::estimated_memory_bytes(&j.scenario))
        .fold(0.0, f64::max);
    // One job fits, two do not.
    let budget = (1.5 * largest) as u64;
    let out = Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(["run", "mini.yaml", "--out", "out", "--quiet"])
        .env(granflow::machine::MEMORY_BUDGET_ENV, budget.to_string())
        .current_dir(tmp.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("running at most 1 job(s) at once instead of 2"),
        "{stderr}"
    );
    assert!(stderr.contains("4 done, 0 failed"), "{stderr}");
}
