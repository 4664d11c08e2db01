//! Heat transfer by conduction (seed 000 §5.1.2.1; VALIDATION E1): two spheres in contact relax at the analytic
//! rate, a sphere on a heated wall heats at its contact's rate, a chain of spheres follows its exact series solution,
//! the soft-contact correction scales the rate as it should, a closed bed keeps its energy, and temperatures are the
//! same bits on any thread count and across a restart.

mod common;

use std::f64::consts::PI;

use common::{built, simulation, thermal_energy_j, whole_and_resumed};
use granflow::engine::Simulation;
use granflow::engine::state::{SimState, first_difference};

const RADIUS_M: f64 = 1.0e-3;
const DENSITY: f64 = 2500.0;
const YOUNGS_PA: f64 = 1.0e7;
const POISSON: f64 = 0.3;
const CONDUCTIVITY: f64 = 1000.0;
const HEAT_CAPACITY: f64 = 800.0;

fn mass_kg() -> f64 {
    DENSITY * 4.0 / 3.0 * PI * RADIUS_M.powi(3)
}

/// A box with a floor (the `box_y_lo` wall) under gravity along −y, spheres placed explicitly, one fill per
/// temperature; `extra_species` and `heat_walls` go into the species entry and the `heat.walls` map.
fn stacked(fills: &[(f64, [f64; 3])], extra_species: &str, heat_walls: &str, gravity: f64) -> String {
    let fill = common::explicit_fills(fills);
    format!(
        r#"
name: heat
domain: {{ lo_m: [-0.01, 0.0, -0.01], hi_m: [0.01, 0.05, 0.01] }}
gravity: {{ vector_m_per_s2: [0.0, {gravity}, 0.0] }}
species:
  - {{ name: s, radius_m: {RADIUS_M}, density_kg_per_m3: {DENSITY}, youngs_modulus_pa: {YOUNGS_PA}, poisson_ratio: {POISSON}, friction_coefficient: 0.3, thermal_conductivity_w_per_m_k: {CONDUCTIVITY}, heat_capacity_j_per_kg_k: {HEAT_CAPACITY}{extra_species} }}
contact: {{ normal: {{ hertz: {{ restitution: 0.2 }} }}, tangential: mindlin }}
walls:
  - box: {{ species: s }}
fill:
{fill}time: {{ dt_s: 2.0e-6, end_time_s: 1.0 }}
heat:
  initial_temperature_k: 300.0
  walls: {{ {heat_walls} }}
"#
    )
}

/// Runs until the motion has died down (the contacts are static from then on).
fn settle(sim: &mut Simulation) {
    sim.run_steps(40_000).expect("stable");
    let speed = sim
        .particles
        .velocity_m_per_s
        .iter()
        .map(|v| v.norm())
        .fold(0.0, f64::max);
    assert!(speed < 1e-4, "settled: largest speed {speed} m/s");
}

/// Hertz contact radius √(R* δ) of the pair (i, j) at the current positions.
fn pair_contact_radius_m(sim: &Simulation, i: usize, j: usize) -> f64 {
    let x = &sim.particles.position_m;
    let overlap = 2.0 * RADIUS_M - (x[i] - x[j]).norm();
    assert!(overlap > 0.0, "particles {i} and {j} touch");
    (0.5 * RADIUS_M * overlap).sqrt()
}

/// E1: a sphere resting on another on an adiabatic floor; their temperature difference decays as
/// exp(−H t (1/(m₁c₁) + 1/(m₂c₂))) with H = 2 R_c k. Returns the measured rate over the predicted one.
fn two_sphere_rate_ratio(extra_species: &str, radius_scale: f64) -> f64 {
    let yaml = stacked(
        &[
            (300.0, [0.0, RADIUS_M, 0.0]),
            (400.0, [0.0, 3.0 * RADIUS_M + 1e-6, 0.0]),
        ],
        extra_species,
        "",
        -9.81,
    );
    let b = built(&yaml);
    let mut sim = simulation(&b, 1);
    settle(&mut sim);
    let t = &sim.particles.temperature_k;
    let (difference_before, time_before) = (t[1] - t[0], sim.time_s);
    let conductance = 2.0 * CONDUCTIVITY * pair_contact_radius_m(&sim, 0, 1) * radius_scale;
    let thermal_mass = mass_kg() * HEAT_CAPACITY;
    sim.run_steps(50_000).expect("stable");
    let t = &sim.particles.temperature_k;
    let elapsed = sim.time_s - time_before;
    let measured = -((t[1] - t[0]) / difference_before).ln() / elapsed;
    let predicted = conductance * 2.0 / thermal_mass;
    println!(
        "two spheres: decay rate {measured:.6e} 1/s, analytic {predicted:.6e} 1/s ({:+.2e}), ΔT {difference_before:.3} \
         -> {:.3} K over {elapsed:.3} s",
        measured / predicted - 1.0,
        t[1] - t[0]
    );
    measured / predicted
}

#[test]
fn two_spheres_in_contact_relax_at_the_analytic_rate() {
    let ratio = two_sphere_rate_ratio("", 1.0);
    assert!((ratio - 1.0).abs() < 1e-3, "rate ratio {ratio}");
}

/// The soft-contact correction on: a species softened from 1e10 to 1e7 Pa conducts through a contact radius scaled
/// by (E*_soft/E*_real)^(1/5) = 1e-3^(1/5).
#[test]
fn the_soft_contact_correction_scales_the_conduction_back() {
    let scale = (YOUNGS_PA / 1.0e10f64).powf(0.2);
    let ratio = two_sphere_rate_ratio(", real_youngs_modulus_pa: 1.0e10", scale);
    assert!((ratio - 1.0).abs() < 1e-3, "corrected rate ratio {ratio}");
    // Without the correction the same contact conducts 1/scale ≈ 4× faster.
    let uncorrected = two_sphere_rate_ratio("", 1.0);
    assert!((uncorrected - 1.0).abs() < 1e-3);
}

/// A sphere resting on a floor at 400 K heats as T_w − T ∝ exp(−H t/(m c)), H = 2 √(R δ) k (the wall an infinite
/// sphere); with the floor adiabatic it keeps its temperature exactly.
#[test]
fn a_sphere_on_a_heated_wall_heats_at_its_contact_rate_and_an_adiabatic_wall_passes_nothing() {
    let yaml = stacked(
        &[(300.0, [0.0, RADIUS_M, 0.0])],
        "",
        "box_y_lo: { temperature_k: 400.0 }, box_y_hi: { adiabatic: true }",
        -9.81,
    );
    let b = built(&yaml);
    let mut sim = simulation(&b, 1);
    settle(&mut sim);
    let (before, time_before) = (400.0 - sim.particles.temperature_k[0], sim.time_s);
    let overlap = RADIUS_M - sim.particles.position_m[0].y;
    let conductance = 2.0 * CONDUCTIVITY * (RADIUS_M * overlap).sqrt();
    sim.run_steps(50_000).expect("stable");
    let after = 400.0 - sim.particles.temperature_k[0];
    let measured = -(after / before).ln() / (sim.time_s - time_before);
    let predicted = conductance / (mass_kg() * HEAT_CAPACITY);
    println!("sphere on a 400 K floor: rate {measured:.6e} 1/s, analytic {predicted:.6e} 1/s");
    assert!((measured / predicted - 1.0).abs() < 1e-3);

    let yaml = stacked(&[(300.0, [0.0, RADIUS_M, 0.0])], "", "", -9.81);
    let mut sim = simulation(&built(&yaml), 1);
    sim.run_steps(20_000).expect("stable");
    assert_eq!(sim.particles.temperature_k, vec![300.0]);
}

/// A row of eight spheres squeezed between two adiabatic walls (no gravity) settles with equal overlaps; the first
/// is then heated by 100 K. The discrete chain dT_i/dt = (H/C)(T_{i−1} − 2T_i + T_{i+1}) with insulated ends has
/// the exact solution T_i(t) = Σ_k a_k e^{−λ_k t} cos(kπ(i + ½)/N), λ_k = (2H/C)(1 − cos(kπ/N)); the simulation
/// follows it to 1e-4 of the initial difference.
#[test]
fn a_chain_of_spheres_follows_its_series_solution() {
    const N: usize = 8;
    let squeeze = 2e-6;
    let fills: Vec<(f64, [f64; 3])> = (0..N)
        .map(|i| {
            (
                300.0,
                [
                    -0.008 + RADIUS_M + 2.0 * RADIUS_M * i as f64 - squeeze * i as f64,
                    0.025,
                    0.0,
                ],
            )
        })
        .collect();
    let mut yaml = stacked(&fills, "", "", 0.0);
    // Walls only at both ends of the chain: the box's x walls moved to squeeze it.
    let right = fills[N - 1].1[0] + RADIUS_M - squeeze;
    yaml = yaml.replace(
        "  - box: { species: s }",
        &format!(
            "  - plane: {{ name: left, species: s, point_m: [{}, 0.0, 0.0], normal: [1.0, 0.0, 0.0] }}\n  - plane: {{ name: right, species: s, point_m: [{right}, 0.0, 0.0], normal: [-1.0, 0.0, 0.0] }}",
            -0.008 + squeeze
        ),
    );
    let b = built(&yaml);
    let mut sim = simulation(&b, 1);
    settle(&mut sim);
    let radii: Vec<f64> = (0..N - 1).map(|i| pair_contact_radius_m(&sim, i, i + 1)).collect();
    let spread = radii.iter().fold(0.0f64, |m, r| m.max((r / radii[0] - 1.0).abs()));
    assert!(spread < 1e-6, "equal contacts along the chain: {radii:?}");
    let rate = 2.0 * CONDUCTIVITY * radii[0] / (mass_kg() * HEAT_CAPACITY);
    let initial: Vec<f64> = (0..N).map(|i| if i == 0 { 400.0 } else { 300.0 }).collect();
    sim.particles.temperature_k = initial.clone();
    let start = sim.time_s;
    sim.run_steps(400_000).expect("stable");
    let t = sim.time_s - start;
    let n = N as f64;
    let mode = |k: usize, i: usize| (k as f64 * PI * (i as f64 + 0.5) / n).cos();
    let exact: Vec<f64> = (0..N)
        .map(|i| {
            (0..N)
                .map(|k| {
                    let norm = if k == 0 { 1.0 / n } else { 2.0 / n };
                    let a_k = norm * (0..N).map(|m| initial[m] * mode(k, m)).sum::<f64>();
                    let lambda = 2.0 * rate * (1.0 - (k as f64 * PI / n).cos());
                    a_k * (-lambda * t).exp() * mode(k, i)
                })
                .sum()
        })
        .collect();
    let worst = (0..N)
        .map(|i| (sim.particles.temperature_k[i] - exact[i]).abs() / 100.0)
        .fold(0.0, f64::max);
    println!(
        "chain after {t:.3} s (rate H/C {rate:.3e} 1/s): simulated {:?}\n  series {:?}\n  worst difference {worst:.2e} of ΔT",
        sim.particles.temperature_k, exact
    );
    assert!(exact[N - 1] - 300.0 > 2.0, "heat reached the far end");
    assert!(worst < 1e-4);
}

/// A rotating drum, half its spheres at 300 K and half at 400 K (so that heat flows), the wall adiabatic.
const DRUM: &str = r#"
name: heat-drum
domain: { lo_m: [-0.041, -0.041, 0.0], hi_m: [0.041, 0.041, 0.012], periodic: [false, false, true] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, material: glass, radius_m: 0.0015, youngs_modulus_pa: 5.0e7, thermal_conductivity_w_per_m_k: 50.0 }
contact: { normal: { hertz: { restitution: 0.6 } }, tangential: mindlin }
walls:
  - drum: { name: drum, species: glass, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: 0.04, rotation_rpm: 120.0 }
fill:
  - lattice: { species: glass, spacing_m: 0.003, lo_m: [-0.04, -0.04, 0.0], hi_m: [0.0, 0.002, 0.012], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum, temperature_k: 400.0 }
  - lattice: { species: glass, spacing_m: 0.003, lo_m: [0.0, -0.04, 0.0], hi_m: [0.04, 0.002, 0.012], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }
time: { dt_s: 1.0e-5, end_time_s: 0.03 }
heat: { initial_temperature_k: 300.0, walls: { drum: { adiabatic: true } } }
output: { checkpoint_every_steps: 500, keep_checkpoints: 2, series_every_steps: 100 }
seed: 3
"#;

/// The drum keeps its particles' energy Σ m c T to rounding while heat flows between them, and the temperatures
/// are the same bits on 1, 2 and 3 threads, through the heat pass and the wide pass, and across a restart in a fresh
/// process.
#[test]
fn a_closed_drum_keeps_its_energy_and_the_same_bits_on_any_thread_count_and_across_a_restart() {
    let b = built(DRUM);
    let before = thermal_energy_j(&simulation(&b, 1).snapshot(), 800.0);
    let states: Vec<SimState> = [1, 2, 3]
        .iter()
        .map(|&threads| {
            let mut sim = simulation(&b, threads);
            sim.run_steps(1500).expect("stable");
            sim.snapshot()
        })
        .collect();
    let t = &states[0].particles.temperature_k;
    let moved = t.iter().filter(|&&t| t != 300.0 && t != 400.0).count();
    let after = thermal_energy_j(&states[0], 800.0);
    println!(
        "drum: {} particles, {moved} changed temperature, range {:.3}–{:.3} K, energy drift {:.2e}",
        t.len(),
        t.iter().copied().fold(f64::INFINITY, f64::min),
        t.iter().copied().fold(0.0, f64::max),
        after / before - 1.0
    );
    assert!(moved > 50, "heat flowed");
    assert!((after / before - 1.0).abs() < 1e-12, "energy {before} -> {after}");
    for (k, s) in states.iter().enumerate().skip(1) {
        if let Some(diff) = first_difference(&states[0], s) {
            panic!("{} threads differ from 1: {diff}", k + 1);
        }
    }

    // The heat pass (a run whose only channel is heat) and the wide pass (here with the contact statistics too)
    // compute the same motion and temperatures.
    let wide = built(&DRUM.replace(
        "series_every_steps: 100 }",
        "series_every_steps: 100, contact_statistics: true }",
    ));
    let mut sim = simulation(&wide, 2);
    sim.run_steps(1500).expect("stable");
    let w = sim.snapshot();
    assert!(w.particles.channels.groups().statistics);
    assert_eq!(w.particles.temperature_k, states[0].particles.temperature_k);
    assert_eq!(w.particles.position_m, states[0].particles.position_m);

    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let (whole, split) = whole_and_resumed(dir, DRUM, 1700);
    assert_eq!(whole.step, 3000);
    assert_eq!(whole.particles.temperature_k.len(), whole.particles.len());
    // The summary's lumped-particle check (seed 000 eq. 5.15): (2/π) √(δ/R) of the deepest contact, small.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("whole/summary.json")).expect("summary")).expect("json");
    let contact = summary["biot_numbers"]["contact_max"]
        .as_f64()
        .expect("a contact Biot number");
    println!("drum: contact Biot number {contact:.3e}");
    assert!(contact > 0.0 && contact < 0.2, "{contact}");
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("the resumed run differs from the uninterrupted one: {diff}");
    }
}
