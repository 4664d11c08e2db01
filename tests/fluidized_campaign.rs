//! A smoke fluidized-bed campaign through the real binary (a few hundred steps per job): the gas metrics are
//! stored, the campaign-level u_mf is derived per group and stored in `derived`, and `granflow report` writes a
//! report whose first line names the case and whose last line is the verdict.

mod common;

use common::{granflow, granflow_ok, png_colours, svg_has};
use granflow::plot::phase_diagram::significant;

fn campaign(check_range: &str) -> String {
    format!(
        r#"
name: bed-smoke
description: A 100-bead pseudo-2-D bed at three inlet velocities, 300 steps each.
base:
  domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.03, 0.1, 0.0027], periodic: [true, false, false] }}
  pseudo_2d: true
  gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
  species:
    - {{ name: glass, radius_m: 0.00135, density_kg_per_m3: 2000.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.33, friction_coefficient: 0.3 }}
  contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
  walls: [ {{ box: {{ species: glass }} }} ]
  fill:
    - lattice: {{ species: glass, spacing_m: 0.003, lo_m: [0.0, 0.0015, 0.0], hi_m: [0.03, 0.0315, 0.0027], origin_m: [0.0015, 0.0015, 0.00135] }}
  gas:
    density_kg_per_m3: 1.23
    viscosity_pa_s: 1.8e-5
    cells: [4, 12, 1]
    sides: {{ y_low: {{ inlet: {{ superficial_velocity_m_per_s: 1.0 }} }}, y_high: outlet }}
    dem_steps_per_gas_step: 5
  time: {{ dt_s: 1.0e-5, end_time_s: 0.003 }}
  output: {{ series_every_steps: 5 }}
sweep:
  grid:
    - {{ param: species.0.density_kg_per_m3, name: density_kg_per_m3, values: [1000.0, 2000.0] }}
    - {{ param: gas.sides.y_low.inlet.superficial_velocity_m_per_s, name: u_m_per_s, values: [0.3, 1.0, 3.0] }}
metrics: [pressure_drop_mean_pa, pressure_drop_std_pa, bed_weight_per_area_pa, mean_height_time_avg_m]
analysis: {{ average_from_s: 0.001 }}
derived:
  - minimum_fluidization_velocity: {{ velocity_param: u_m_per_s }}
executor: {{ local: {{ max_parallel: 2 }} }}
validation:
  case: X1
  title: smoke
  source: nothing (a plumbing test)
  choices: ["300 steps only"]
  checks:
    - name: "bed weight per area, rho = 2000"
      value: {{ metric: bed_weight_per_area_pa }}
      where: {{ density_kg_per_m3: 2000.0 }}
      expected: 0.0
      range: {check_range}
    - name: "u_mf found for rho = 1000"
      value: {{ derived: u_mf_pressure_fluctuation_m_per_s }}
      where: {{ density_kg_per_m3: 1000.0 }}
      expected: 1.0
      range: [0.3, 3.0]
"#
    )
}

#[test]
fn a_fluidized_bed_campaign_stores_gas_metrics_derives_u_mf_and_reports() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // W/A of 100 beads of 2.7 mm at 2000 kg/m3 over 30 mm x 2.7 mm: 100 x 2.0612e-5 kg x 9.81 / 8.1e-5 m2 = 249.6 Pa.
    std::fs::write(dir.join("bed.yaml"), campaign("[249.0, 250.2]")).unwrap();
    let out = granflow(&["run", "bed.yaml", "--out", "bed", "--quiet"], dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    let sql = |q: &str| -> String {
        let out = granflow(&["query", "bed", "--sql", q, "--format", "csv"], dir);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let metrics = sql("SELECT count(*) FROM metrics WHERE value IS NOT NULL");
    assert!(metrics.contains("24"), "4 metrics x 6 jobs: {metrics}");
    // The packed bed at 0.3 m/s carries less than its weight; every pressure drop is positive.
    let dp = sql(
        "SELECT p.value_real, m.value FROM metrics m JOIN params p ON p.job_id = m.job_id \
         WHERE m.name = 'pressure_drop_mean_pa' AND p.name = 'u_m_per_s' ORDER BY p.value_real",
    );
    let values: Vec<(f64, f64)> = dp
        .lines()
        .skip(1)
        .map(|l| {
            let mut f = l.split(',').map(|x| x.parse::<f64>().unwrap());
            (f.next().unwrap(), f.next().unwrap())
        })
        .collect();
    assert_eq!(values.len(), 6);
    assert!(values.iter().all(|&(_, p)| p > 0.0), "{values:?}");
    assert!(values[0].1 < values[5].1, "ΔP grows with the gas velocity: {values:?}");
    // One u_mf row per density group, five names each.
    let derived = sql("SELECT group_json, name, value FROM derived ORDER BY group_json, name");
    assert_eq!(derived.lines().count(), 1 + 2 * 5, "{derived}");
    assert!(derived.contains("density_kg_per_m3") && derived.contains("u_mf_pressure_fluctuation_m_per_s"));

    let out = granflow(&["report", "bed", "--out", "report/REPORT.md"], dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report = std::fs::read_to_string(dir.join("report/REPORT.md")).unwrap();
    assert_eq!(report.lines().next(), Some("# X1 smoke"), "{report}");
    assert_eq!(report.lines().last(), Some("verdict: pass"), "{report}");
    assert!(report.contains("granflow run ") && report.contains("300 steps only"));
    // Provenance: the file the user ran, the build of every job (in the database and each result.json).
    let build = granflow::provenance::build_id();
    assert!(report.contains("granflow run bed.yaml --out bed\n"), "{report}");
    assert!(
        report.contains(&format!("All 6 done jobs were run by granflow {build}.")),
        "{report}"
    );
    assert_eq!(sql("SELECT DISTINCT build FROM attempts"), format!("build\n{build}\n"));
    // The wall time the jobs took, from their attempts, and per job.
    assert!(
        report.contains("Wall time: ") && report.contains(" of worker time in all"),
        "{report}"
    );
    assert!(
        report.contains("| wall s (all attempts) | wall s per simulated s |"),
        "{report}"
    );
    let result_dir = std::fs::read_dir(dir.join("bed/jobs"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let result: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(result_dir.join("result.json")).unwrap()).unwrap();
    assert_eq!(result["build"], build.as_str());

    // The same results judged by a range the bed weight misses: the verdict names the failed check.
    std::fs::write(dir.join("bed.yaml"), campaign("[100.0, 200.0]")).unwrap();
    let out = granflow(&["run", "bed.yaml", "--out", "bed", "--quiet"], dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = granflow(&["report", "bed"], dir);
    let report = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        report.lines().last(),
        Some("verdict: fail (bed weight per area, rho = 2000)"),
        "{report}"
    );
}

/// A gas cycle (`inflow_levels`: down from 3 m/s to 0 and back up, 0.5 ms per level) reduces to seed 001's cycle
/// metrics; the overshoot ratio is the rising branch's largest level-mean pressure drop over W/A.
#[test]
fn a_gas_cycle_reduces_to_seed_001s_cycle_metrics() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let yaml = campaign("[249.0, 250.2]")
        .replace(
            "dem_steps_per_gas_step: 5",
            "dem_steps_per_gas_step: 5\n    inflow_levels: { hold_s: 0.0005, factors: [1.0, 0.5, 0.0, 0.5, 1.0, 1.0] }",
        )
        .replace("values: [0.3, 1.0, 3.0]", "values: [3.0]")
        .replace(
            "metrics: [pressure_drop_mean_pa,",
            "metrics: [pressure_overshoot_ratio, defluidization_velocity_m_per_s, pressure_drop_mean_pa,",
        );
    std::fs::write(dir.join("cycle.yaml"), &yaml).unwrap();
    let ratios = run_and_read(dir, "cycle", "pressure_overshoot_ratio");
    assert_eq!(ratios.len(), 2, "{ratios:?}");
    assert!(ratios.iter().all(|r| r.is_finite() && *r > 0.0), "{ratios:?}");
    // The cycle as a picture: both jobs' branches, each named by what differs between them (the density).
    let printed = granflow_ok(&["plot", "cycle", "fluidization"], dir).stdout;
    assert_eq!(
        printed.lines().collect::<Vec<_>>(),
        ["cycle/plots/fluidization.png", "cycle/plots/fluidization.svg"]
    );
    assert!(png_colours(&dir.join("cycle/plots/fluidization.png")) > 20);
    let svg = std::fs::read_to_string(dir.join("cycle/plots/fluidization.svg")).unwrap();
    for density in ["1000", "2000"] {
        for branch in ["falling branch", "rising branch"] {
            let text = format!("density_kg_per_m3={density}.0: {branch}");
            assert!(svg_has(&svg, &text), "the cycle's SVG lacks `{text}`");
        }
    }
    assert!(svg_has(&svg, "gas superficial velocity [m/s]"));
    // Seed 001's reading: the first node against W'/A. The same runs (the analysis does not change the physics):
    // the bottom row of beads (a tenth of the bed) sits below the node and W'/A is 0.9 W/A, but the node also
    // leaves out the bottom half-cell of ΔP (4.2 of the bed's 30 mm, 14 % of a uniform packed bed's drop): ΔP* falls
    // by a few per cent.
    let node_yaml = yaml.replace(
        "analysis: { average_from_s: 0.001 }",
        "analysis: { average_from_s: 0.001, cycle_pressure: first_node }",
    );
    assert_ne!(node_yaml, yaml);
    std::fs::write(dir.join("node.yaml"), &node_yaml).unwrap();
    let node_ratios = run_and_read(dir, "node", "pressure_overshoot_ratio");
    assert_eq!(node_ratios.len(), 2, "{node_ratios:?}");
    for (column, node) in ratios.iter().zip(&node_ratios) {
        assert!(node.is_finite() && *node != *column, "column {column}, node {node}");
        assert!(*node < *column && *node > 0.8 * column, "column {column}, node {node}");
    }
    // The net force by mechanism at the climb's top (the plumbing; `tests/fluidized_bed.rs` checks the physics).
    // In these 3 ms the lattice, 0.15 mm above the distributor, has not reached it, and the 3 m/s gas pushes the
    // beads up; without cohesion nothing is held down, and the box's x sides are periodic: no sidewalls.
    let parts = [
        "overshoot_fluid_force_per_weight",
        "overshoot_distributor_contact_per_weight",
        "overshoot_distributor_cohesion_per_weight",
        "overshoot_sidewall_friction_per_weight",
    ];
    let forces_yaml = node_yaml
        .replace(
            "output: { series_every_steps: 5 }",
            "output: { series_every_steps: 5, net_forces: true }",
        )
        .replace("metrics: [", &format!("metrics: [{}, ", parts.join(", ")));
    std::fs::write(dir.join("forces.yaml"), &forces_yaml).unwrap();
    let value = |k: usize| run_and_read(dir, "forces", parts[k]);
    let (fluid, contact, cohesion, friction) = (value(0), value(1), value(2), value(3));
    println!("fluid {fluid:?}, distributor contact {contact:?}, cohesion {cohesion:?}, sidewall friction {friction:?}");
    assert_eq!(
        run_and_read(dir, "forces", "pressure_overshoot_ratio"),
        node_ratios,
        "same runs"
    );
    for k in 0..2 {
        assert!(fluid[k] > 1.0 && fluid[k] < 3.0, "{fluid:?}");
        assert_eq!((contact[k], cohesion[k], friction[k]), (0.0, 0.0, 0.0));
    }
}

/// A bed stepped up through gas levels (`inflow_levels`, 0.1 s each, after 0.1 s of settling) reduces to one u_mf:
/// the slowest level from which the bed keeps moving. Seed 000's beads (R = 1.35 mm, 2000 kg/m³) fluidize at
/// 1.45-1.65 m/s in its 40-row bed (D2, D3); this bed of 10 rows is looser at its ends, its packed ΔP reaches W/A
/// (250 Pa) near 1.7 m/s, and it starts moving there. The levels bracket that onset.
#[test]
fn a_bed_stepped_up_through_gas_levels_reduces_to_its_onset_velocity() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let yaml = campaign("[249.0, 250.2]")
        .replace(
            "dem_steps_per_gas_step: 5",
            "dem_steps_per_gas_step: 5\n    inflow_ramp: { start_s: 0.1, duration_s: 0.05 }\n    inflow_levels: { start_s: 0.15, hold_s: 0.1, factors: [0.8, 1.0, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 2.0, 2.2, 2.4] }",
        )
        .replace("values: [0.3, 1.0, 3.0]", "values: [1.0]")
        .replace("values: [1000.0, 2000.0]", "values: [2000.0]")
        .replace("end_time_s: 0.003", "end_time_s: 1.35")
        .replace("series_every_steps: 5", "series_every_steps: 50")
        .replace(
            "metrics: [pressure_drop_mean_pa,",
            "metrics: [stepped_fluidization_velocity_m_per_s, pressure_drop_mean_pa,",
        );
    let yaml = yaml[..yaml.find("derived:").unwrap()].to_string() + "executor: { local: { max_parallel: 1 } }\n";
    std::fs::write(dir.join("steps.yaml"), yaml).unwrap();
    let onset = run_and_read(dir, "steps", "stepped_fluidization_velocity_m_per_s")[0];
    println!("stepped onset: {onset} m/s");
    assert!((1.5..=2.0).contains(&onset), "{onset}");
    // The picture marks the stored onset (the same function on the same levels), under the job's parameters.
    granflow_ok(&["plot", "steps", "fluidization", "--out", "steps.svg"], dir);
    let svg = std::fs::read_to_string(dir.join("steps.svg")).unwrap();
    let text = format!("stepped onset = {} m/s", significant(onset, 4));
    assert!(svg_has(&svg, &text), "the stepped cycle's SVG lacks `{text}`");
}

/// Runs `<name>.yaml` in `dir` into `<name>/` and returns every job's value of `metric`, in sweep order.
fn run_and_read(dir: &std::path::Path, name: &str, metric: &str) -> Vec<f64> {
    let out = granflow(&["run", &format!("{name}.yaml"), "--out", name, "--quiet"], dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let query = format!(
        "SELECT m.value FROM metrics m JOIN jobs j USING (job_id) WHERE m.name = '{metric}' ORDER BY j.ordinal"
    );
    let out = granflow(&["query", name, "--sql", &query, "--format", "csv"], dir);
    let text = String::from_utf8_lossy(&out.stdout);
    text.lines().skip(1).map(|l| l.parse().unwrap()).collect()
}
