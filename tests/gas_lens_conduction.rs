//! Conduction through the gas lens (`heat.gas.lens_conduction`; Rong & Horio 1999 as in MFIX-DEM): two spheres a
//! small gap apart in still gas relax at the rate of the lens's conductance and keep their energy, a sphere beside a
//! heated wall heats at the wall lens's rate, and without gas (`gas.vacuum`) or without the key nothing crosses the
//! gap.

mod common;

use std::f64::consts::PI;

use common::{KILN, built};
use granflow::engine::Simulation;
use granflow::engine::models::gas_lens::GasLens;

const RADIUS_M: f64 = 1.0e-3;
const DENSITY: f64 = 2500.0;
const HEAT_CAPACITY: f64 = 800.0;
const GAS_CONDUCTIVITY: f64 = 0.0261;

fn thermal_mass_j_per_k() -> f64 {
    DENSITY * 4.0 / 3.0 * PI * RADIUS_M.powi(3) * HEAT_CAPACITY
}

/// Spheres at rest at `positions` (temperatures `temperatures`) in a 2 cm box of still gas, no gravity; seed 000's
/// correlation, which at rest (Re = 0) exchanges nothing with the gas, so only the lens moves heat. `lens` is the
/// `heat.gas` entry, `walls` the `heat.walls` map.
fn spheres_in_still_gas(positions: &[[f64; 3]], temperatures: &[f64], lens: &str, walls: &str) -> String {
    let fills: Vec<(f64, [f64; 3])> = temperatures.iter().copied().zip(positions.iter().copied()).collect();
    let fill = common::explicit_fills(&fills);
    format!(
        r#"
name: lens
domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.02, 0.02, 0.02] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, 0.0] }}
species:
  - {{ name: s, radius_m: {RADIUS_M}, density_kg_per_m3: {DENSITY}, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3, thermal_conductivity_w_per_m_k: 1.0, heat_capacity_j_per_kg_k: {HEAT_CAPACITY} }}
contact: {{ normal: {{ hertz: {{ restitution: 0.5 }} }}, tangential: mindlin }}
walls:
  - box: {{ species: s }}
fill:
{fill}time: {{ dt_s: 1.0e-5, end_time_s: 1.0 }}
gas:
  density_kg_per_m3: 1.2
  viscosity_pa_s: 1.8e-5
  cells: [4, 4, 4]
  dem_steps_per_gas_step: 20
heat:
  initial_temperature_k: 300.0
  walls: {{ {walls} }}
  gas: {{ conductivity_w_per_m_k: {GAS_CONDUCTIVITY}, nusselt: {{ seed000: {{}} }}{lens} }}
"#
    )
}

fn with_gas(yaml: &str) -> Simulation {
    common::with_gas(&built(yaml))
}

const MFIX_LENS: GasLens = GasLens {
    gas_conductivity_w_per_m_k: GAS_CONDUCTIVITY,
    lens_radius_fraction: 0.2,
    min_gap_m: 4e-10,
};

/// Two spheres 20 µm apart, 300 and 400 K: ΔT decays as exp(−2 H t/(m c)) with H the lens's conductance at that
/// gap, and Σ m c T stays what it was.
#[test]
fn two_spheres_a_gap_apart_in_gas_relax_at_the_lens_rate_and_keep_their_energy() {
    let gap = 2.0e-5;
    let positions = [[0.01, 0.01, 0.01], [0.01 + 2.0 * RADIUS_M + gap, 0.01, 0.01]];
    let mut sim = with_gas(&spheres_in_still_gas(
        &positions,
        &[300.0, 400.0],
        ", lens_conduction: {}",
        "",
    ));
    let energy = |sim: &Simulation| sim.particles.temperature_k.iter().sum::<f64>() * thermal_mass_j_per_k();
    let (energy_before, t0) = (energy(&sim), sim.time_s);
    sim.run_steps(20_000).expect("stable");
    let t = &sim.particles.temperature_k;
    let moved = (sim.particles.position_m[1] - sim.particles.position_m[0]).norm() - 2.0 * RADIUS_M - gap;
    assert!(moved.abs() < 1e-12, "the spheres stay put (gap moved {moved} m)");
    let measured = -((t[1] - t[0]) / 100.0).ln() / (sim.time_s - t0);
    let conductance = MFIX_LENS.pair_conductance_w_per_k(RADIUS_M, RADIUS_M, 2.0 * RADIUS_M + gap);
    let predicted = 2.0 * conductance / thermal_mass_j_per_k();
    println!(
        "lens: H {conductance:.4e} W/K, decay {measured:.6e} 1/s against {predicted:.6e} ({:+.2e}); ΔT 100 -> {:.4} K",
        measured / predicted - 1.0,
        t[1] - t[0]
    );
    assert!((measured / predicted - 1.0).abs() < 1e-4);
    assert!(t[1] - t[0] < 99.5, "heat crossed the gap");
    let drift = (energy(&sim) - energy_before).abs() / energy_before;
    assert!(drift < 1e-12, "energy drift {drift:e}");
}

/// A sphere 30 µm above a floor held at 400 K heats as T_w − T ∝ exp(−H_w t/(m c)), H_w the wall lens's
/// conductance (the floor a sphere of infinite radius).
#[test]
fn a_sphere_beside_a_heated_wall_heats_at_the_wall_lens_rate() {
    let gap = 3.0e-5;
    let mut sim = with_gas(&spheres_in_still_gas(
        &[[0.01, RADIUS_M + gap, 0.01]],
        &[300.0],
        ", lens_conduction: {}",
        "box_y_lo: { temperature_k: 400.0 }",
    ));
    let t0 = sim.time_s;
    sim.run_steps(20_000).expect("stable");
    let t = sim.particles.temperature_k[0];
    let measured = -((400.0 - t) / 100.0).ln() / (sim.time_s - t0);
    let predicted = MFIX_LENS.wall_conductance_w_per_k(RADIUS_M, gap) / thermal_mass_j_per_k();
    println!(
        "wall lens: decay {measured:.6e} 1/s against {predicted:.6e} ({:+.2e}); T 300 -> {t:.4} K",
        measured / predicted - 1.0
    );
    assert!((measured / predicted - 1.0).abs() < 1e-4);
}

/// Without the key, or in vacuum with it, the same spheres exchange nothing across the gap (and nothing with the
/// still gas).
#[test]
fn without_the_lens_or_without_gas_nothing_crosses_the_gap() {
    let positions = [[0.01, 0.01, 0.01], [0.01 + 2.0 * RADIUS_M + 2.0e-5, 0.01, 0.01]];
    let lens = spheres_in_still_gas(&positions, &[300.0, 400.0], ", lens_conduction: {}", "");
    for yaml in [
        spheres_in_still_gas(&positions, &[300.0, 400.0], "", ""),
        lens.replace("gas:\n  density", "gas:\n  vacuum: true\n  density"),
    ] {
        let mut sim = with_gas(&yaml);
        sim.run_steps(2_000).expect("stable");
        assert_eq!(sim.particles.temperature_k, vec![300.0, 400.0]);
    }
}

/// The gas-heat tests' small glass kiln in air (the drum at 400 K from 0.02 s, 10 × 10 × 1 gas cells inside it) with
/// the lens.
fn kiln_with_lens() -> String {
    format!("{KILN}  gas: {{ lens_conduction: {{}} }}\n")
}

/// With the lens the kiln's glass bed takes more heat from its wall than without (glass conducts little through its
/// contact spots), and its temperatures are the same bits on 1 and 2 threads and across a restart.
#[test]
fn a_kiln_with_the_lens_heats_faster_and_restarts_to_the_same_bits_on_any_thread_count() {
    let mean_temperature = |yaml: &str| {
        let mut sim = with_gas(yaml);
        sim.run_steps(10_000).expect("stable");
        let t = &sim.particles.temperature_k;
        t.iter().sum::<f64>() / t.len() as f64
    };
    let with_lens = mean_temperature(&kiln_with_lens());
    let without = mean_temperature(KILN);
    println!("small glass kiln after 0.18 s of heating: mean {with_lens:.4} K with the lens, {without:.4} K without");
    assert!(with_lens - 300.0 > 2.0 * (without - 300.0), "{with_lens} vs {without}");

    let tmp = tempfile::tempdir().expect("temp dir");
    let (whole, split) = common::whole_and_resumed(tmp.path(), &kiln_with_lens(), 5_010);
    assert_eq!(whole.step, 10_000);
    // The summary reports the lens's Biot number: glass (k_s 1.7 W/(m K)) in air is not far below 1 at its contacts.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.path().join("whole/summary.json")).expect("summary"))
            .expect("json");
    let lens_biot = summary["biot_numbers"]["lens_max"].as_f64().expect("lens_max");
    println!("lens Biot number {lens_biot:.3}");
    assert!(lens_biot > 0.1 && lens_biot < 1.0, "{lens_biot}");
    if let Some(diff) = granflow::engine::state::first_difference(&whole, &split) {
        panic!("the resumed run differs from the uninterrupted one: {diff}");
    }
}
