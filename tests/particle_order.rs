//! Particles sorted by place (`neighbor.sort_every_steps`, `engine::particle_order`): a sorted run restarts bit for
//! bit (with its liquid bridges, tangential histories and held drag carried through the reordering), gives the same
//! bits on one and two threads, and follows the same trajectories as the unsorted run (particle by particle, by id)
//! to rounding.

mod common;

use common::{built, simulation, whole_and_resumed};
use granflow::engine::state::{SimState, first_difference};
use granflow::engine::{Simulation, Vec3};

/// The wet drum of the cohesion tests (seed 000's liquid bridges, sprayed liquid, two species) with Walton-Braun
/// friction and its vector histories, 0.03 s: the drum turns at 120 rpm and mixes, so every sort moves many beads.
fn wet_drum() -> String {
    let mut yaml = common::WET_DRUM.to_string();
    for (from, to) in [
        ("name: wet-drum", "name: sorted-wet-drum"),
        ("tangential: mindlin", "tangential: { walton_braun: {} }"),
        ("end_time_s: 0.08", "end_time_s: 0.03"),
        ("checkpoint_every_steps: 2000", "checkpoint_every_steps: 500"),
    ] {
        assert!(yaml.contains(from), "the wet drum has {from}");
        yaml = yaml.replace(from, to);
    }
    yaml
}

/// A pseudo-2-D bed bubbling under 3.5 m/s, drag held over the gas step (7 DEM steps), cell-averaged and
/// semi-implicit: a sort every 50 steps falls inside gas steps, where the held drag must follow its particles.
const HELD_DRAG_BED: &str = r#"
name: sorted-bed
domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.03, 0.1, 0.0027], periodic: [true, false, false] }
pseudo_2d: true
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, radius_m: 0.00135, density_kg_per_m3: 2000.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.33, friction_coefficient: 0.3 }
contact: { normal: { hertz: { restitution: 0.9 } }, tangential: mindlin }
walls: [ { box: { species: glass } } ]
fill:
  - lattice: { species: glass, spacing_m: 0.003, lo_m: [0.0, 0.0015, 0.0], hi_m: [0.03, 0.0315, 0.0027], origin_m: [0.0015, 0.0015, 0.00135] }
gas:
  density_kg_per_m3: 1.23
  viscosity_pa_s: 1.8e-5
  cells: [4, 12, 1]
  sides: { y_low: { inlet: { superficial_velocity_m_per_s: 3.5 } }, y_high: outlet }
  dem_steps_per_gas_step: 7
  drag_update: every_gas_step
  drag_velocities: cell_averaged
  drag_coupling: semi_implicit
time: { dt_s: 1.0e-5, end_time_s: 0.03 }
output: { checkpoint_every_steps: 1000, keep_checkpoints: 2, series_every_steps: 70 }
"#;

fn sorted(yaml: &str, every: u64) -> String {
    format!("{yaml}neighbor: {{ sort_every_steps: {every} }}\n")
}

/// Particles moved away from their fill order (the identity order `0..n`).
fn reordered_particles(s: &SimState) -> usize {
    s.particles
        .id
        .iter()
        .enumerate()
        .filter(|(k, id)| id.0 as usize != *k)
        .count()
}

#[test]
fn a_sorted_wet_drum_restarts_bit_identically_across_a_sort() {
    let tmp = tempfile::tempdir().expect("temp dir");
    // The stop at step 1500 is itself a sort step: the checkpoint holds the sorted state.
    let (whole, split) = whole_and_resumed(tmp.path(), &sorted(&wet_drum(), 100), 1500);
    assert_eq!(whole.step, 3000);
    let moved = reordered_particles(&whole);
    let bridges = whole
        .contacts
        .pairs
        .iter()
        .filter(|c| c.2.cohesion.bridge_volume_m3 > 0.0)
        .count();
    let sliding = whole
        .contacts
        .pairs
        .iter()
        .filter(|c| c.2.tangential.reversal_force_n != Vec3::zeros())
        .count();
    println!(
        "sorted wet drum: {} particles, {moved} away from their fill order, {bridges} bridges, {sliding} contacts with a slip reversal",
        whole.particles.len()
    );
    assert!(moved > whole.particles.len() / 4, "the sorts must reorder the drum");
    assert!(bridges > 100 && sliding > 0);
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("the restarted sorted drum differs from the uninterrupted one: {diff}");
    }
}

#[test]
fn a_sorted_bed_with_held_drag_restarts_bit_identically_inside_a_gas_step() {
    let tmp = tempfile::tempdir().expect("temp dir");
    // Step 1503 is 5 DEM steps into a gas step and 3 after the sort of step 1500 (itself 2 into a gas step).
    let (whole, split) = whole_and_resumed(tmp.path(), &sorted(HELD_DRAG_BED, 50), 1503);
    assert_eq!(whole.step, 3000);
    assert!(reordered_particles(&whole) > 10, "the bubbling bed must be reordered");
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("the restarted sorted bed differs from the uninterrupted one: {diff}");
    }
}

#[test]
fn a_sorted_run_gives_the_same_bits_on_one_and_two_threads() {
    for yaml in [sorted(&wet_drum(), 100), sorted(HELD_DRAG_BED, 50)] {
        let b = built(&yaml);
        let states: Vec<SimState> = [1, 2]
            .iter()
            .map(|&threads| {
                let mut sim = simulation(&b, threads);
                granflow::simulate::attach_gas(&b, &mut sim, None).expect("the gas attaches");
                sim.run_steps(1200).expect("stable");
                sim.snapshot()
            })
            .collect();
        assert!(reordered_particles(&states[0]) > 0, "{}: sorted", b.spec.name);
        if let Some(diff) = first_difference(&states[0], &states[1]) {
            panic!("{}: two threads differ from one: {diff}", b.spec.name);
        }
    }
}

/// Sorting changes the order in which forces are summed, nothing else: from a state of the turning drum with its
/// bridges and sliding contacts (1500 steps in), 300 steps sorted every 10 steps put each particle, found by its id,
/// where the unsorted run puts it, to rounding (the sums differ in their last bits, which the contacts amplify). A
/// history that did not follow its pair, or a tangential vector not reversed where the pair turned round, moves
/// particles by micrometres in that time.
#[test]
fn a_sorted_run_follows_the_unsorted_trajectories() {
    let plain = built(&wet_drum());
    let every_10 = built(&sorted(&wet_drum(), 10));
    let mut start = simulation(&plain, 1);
    start.run_steps(1500).expect("stable");
    let start = start.snapshot();
    let mut a = Simulation::restore(plain.config.clone(), start.clone(), 1).expect("restores");
    let mut b = Simulation::restore(every_10.config.clone(), start, 1).expect("restores");
    a.run_steps(300).expect("stable");
    b.run_steps(300).expect("stable");
    let (a, b) = (a.snapshot(), b.snapshot());
    assert!(reordered_particles(&b) > b.particles.len() / 4, "sorted");
    let mut worst_position_m: f64 = 0.0;
    let mut worst_velocity_m_per_s: f64 = 0.0;
    for (k, id) in b.particles.id.iter().enumerate() {
        let i = id.0 as usize;
        assert_eq!(a.particles.id[i], *id, "the unsorted run keeps its fill order");
        worst_position_m = worst_position_m.max((a.particles.position_m[i] - b.particles.position_m[k]).norm());
        worst_velocity_m_per_s =
            worst_velocity_m_per_s.max((a.particles.velocity_m_per_s[i] - b.particles.velocity_m_per_s[k]).norm());
    }
    let liquid = |s: &SimState| s.particles.liquid_m3.iter().sum::<f64>() + s.contacts.bridge_liquid_m3();
    let sliding = b
        .contacts
        .pairs
        .iter()
        .filter(|c| c.2.tangential.shear != Vec3::zeros())
        .count();
    println!(
        "sorted against unsorted, 300 steps from step 1500: positions {worst_position_m:.3e} m, velocities \
         {worst_velocity_m_per_s:.3e} m/s apart; {} and {} pair records, {sliding} with a tangential force",
        a.contacts.pairs.len(),
        b.contacts.pairs.len()
    );
    assert!(sliding > 150, "the comparison must cross sliding contacts");
    assert!(worst_position_m < 1.0e-12, "positions {worst_position_m:e} m apart");
    assert!(
        worst_velocity_m_per_s < 1.0e-9,
        "velocities {worst_velocity_m_per_s:e} m/s apart"
    );
    assert_eq!(a.contacts.pairs.len(), b.contacts.pairs.len());
    assert!(((liquid(&a) - liquid(&b)) / liquid(&a)).abs() < 1.0e-12);
}
