//! The cohesion pass in running simulations: liquid conservation while bridges form and break (VALIDATION B4),
//! exact restart and thread-count independence with bridges and wells, and analytic checks of the capillary,
//! Hamaker and square-well forces on particle pairs.

mod common;

use std::f64::consts::PI;
use std::path::Path;

use common::{WET_DRUM, built, granflow, simulation};
use granflow::checkpoint::CheckpointSeries;
use granflow::engine::Vec3;
use granflow::engine::models::capillary::mikami_force_n;
use granflow::engine::models::capillary_table::CapillaryTable;
use granflow::engine::state::{SimState, first_difference};

/// Liquid on the particles and in bridges, less what the spray brought.
fn liquid(state: &SimState) -> f64 {
    state.particles.liquid_m3.iter().sum::<f64>() + state.contacts.bridge_liquid_m3()
        - state.particles.sprayed_m3.iter().sum::<f64>()
}

/// VALIDATION B4 (bridges and spray; evaporation is not built yet): the particles' liquid plus the bridges' volume
/// stays what the particles started with plus what was sprayed, to 1e-10 relative, while thousands of bridges form
/// and break between particles of unequal wettability and the surface is sprayed.
#[test]
fn b4_liquid_is_conserved_while_bridges_form_and_break() {
    let b = built(WET_DRUM);
    let start: f64 = b.particles.liquid_m3.iter().sum();
    assert!(start > 0.0);
    let mut sim = simulation(&b, 2);
    let mut worst: f64 = 0.0;
    for _ in 0..8 {
        sim.run_steps(1000).expect("stable");
        let s = sim.snapshot();
        worst = worst.max((liquid(&s) / start - 1.0).abs());
        assert!(
            s.particles.liquid_m3.iter().all(|&l| l >= 0.0),
            "negative liquid on a particle"
        );
    }
    let s = sim.snapshot();
    let events = sim.cohesion_events;
    let sprayed: f64 = s.particles.sprayed_m3.iter().sum();
    let wetted = s.particles.sprayed_m3.iter().filter(|&&v| v > 0.0).count();
    println!(
        "spray: {sprayed:e} m³ ({:.2} of the start) onto {wetted} particles, CV_m {:.2}",
        sprayed / start,
        granflow::engine::spray::coating_variability(&s.particles.sprayed_m3)
    );
    assert!(
        sprayed > 0.1 * start && wetted > 20 && wetted < s.particles.len() / 2,
        "{wetted} sprayed"
    );
    assert!((sim.sprayed_m3 / sprayed - 1.0).abs() < 1e-12);
    let on_b: f64 = s
        .particles
        .liquid_m3
        .iter()
        .zip(&s.particles.species)
        .filter(|(_, sp)| sp.0 == 1)
        .map(|(l, _)| l)
        .sum();
    println!(
        "B4: {} particles, {} bridges formed, {} broken, {} standing ({} to walls), liquid drift {worst:e}; the 50° species holds {:.3} of the particles' liquid",
        s.particles.len(),
        events.bridges_formed,
        events.bridges_ruptured,
        s.contacts.cohesion().pairs.len() + s.contacts.cohesion().walls.len(),
        s.contacts.cohesion().walls.len(),
        on_b / s.particles.liquid_m3.iter().sum::<f64>()
    );
    assert!(
        events.bridges_formed > 1500 && events.bridges_ruptured > 500,
        "{events:?}"
    );
    assert!(worst < 1e-10, "liquid drifted by {worst:e} of the total");
    assert!(!s.contacts.cohesion().walls.is_empty(), "bridges to the drum stand");
    // The coating mass gains (CV_m's distribution) share out every particle's film and bridge liquid, less the start:
    // they sum to what was sprayed (B4's ledger), and bridges have carried sprayed liquid to particles the spray
    // never reached.
    let gains = sim.coating_gain_m3();
    let start_of =
        |i: usize| b.config.species.get(s.particles.species[i]).liquid_content * s.particles.radius_m[i].powi(3);
    let held: f64 = gains.iter().enumerate().map(|(i, g)| g + start_of(i)).sum();
    let total = s.particles.liquid_m3.iter().sum::<f64>() + s.contacts.bridge_liquid_m3();
    assert!(
        (held / total - 1.0).abs() < 1e-12,
        "held {held:e} vs particles + bridges {total:e}"
    );
    let gained: f64 = gains.iter().sum();
    assert!(
        (gained / sprayed - 1.0).abs() < 1e-9,
        "gains {gained:e} vs sprayed {sprayed:e}"
    );
    let reached_by_bridges = (0..gains.len())
        .filter(|&i| s.particles.sprayed_m3[i] == 0.0 && gains[i] > 0.0)
        .count();
    println!(
        "coating gains: CV_m {:.3} (direct spray alone {:.3}); {reached_by_bridges} unsprayed particles gained liquid",
        granflow::engine::spray::coating_variability(&gains),
        granflow::engine::spray::coating_variability(&s.particles.sprayed_m3)
    );
}

/// Bridges survive the two-level neighbour list's refilters: the wet drum ends with the same bits with the force
/// pass's list refiltered from the candidates as with a single list.
#[test]
fn a_wet_drum_gives_the_same_bits_with_one_or_two_neighbour_list_levels() {
    let mut single = simulation(
        &built(&format!(
            "{WET_DRUM}neighbor: {{ skin_m: 0.0006, inner_skin_m: 0.0006 }}\n"
        )),
        1,
    );
    let mut refiltered = simulation(
        &built(&format!(
            "{WET_DRUM}neighbor: {{ skin_m: 0.0006, inner_skin_m: 0.00015 }}\n"
        )),
        1,
    );
    single.run_steps(3000).expect("stable");
    refiltered.run_steps(3000).expect("stable");
    let events = refiltered.cohesion_events;
    println!(
        "two levels: {} builds + {} refilters; {} bridges formed, {} broken",
        refiltered.neighbor_builds(),
        refiltered.neighbor_refilters(),
        events.bridges_formed,
        events.bridges_ruptured
    );
    assert!(
        refiltered.neighbor_refilters() > 10 && events.bridges_ruptured > 100,
        "{events:?}"
    );
    if let Some(diff) = first_difference(&single.snapshot(), &refiltered.snapshot()) {
        panic!("the two-level list changes the wet drum: {diff}");
    }
}

/// A liquid-bridge run without liquid and without a spray (the dry beds of a wet sweep) can never form a bridge: it
/// takes the dry force pass and skips the liquid inventory, and moves its particles exactly as the same drum
/// without cohesion does, to the bit, on one and two threads (the drum with a spray, and the same dry drum wetted,
/// are the controls: there the bridges act).
#[test]
fn a_liquid_bridge_drum_without_liquid_moves_exactly_as_a_dry_one() {
    let dry_wet_model = WET_DRUM
        .replace("liquid_content: 0.01", "liquid_content: 0.0")
        .replace(", spray: { max_liquid_content: 0.02, every_steps: 50 }", "");
    assert!(!dry_wet_model.contains("liquid_content: 0.01") && !dry_wet_model.contains("spray"));
    let no_model = dry_wet_model
        .lines()
        .filter(|l| !l.starts_with("cohesion:"))
        .collect::<Vec<_>>()
        .join("\n");
    let wetted = dry_wet_model.replace("liquid_content: 0.0", "liquid_content: 0.01");
    let motion = |yaml: &str, threads: usize| {
        let mut sim = simulation(&built(yaml), threads);
        sim.run_steps(3000).expect("stable");
        let p = sim.snapshot().particles;
        (
            p.position_m,
            p.velocity_m_per_s,
            p.angular_velocity_rad_per_s,
            sim.timers.liquid,
        )
    };
    let bits = |m: &(Vec<Vec3>, Vec<Vec3>, Vec<Vec3>, std::time::Duration)| -> Vec<u64> {
        [&m.0, &m.1, &m.2]
            .iter()
            .flat_map(|v| v.iter().flat_map(|x| x.iter().map(|c| c.to_bits())))
            .collect()
    };
    let reference = bits(&motion(&no_model, 1));
    for threads in [1, 2] {
        let inert = motion(&dry_wet_model, threads);
        assert_eq!(bits(&inert), reference, "{threads} thread(s)");
        assert_eq!(inert.3, std::time::Duration::ZERO, "the liquid inventory ran");
    }
    let wet = motion(&wetted, 1);
    assert_ne!(bits(&wet), reference, "the wetted control moves like the dry drum");
    assert!(wet.3 > std::time::Duration::ZERO);
}

fn final_state(dir: &Path) -> SimState {
    let series = CheckpointSeries::new(dir, 2);
    series
        .latest_valid()
        .expect("lists")
        .expect("a checkpoint exists")
        .state
}

/// A wet run stopped and resumed in a fresh process (on another thread count) ends bit-identical to an
/// uninterrupted one, bridges, liquid and all; 1 and 2 threads agree to the bit.
#[test]
fn a_wet_drum_restarts_bit_identically_on_any_thread_count() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    let short = WET_DRUM.replace("end_time_s: 0.08", "end_time_s: 0.04");
    std::fs::write(dir.join("wet.yaml"), &short).expect("write scenario");
    let run = |args: &[&str]| {
        let out = granflow(args, dir);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    run(&["simulate", "wet.yaml", "--out", "whole", "--quiet"]);
    run(&[
        "simulate",
        "wet.yaml",
        "--out",
        "split",
        "--max-steps",
        "2000",
        "--threads",
        "2",
        "--quiet",
    ]);
    let middle = final_state(&dir.join("split"));
    assert!(middle.contacts.cohesion().pairs.len() > 50, "bridges cross the restart");
    assert!(
        !middle.contacts.cohesion().walls.is_empty(),
        "bridges to walls cross the restart"
    );
    run(&["simulate", "wet.yaml", "--out", "split", "--threads", "1", "--quiet"]);
    let whole = final_state(&dir.join("whole"));
    let split = final_state(&dir.join("split"));
    assert_eq!(whole.step, 4000);
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("restarted wet run differs from the uninterrupted one: {diff}");
    }
    let b = built(&short);
    let mut two = simulation(&b, 2);
    two.run_steps(4000).expect("stable");
    if let Some(diff) = first_difference(&whole, &two.snapshot()) {
        panic!("2 threads differ from 1: {diff}");
    }
}

/// Two beads in one layer, no gravity.
fn pair(cohesion: &str, gap_m: f64, extra_species: &str) -> String {
    format!(
        r#"
name: pair
domain: {{ lo_m: [-0.01, -0.01, -0.01], hi_m: [0.01, 0.01, 0.01] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, 0.0] }}
species:
  - {{ name: s, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3{extra_species} }}
contact: {{ normal: {{ hertz: {{ restitution: 0.8 }} }}, tangential: mindlin }}
cohesion: {cohesion}
fill:
  - lattice: {{ species: s, spacing_m: {spacing}, lo_m: [-0.0015, -0.0005, -0.0005], hi_m: [0.0025, 0.0005, 0.0005], origin_m: [-0.001, 0.0, 0.0] }}
time: {{ dt_s: 1.0e-6, end_time_s: 1.0 }}
"#,
        spacing = 0.002 + gap_m
    )
}

fn two_beads(yaml: &str) -> granflow::engine::Simulation {
    let b = built(yaml);
    assert_eq!(b.particles.len(), 2, "the fill places two beads");
    simulation(&b, 1)
}

/// The Hamaker force on two beads at rest is A R*/(6 H²) (seed 001 eq 6.34), pulling them together, and is
/// left out beyond the outer cutoff.
#[test]
fn hamaker_pulls_two_beads_with_the_printed_force() {
    for (gap, inside) in [(2.0e-6, true), (5.0e-5, false)] {
        let sim = two_beads(&pair(
            "{ hamaker: { constant_j: 1.0e-17, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 2.0e-5 } }",
            gap,
            "",
        ));
        let expected = if inside {
            1.0e-17 * 0.0005 / (6.0 * gap * gap)
        } else {
            0.0
        };
        let f = sim.particles.force_n[0];
        assert!(
            (f.x - expected).abs() <= 1e-9 * expected,
            "gap {gap}: {f:?} vs {expected}"
        );
        assert_eq!(sim.particles.force_n[1].x, -f.x);
    }
}

/// Two beads of V̂ = 0.02 pushed together at 1 cm/s under `cohesion`, after 0.2 s: they hold one bridge.
fn wet_pair_at_rest(cohesion: &str) -> SimState {
    let mut sim = two_beads(&pair(cohesion, 1.0e-6, ", liquid_content: 0.02"));
    sim.particles.velocity_m_per_s[0].x = 0.005;
    sim.particles.velocity_m_per_s[1].x = -0.005;
    sim.run_steps(200_000).expect("stable");
    let s = sim.snapshot();
    assert_eq!(s.contacts.cohesion().pairs.len(), 1, "one bridge");
    s
}

/// `bridge_volume: { fixed: V̂ }` (issue 41's larger bridges): two beads of R = 1 mm meeting form a bridge of
/// exactly V̂ R³, half from each, and hold at the Hertz–Mikami balance of that bridge; beads holding less than
/// half of it give all they hold. Liquid on the beads plus the bridge stays what they started with.
#[test]
fn a_fixed_volume_bridge_takes_half_its_volume_from_each_bead() {
    let cohesion =
        "{ liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.01, bridge_volume: { fixed: 0.03 } } }";
    let s = wet_pair_at_rest(cohesion);
    let r3 = 1.0e-9;
    let volume = s.contacts.cohesion().pairs[0].2.bridge_volume_m3;
    assert!((volume / (0.03 * r3) - 1.0).abs() < 1e-12, "bridge of {volume} m³");
    for l in &s.particles.liquid_m3 {
        assert!((l / (0.005 * r3) - 1.0).abs() < 1e-12, "bead keeps {l} m³");
    }
    let d = (s.particles.position_m[0] - s.particles.position_m[1]).norm();
    let e_star = 1.0e7 / (2.0 * (1.0 - 0.09));
    let capillary = mikami_force_n(0.0005, volume, 0.0, 0.0, 0.072);
    let expected = (capillary / (4.0 / 3.0 * e_star * 0.0005f64.sqrt())).powf(2.0 / 3.0);
    assert!(
        ((0.002 - d) / expected - 1.0).abs() < 0.01,
        "overlap {} vs {expected}",
        0.002 - d
    );
    // V̂ = 0.02 per bead, 0.05 asked: each gives its whole 0.02.
    let s = wet_pair_at_rest(&cohesion.replace("0.03", "0.05"));
    let volume = s.contacts.cohesion().pairs[0].2.bridge_volume_m3;
    assert!((volume / (0.04 * r3) - 1.0).abs() < 1e-12, "bridge of {volume} m³");
    assert!(s.particles.liquid_m3.iter().all(|&l| l == 0.0));
}

/// Two wet beads brought into contact hold together: a bridge forms on contact, and once the viscous liquid has
/// damped the motion they rest at the overlap where the Hertz force balances Mikami's capillary force at contact.
#[test]
fn a_liquid_bridge_holds_two_beads_at_the_hertz_capillary_balance() {
    let s = wet_pair_at_rest("{ liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.01 } }");
    let volume = s.contacts.cohesion().pairs[0].2.bridge_volume_m3;
    // Each bead gave the liquid on its cap facing the other: (L/2)(1 − √(1 − 1/4)) of L = 0.02 R³.
    let expected_volume = 2.0 * 0.5 * 0.02e-9 * (1.0 - 0.75f64.sqrt());
    assert!(
        (volume / expected_volume - 1.0).abs() < 1e-12,
        "{volume} vs {expected_volume}"
    );
    let d = (s.particles.position_m[0] - s.particles.position_m[1]).norm();
    let overlap = 0.002 - d;
    let r_star = 0.0005;
    let e_star = 1.0e7 / (2.0 * (1.0 - 0.09));
    let capillary = mikami_force_n(r_star, volume, 0.0, 0.0, 0.072);
    let expected = (capillary / (4.0 / 3.0 * e_star * r_star.sqrt())).powf(2.0 / 3.0);
    println!("bridge: V = {volume:e} m³, overlap {overlap:e} m (Hertz–capillary balance {expected:e} m)");
    assert!((overlap / expected - 1.0).abs() < 0.01, "{overlap} vs {expected}");
    assert!(s.particles.velocity_m_per_s[0].norm() < 1e-6);
    // The force scale: about 2πRγ cos θ at contact for R = 2R*.
    assert!(
        (capillary / (2.0 * PI * 0.001 * 0.072) - 0.9).abs() < 0.1,
        "{capillary}"
    );
}

/// With `capillary_force: young_laplace` the bridge pulls with the exact Young–Laplace force of the pair's table
/// (seed 000 eqs 6.5–6.28) instead of Mikami's fit: the beads rest where the Hertz force balances the table's force
/// at contact, which for equal beads at θ = 0 is within 5 % of Mikami's (VALIDATION B2).
#[test]
fn a_young_laplace_bridge_holds_two_beads_at_its_own_balance() {
    let s = wet_pair_at_rest(
        "{ liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.01, capillary_force: young_laplace } }",
    );
    let volume = s.contacts.cohesion().pairs[0].2.bridge_volume_m3;
    let table = granflow::engine::models::capillary_table::CapillaryTable::new(0.001, 0.001, 0.0, 0.0);
    let capillary = table.force_n(volume, 0.0, 0.072);
    let overlap = 0.002 - (s.particles.position_m[0] - s.particles.position_m[1]).norm();
    let (r_star, e_star) = (0.0005f64, 1.0e7 / (2.0 * (1.0 - 0.09)));
    let expected = (capillary / (4.0 / 3.0 * e_star * r_star.sqrt())).powf(2.0 / 3.0);
    assert!((overlap / expected - 1.0).abs() < 0.01, "{overlap} vs {expected}");
    let mikami = mikami_force_n(r_star, volume, 0.0, 0.0, 0.072);
    assert!(
        (capillary / mikami - 1.0).abs() < 0.05,
        "{capillary} vs Mikami {mikami}"
    );
}

/// The bridge's energy account: two elastic (restitution 1), wet beads with an inviscid liquid meet head-on, a
/// bridge forms on contact and ruptures at Lian's distance (seed 000 eq 2.18), and they leave with exactly the
/// kinetic energy they came with less the rupture work, the integral of Mikami's force (eqs 2.16–2.17) from contact
/// to the rupture distance: the capillary force adds no energy and loses none but that work.
#[test]
fn a_bridge_takes_exactly_its_rupture_work_from_an_elastic_pair() {
    use granflow::engine::models::capillary::lian_rupture_gap_m;
    let yaml = pair(
        "{ liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.0 } }",
        5.0e-4,
        ", liquid_content: 0.02",
    )
    .replace("restitution: 0.8", "restitution: 1.0");
    let mut sim = two_beads(&yaml);
    let approach = 0.12;
    sim.particles.velocity_m_per_s[0].x = 0.5 * approach;
    sim.particles.velocity_m_per_s[1].x = -0.5 * approach;
    let mass = sim.particles.mass_kg[0];
    let reduced_mass = 0.5 * mass;
    sim.run_steps(30_000).expect("stable");
    let s = sim.snapshot();
    assert!(s.contacts.cohesion().pairs.is_empty(), "the bridge has ruptured");
    assert_eq!(sim.cohesion_events.bridges_formed, 1);
    assert_eq!(sim.cohesion_events.bridges_ruptured, 1);
    // The bridge took the liquid on each bead's facing cap, (L/2)(1 − √(3/4)) of L = 0.02 R³ (see above).
    let volume = 2.0 * 0.5 * 0.02e-9 * (1.0 - 0.75f64.sqrt());
    let rupture_gap = lian_rupture_gap_m(volume, 0.0, 0.0);
    let r_star = 0.0005;
    // Simpson's rule over [0, rupture gap].
    let intervals = 20_000;
    let h = rupture_gap / intervals as f64;
    let work: f64 = (0..=intervals)
        .map(|k| {
            let weight = if k == 0 || k == intervals {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            weight * mikami_force_n(r_star, volume, k as f64 * h, 0.0, 0.072)
        })
        .sum::<f64>()
        * h
        / 3.0;
    let speed = s.particles.velocity_m_per_s[1].x - s.particles.velocity_m_per_s[0].x;
    let lost = 0.5 * reduced_mass * (approach * approach - speed * speed);
    println!(
        "bridge of {volume:e} m³, rupture gap {rupture_gap:e} m, rupture work {work:e} J; the pair lost {lost:e} J \
         (came at {approach} m/s, leaves at {speed:e} m/s)"
    );
    assert!(
        work > 0.1 * 0.5 * reduced_mass * approach * approach,
        "the work must be a sizeable part of the energy"
    );
    assert!(
        (lost / work - 1.0).abs() < 0.01,
        "lost {lost:e} J against the rupture work {work:e} J"
    );
}

/// Square well as crossing impulses (seed 001 §6.2.4.2): a head-on pair approaching at relative speed a₀ gains
/// 2D/μ of squared speed entering the well, collides with restitution e and escapes with √(e²(a₀² + 2D/μ) − 2D/μ)
/// if that is real; otherwise it is captured and stays in the well.
#[test]
fn square_well_pairs_escape_or_are_captured_as_the_energy_balance_says() {
    let mass = 2500.0 * 4.0 / 3.0 * PI * 1e-9;
    let mu = mass / 2.0;
    let energy = 0.01; // 2D/μ, m²/s²
    let depth = energy * mu / 2.0;
    let e: f64 = 0.8;
    for approach in [0.1, 0.05] {
        let mut sim = two_beads(&pair(
            &format!("{{ square_well: {{ depth_j: {depth:e}, outer_to_inner_radius_ratio: 1.01 }} }}"),
            5.0e-4,
            "",
        ));
        sim.particles.velocity_m_per_s[0].x = 0.5 * approach;
        sim.particles.velocity_m_per_s[1].x = -0.5 * approach;
        sim.run_steps(20_000).expect("stable");
        let s = sim.snapshot();
        let separation = (s.particles.position_m[1] - s.particles.position_m[0]).x;
        let speed = s.particles.velocity_m_per_s[1].x - s.particles.velocity_m_per_s[0].x;
        let left = e * e * (approach * approach + energy) - energy;
        println!(
            "square well, a0 = {approach} m/s: separation {separation:e} m, separating at {speed:e} m/s, in well: {}",
            s.contacts.cohesion().pairs.len()
        );
        if left > 0.0 {
            let expected = left.sqrt();
            assert!(separation > 0.00202, "escaped");
            assert!((speed / expected - 1.0).abs() < 0.03, "{speed} vs {expected}");
            assert!(s.contacts.cohesion().pairs.is_empty());
        } else {
            assert_eq!(s.contacts.cohesion().pairs.len(), 1, "captured");
            assert!(s.contacts.cohesion().pairs[0].2.in_well);
            assert!(separation < 0.002 * 1.01 + 1e-6, "still in the well: {separation}");
        }
    }
}

/// A wet bead (V̂ = 0.02, θ = 10°) resting on a floor, with or without wall bridges, bridges forming from
/// `bridges_from_s`.
fn bead_on_floor(walls: bool, bridges_from_s: f64) -> String {
    format!(
        r#"
name: bead-on-floor
domain: {{ lo_m: [-0.005, 0.0, -0.005], hi_m: [0.005, 0.01, 0.005] }}
gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
species:
  - {{ name: s, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3, contact_angle_deg: 10.0, liquid_content: 0.02 }}
contact: {{ normal: {{ hertz: {{ restitution: 0.5 }} }}, tangential: mindlin }}
walls: [ {{ box: {{ species: s }} }} ]
cohesion: {{ liquid_bridge: {{ surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.01, walls: {walls}, bridges_from_s: {bridges_from_s} }} }}
fill:
  - lattice: {{ species: s, spacing_m: 0.004, lo_m: [-0.001, 0.0012, -0.001], hi_m: [0.001, 0.0014, 0.001], origin_m: [0.0, 0.0013, 0.0] }}
time: {{ dt_s: 1.0e-6, end_time_s: 1.0 }}
"#
    )
}

/// With `bridges_from_s` the bead touches the floor dry until then, and the bridge forms in place at that time.
#[test]
fn bridges_form_only_from_their_start_time() {
    let mut sim = simulation(&built(&bead_on_floor(true, 0.1)), 1);
    sim.run_steps(99_000).expect("stable");
    let before = sim.snapshot();
    assert!(before.contacts.cohesion().walls.is_empty(), "no bridge before 0.1 s");
    assert!(
        (before.particles.liquid_m3[0] / 0.02e-9 - 1.0).abs() < 1e-14,
        "all the liquid still on the bead"
    );
    assert!(
        before.particles.position_m[0].y < 0.001,
        "resting on the floor, in contact"
    );
    sim.run_steps(2_000).expect("stable");
    assert_eq!(
        sim.snapshot().contacts.cohesion().walls.len(),
        1,
        "the bridge forms at 0.1 s, in place"
    );
}

/// A wet bead on a floor, with `walls: true`: a bridge to the wall forms on contact with half the bead's liquid and
/// the bead rests where the Hertz force balances its weight plus the exact sphere–plane bridge's force at contact
/// (the Young–Laplace table with the wall a sphere of infinite radius; Mikami's fit read at R* = R is within a few
/// per cent of it at contact); liquid on the bead plus the bridge stays what the bead started with. With the
/// default (no wall bridges) nothing forms.
#[test]
fn a_wet_bead_bridges_to_the_floor_only_when_wall_bridges_are_on() {
    let yaml = |walls: bool| bead_on_floor(walls, 0.0);
    let liquid = 0.02e-9;
    let mut dry_walls = simulation(&built(&yaml(false)), 1);
    dry_walls.run_steps(50_000).expect("stable");
    assert!(
        dry_walls.snapshot().contacts.cohesion().walls.is_empty(),
        "no wall bridge by default"
    );
    let b = built(&yaml(true));
    assert_eq!(b.particles.len(), 1);
    let mut sim = simulation(&b, 1);
    sim.run_steps(300_000).expect("stable");
    let s = sim.snapshot();
    assert_eq!(s.contacts.cohesion().walls.len(), 1, "one bridge, to the floor");
    let volume = s.contacts.cohesion().walls[0].2.bridge_volume_m3;
    assert!((volume / (0.5 * liquid) - 1.0).abs() < 1e-12, "{volume}");
    assert!(((s.particles.liquid_m3[0] + volume) / liquid - 1.0).abs() < 1e-12);
    let overlap = 0.001 - s.particles.position_m[0].y;
    let (r, e_star) = (0.001f64, 1.0e7 / (2.0 * (1.0 - 0.09)));
    let weight = 2500.0 * 4.0 / 3.0 * PI * r.powi(3) * 9.81;
    let theta = 10f64.to_radians();
    let capillary = CapillaryTable::new(r, f64::INFINITY, theta, theta).force_n(volume, 0.0, 0.072);
    let mikami = mikami_force_n(r, volume, 0.0, theta, 0.072);
    println!("bead on a floor: sphere-plane bridge {capillary:.4e} N, Mikami at R* = R {mikami:.4e} N");
    assert!((mikami / capillary - 1.0).abs() < 0.1, "{mikami} vs {capillary}");
    let expected = ((weight + capillary) / (4.0 / 3.0 * e_star * r.sqrt())).powf(2.0 / 3.0);
    assert!((overlap / expected - 1.0).abs() < 0.01, "{overlap} vs {expected}");
    assert!(
        capillary > 3.0 * weight,
        "the bridge, more than the weight, presses the bead down"
    );
}

/// One seed-001 bead (1 mm, 2650 kg/m³, linear contacts) placed against a sidewall that attracts it (Hamaker,
/// `walls: true`), in one layer, recording net forces, with the tangential model `tangential`.
fn bead_on_sidewall(tangential: &str) -> String {
    format!(
        r#"
name: bead-on-sidewall
domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.01, 0.1, 0.001] }}
pseudo_2d: true
gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
species:
  - {{ name: sand, radius_m: 0.0005, density_kg_per_m3: 2650.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3 }}
contact:
  normal: {{ linear_spring_dashpot: {{ stiffness_n_per_m: 800.0, damping_kg_per_s: 0.00079 }} }}
  tangential: {{ {tangential}: {{ stiffness_n_per_m: 800.0, damping_kg_per_s: 0.00079 }} }}
walls: [ {{ box: {{ species: sand }} }} ]
cohesion: {{ hamaker: {{ constant_j: 7.49e-19, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 5.0e-6, walls: true }} }}
fill:
  - lattice: {{ species: sand, spacing_m: 0.004, lo_m: [0.0, 0.079, 0.0], hi_m: [0.002, 0.081, 0.001], origin_m: [0.0005, 0.08, 0.0005] }}
time: {{ dt_s: 2.25e-5, end_time_s: 0.04 }}
output: {{ series_every_steps: 100, net_forces: true }}
"#
    )
}

/// A bead that a sidewall attracts rolls down it (seed 001 ch. 8: "cohesion with the sidewalls ... only raises the
/// normal load and hence the friction"). Across gravity the wall pushes as hard as it pulls, A R/(6 H_cut²) (about 29
/// bead weights); along it, rolling without slip needs a friction of 2/7 of the weight (I = 2/5 m R²: the bead falls
/// at 5/7 g), far below μ times that load. The same holds for seed 001's eq 6.24 read per step
/// (`linear_step_spring_coulomb`), whose friction comes from a steady slip instead of a stretched spring. Checks the
/// series' `*_across_n` columns and the sidewall's friction in `*_contact_up_n`.
#[test]
fn a_bead_attracted_to_a_sidewall_rolls_down_it_held_by_two_sevenths_of_its_weight() {
    let pull_n = 7.49e-19 * 0.0005 / (6.0 * 4.0e-10 * 4.0e-10);
    for tangential in ["linear_spring_coulomb", "linear_step_spring_coulomb"] {
        let tmp = tempfile::tempdir().expect("temp dir");
        let dir = tmp.path();
        std::fs::write(dir.join("bead.yaml"), bead_on_sidewall(tangential)).unwrap();
        let out = granflow(&["simulate", "bead.yaml", "--out", "bead", "--quiet"], dir);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let series = std::fs::read_to_string(dir.join("bead/series.csv")).unwrap();
        let header: Vec<&str> = series.lines().next().unwrap().split(',').collect();
        let last: Vec<f64> = series
            .lines()
            .last()
            .unwrap()
            .split(',')
            .map(|f| f.parse().unwrap())
            .collect();
        let value = |name: &str| last[header.iter().position(|h| *h == name).expect(name)];
        let weight_n = value("weight_n");
        assert!(
            pull_n > 25.0 * weight_n,
            "{pull_n:e} N against a weight of {weight_n:e} N"
        );
        let pull = value("wall_box_x_lo_cohesion_across_n");
        assert!(
            (pull - pull_n).abs() < 1e-9 * pull_n,
            "{tangential}: pull {pull:e} N, expected {pull_n:e} N"
        );
        let push = value("wall_box_x_lo_contact_across_n");
        assert!(
            (push - pull_n).abs() < 1e-3 * pull_n,
            "{tangential}: push {push:e} N against pull {pull_n:e} N"
        );
        let friction = value("wall_box_x_lo_contact_up_n");
        assert!(
            (friction / weight_n - 2.0 / 7.0).abs() < 1e-3,
            "{tangential}: friction {:.4} of the weight, expected 2/7",
            friction / weight_n
        );
        assert_eq!(value("wall_box_x_lo_cohesion_up_n"), 0.0);
        for other in ["box_x_hi", "box_y_lo", "box_y_hi"] {
            assert_eq!(
                value(&format!("wall_{other}_contact_across_n")),
                0.0,
                "{tangential}: {other}"
            );
        }
    }
}

/// A bridge too small to count does not form (`engine::liquid::SMALLEST_BRIDGE`, 1e-6 R³): Mikami's fit read at
/// vanishing volumes pulls without bound, so films of 5e-6 R³ (caps of 6.7e-7 R³ together) stay films when two
/// beads touch, while films of 2e-5 R³ (caps of 2.7e-6 R³) bridge them; a bead with 1e-6 R³ on a floor (half of it,
/// below the floor, would go to the wall) stays unbridged, one with 4e-6 R³ bridges.
#[test]
fn a_bridge_below_the_smallest_volume_does_not_form() {
    for (content, forms) in [(5.0e-6, false), (2.0e-5, true)] {
        let mut sim = two_beads(&pair(
            "{ liquid_bridge: { surface_tension_n_per_m: 0.072, viscosity_pa_s: 0.001 } }",
            5.0e-6,
            &format!(", liquid_content: {content}"),
        ));
        sim.particles.velocity_m_per_s[0].x = 0.005;
        sim.particles.velocity_m_per_s[1].x = -0.005;
        sim.run_steps(2_000).expect("stable");
        let s = sim.snapshot();
        assert_eq!(
            sim.cohesion_events.bridges_formed,
            u64::from(forms),
            "content {content}"
        );
        assert_eq!(s.contacts.cohesion().pairs.len(), usize::from(forms));
        if !forms {
            assert_eq!(s.particles.liquid_m3[0], content * 1e-9, "the film is untouched");
        }
    }
    for (content, forms) in [(1.0e-6, false), (4.0e-6, true)] {
        let yaml = bead_on_floor(true, 0.0).replace("liquid_content: 0.02", &format!("liquid_content: {content}"));
        let mut sim = simulation(&built(&yaml), 1);
        sim.run_steps(50_000).expect("stable");
        assert_eq!(
            sim.snapshot().contacts.cohesion().walls.len(),
            usize::from(forms),
            "wall, content {content}"
        );
    }
}
