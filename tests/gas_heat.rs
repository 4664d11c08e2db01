//! The gas's energy and gas–particle convection (seed 000 eqs. 5.5–5.8; VALIDATION E2, E3): a particle in hot gas
//! heats at h_gp S_p from the Nusselt correlation, a closed adiabatic box of gas and particles keeps its energy, a
//! heated wall heats the gas, `gas.vacuum` switches convection off, and the gas temperature restarts exactly.

mod common;

use std::f64::consts::PI;

use common::{KILN, built, whole_and_resumed, with_gas};
use granflow::engine::Simulation;
use granflow::engine::state::first_difference;

/// One sphere of radius 1 mm in a 2 cm box of gas (4 × 4 × 4 cells), no gravity; `gas_sides` and `nusselt` as
/// given; the gas's heat capacity `gas_c` (a huge one holds the gas at its temperature).
fn sphere_in_gas(density: f64, gas_sides: &str, nusselt: &str, gas_c: f64) -> String {
    format!(
        r#"
name: sphere-in-gas
domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.02, 0.02, 0.02] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, 0.0] }}
species:
  - {{ name: s, radius_m: 0.001, density_kg_per_m3: {density}, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3, thermal_conductivity_w_per_m_k: 1.0, heat_capacity_j_per_kg_k: 8.0 }}
contact: {{ normal: {{ hertz: {{ restitution: 0.5 }} }}, tangential: mindlin }}
walls:
  - box: {{ species: s }}
fill:
  - explicit: {{ species: s, positions_m: [[0.01, 0.01, 0.01]] }}
time: {{ dt_s: 1.0e-5, end_time_s: 1.0 }}
gas:
  density_kg_per_m3: 1.2
  viscosity_pa_s: 1.8e-5
  cells: [4, 4, 4]
  dem_steps_per_gas_step: 20
  sides: {{ {gas_sides} }}
heat:
  initial_temperature_k: 300.0
  gas: {{ initial_temperature_k: 400.0, heat_capacity_j_per_kg_k: {gas_c}, nusselt: {nusselt} }}
"#
    )
}

/// Runs `steps` and returns the measured relaxation rate of T_gas − T_p, and h S / (m c) from the model's
/// conductance at the end.
fn heating_rate(sim: &mut Simulation, steps: u64) -> (f64, f64) {
    let gas_temperature = |sim: &Simulation| {
        let gas = sim.gas.as_ref().expect("a gas");
        let (c, _) = gas
            .convection_conductance(&sim.particles.position_m[0], &sim.particles.velocity_m_per_s[0], 1e-3)
            .expect("heat");
        gas.temperature_k().expect("a temperature")[c]
    };
    let before = gas_temperature(sim) - sim.particles.temperature_k[0];
    let t0 = sim.time_s;
    sim.run_steps(steps).expect("stable");
    let after = gas_temperature(sim) - sim.particles.temperature_k[0];
    let measured = -(after / before).ln() / (sim.time_s - t0);
    let p = &sim.particles;
    let (_, conductance) = sim
        .gas
        .as_ref()
        .unwrap()
        .convection_conductance(&p.position_m[0], &p.velocity_m_per_s[0], 1e-3)
        .unwrap();
    (measured, conductance / (p.mass_kg[0] * 8.0))
}

/// E2 at rest: Ranz–Marshall's Nu = 2, h = 2 k_g/d exactly, and the particle heats as exp(−h S t/(m c)).
#[test]
fn a_sphere_in_still_hot_gas_heats_at_nu_2() {
    let b = built(&sphere_in_gas(2500.0, "", "ranz_marshall", 1.0e9));
    let mut sim = with_gas(&b);
    let (measured, model) = heating_rate(&mut sim, 20_000);
    let mass = 2500.0 * 4.0 / 3.0 * PI * 1e-9;
    let analytic = 2.0 * 0.0261 / 2e-3 * 4.0 * PI * 1e-6 / (mass * 8.0);
    println!("still gas: rate {measured:.6e} 1/s, model {model:.6e}, analytic {analytic:.6e}");
    assert!((model / analytic - 1.0).abs() < 1e-12);
    assert!((measured / analytic - 1.0).abs() < 0.01);
}

/// E2 in a flow: gas at 1 m/s through the box past a heavy sphere (Re ≈ 130, seed 000's eq. 5.6); the particle
/// heats at the correlation's rate, and that rate is eq. 5.6's at the particle's Reynolds number.
#[test]
fn a_sphere_in_a_hot_gas_flow_heats_at_the_seed_correlation() {
    let sides = "y_low: { inlet: { superficial_velocity_m_per_s: 1.0 } }, y_high: outlet";
    let b = built(&sphere_in_gas(1.0e5, sides, "{ seed000: { coefficient: 1.8 } }", 1.0e9));
    let mut sim = with_gas(&b);
    let (measured, model) = heating_rate(&mut sim, 30_000);
    // Eq. 5.6 at Re = ρ d U/μ (ε |u − v| is the superficial velocity in a straight flow), Pr = c μ/k.
    let (re, pr) = (1.2 * 2e-3 * 1.0 / 1.8e-5, 1.0e9 * 1.8e-5 / 0.0261);
    let h = (2.0 + 1.8 * f64::sqrt(re) * f64::cbrt(pr)) * 0.0261 / 2e-3;
    let mass = 1.0e5 * 4.0 / 3.0 * PI * 1e-9;
    let expected = h * 4.0 * PI * 1e-6 / (mass * 8.0);
    println!("gas flow: rate {measured:.6e} 1/s, model {model:.6e}, eq. 5.6 at Re {re:.1}: {expected:.6e}");
    assert!((measured / model - 1.0).abs() < 0.01);
    assert!((model / expected - 1.0).abs() < 0.02, "the cell's Re is the flow's");
}

/// A closed box (walls adiabatic) of gas at 400 K with 27 spheres at 300 K falling and bouncing: the particles'
/// and the gas's energy together stay constant to 1e-8 (read after each gas step, when the gas has taken every
/// exchange).
const CLOSED_BOX: &str = r#"
name: closed-box
domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.02, 0.03, 0.02] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: s, material: steel, radius_m: 0.001, youngs_modulus_pa: 1.0e7, heat_capacity_j_per_kg_k: 5.0 }
contact: { normal: { hertz: { restitution: 0.5 } }, tangential: mindlin }
walls:
  - box: { species: s }
fill:
  - lattice: { species: s, spacing_m: 0.005, lo_m: [0.004, 0.01, 0.004], hi_m: [0.016, 0.025, 0.016] }
time: { dt_s: 1.0e-5, end_time_s: 0.05 }
gas:
  density_kg_per_m3: 1.2
  viscosity_pa_s: 1.8e-5
  cells: [4, 6, 4]
  dem_steps_per_gas_step: 20
  solver: { mass_tolerance: 1.0e-12, linear_tolerance: 1.0e-13, max_outer_iterations: 200 }
heat:
  initial_temperature_k: 300.0
  gas: { initial_temperature_k: 400.0, nusselt: gunn }
output: { checkpoint_every_steps: 500, keep_checkpoints: 2, series_every_steps: 100 }
"#;

fn total_energy_j(sim: &Simulation) -> (f64, f64) {
    let p = &sim.particles;
    let particles: f64 = p.mass_kg.iter().zip(&p.temperature_k).map(|(m, t)| m * 5.0 * t).sum();
    (particles, sim.gas.as_ref().unwrap().thermal_energy_j().unwrap())
}

#[test]
fn a_closed_adiabatic_box_keeps_its_energy() {
    let b = built(CLOSED_BOX);
    let mut sim = with_gas(&b);
    let (p0, g0) = total_energy_j(&sim);
    let mut worst = 0.0f64;
    for _ in 0..50 {
        sim.run_steps(20).expect("stable");
        let (p, g) = total_energy_j(&sim);
        worst = worst.max(((p + g) / (p0 + g0) - 1.0).abs());
    }
    let (p, g) = total_energy_j(&sim);
    let moved = sim.particles.temperature_k.iter().fold(0.0f64, |m, t| m.max(t - 300.0));
    println!(
        "closed box: particles {p0:.6e} -> {p:.6e} J, gas {g0:.6e} -> {g:.6e} J, particles warmed by up to {moved:.3} K, \
         worst relative drift of the total {worst:.2e}"
    );
    assert!(moved > 1.0, "heat flowed into the particles");
    assert!(g < g0, "the gas cooled");
    assert!(worst < 1e-8);
}

/// A floor held at 500 K heats the gas above it; in `vacuum` the same scenario has no gas and its
/// particles do not heat.
#[test]
fn a_heated_wall_heats_the_gas_and_vacuum_switches_the_gas_off() {
    let yaml = sphere_in_gas(2500.0, "", "ranz_marshall", 1000.7).replace(
        "heat:\n  initial_temperature_k: 300.0\n",
        "heat:\n  initial_temperature_k: 300.0\n  walls: { box_y_lo: { temperature_k: 500.0 } }\n",
    );
    let b = built(&yaml);
    let mut sim = with_gas(&b);
    sim.run_steps(2_000).expect("stable");
    let t = sim.gas.as_ref().unwrap().temperature_k().unwrap().to_vec();
    // Cell (i, j, k) = i + 4 j + 16 k: the layers above the floor (j = 0, 1) warm, the bottom one most; the middle
    // ones hold the 300 K sphere, which cools its cell.
    let layer = |j: usize| {
        (0..4)
            .flat_map(|i| (0..4).map(move |k| i + 4 * j + 16 * k))
            .map(|c| t[c])
            .sum::<f64>()
            / 16.0
    };
    println!(
        "heated floor: gas layers {:.3} {:.3} {:.3} {:.3} K",
        layer(0),
        layer(1),
        layer(2),
        layer(3)
    );
    assert!(layer(0) > 401.0 && layer(0) > layer(1) && layer(1) > 400.0);

    let vacuum = built(&yaml.replace("gas:\n  density", "gas:\n  vacuum: true\n  density"));
    assert!(vacuum.gas.is_none());
    let mut sim = with_gas(&vacuum);
    sim.run_steps(2_000).expect("stable");
    assert_eq!(sim.particles.temperature_k, vec![300.0]);
}

/// The gas temperature and its pending exchange are in the checkpoint: a run stopped mid-way (between gas steps)
/// and resumed on another thread count ends with the same bits.
#[test]
fn the_gas_temperature_restarts_exactly() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let (whole, split) = whole_and_resumed(dir, CLOSED_BOX, 2510);
    assert_eq!(whole.step, 5000);
    assert_eq!(whole.gas.as_ref().unwrap().scalars.len(), 1);
    // The summary reports the lumped-particle check (seed 000 §5.1.3): both Biot numbers small.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("whole/summary.json")).expect("summary")).expect("json");
    let biot = &summary["biot_numbers"];
    let (contact, convection) = (
        biot["contact_max"].as_f64().unwrap(),
        biot["convection_max"].as_f64().unwrap(),
    );
    println!("closed box: Biot numbers contact {contact:.3e}, convection {convection:.3e}");
    assert!((0.0..0.1).contains(&contact), "{contact}");
    assert!(convection > 0.0 && convection < 0.01, "{convection}");
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("the resumed run differs from the uninterrupted one: {diff}");
    }
}

#[test]
fn a_kiln_solves_the_gas_inside_its_drum_turns_it_with_the_wall_and_heats_from_its_start_time() {
    let b = built(KILN);
    let setup = b.gas.as_ref().expect("a gas");
    let blocked = setup.config.blocked.iter().filter(|&&x| x).count();
    // 10 × 10 cells of 4.2 mm in a 42 mm square around a drum of radius 20 mm: six cells per corner are outside.
    assert_eq!(blocked, 24, "blocked cells");
    let mut sim = with_gas(&b);
    sim.run_steps(990).expect("stable"); // to t = 0.0198 s
    assert!(
        sim.particles.temperature_k.iter().all(|&t| t == 300.0),
        "no heat before from_s"
    );
    assert!(
        sim.gas
            .as_ref()
            .unwrap()
            .temperature_k()
            .unwrap()
            .iter()
            .all(|&t| t == 300.0)
    );
    sim.run_steps(2010).expect("stable"); // to t = 0.06 s
    let hot = sim.particles.temperature_k.iter().filter(|&&t| t > 300.0).count();
    let gas = sim.gas.as_ref().unwrap();
    let t = gas.temperature_k().unwrap();
    let grid = &gas.solver.config.grid;
    let blocked = &gas.solver.config.blocked;
    let warm = (0..t.len()).filter(|&c| !blocked[c] && t[c] > 300.5).count();
    // The gas turns with the drum: the mean angular momentum (r × u)·z of the open cells has ω's sign.
    let u = gas.solver.interstitial_velocity_m_per_s();
    let mut swirl = 0.0;
    for j in 0..grid.n[1] {
        for i in 0..grid.n[0] {
            let c = grid.cell([i, j, 0]);
            if blocked[c] {
                continue;
            }
            let x = grid.cell_centre_m([i, j, 0]);
            let (ux, uy) = (
                0.5 * (u[0][grid.face(0, [i, j, 0])] + u[0][grid.face(0, [i + 1, j, 0])]),
                0.5 * (u[1][grid.face(1, [i, j, 0])] + u[1][grid.face(1, [i, j + 1, 0])]),
            );
            swirl += x[0] * uy - x[1] * ux;
        }
    }
    println!(
        "kiln at 0.06 s: {hot} particles warmed, {warm} gas cells above 300.5 K, swirl {swirl:.3e} m²/s, last gas \
         step {} outer iterations, mass imbalance {:.2e}",
        gas.last.outer_iterations, gas.last.mass_imbalance
    );
    // The reference pressure on top of the kiln takes up the gas volume the particles displace into the blocked
    // cells' share of the porosity: without it the closed kiln's gas did not converge (imbalance 3-5e-2).
    assert!(gas.last.converged, "the gas step converged");
    assert!(hot > 5, "particles touching the drum heat");
    assert!(warm > 5, "the drum heats the gas beside it");
    assert!(swirl > 0.0, "the gas turns with the drum");
}
