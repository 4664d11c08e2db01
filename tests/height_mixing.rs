//! Seed 001's height mixing index (`height_mixing_index`, §7.2.2) through the real binary: a bed of four equal
//! layers standing on the floor has the index 3 exactly (top half's mean height 3/4 of the bed's, bottom half's 1/4)
//! and keeps it while nothing moves; the families are taken at the first row at or after
//! `analysis.height_families_at_s`, the rows before it hold no value; the metric is the last row's value; a time
//! outside the run is bad input.

mod common;

use std::path::Path;

use common::{granflow, granflow_ok};

/// One job: 4 × 4 × 4 beads on a lattice whose lowest layer's centres sit 1.25 mm above the floor; gravity off and
/// no velocities, so nothing moves. `analysis` is the campaign's `analysis:` section.
fn campaign(analysis: &str) -> String {
    format!(
        r#"name: frozen-layers
base:
  domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.01, 0.01, 0.02] }}
  gravity: {{ vector_m_per_s2: [0.0, 0.0, 0.0] }}
  species:
    - {{ name: glass, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3 }}
  contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
  walls:
    - box: {{ species: glass }}
  fill:
    - lattice: {{ species: glass, spacing_m: 0.0025, lo_m: [0.0, 0.0, 0.0], hi_m: [0.01, 0.01, 0.01], origin_m: [0.00125, 0.00125, 0.00125] }}
  time: {{ dt_s: 1.0e-5, end_time_s: 0.002 }}
  output: {{ series_every_steps: 20 }}
sweep:
  param: seed
  values: [1]
metrics: [height_mixing_index, mean_height_m]
analysis: {analysis}
"#
    )
}

/// (time, height_mixing_index) of every row of the only job's series.
fn index_rows(out: &Path) -> Vec<(f64, f64)> {
    let jobs = out.join("jobs");
    let job = std::fs::read_dir(&jobs).unwrap().next().unwrap().unwrap().path();
    let text = std::fs::read_to_string(job.join("series.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (t, h) = (
        header.iter().position(|c| *c == "time_s").unwrap(),
        header.iter().position(|c| *c == "height_mixing_index").unwrap(),
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[t].parse().unwrap(), f[h].parse().unwrap())
        })
        .collect()
}

fn metric(out: &Path) -> String {
    granflow_ok(
        &[
            "query",
            out.to_str().unwrap(),
            "--sql",
            "SELECT value FROM metrics WHERE name = 'height_mixing_index'",
            "--format",
            "csv",
        ],
        out.parent().unwrap(),
    )
    .stdout
}

#[test]
fn four_still_layers_have_the_index_three_from_the_families_time_on() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, analysis, first_s) in [
        ("from-start", "{}", 0.0),
        ("from-1ms", "{ height_families_at_s: 0.001 }", 0.001),
    ] {
        let file = tmp.path().join(format!("{name}.yaml"));
        std::fs::write(&file, campaign(analysis)).unwrap();
        let out = tmp.path().join(name);
        granflow_ok(
            &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
            tmp.path(),
        );
        let rows = index_rows(&out);
        assert_eq!(rows.len(), 11, "{name}: rows at 0, 0.2, ..., 2 ms");
        for &(t, index) in &rows {
            // The row at the families' time itself may fall just before it (time accumulates in steps of dt).
            if (t - first_s).abs() < 1e-9 && first_s > 0.0 {
                continue;
            }
            if t < first_s {
                assert!(
                    index.is_nan(),
                    "{name}: no families before {first_s} s, got {index} at {t} s"
                );
            } else {
                assert!((index - 3.0).abs() < 1e-12, "{name}: {index} at {t} s");
            }
        }
        let value: f64 = metric(&out).lines().nth(1).unwrap().trim().parse().unwrap();
        assert!((value - 3.0).abs() < 1e-12, "{name}: metric {value}");
    }
    // Families after the run's end: exit 2 at the key, nothing written.
    let file = tmp.path().join("late.yaml");
    std::fs::write(&file, campaign("{ height_families_at_s: 0.5 }")).unwrap();
    let out = granflow(
        &[
            "run",
            file.to_str().unwrap(),
            "--out",
            tmp.path().join("late").to_str().unwrap(),
        ],
        tmp.path(),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("analysis.height_families_at_s"), "{stderr}");
    assert!(!tmp.path().join("late").exists());
}
