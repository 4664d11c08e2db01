//! A coupled fluidized bed through the real binary: exact restart with the gas in the checkpoint (stopping between
//! two gas steps, switching thread counts across the restart), the pressure-drop series, and bad gas input.

mod common;

use std::path::Path;

use common::{granflow, granflow_ok};
use granflow::checkpoint::CheckpointSeries;
use granflow::engine::gas::coupled::GasSnapshot;
use granflow::engine::state::{SimState, first_difference};

/// A small pseudo-2-D bed: 100 beads of 2.7 mm, 10 layers, gas inflow 2.5 m/s from below (fluidized).
fn bed(end_time_s: f64, extra: &str) -> String {
    format!(
        r#"
name: small-bed
domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.03, 0.1, 0.0027], periodic: [true, false, false] }}
pseudo_2d: true
gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
species:
  - {{ name: glass, radius_m: 0.00135, density_kg_per_m3: 2000.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.33, friction_coefficient: 0.3 }}
contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
walls: [ {{ box: {{ species: glass }} }} ]
fill:
  - lattice: {{ species: glass, spacing_m: 0.003, lo_m: [0.0, 0.0015, 0.0], hi_m: [0.03, 0.0315, 0.0027], origin_m: [0.0015, 0.0015, 0.00135] }}
gas:
  density_kg_per_m3: 1.23
  viscosity_pa_s: 1.8e-5
  cells: [4, 12, 1]
  sides: {{ y_low: {{ inlet: {{ superficial_velocity_m_per_s: 2.5 }} }}, y_high: outlet }}
  dem_steps_per_gas_step: 7
  pressure_probe_height_m: 0.02
{extra}
time: {{ dt_s: 1.0e-5, end_time_s: {end_time_s} }}
output: {{ checkpoint_every_steps: 1000, keep_checkpoints: 2, series_every_steps: 70{net_forces} }}
"#,
        extra = extra.replace(NET_FORCES, ""),
        net_forces = if extra.contains(NET_FORCES) {
            ", net_forces: true"
        } else {
            ""
        },
    )
}

fn final_state(dir: &Path) -> SimState {
    let loaded = CheckpointSeries::new(dir, 2)
        .latest_valid()
        .expect("lists")
        .expect("a checkpoint exists");
    loaded.state
}

/// Runs scenario `text` as `<name>.yaml` into `<name>/` and returns the gas of its last checkpoint.
fn final_gas(dir: &Path, name: &str, text: &str) -> GasSnapshot {
    let file = format!("{name}.yaml");
    std::fs::write(dir.join(&file), text).unwrap();
    granflow_ok(&["simulate", &file, "--out", name, "--quiet"], dir);
    final_state(&dir.join(name)).gas.expect("the checkpoint holds the gas")
}

/// The values of column `name` in every row of series text `series`, first row first.
fn column_values(series: &str, name: &str) -> Vec<f64> {
    let k = series
        .lines()
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("column {name}"));
    series
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// The value of column `name` in the last row of series text `series`.
fn last_row_value(series: &str, name: &str) -> f64 {
    *column_values(series, name).last().expect("a row")
}

#[test]
fn a_fluidized_bed_restarts_bit_identically_with_its_gas() {
    restart_is_exact("");
}

#[test]
fn a_semi_implicit_bed_restarts_bit_identically_with_its_gas() {
    restart_is_exact("  drag_coupling: semi_implicit\n  drag_velocities: cell_averaged");
}

/// Drag held over the gas step: the checkpoint 5 DEM steps into a gas step holds each particle's position and
/// velocity at the evaluation and its velocity sum, and the held values are evaluated again from them.
#[test]
fn a_bed_with_drag_held_over_the_gas_step_restarts_bit_identically() {
    restart_is_exact("  drag_update: every_gas_step");
}

#[test]
fn a_semi_implicit_cell_averaged_bed_with_held_drag_restarts_bit_identically() {
    restart_is_exact("  drag_update: every_gas_step\n  drag_coupling: semi_implicit\n  drag_velocities: cell_averaged");
}

/// PISO instead of SIMPLE (`solver.pressure_velocity`), with held cell-averaged semi-implicit drag as D7 would use it.
#[test]
fn a_bed_under_piso_restarts_bit_identically() {
    restart_is_exact(
        "  drag_update: every_gas_step\n  drag_velocities: cell_averaged\n  drag_coupling: semi_implicit\n  \
         solver: { pressure_velocity: { piso: { correctors: 2 } } }",
    );
}

/// PISO's step: one predictor and two corrections, no outer iterations, and continuity after the last correction
/// (each correction is solved exactly): the mass imbalance of every series row far below SIMPLE's tolerance of 1e-5,
/// while the bed carries its weight as under SIMPLE.
#[test]
fn a_piso_step_ends_with_continuity_and_the_bed_carries_its_weight() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let run = |name: &str, extra: &str| {
        std::fs::write(dir.join(format!("{name}.yaml")), bed(0.03, extra)).unwrap();
        granflow_ok(&["simulate", &format!("{name}.yaml"), "--out", name, "--quiet"], dir);
        std::fs::read_to_string(dir.join(format!("{name}/series.csv"))).unwrap()
    };
    let piso = run("piso", "  solver: { pressure_velocity: { piso: {} } }");
    let simple = run("simple", "");
    // The rows after the first (the state at t = 0, before any gas step).
    let column = |series: &str, name: &str| column_values(series, name).split_off(1);
    let imbalance = column(&piso, "gas_mass_imbalance");
    let worst = imbalance.iter().fold(0.0f64, |m, &v| m.max(v));
    println!(
        "PISO: worst mass imbalance after the corrections {worst:e} over {} rows",
        imbalance.len()
    );
    assert!(worst < 1.0e-8, "{worst:e}");
    assert!(column(&piso, "gas_outer_iterations").iter().all(|&n| n == 1.0));
    let mean = |v: Vec<f64>| v.iter().sum::<f64>() / v.len() as f64;
    let (dp_piso, dp_simple) = (
        mean(column(&piso, "column_pressure_drop_pa")),
        mean(column(&simple, "column_pressure_drop_pa")),
    );
    println!("mean column pressure drop: PISO {dp_piso:.1} Pa, SIMPLE {dp_simple:.1} Pa");
    assert!(((dp_piso - dp_simple) / dp_simple).abs() < 0.05);
}

#[test]
fn a_bed_under_an_inflow_ramp_restarts_bit_identically() {
    // The stop at step 1503 (t = 15 ms) falls inside the ramp (5-25 ms).
    restart_is_exact("  inflow_ramp: { start_s: 0.005, duration_s: 0.02 }");
}

#[test]
fn a_bed_under_stepped_inflow_levels_restarts_bit_identically() {
    // Levels of 4 ms from 5 ms: the stop at 15 ms falls in the third level (the gas off).
    restart_is_exact("  inflow_levels: { start_s: 0.005, hold_s: 0.004, factors: [1.0, 0.5, 0.0, 0.5, 1.0] }");
}

/// The net-force sums run across the stop at step 1503, between two series rows (1470 and 1540): the checkpoint
/// carries them, so the resumed run writes the same row at 1540.
#[test]
fn a_cohesive_bed_recording_net_forces_restarts_bit_identically() {
    restart_is_exact(&format!("{HAMAKER_WITH_WALLS}\n{NET_FORCES}"));
}

/// Hamaker cohesion between beads and with the walls, about one bead weight at contact.
const HAMAKER_WITH_WALLS: &str =
    "cohesion: { hamaker: { constant_j: 3.0e-19, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 1.0e-5, walls: true } }";

/// Marks a `bed` to record net forces (replaced by the output line in [`bed`]).
const NET_FORCES: &str = "# net_forces";

fn restart_is_exact(extra: &str) {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("bed.yaml"), bed(0.03, extra)).expect("write scenario");
    granflow_ok(&["simulate", "bed.yaml", "--out", "whole", "--quiet"], dir);
    // 1503 steps: the stop falls 5 DEM steps into a gas step (the drag reaction sum is mid-way).
    granflow_ok(
        &[
            "simulate",
            "bed.yaml",
            "--out",
            "split",
            "--max-steps",
            "1503",
            "--threads",
            "2",
            "--quiet",
        ],
        dir,
    );
    let middle = final_state(&dir.join("split"));
    assert_eq!(middle.step, 1503);
    let gas = middle.gas.as_ref().expect("the checkpoint holds the gas");
    assert_eq!(
        gas.reaction_steps, 5,
        "the restart must carry a partly accumulated reaction"
    );
    assert_eq!(
        gas.held_drag.is_some(),
        extra.contains("every_gas_step"),
        "held drag in the checkpoint exactly when the scenario holds it"
    );
    let log = granflow_ok(&["simulate", "bed.yaml", "--out", "split", "--threads", "1"], dir).stderr;
    assert!(log.contains("resuming from"), "{log}");
    let whole = final_state(&dir.join("whole"));
    let split = final_state(&dir.join("split"));
    assert_eq!(whole.step, 3000);
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("restarted bed differs from the uninterrupted one: {diff}");
    }
    let a = std::fs::read_to_string(dir.join("whole/series.csv")).unwrap();
    let b = std::fs::read_to_string(dir.join("split/series.csv")).unwrap();
    assert_eq!(a, b, "the series of the restarted run differs");
    // The gas moved and the bed felt it: a pressure drop across the bed, gas faster than the inflow inside it.
    let last = a.lines().last().unwrap();
    let value = |name: &str| last_row_value(&a, name);
    assert!(value("column_pressure_drop_pa") > 100.0, "{last}");
    assert!(
        value("probe_pressure_drop_pa") > 0.0 && value("probe_pressure_drop_pa") < value("column_pressure_drop_pa")
    );
    assert!(value("gas_outer_iterations") >= 1.0);
}

/// Seed 001's pressure reading (notes §4.1) in the series: the first node (the centre of the inlet layer of cells,
/// here 1/24 of 0.1 m up) to the outlet, and W'/A, the weight of the particles above that node over the bed's
/// area, recomputed here from the checkpoint written at the same step.
#[test]
fn the_series_holds_the_first_node_pressure_drop_and_the_weight_above_that_node() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let text = bed(0.01, "").replace("series_every_steps: 70", "series_every_steps: 50");
    std::fs::write(dir.join("bed.yaml"), text).unwrap();
    granflow_ok(&["simulate", "bed.yaml", "--out", "bed", "--quiet"], dir);
    let state = final_state(&dir.join("bed"));
    assert_eq!(state.step, 1000);
    let series = std::fs::read_to_string(dir.join("bed/series.csv")).unwrap();
    let value = |name: &str| last_row_value(&series, name);
    assert_eq!(value("step"), 1000.0);
    let node_m = 0.5 * 0.1 / 12.0;
    let p = &state.particles;
    let above_kg: f64 = (0..p.len())
        .filter(|&i| p.position_m[i][1] > node_m)
        .map(|i| p.mass_kg[i])
        .sum();
    let expected_pa = above_kg * 9.81 / (0.03 * 0.0027);
    let whole_pa = p.mass_kg.iter().sum::<f64>() * 9.81 / (0.03 * 0.0027);
    let weight_pa = value("node_weight_per_area_pa");
    assert!(
        (weight_pa - expected_pa).abs() <= 1e-9 * expected_pa,
        "{weight_pa} against {expected_pa}"
    );
    // The bottom layer of beads (centres at 1.5 mm) lies below the node: a tenth of the bed.
    assert!(
        weight_pa < 0.95 * whole_pa && weight_pa > 0.8 * whole_pa,
        "{weight_pa} of {whole_pa}"
    );
    let (node_pa, column_pa) = (value("node_pressure_drop_pa"), value("column_pressure_drop_pa"));
    assert!(
        node_pa > 0.5 * weight_pa && node_pa < column_pa,
        "node {node_pa}, column {column_pa}, W'/A {weight_pa}"
    );
}

/// The net force by mechanism closes the bed's momentum balance exactly. Velocity Verlet kicks each step with the
/// mean of two consecutive forces, so over steps 2000-3000 the change of the vertical momentum is
/// ΔP = dt [Σ_k (F_k − W) + (F_2000 − F_3000)/2], k = 2001..3000, where F_k, the force on all particles, is what
/// the series splits into gas, wall contact and wall cohesion (particle–particle forces cancel), and the end terms
/// are the force totals in the two checkpoints. The bed is cohesive, lands on the distributor during the window
/// (a large, changing force), and the distributor's cohesion pulls it down.
#[test]
fn the_net_forces_by_mechanism_close_the_momentum_balance_of_a_cohesive_bed() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // Beads touching from the start, the lowest row on the distributor, under a gas too slow to lift them.
    let text = bed(0.03, &format!("{HAMAKER_WITH_WALLS}\n{NET_FORCES}"))
        .replace("series_every_steps: 70", "series_every_steps: 50")
        .replace("spacing_m: 0.003", "spacing_m: 0.0027")
        .replace(
            "origin_m: [0.0015, 0.0015, 0.00135]",
            "origin_m: [0.00135, 0.00135, 0.00135]",
        )
        .replace("superficial_velocity_m_per_s: 2.5", "superficial_velocity_m_per_s: 1.0");
    std::fs::write(dir.join("bed.yaml"), text).unwrap();
    granflow_ok(
        &["simulate", "bed.yaml", "--out", "bed", "--max-steps", "2000", "--quiet"],
        dir,
    );
    let before = final_state(&dir.join("bed"));
    granflow_ok(&["simulate", "bed.yaml", "--out", "bed", "--quiet"], dir);
    let after = final_state(&dir.join("bed"));
    assert_eq!((before.step, after.step), (2000, 3000));
    let momentum = |s: &SimState| -> f64 {
        let p = &s.particles;
        (0..p.len()).map(|i| p.mass_kg[i] * p.velocity_m_per_s[i].y).sum()
    };
    let series = std::fs::read_to_string(dir.join("bed/series.csv")).unwrap();
    let header: Vec<&str> = series.lines().next().unwrap().split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("column {name}"))
    };
    let up_forces: Vec<usize> = header
        .iter()
        .enumerate()
        .filter(|(_, h)| h.ends_with("_up_n"))
        .map(|(k, _)| k)
        .collect();
    // The gas, and contact and cohesion of the box's four walls (box_y_lo, box_y_hi, box_z_lo, box_z_hi; x is periodic).
    assert_eq!(up_forces.len(), 1 + 2 * 4, "{header:?}");
    let (step, weight) = (column("step"), column("weight_n"));
    let (mut net_sum, mut rows) = (0.0, 0);
    for line in series.lines().skip(1) {
        let fields: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        if fields[step] > 2000.0 {
            net_sum += up_forces.iter().map(|&k| fields[k]).sum::<f64>() - fields[weight];
            rows += 1;
        }
    }
    assert_eq!(rows, 20);
    let weight_n = before.particles.mass_kg.iter().sum::<f64>() * 9.81;
    let total_up = |s: &SimState| s.particles.force_n.iter().map(|f| f.y).sum::<f64>();
    // Σ_k (F_k − W) over the 1000 steps, from the 20 row means of 50 steps each.
    let summed_n = 50.0 * net_sum + 0.5 * (total_up(&before) - total_up(&after));
    let expected_n = (momentum(&after) - momentum(&before)) / 1.0e-5;
    assert!(
        (summed_n - expected_n).abs() < 1e-9 * 1000.0 * weight_n,
        "net forces summed {summed_n:e} N against ΔP/dt {expected_n:e} N (W = {weight_n:e} N)"
    );
    // Without the end terms the balance would be off by this much: the test can tell.
    assert!((total_up(&before) - total_up(&after)).abs() > 1e-3 * weight_n);
    // Landed, the bottom row of beads is held down (about −0.12 W; walls act at twice the pair force).
    let landed = last_row_value(&series, "wall_box_y_lo_cohesion_up_n");
    assert!(
        landed < -0.05 * weight_n,
        "the distributor's cohesion pulls the bed down: {landed:e} N"
    );
}

/// `cohesion_off` switches the model off exactly where it says (seed 001 ch. 8's exclusion runs): a Hamaker bed
/// landing on the distributor (within its 3000 steps) with the cohesion off between particles and at the distributor has nothing left to
/// feel (the top wall is out of reach, the front and back planes act along z only), so it ends bit for bit as the
/// same bed without cohesion; with only the distributor off, the particles still attract each other, and with only
/// the particles off, the distributor still pulls.
#[test]
fn cohesion_switched_off_between_particles_and_at_the_distributor_leaves_a_dry_bed() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let landing = |extra: &str| {
        bed(0.03, extra)
            .replace("spacing_m: 0.003", "spacing_m: 0.0027")
            .replace(
                "origin_m: [0.0015, 0.0015, 0.00135]",
                "origin_m: [0.00135, 0.00135, 0.00135]",
            )
            .replace("superficial_velocity_m_per_s: 2.5", "superficial_velocity_m_per_s: 1.0")
    };
    let cases = [
        ("dry", String::new()),
        (
            "off",
            format!("{HAMAKER_WITH_WALLS}\ncohesion_off: {{ between_particles: true, walls: [box_y_lo] }}"),
        ),
        (
            "distributor-off",
            format!("{HAMAKER_WITH_WALLS}\ncohesion_off: {{ walls: [box_y_lo] }}"),
        ),
        (
            "particles-off",
            format!("{HAMAKER_WITH_WALLS}\ncohesion_off: {{ between_particles: true }}"),
        ),
    ];
    let mut states = Vec::new();
    for (name, extra) in &cases {
        std::fs::write(dir.join(format!("{name}.yaml")), landing(extra)).unwrap();
        granflow_ok(&["simulate", &format!("{name}.yaml"), "--out", name, "--quiet"], dir);
        states.push(final_state(&dir.join(name)));
    }
    let bits = |s: &SimState| -> Vec<u64> {
        let p = &s.particles;
        p.position_m
            .iter()
            .chain(&p.velocity_m_per_s)
            .chain(&p.angular_velocity_rad_per_s)
            .flat_map(|v| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>())
            .collect()
    };
    assert_eq!(states[0].step, 3000);
    assert!(
        bits(&states[0]) == bits(&states[1]),
        "cohesion switched off everywhere it reaches changed the bed"
    );
    assert!(
        bits(&states[0]) != bits(&states[2]),
        "particle–particle cohesion was switched off too"
    );
    assert!(
        bits(&states[0]) != bits(&states[3]),
        "the distributor's cohesion was switched off too"
    );
}

/// A run interrupted by one granflow and resumed by another that writes other series columns is refused with the
/// file named, and its series is left as it was (not cut down to the rows that fit the new header).
#[test]
fn resuming_a_series_with_other_columns_is_refused_and_the_series_kept() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("bed.yaml"), bed(0.01, "")).unwrap();
    granflow_ok(
        &["simulate", "bed.yaml", "--out", "bed", "--max-steps", "500", "--quiet"],
        dir,
    );
    // What an older version wrote: the series without the two first-node columns.
    let path = dir.join("bed/series.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let drop: Vec<usize> = ["node_pressure_drop_pa", "node_weight_per_area_pa"]
        .iter()
        .map(|c| header.iter().position(|h| h == c).expect("column"))
        .collect();
    let older: String = text
        .lines()
        .map(|l| {
            let kept: Vec<&str> = l
                .split(',')
                .enumerate()
                .filter(|(k, _)| !drop.contains(k))
                .map(|(_, f)| f)
                .collect();
            kept.join(",") + "\n"
        })
        .collect();
    std::fs::write(&path, &older).unwrap();
    let out = granflow(&["simulate", "bed.yaml", "--out", "bed", "--quiet"], dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("series.csv has the columns"), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), older, "the series was changed");
}

#[test]
fn bad_gas_input_is_rejected_with_its_key_before_anything_is_written() {
    let cases: &[(&str, &str, &str)] = &[
        ("cells: [4, 12, 1]", "cells: [4, 12, 2]", "gas.cells[2]"),
        ("y_high: outlet", "y_high: outlet, x_low: wall", "gas.sides.x_low"),
        (
            "dem_steps_per_gas_step: 7",
            "dem_steps_per_gas_step: 0",
            "gas.dem_steps_per_gas_step",
        ),
        (
            "superficial_velocity_m_per_s: 2.5",
            "superficial_velocity_m_per_s: -1.0",
            "gas.sides.y_low.inlet.superficial_velocity_m_per_s",
        ),
        ("viscosity_pa_s: 1.8e-5", "viscosity_pa_s: 0.0", "gas.viscosity_pa_s"),
        ("drag: di_felice", "drag: di_felise", "di_felice"),
        (
            "dem_steps_per_gas_step: 7",
            "dem_steps_per_gas_step: 7\n  inflow_ramp: { start_s: -0.1, duration_s: 0.1 }",
            "gas.inflow_ramp.start_s",
        ),
        (
            "dem_steps_per_gas_step: 7",
            "dem_steps_per_gas_step: 7\n  inflow_ramp: { start_s: 0.0, duration_s: .nan }",
            "gas.inflow_ramp.duration_s",
        ),
        (
            "dem_steps_per_gas_step: 7",
            "dem_steps_per_gas_step: 7\n  inflow_levels: { hold_s: 0.0, factors: [1.0] }",
            "gas.inflow_levels.hold_s",
        ),
        (
            "dem_steps_per_gas_step: 7",
            "dem_steps_per_gas_step: 7\n  inflow_levels: { hold_s: 0.1, factors: [1.0, -0.5] }",
            "gas.inflow_levels.factors[1]",
        ),
        (
            "dem_steps_per_gas_step: 7",
            "dem_steps_per_gas_step: 7\n  solver: { pressure_velocity: { piso: { correctors: 0 } } }",
            "gas.solver.pressure_velocity.piso.correctors",
        ),
        (
            "dem_steps_per_gas_step: 7",
            "dem_steps_per_gas_step: 7\n  solver: { pressure_velocity: pimple }",
            "pressure_velocity",
        ),
    ];
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    for (k, (from, to, expected)) in cases.iter().enumerate() {
        let base = bed(
            0.01,
            "  drag: di_felice\n  jets: [ { side: y_low, lo_m: [0.012, 0.0, 0.0], hi_m: [0.018, 0.0, 0.0027], superficial_velocity_m_per_s: 10.0 } ]",
        );
        assert!(base.contains(from), "case {k}: `{from}` not in the base");
        let text = base.replacen(from, to, 1);
        let file = format!("bad{k}.yaml");
        std::fs::write(dir.join(&file), text).unwrap();
        let out = granflow(&["simulate", &file, "--out", &format!("out{k}"), "--quiet"], dir);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "case {k}: {err}");
        assert!(
            err.contains(expected) && err.contains(&file),
            "case {k}: expected `{expected}` in: {err}"
        );
        assert!(!dir.join(format!("out{k}")).exists(), "case {k}: wrote output");
    }
    // A blocked box holding no cell centre.
    let text = bed(
        0.01,
        "  blocked: [ { lo_m: [0.0, 0.0501, 0.0], hi_m: [0.03, 0.0502, 0.0027] } ]",
    );
    std::fs::write(dir.join("blocked.yaml"), text).unwrap();
    let out = granflow(&["simulate", "blocked.yaml", "--out", "blocked", "--quiet"], dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("gas.blocked[0]") && err.contains("no cell centre"),
        "{err}"
    );
    // A jet box holding no face of its side.
    let text = bed(
        0.01,
        "  jets: [ { side: y_low, lo_m: [0.0101, 0.0, 0.0], hi_m: [0.0102, 0.0, 0.0027], superficial_velocity_m_per_s: 10.0 } ]",
    );
    std::fs::write(dir.join("jet.yaml"), text).unwrap();
    let out = granflow(&["simulate", "jet.yaml", "--out", "jet", "--quiet"], dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("gas.jets[0].lo_m") && err.contains("no face centre"),
        "{err}"
    );
}

#[test]
fn a_jet_carries_its_own_inflow() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // A central jet over the middle two of four cells (face centres at x = 11.25 and 18.75 mm).
    let text = bed(
        0.005,
        "  jets: [ { side: y_low, lo_m: [0.01, 0.0, 0.0], hi_m: [0.02, 0.0, 0.0027], superficial_velocity_m_per_s: 10.0 } ]",
    );
    let gas = final_gas(dir, "jet", &text);
    // Bottom faces of v (normal to y): the first row of 4.
    let bottom = &gas.velocity_m_per_s[1][..4];
    assert_eq!(bottom, &[2.5, 10.0, 10.0, 2.5], "inlet faces: {bottom:?}");
}

#[test]
fn an_inflow_ramp_scales_every_inlet_until_it_ends() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // The run ends 5 ms into a 10 ms ramp: the side and the jet are both at the ramp's fraction of their value.
    let text = bed(
        0.005,
        "  inflow_ramp: { start_s: 0.0, duration_s: 0.01 }\n  jets: [ { side: y_low, lo_m: [0.01, 0.0, 0.0], hi_m: [0.02, 0.0, 0.0027], superficial_velocity_m_per_s: 10.0 } ]",
    );
    let gas = final_gas(dir, "ramp", &text);
    let fraction = gas.time_s / 0.01;
    assert!(fraction > 0.45 && fraction < 0.5, "gas time {}", gas.time_s);
    let bottom = &gas.velocity_m_per_s[1][..4];
    let expected = [2.5, 10.0, 10.0, 2.5].map(|u| u * fraction);
    for (got, want) in bottom.iter().zip(expected) {
        assert!(
            (got - want).abs() <= 1e-12 * want,
            "inlet faces {bottom:?}, expected {expected:?}"
        );
    }
    // The outlet carries what came in (mass balance of the ramped inflow; the gas is nearly incompressible here).
    let top = &gas.velocity_m_per_s[1][gas.velocity_m_per_s[1].len() - 4..];
    let (inflow, outflow): (f64, f64) = (bottom.iter().sum(), top.iter().sum());
    assert!(
        (outflow - inflow).abs() < 0.05 * inflow,
        "outflow {outflow} vs inflow {inflow}"
    );
}

#[test]
fn a_three_dimensional_bed_runs_with_a_three_dimensional_gas() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // Two particle layers deep in z with walls front and back, 4 x 12 x 2 gas cells.
    let text = bed(0.01, "")
        .replace("hi_m: [0.03, 0.1, 0.0027]", "hi_m: [0.03, 0.1, 0.0066]")
        .replace("pseudo_2d: true", "pseudo_2d: false")
        .replace("hi_m: [0.03, 0.0315, 0.0027]", "hi_m: [0.03, 0.0315, 0.0066]")
        .replace("cells: [4, 12, 1]", "cells: [4, 12, 2]");
    assert!(text.contains("cells: [4, 12, 2]") && text.contains("0.0066"));
    std::fs::write(dir.join("bed3d.yaml"), text).unwrap();
    granflow_ok(
        &["simulate", "bed3d.yaml", "--out", "bed3d", "--quiet", "--threads", "2"],
        dir,
    );
    let state = final_state(&dir.join("bed3d"));
    assert_eq!(state.particles.len(), 200);
    let gas = state.gas.expect("gas");
    assert_eq!(gas.pressure_pa.len(), 4 * 12 * 2);
    assert!(gas.velocity_m_per_s[2].iter().all(|w| w.is_finite()));
    assert!(
        gas.velocity_m_per_s[2].iter().any(|w| w.abs() > 1e-9),
        "the z velocity is solved in 3-D"
    );
    let series = std::fs::read_to_string(dir.join("bed3d/series.csv")).unwrap();
    let dp = last_row_value(&series, "column_pressure_drop_pa");
    assert!(dp > 100.0, "pressure drop across the 3-D bed: {dp}");
}

#[test]
fn cell_averaged_drag_gives_the_same_bits_on_one_and_two_threads() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("bed.yaml"), bed(0.01, "  drag_velocities: cell_averaged")).unwrap();
    granflow_ok(
        &["simulate", "bed.yaml", "--out", "one", "--quiet", "--threads", "1"],
        dir,
    );
    granflow_ok(
        &["simulate", "bed.yaml", "--out", "two", "--quiet", "--threads", "2"],
        dir,
    );
    let (one, two) = (final_state(&dir.join("one")), final_state(&dir.join("two")));
    assert_eq!(one.step, 1000);
    if let Some(diff) = first_difference(&one, &two) {
        panic!("1 and 2 threads differ: {diff}");
    }
}

/// Seed 001's distributor: jets through a wall. The side with the jets is the inlet side, the superficial velocity
/// counts each jet over the whole side (eq 6.41: U = Σ A_jet V_jet / A_b), and the faces between the jets stay shut.
#[test]
fn jets_through_a_wall_make_the_inlet_side_and_its_superficial_velocity() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // One jet of 10 m/s through the second of four cells: U = 10/4 = 2.5 m/s.
    let text = bed(
        0.002,
        "  jets: [ { side: y_low, lo_m: [0.0076, 0.0, 0.0], hi_m: [0.0149, 0.0, 0.0027], superficial_velocity_m_per_s: 10.0 } ]",
    )
    .replace("y_low: { inlet: { superficial_velocity_m_per_s: 2.5 } }", "y_low: wall");
    assert!(text.contains("y_low: wall"));
    let b = common::built(&text);
    let mut sim = common::simulation(&b, 1);
    granflow::simulate::attach_gas(&b, &mut sim, None).expect("the gas attaches");
    let gas = sim.gas.as_ref().expect("a gas");
    assert_eq!(gas.inlet_side(), Some((1, false)));
    assert_eq!(gas.superficial_inflow_m_per_s(), Some(2.5));
    let gas = final_gas(dir, "wall-jet", &text);
    assert_eq!(&gas.velocity_m_per_s[1][..4], &[0.0, 10.0, 0.0, 0.0]);
}

/// A gas state taken inside a gas step carries the drag scheme's sums: one written under drag held over the gas step
/// is refused by a scenario that evaluates drag every DEM step, and the other way round, with a message that names
/// `gas.drag_update`. (The binary refuses such a resume earlier, because the scenarios differ; this is the last
/// line of defence for a checkpoint put beside another scenario.)
#[test]
fn a_gas_state_inside_a_gas_step_is_refused_under_the_other_drag_update() {
    let snapshot_after = |extra: &str, steps: u64| {
        let b = common::built(&bed(0.03, extra));
        let mut sim = common::simulation(&b, 1);
        granflow::simulate::attach_gas(&b, &mut sim, None).expect("the gas attaches");
        sim.run_steps(steps).expect("stable");
        sim.gas.as_ref().expect("a gas").snapshot()
    };
    let restore_into = |extra: &str, snap: &GasSnapshot| {
        let b = common::built(&bed(0.03, extra));
        let mut sim = common::simulation(&b, 1);
        granflow::simulate::attach_gas(&b, &mut sim, None).expect("the gas attaches");
        sim.restore_gas(snap)
    };
    // 703 steps: 3 DEM steps into a gas step of 7.
    let held = snapshot_after("  drag_update: every_gas_step", 703);
    let every_step = snapshot_after("", 703);
    assert!(held.held_drag.is_some() && every_step.held_drag.is_none());
    assert_eq!((held.reaction_steps, every_step.reaction_steps), (3, 3));
    let err = restore_into("", &held).expect_err("held drag into an every-step scenario");
    assert!(err.contains("every_dem_step"), "{err}");
    let err = restore_into("  drag_update: every_gas_step", &every_step).expect_err("the other way round");
    assert!(err.contains("every_gas_step") && err.contains("3 DEM steps"), "{err}");
    // Each scheme takes back its own.
    restore_into("  drag_update: every_gas_step", &held).expect("held into held");
    restore_into("", &every_step).expect("every step into every step");
}
