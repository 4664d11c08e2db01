//! A sweep far too large is refused from its count, before anything is expanded: through the real binary, each
//! refusal takes under a second and under 100 MB of memory, exits with 2 and writes nothing. So is a campaign file
//! too large to read.
//!
//! One test in its own binary, so that the peak resident memory of this process's children
//! (`getrusage(RUSAGE_CHILDREN)`) is that of the refusals alone.

mod common;

use std::time::{Duration, Instant};

use common::granflow;

/// A small valid campaign whose sweep is replaced by each case's.
const BASE: &str = r#"name: size
base:
  domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.02, 0.02, 0.02] }
  gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
  species:
    - { name: glass, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e6, poisson_ratio: 0.3, friction_coefficient: 0.4 }
  contact: { normal: { hertz: { restitution: 0.7 } }, tangential: mindlin }
  walls: [{ box: { species: glass } }]
  fill: [{ lattice: { species: glass, spacing_m: 0.0025, lo_m: [0.0, 0.0, 0.0], hi_m: [0.02, 0.01, 0.02] } }]
  time: { dt_s: 2.0e-5, end_time_s: 0.001 }
"#;

/// (case, sweep section)
const CASES: &[(&str, &str)] = &[
    (
        "grid of 1e8",
        "sweep:\n  grid:\n    - { param: time.dt_s, values: [1.0e-5, 2.0e-5] }\n    - { param: species.0.friction_coefficient, linspace: { start: 0.1, stop: 0.5, num: 50000000 } }\n",
    ),
    (
        "grid of 1e12",
        "sweep:\n  grid:\n    - { param: species.0.friction_coefficient, linspace: { start: 0.1, stop: 0.5, num: 1000000 } }\n    - { param: species.0.poisson_ratio, linspace: { start: 0.1, stop: 0.4, num: 1000000 } }\n",
    ),
    (
        "linspace of 1e9",
        "sweep: { param: species.0.friction_coefficient, linspace: { start: 0.1, stop: 0.5, num: 1000000000 } }\n",
    ),
    (
        "logspace of 1e9",
        "sweep: { param: species.0.friction_coefficient, logspace: { start: 0.1, stop: 0.5, num: 1000000000 } }\n",
    ),
];

/// The largest resident set of any child this process has waited for, in bytes.
fn children_peak_rss_bytes() -> u64 {
    let usage = nix::sys::resource::getrusage(nix::sys::resource::UsageWho::RUSAGE_CHILDREN).expect("getrusage");
    // Linux reports ru_maxrss in kilobytes.
    usage.max_rss() as u64 * 1024
}

#[test]
fn huge_sweeps_are_refused_fast_in_little_memory_writing_nothing() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // The base with a one-point sweep is valid, so each refusal below is due to its sweep's size.
    std::fs::write(
        dir.join("good.yaml"),
        format!("{BASE}sweep: {{ param: seed, values: [1] }}\n"),
    )
    .expect("write");
    let check = granflow(&["run", "good.yaml", "--out", "good-out", "--quiet"], dir);
    assert!(
        check.status.success(),
        "the one-point campaign fails: {}",
        String::from_utf8_lossy(&check.stderr)
    );
    std::fs::remove_dir_all(dir.join("good-out")).expect("remove");
    let mut failures = Vec::new();
    for (case, sweep) in CASES {
        std::fs::write(dir.join("huge.yaml"), format!("{BASE}{sweep}")).expect("write");
        let started = Instant::now();
        let out = granflow(&["run", "huge.yaml", "--out", "huge-out"], dir);
        let took = started.elapsed();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let peak = children_peak_rss_bytes();
        let mut problems = Vec::new();
        if out.status.code() != Some(2) {
            problems.push(format!("exit code {:?}, expected 2", out.status.code()));
        }
        if !stderr.contains("more than max_jobs = 10000") {
            problems.push("the message does not name max_jobs".into());
        }
        if took > Duration::from_secs(1) {
            problems.push(format!("took {took:?}, expected under 1 s"));
        }
        if peak > 100 << 20 {
            problems.push(format!("peak resident memory {} MB, expected under 100 MB", peak >> 20));
        }
        let written: Vec<String> = std::fs::read_dir(dir)
            .expect("read dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .filter(|n| n != "good.yaml" && n != "huge.yaml")
            .collect();
        if !written.is_empty() {
            problems.push(format!("wrote {written:?}"));
        }
        eprintln!(
            "{case}: exit {:?} in {took:?}, children's peak resident memory so far {} MB",
            out.status.code(),
            peak >> 20
        );
        if !problems.is_empty() {
            failures.push(format!(
                "{case}: {}\n    stderr: {}",
                problems.join("; "),
                stderr.trim_end()
            ));
        }
    }
    // A file of 65 MiB (a valid campaign followed by comments) is refused before it is read.
    // Written in pieces: a child's peak resident memory counts this process's pages while it is being spawned.
    {
        use std::io::Write;
        let mut file = std::io::BufWriter::new(std::fs::File::create(dir.join("huge.yaml")).expect("create"));
        writeln!(file, "{BASE}sweep: {{ param: seed, values: [1] }}").expect("write");
        let comment = format!("# {}\n", "x".repeat(1022));
        for _ in 0..=(65 << 10) {
            file.write_all(comment.as_bytes()).expect("write");
        }
    }
    let started = Instant::now();
    let out = granflow(&["run", "huge.yaml", "--out", "huge-out"], dir);
    let took = started.elapsed();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let peak = children_peak_rss_bytes();
    eprintln!(
        "65 MiB file: exit {:?} in {took:?}, children's peak resident memory so far {} MB",
        out.status.code(),
        peak >> 20
    );
    if out.status.code() != Some(2) || !stderr.contains("more than the 67108864 an input file may have") {
        failures.push(format!("65 MiB file: exit {:?}: {stderr}", out.status.code()));
    }
    if took > Duration::from_secs(1) || peak > 100 << 20 {
        failures.push(format!("65 MiB file: {took:?}, {} MB", peak >> 20));
    }
    if dir.join("huge-out").exists() {
        failures.push("65 MiB file: wrote huge-out".into());
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
