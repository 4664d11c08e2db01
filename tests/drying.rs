//! Drying (seed 000 chapter 7; VALIDATION E4): a wet particle in dry gas at a fixed temperature loses its liquid at
//! the Hertz–Knudsen rate (eq. 7.2), a closed box saturates at p_sat (eq. 7.4) and stops evaporating, the liquid,
//! vapour and energy ledgers close, evaporation cools the particles, and a drying run restarts exactly.

mod common;

use std::f64::consts::PI;

use common::{built, wet_drying_kiln, whole_and_resumed, with_gas, with_gas_on};
use granflow::engine::Simulation;
use granflow::engine::models::evaporation::{
    WATER_MOLAR_MASS_KG_PER_MOL, hertz_knudsen_conductance_kg_per_s_pa, saturation_pressure_pa, vapour_pressure_pa,
};
use granflow::engine::state::first_difference;

/// A box of `side_m` with gas (`cells` per axis) and wet 1 mm spheres (V̂ = `liquid_content`) of heat capacity
/// `c_p`, no gravity; the gas at `gas_t` with heat capacity `gas_c`; `sides` of the gas and the drying keys.
#[allow(clippy::too_many_arguments)]
fn wet_box(
    side_m: f64,
    cells: usize,
    fill: &str,
    liquid_content: f64,
    c_p: f64,
    gas_t: f64,
    gas_c: f64,
    sides: &str,
    drying: &str,
) -> String {
    format!(
        r#"
name: wet-box
domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [{side_m}, {side_m}, {side_m}] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, 0.0] }}
species:
  - {{ name: s, radius_m: 0.001, density_kg_per_m3: 2600.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3, thermal_conductivity_w_per_m_k: 1.0, heat_capacity_j_per_kg_k: {c_p}, liquid_content: {liquid_content} }}
contact: {{ normal: {{ hertz: {{ restitution: 0.5 }} }}, tangential: mindlin }}
cohesion: {{ liquid_bridge: {{ surface_tension_n_per_m: 0.072, walls: true }} }}
walls:
  - box: {{ species: s }}
fill:
{fill}
time: {{ dt_s: 1.0e-5, end_time_s: 0.2 }}
gas:
  density_kg_per_m3: 1.2
  viscosity_pa_s: 1.8e-5
  cells: [{cells}, {cells}, {cells}]
  dem_steps_per_gas_step: 20
  sides: {{ {sides} }}
  solver: {{ mass_tolerance: 1.0e-12, linear_tolerance: 1.0e-13, max_outer_iterations: 200 }}
heat:
  initial_temperature_k: 300.0
  gas: {{ initial_temperature_k: {gas_t}, heat_capacity_j_per_kg_k: {gas_c}, nusselt: ranz_marshall }}
drying: {{ {drying} }}
output: {{ checkpoint_every_steps: 500, keep_checkpoints: 2, series_every_steps: 100 }}
"#
    )
}

/// E4, the rate: one sphere at 300 K (a heat capacity of 1e9 J/(kg K) holds it there) in a 10 cm box flushed by
/// dry gas at 1 m/s, α = 1e-6 so the vapour it makes stays below 1e-7 of p_sat: its liquid falls at
/// α π d² p_sat(T) √(M/(2πRT)) (eq. 7.2 with p_v = 0) to 1e-6 relative.
#[test]
fn a_wet_particle_in_dry_gas_loses_liquid_at_the_hertz_knudsen_rate() {
    let yaml = wet_box(
        0.1,
        2,
        "  - explicit: { species: s, positions_m: [[0.05, 0.05, 0.05]] }",
        0.5,
        1.0e9,
        300.0,
        1000.7,
        "y_low: { inlet: { superficial_velocity_m_per_s: 1.0 } }, y_high: outlet",
        "evaporation_coefficient: 1.0e-6",
    );
    let b = built(&yaml);
    let mut sim = with_gas(&b);
    let liquid0 = sim.total_liquid_m3() * 1000.0;
    sim.run_steps(10_000).expect("stable");
    let lost = liquid0 - sim.total_liquid_m3() * 1000.0;
    let rate = hertz_knudsen_conductance_kg_per_s_pa(1.0e-6, 2e-3, 300.0, WATER_MOLAR_MASS_KG_PER_MOL)
        * saturation_pressure_pa(300.0);
    let expected = rate * sim.time_s;
    let gas = sim.gas.as_ref().unwrap();
    let humidity = gas.mean_relative_humidity().unwrap();
    println!(
        "E4 rate: lost {lost:.9e} kg in {:.3} s, eq. 7.2 {expected:.9e} kg (relative {:.2e}); the gas's mean relative \
         humidity {humidity:.2e}; particle at {} K",
        sim.time_s,
        lost / expected - 1.0,
        sim.particles.temperature_k[0]
    );
    assert!((lost / expected - 1.0).abs() < 1e-6);
    assert!((sim.particles.temperature_k[0] - 300.0).abs() < 1e-9);
    assert!(humidity < 1e-7);
    assert!(sim.drying_closure().unwrap().abs() < 1e-10);
}

/// 27 wet spheres (one per gas cell) at 300 K in a closed 1.2 cm box of gas held at 300 K (huge heat capacities on both sides), α = 1:
/// the vapour pressure rises to p_sat(300 K) and evaporation stops; liquid + vapour stay the start's to 1e-10 at
/// every gas step.
#[test]
fn a_closed_box_saturates_at_the_saturation_pressure() {
    let fill = "  - lattice: { species: s, spacing_m: 0.004, lo_m: [0.0, 0.0, 0.0], hi_m: [0.012, 0.012, 0.012], origin_m: [0.002, 0.002, 0.002] }";
    let b = built(&wet_box(
        0.012,
        3,
        fill,
        0.05,
        1.0e9,
        300.0,
        1.0e9,
        "",
        "evaporation_coefficient: 1.0",
    ));
    let mut sim = with_gas(&b);
    let mut worst = 0.0f64;
    let mut lost_per_gas_step = Vec::new();
    let liquid = |sim: &Simulation| sim.total_liquid_m3() * 1000.0;
    for _ in 0..200 {
        let before = liquid(&sim);
        sim.run_steps(20).expect("stable");
        lost_per_gas_step.push(before - liquid(&sim));
        worst = worst.max(sim.drying_closure().unwrap().abs());
    }
    let gas = sim.gas.as_ref().unwrap();
    let p_sat = saturation_pressure_pa(300.0);
    let w = &gas.scalar(gas.drying.as_ref().unwrap().vapour).value;
    let p_v = vapour_pressure_pa(1.2 * w[0], 300.0, WATER_MOLAR_MASS_KG_PER_MOL);
    let first = lost_per_gas_step[0];
    let last = *lost_per_gas_step.last().unwrap();
    println!(
        "closed box: p_v {p_v:.6} Pa against p_sat {p_sat:.6} Pa (relative {:.2e}); evaporated {first:.3e} kg in the \
         first gas step, {last:.3e} kg in the last; worst closure {worst:.2e}; liquid left {:.3e} kg",
        p_v / p_sat - 1.0,
        liquid(&sim)
    );
    assert!((p_v / p_sat - 1.0).abs() < 1e-6);
    assert!(w.iter().all(|&x| (x / w[0] - 1.0).abs() < 1e-6), "uniform");
    assert!(last.abs() < 1e-6 * first);
    assert!(liquid(&sim) > 0.0, "liquid remains: the box saturated first");
    assert!(worst < 1e-10);
}

/// The same box adiabatic, with glass's heat capacity and the gas's own: evaporation cools the particles (and,
/// through convection, the gas), and the particles' and the gas's sensible heat plus H × the vapour made stay
/// constant to 1e-10.
#[test]
fn evaporation_cools_the_particles_and_the_energy_ledger_closes() {
    let fill = "  - lattice: { species: s, spacing_m: 0.004, lo_m: [0.0, 0.0, 0.0], hi_m: [0.012, 0.012, 0.012], origin_m: [0.002, 0.002, 0.002] }";
    let b = built(&wet_box(
        0.012,
        3,
        fill,
        0.05,
        800.0,
        300.0,
        1000.7,
        "",
        "evaporation_coefficient: 1.0",
    ));
    let mut sim = with_gas(&b);
    let energy = |sim: &Simulation| {
        let p = &sim.particles;
        let particles: f64 = p.mass_kg.iter().zip(&p.temperature_k).map(|(m, t)| m * 800.0 * t).sum();
        let gas = sim.gas.as_ref().unwrap();
        let ledger = gas.drying.as_ref().unwrap().ledger;
        particles + gas.thermal_energy_j().unwrap() + 2.26e6 * ledger.evaporated_kg
    };
    let e0 = energy(&sim);
    let mut worst = 0.0f64;
    let mut coldest = f64::INFINITY;
    for _ in 0..100 {
        sim.run_steps(20).expect("stable");
        worst = worst.max((energy(&sim) / e0 - 1.0).abs());
        coldest = coldest.min(
            sim.particles
                .temperature_k
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min),
        );
    }
    let gas = sim.gas.as_ref().unwrap();
    println!(
        "adiabatic box: coldest particle {coldest:.4} K, gas mean {:.4} K, relative humidity {:.4}, worst energy drift \
         {worst:.2e}, closure {:.2e}",
        gas.mean_temperature_k().unwrap(),
        gas.mean_relative_humidity().unwrap(),
        sim.drying_closure().unwrap()
    );
    assert!(coldest < 299.9, "evaporative cooling");
    assert!(gas.mean_temperature_k().unwrap() < 300.0);
    assert!(worst < 1e-10);
    // The product's own ledger agrees (nothing crosses an adiabatic box's boundary).
    let closure = sim.energy_closure().expect("a heat run has an energy ledger");
    assert!(closure.abs() < 1e-10, "{closure:e}");
}

/// The vapour, the ledger, the liquid and the temperatures are in the checkpoint: a drying run stopped between gas
/// steps and resumed on two threads ends with the same bits as the uninterrupted one.
#[test]
fn a_drying_run_restarts_exactly() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let fill = "  - lattice: { species: s, spacing_m: 0.004, lo_m: [0.0, 0.0, 0.0], hi_m: [0.012, 0.012, 0.012], origin_m: [0.002, 0.002, 0.002] }";
    let yaml = wet_box(
        0.012,
        3,
        fill,
        0.05,
        800.0,
        300.0,
        1000.7,
        "",
        "evaporation_coefficient: 0.5",
    )
    .replace("end_time_s: 0.2", "end_time_s: 0.05")
    .replace(
        "gravity: { vector_m_per_s2: [0.0, 0.0, 0.0] }",
        "gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }",
    );
    let (whole, split) = whole_and_resumed(tmp.path(), &yaml, 2510);
    let gas = whole.gas.as_ref().unwrap();
    assert_eq!(gas.scalars.len(), 2);
    assert!(gas.drying.unwrap().evaporated_kg > 0.0);
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("the resumed run differs from the uninterrupted one: {diff}");
    }
    assert_eq!(whole.gas.as_ref().unwrap().drying, split.gas.as_ref().unwrap().drying);
    let _ = PI;
}

/// Two wet beads pressed together (a bridge forms at once) in a hot, dry flushed box dry completely: the bridge
/// shrinks, breaks once below V/R³ = 1e-6 (its remnant back on the films) rather than shrinking for ever (Mikami's
/// fit extrapolated to vanishing bridges pulls ever harder), the pair stays at its rest overlap, and the ledger
/// closes.
#[test]
fn a_drying_bridge_breaks_and_the_pair_stays_at_rest() {
    let fill = "  - explicit: { species: s, positions_m: [[0.049, 0.05, 0.05], [0.050999, 0.05, 0.05]] }";
    let yaml = wet_box(
        0.1,
        2,
        fill,
        0.02,
        800.0,
        400.0,
        1.0e6,
        "y_low: { inlet: { superficial_velocity_m_per_s: 1.0 } }, y_high: outlet",
        "evaporation_coefficient: 1.0",
    )
    .replace(
        "heat:\n  initial_temperature_k: 300.0",
        "heat:\n  initial_temperature_k: 360.0",
    );
    let b = built(&yaml);
    let mut sim = with_gas(&b);
    let bridge_m3 = |sim: &Simulation| sim.total_liquid_m3() - sim.particles.liquid_m3.iter().sum::<f64>();
    sim.run_steps(1).expect("stable");
    assert!(bridge_m3(&sim) > 0.0, "a bridge formed");
    let mut worst = 0.0f64;
    let mut largest_overlap = 0.0f64;
    for _ in 0..300 {
        sim.run_steps(20).expect("stable");
        worst = worst.max(sim.drying_closure().unwrap().abs());
        let p = &sim.particles;
        largest_overlap = largest_overlap.max(2e-3 - (p.position_m[0] - p.position_m[1]).norm());
    }
    println!(
        "drying pair: bridge {:.3e} m3, films {:?} m3, largest overlap {largest_overlap:.3e} m, worst closure {worst:.2e}",
        bridge_m3(&sim),
        sim.particles.liquid_m3
    );
    assert_eq!(bridge_m3(&sim), 0.0, "the bridge broke");
    assert!(sim.total_liquid_m3() == 0.0, "dry");
    assert!(largest_overlap < 0.01 * 1e-3, "{largest_overlap}");
    assert!(worst < 1e-10);
}

/// The energy ledger of a heated drying drum (`engine::heat_ledger`): the wall at 400 K heats the wet beads through
/// contacts, gas lenses and wall bridges, and the gas through the drum's wall; evaporation takes latent heat. The
/// held energy (particles, gas, latent heat of the liquid evaporated) equals the start plus the heat from the walls
/// and across the gas's boundary (with the gas temperature's continuity term) at every gas step, to 1e-10, while
/// that heat is percent of the start's; and the ledger is the same bits on one thread and on two.
#[test]
fn a_heated_drying_drum_closes_its_energy_ledger_on_any_thread_count() {
    let yaml = wet_drying_kiln();
    let b = built(&yaml);
    let mut one = with_gas_on(&b, 1);
    let mut two = with_gas_on(&b, 2);
    let e0 = one.heat_ledger.expect("started").initial_energy_j;
    let mut worst = 0.0f64;
    for _ in 0..150 {
        one.run_steps(20).expect("stable");
        two.run_steps(20).expect("stable");
        worst = worst.max(one.energy_closure().unwrap().abs());
    }
    let ledger = one.heat_ledger.unwrap();
    let evaporated = one.gas.as_ref().unwrap().drying.as_ref().unwrap().ledger.evaporated_kg;
    println!(
        "heated drying drum, 0.06 s: E0 {e0:.4} J, walls into particles {:.4e} J, into the gas {:.4e} J (out {:.3e}), \
         continuity term {:.3e} J, latent {:.3e} J, worst closure {worst:.2e}",
        ledger.wall_to_particles_j,
        ledger.gas_boundary_in_j,
        ledger.gas_boundary_out_j,
        ledger.gas_continuity_j,
        2.26e6 * evaporated
    );
    assert!(ledger.wall_to_particles_j > 1e-3 * e0, "the wall heated the beads");
    assert!(ledger.gas_boundary_in_j > 0.0, "the wall heated the gas");
    assert!(evaporated > 0.0);
    assert!(worst < 1e-10, "{worst:e}");
    if let Some(diff) = first_difference(&one.snapshot(), &two.snapshot()) {
        panic!("one thread and two differ: {diff}");
    }
}
