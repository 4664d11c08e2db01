//! Contact statistics (`output.contact_statistics`): each contact's duration kept in its history's duration slot and,
//! when the contact ends, added to the particles' channels (`engine::channels`) by the pair pass. Checked against
//! Hertz's contact time for a head-on collision and for an impact on a wall, and for the engine's guarantees: the
//! same bits on any thread count and across a restart in a fresh process.

mod common;

use std::f64::consts::PI;

use common::{built, simulation, whole_and_resumed};
use granflow::engine::state::{SimState, first_difference};

/// Hertz's elastic contact time t_c = 2.87 (m*²/(R* E*² v))^{1/5}.
fn hertz_contact_time_s(m_star: f64, r_star: f64, e_star: f64, v: f64) -> f64 {
    2.87 * (m_star * m_star / (r_star * e_star * e_star * v)).powf(0.2)
}

/// Two equal spheres meet head-on at relative speed 1 m/s, and a third (far from them) hits a plane wall at 1 m/s;
/// elastic Hertz, no friction, no gravity, 2000 steps per contact time. The channels give t_c for both to 2 %.
#[test]
fn collision_and_wall_impact_last_hertz_contact_times() {
    let (r, rho, e_mod, nu, v): (f64, f64, f64, f64, f64) = (1e-3, 2500.0, 7e10, 0.25, 1.0);
    let m = rho * 4.0 / 3.0 * PI * r.powi(3);
    let e_star = e_mod / (2.0 * (1.0 - nu * nu));
    let pair_tc = hertz_contact_time_s(m / 2.0, r / 2.0, e_star, v);
    let wall_tc = hertz_contact_time_s(m, r, e_star, v);
    let dt = pair_tc / 2000.0;
    let gap = 0.01 * r;
    let yaml = format!(
        r#"
name: contact-times
domain: {{ lo_m: [-0.1, -0.1, -0.1], hi_m: [0.1, 0.1, 0.1] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, 0.0] }}
species:
  - {{ name: s, radius_m: {r}, density_kg_per_m3: {rho}, youngs_modulus_pa: {e_mod}, poisson_ratio: {nu}, friction_coefficient: 0.0 }}
contact: {{ normal: {{ hertz: {{ restitution: 1.0 }} }}, tangential: mindlin }}
walls:
  - plane: {{ name: floor, species: s, point_m: [0.0, -0.05, 0.0], normal: [0.0, 1.0, 0.0] }}
fill:
  - explicit:
      species: s
      positions_m: [[{x0}, 0.0, 0.0], [{x1}, 0.0, 0.0], [0.05, {y2}, 0.0]]
      velocities_m_per_s: [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0], [0.0, -1.0, 0.0]]
time: {{ dt_s: {dt}, end_time_s: 1.0 }}
output: {{ contact_statistics: true }}
"#,
        x0 = -r - gap,
        x1 = r + gap,
        y2 = -0.05 + r + gap,
    );
    let b = built(&yaml);
    let mut sim = simulation(&b, 1);
    // Until both contacts have ended (the pair's surfaces start 2 gaps apart) and a little more.
    let steps = ((4.0 * gap / v + 3.0 * wall_tc) / dt) as u64;
    sim.run_steps(steps).expect("stable");
    let c = &sim.particles.channels;
    assert_eq!(
        c.contacts_ended,
        vec![1.0, 1.0, 0.0],
        "one collision, counted on both spheres"
    );
    assert_eq!(c.wall_contacts_ended, vec![0.0, 0.0, 1.0], "one wall impact");
    let pair = c.mean_collision_duration_s();
    let wall = c.mean_wall_contact_duration_s();
    println!(
        "contact times: pair {pair:.6e} s vs Hertz {pair_tc:.6e} s ({:+.3} %), wall {wall:.6e} s vs {wall_tc:.6e} s \
         ({:+.3} %)",
        100.0 * (pair / pair_tc - 1.0),
        100.0 * (wall / wall_tc - 1.0)
    );
    assert!((pair / pair_tc - 1.0).abs() < 0.02, "pair {pair} vs {pair_tc}");
    assert!((wall / wall_tc - 1.0).abs() < 0.02, "wall {wall} vs {wall_tc}");
    // The time in contact with a wall is that one impact, step for step.
    assert_eq!(c.wall_contact_time_s[2], c.wall_contact_time_ended_s[2]);
    assert_eq!(c.wall_contact_time_s[0], 0.0);
    let fraction = c.wall_contact_time_fraction(sim.time_s);
    let expected = wall / (3.0 * sim.time_s);
    assert!((fraction / expected - 1.0).abs() < 1e-12, "{fraction} vs {expected}");
}

/// A drum with baffles (contacts and wall contacts forming and ending all the time).
const DRUM: &str = r#"
name: statistics-drum
domain: { lo_m: [-0.041, -0.041, 0.0], hi_m: [0.041, 0.041, 0.012], periodic: [false, false, true] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.3, friction_coefficient: 0.4 }
contact: { normal: { hertz: { restitution: 0.6 } }, tangential: mindlin }
walls:
  - drum:
      name: drum
      species: glass
      axis_point_m: [0.0, 0.0, 0.0]
      axis: [0.0, 0.0, 1.0]
      radius_m: 0.04
      rotation_rpm: 120.0
      baffles:
        - traditional: { count: 4, length_m: 0.01, half_thickness_m: 0.001, tilt_deg: 20.0 }
fill:
  - lattice: { species: glass, spacing_m: 0.003, lo_m: [-0.04, -0.04, 0.0], hi_m: [0.04, 0.002, 0.012], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }
time: { dt_s: 1.0e-5, end_time_s: 0.03 }
output: { checkpoint_every_steps: 500, keep_checkpoints: 2, series_every_steps: 100, contact_statistics: true }
seed: 3
"#;

/// The channels and the contacts' durations are the same bits on 1, 2 and 3 threads (and on unequal ranges), and
/// a run stopped half-way and resumed in a fresh process ends with the same bits as an uninterrupted one.
#[test]
fn contact_statistics_are_the_same_bits_on_any_thread_count_and_across_a_restart() {
    let b = built(DRUM);
    let states: Vec<SimState> = [1, 2, 3]
        .iter()
        .map(|&threads| {
            let mut sim = simulation(&b, threads);
            sim.run_steps(1500).expect("stable");
            sim.snapshot()
        })
        .collect();
    let c = &states[0].particles.channels;
    let (pair_ended, wall_ended): (f64, f64) = (c.contacts_ended.iter().sum(), c.wall_contacts_ended.iter().sum());
    let timed = states[0]
        .contacts
        .pairs
        .iter()
        .filter(|r| r.2.duration.duration_s > 0.0)
        .count();
    println!(
        "drum: {pair_ended} pair and {wall_ended} wall contacts ended, {timed} standing contacts timed, mean \
         collision {:.3e} s, wall contact {:.3e} s, wall time fraction {:.3}",
        c.mean_collision_duration_s(),
        c.mean_wall_contact_duration_s(),
        c.wall_contact_time_fraction(states[0].time_s)
    );
    assert!(pair_ended > 100.0 && wall_ended > 10.0 && timed > 100);
    for (k, s) in states.iter().enumerate().skip(1) {
        if let Some(diff) = first_difference(&states[0], s) {
            panic!("{} threads differ from 1: {diff}", k + 1);
        }
    }
    let mut odd = simulation(&b, 2);
    odd.range_block = vec![0.05, 1.0, 0.3, 0.02];
    odd.run_steps(1500).expect("stable");
    if let Some(diff) = first_difference(&states[0], &odd.snapshot()) {
        panic!("unequal ranges differ from 1 thread: {diff}");
    }

    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let (whole, split) = whole_and_resumed(dir, DRUM, 1700);
    assert_eq!(whole.step, 3000);
    assert!(whole.particles.channels.is_on());
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("the resumed run differs from the uninterrupted one: {diff}");
    }
}
