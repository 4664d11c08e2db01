//! Seed 000's zig-zag chute metrics (§3.2, eqs 3.4-3.5) through the real binary: a small two-density bed on a floor
//! roughened with glued beads, gravity inclined and flipping across the bed. The series gets the column
//! `shear_rate_per_s` at every row; the metric `shear_rate_per_s` is its mean from `analysis.average_from_s`,
//! `critical_flip_frequency_hz` is 0.01 β γ̇ (1 − ρ̄) with the campaign's β and the two kinds' density ratio,
//! `flip_frequency_ratio` is f over it and `flip_rule_agreement` is (IS − 0.25) times the sign of 1 − f/f_crit. A
//! metric that needs a flipping gravity, a β that is not positive and a floor's bead lattice that does not repeat
//! with the periodic box are bad input at their lines.

mod common;

use std::path::Path;

use common::{granflow, granflow_fails_with_2, granflow_ok, only_job_series};

/// A bed of 2 mm beads, 400 light (1000 kg/m³) and 400 heavy (3000 kg/m³), in a box 16.8 × 8.4 mm periodic along
/// the flow (x) and across it (z), on a floor of glued beads, under gravity 26° off the floor's normal flipping at
/// 5 Hz; 0.4 s. `extra` is appended to the campaign (metrics and analysis).
fn campaign(floor_spacing_m: f64, metrics: &str, analysis: &str) -> String {
    format!(
        r#"name: chute
base:
  domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.0168, 0.04, 0.0084], periodic: [true, false, true] }}
  gravity: {{ vector_m_per_s2: [4.300411, -8.817194, 0.0], flip: {{ axis: y, frequency_hz: 5.0 }} }}
  species:
    - {{ name: light, radius_m: 0.001, density_kg_per_m3: 1000.0, youngs_modulus_pa: 1.0e6, poisson_ratio: 0.3, friction_coefficient: 0.5 }}
    - {{ name: heavy, radius_m: 0.001, density_kg_per_m3: 3000.0, youngs_modulus_pa: 1.0e6, poisson_ratio: 0.3, friction_coefficient: 0.5 }}
  contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
  walls:
    - plane: {{ name: floor, species: light, point_m: [0.0, 0.0, 0.0], normal: [0.0, 1.0, 0.0], glued_beads: {{ radius_m: 0.001, spacing_m: [{floor_spacing_m}, 0.0021] }} }}
    - plane: {{ name: roof, species: light, point_m: [0.0, 0.04, 0.0], normal: [0.0, -1.0, 0.0] }}
  fill:
    - lattice: {{ species: light, spacing_m: 0.0021, lo_m: [0.0, 0.003, 0.0], hi_m: [0.0168, 0.0135, 0.0084], origin_m: [0.00105, 0.00315, 0.00105] }}
    - lattice: {{ species: heavy, spacing_m: 0.0021, lo_m: [0.0, 0.0135, 0.0], hi_m: [0.0168, 0.024, 0.0084], origin_m: [0.00105, 0.00315, 0.00105] }}
  time: {{ dt_fraction_of_contact_time: 0.05, end_time_s: 0.4 }}
  output: {{ series_every_steps: 500 }}
sweep: {{ param: seed, values: [1] }}
metrics: {metrics}
analysis: {analysis}
"#
    )
}

const METRICS: &str = "[shear_rate_per_s, critical_flip_frequency_hz, flip_frequency_ratio, flip_rule_agreement, intensity_of_segregation]";
const ANALYSIS: &str = "{ mixing_species: light, average_from_s: 0.1, segregation_beta: 0.3 }";

fn metric(out: &Path, name: &str) -> f64 {
    let printed = granflow_ok(
        &[
            "query",
            out.to_str().unwrap(),
            "--sql",
            &format!("SELECT value FROM metrics WHERE name = '{name}'"),
            "--format",
            "csv",
        ],
        Path::new("."),
    );
    printed
        .stdout
        .lines()
        .filter_map(|l| l.trim().parse::<f64>().ok())
        .next()
        .unwrap_or_else(|| panic!("no value of {name} in {}", printed.stdout))
}

#[test]
fn the_shear_rate_column_and_the_critical_frequency_of_eq_3_5() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("c.yaml"), campaign(0.0021, METRICS, ANALYSIS)).unwrap();
    granflow_ok(&["run", "c.yaml", "--out", "out", "--quiet"], tmp.path());
    let out = tmp.path().join("out");
    let series = only_job_series(&out);
    let rows: Vec<(f64, f64)> = series["time_s"]
        .iter()
        .copied()
        .zip(series["shear_rate_per_s"].iter().copied())
        .collect();
    let window: Vec<f64> = rows.iter().filter(|(t, _)| *t >= 0.1).map(|&(_, g)| g).collect();
    assert!(
        window.len() > 10 && window.iter().all(|g| g.is_finite() && *g >= 0.0),
        "{rows:?}"
    );
    let mean = window.iter().sum::<f64>() / window.len() as f64;
    assert!(mean > 0.0, "the bed sheared: {rows:?}");
    let shear = metric(&out, "shear_rate_per_s");
    assert!(
        (shear / mean - 1.0).abs() < 1e-9,
        "{shear} against the column's mean {mean}"
    );
    let f_crit = metric(&out, "critical_flip_frequency_hz");
    assert!(
        (f_crit / (0.01 * 0.3 * shear * (1.0 - 1.0 / 3.0)) - 1.0).abs() < 1e-9,
        "{f_crit}"
    );
    let ratio = metric(&out, "flip_frequency_ratio");
    assert!((ratio / (5.0 / f_crit) - 1.0).abs() < 1e-9, "{ratio}");
    let is_end = metric(&out, "intensity_of_segregation");
    let agreement = metric(&out, "flip_rule_agreement");
    assert!(
        (agreement - (is_end - 0.25) * (1.0 - ratio).signum()).abs() < 1e-12,
        "{agreement}"
    );
}

#[test]
fn chute_input_errors_exit_2_at_their_lines() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        // A metric that needs a flipping gravity, on a scenario without one.
        (
            campaign(0.0021, METRICS, ANALYSIS).replace(", flip: { axis: y, frequency_hz: 5.0 }", ""),
            "needs a flipping gravity",
        ),
        (
            campaign(0.0021, METRICS, &ANALYSIS.replace("0.3 }", "0.0 }")),
            "analysis.segregation_beta",
        ),
        // 16.8 mm / 2.4 mm = 7 beads along the periodic x: an odd number.
        (campaign(0.0024, METRICS, ANALYSIS), "an even number of beads"),
        // Closer than a bead and a particle radius.
        (
            campaign(0.0019, METRICS, ANALYSIS),
            "walls[0].plane.glued_beads.spacing_m",
        ),
    ];
    for (k, (text, message)) in cases.iter().enumerate() {
        let file = format!("bad-{k}.yaml");
        std::fs::write(tmp.path().join(&file), text).unwrap();
        granflow_fails_with_2(&["run", &file, "--out", "out", "--quiet"], tmp.path(), message);
        let stderr = String::from_utf8_lossy(&granflow(&["run", &file, "--out", "out", "--quiet"], tmp.path()).stderr)
            .into_owned();
        assert!(
            stderr.contains(&format!("{file}:")),
            "case {k}: no file and line in {stderr}"
        );
        assert!(!tmp.path().join("out").exists(), "case {k}: wrote output");
    }
}
