//! Conduction through liquid bridges (seed 000 §7.2.1, eqs 7.8–7.11) in running simulations: two wet spheres
//! joined by a bridge relax at the rate H_l = k_l V/d² gives, with d from the parabolic bridge solved directly; a
//! wet drum keeps its energy and the same bits on any thread count and across a restart.

mod common;

use common::{built, simulation, thermal_energy_j, whole_and_resumed};
use granflow::engine::models::liquid_transfer::ParabolicBridge;
use granflow::engine::state::{SimState, first_difference};

const RADIUS_M: f64 = 1.0e-3;
const DENSITY: f64 = 2500.0;
const HEAT_CAPACITY: f64 = 800.0;
const LIQUID_CONDUCTIVITY: f64 = 0.61;

/// One sphere resting on another on a floor, both wet (1 % liquid, θ = 0), the solids barely conducting (k_s =
/// 1e-9 W/(m K)) so that the bridge carries the heat.
fn wet_pair() -> String {
    format!(
        r#"
name: wet-pair
domain: {{ lo_m: [-0.01, 0.0, -0.01], hi_m: [0.01, 0.05, 0.01] }}
gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
species:
  - {{ name: s, radius_m: {RADIUS_M}, density_kg_per_m3: {DENSITY}, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3, thermal_conductivity_w_per_m_k: 1.0e-9, heat_capacity_j_per_kg_k: {HEAT_CAPACITY}, liquid_content: 0.01, contact_angle_deg: 0.0 }}
contact: {{ normal: {{ hertz: {{ restitution: 0.2 }} }}, tangential: mindlin }}
cohesion: {{ liquid_bridge: {{ surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.001 }} }}
walls:
  - box: {{ species: s }}
fill:
  - explicit: {{ species: s, positions_m: [[0.0, {RADIUS_M}, 0.0]], temperature_k: 300.0 }}
  - explicit: {{ species: s, positions_m: [[0.0, {}, 0.0]], temperature_k: 400.0 }}
time: {{ dt_s: 2.0e-6, end_time_s: 1.0 }}
heat:
  initial_temperature_k: 300.0
  liquid_conductivity_w_per_m_k: {LIQUID_CONDUCTIVITY}
"#,
        3.0 * RADIUS_M + 1e-6
    )
}

#[test]
fn two_wet_spheres_relax_at_the_bridge_conductance() {
    let b = built(&wet_pair());
    let mut sim = simulation(&b, 1);
    sim.run_steps(40_000).expect("stable");
    let speed = sim
        .particles
        .velocity_m_per_s
        .iter()
        .map(|v| v.norm())
        .fold(0.0, f64::max);
    assert!(speed < 1e-4, "settled: largest speed {speed} m/s");
    let snapshot = sim.snapshot();
    let volume_m3 = snapshot
        .contacts
        .pairs
        .iter()
        .map(|(_, _, h)| h.cohesion.bridge_volume_m3)
        .fold(0.0, f64::max);
    assert!(volume_m3 > 0.0, "a bridge joins the pair");
    // They overlap: the bridge is the bridge at contact (an overlap does not shorten it).
    let bridge = ParabolicBridge::solve(RADIUS_M, RADIUS_M, 0.0, 0.0, volume_m3, 0.0).expect("a parabola fits");
    let conductance = LIQUID_CONDUCTIVITY * volume_m3 / (bridge.d_m * bridge.d_m);
    let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS_M.powi(3);
    let predicted = 2.0 * conductance / (mass * HEAT_CAPACITY);
    let t = &sim.particles.temperature_k;
    let (before, time_before) = (t[1] - t[0], sim.time_s);
    sim.run_steps(50_000).expect("stable");
    let t = &sim.particles.temperature_k;
    let measured = -((t[1] - t[0]) / before).ln() / (sim.time_s - time_before);
    println!(
        "wet pair: V̂ = {:.3e}, d/R = {:.4}, H_l = {conductance:.4e} W/K ((π/5) k_l R = {:.4e}); decay {measured:.6e} \
         1/s, predicted {predicted:.6e} 1/s ({:+.2e})",
        volume_m3 / RADIUS_M.powi(3),
        bridge.d_m / RADIUS_M,
        std::f64::consts::PI / 5.0 * LIQUID_CONDUCTIVITY * RADIUS_M,
        measured / predicted - 1.0
    );
    assert!((measured / predicted - 1.0).abs() < 0.01);
}

/// A wet drum (bridges between particles and to its wall, half the bed hot): heat flows through contacts and
/// bridges, the particles' energy is kept to rounding, and the bits do not depend on the thread count or a restart.
const WET_DRUM: &str = r#"
name: wet-heat-drum
domain: { lo_m: [-0.041, -0.041, 0.0], hi_m: [0.041, 0.041, 0.012], periodic: [false, false, true] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, material: glass, radius_m: 0.0015, youngs_modulus_pa: 5.0e7, liquid_content: 0.01, contact_angle_deg: 20.0 }
contact: { normal: { hertz: { restitution: 0.6 } }, tangential: mindlin }
cohesion: { liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.001, walls: true } }
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

#[test]
fn a_wet_drum_keeps_its_energy_and_the_same_bits_on_any_thread_count_and_across_a_restart() {
    let b = built(WET_DRUM);
    assert!(b.config.heat.as_ref().is_some_and(|h| h.bridges.is_some()));
    let before = thermal_energy_j(&simulation(&b, 1).snapshot(), HEAT_CAPACITY);
    let states: Vec<SimState> = [1, 2]
        .iter()
        .map(|&threads| {
            let mut sim = simulation(&b, threads);
            sim.run_steps(1500).expect("stable");
            sim.snapshot()
        })
        .collect();
    let bridges = states[0]
        .contacts
        .pairs
        .iter()
        .filter(|(_, _, h)| h.cohesion.bridge_volume_m3 > 0.0)
        .count();
    let after = thermal_energy_j(&states[0], HEAT_CAPACITY);
    println!("wet drum: {bridges} bridges, energy drift {:.2e}", after / before - 1.0);
    assert!(bridges > 100, "bridges formed");
    assert!((after / before - 1.0).abs() < 1e-12, "energy {before} -> {after}");
    if let Some(diff) = first_difference(&states[0], &states[1]) {
        panic!("2 threads differ from 1: {diff}");
    }
    // Without bridge conduction (a liquid that barely conducts) the temperatures differ: the bridges carry heat.
    let dry_liquid = built(&WET_DRUM.replace(
        "walls: { drum: { adiabatic: true } } }",
        "walls: { drum: { adiabatic: true } }, liquid_conductivity_w_per_m_k: 1.0e-12 }",
    ));
    let mut sim = simulation(&dry_liquid, 1);
    sim.run_steps(1500).expect("stable");
    assert_ne!(sim.particles.temperature_k, states[0].particles.temperature_k);

    let tmp = tempfile::tempdir().expect("temp dir");
    let (whole, split) = whole_and_resumed(tmp.path(), WET_DRUM, 1700);
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("the resumed run differs from the uninterrupted one: {diff}");
    }
}
