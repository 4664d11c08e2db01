//! Glued beads on a drum (`walls[].drum.glued_beads`, seed 000 §3.4's wall "created by loading the particles along
//! a cylindrical geometry"): a drum slice of 3 mm beads turning at 6 rpm, once with a smooth wall and once with 40
//! beads glued around it. On the smooth wall the outer layer turns like the balls of a bearing — spinning at about
//! R/(2a) times the drum's rate while its centres lag at about half the wall's speed — and the bed does not lift; on
//! the beads the outer layer turns with the drum as a solid body. A sphere resting on a bead sinks to Hertz's overlap
//! for the pair (the bead a glued particle), a run with beads resumes bit for bit on another thread count, and
//! impossible bead lattices are bad input at their key.

mod common;

use common::{built, granflow, granflow_fails_with_2, simulation, whole_and_resumed};
use granflow::engine::state::first_difference;

const RPM: f64 = 6.0;
const DRUM_RADIUS_M: f64 = 0.02;

/// A drum slice 20 mm in radius, two bead layers deep (6.3 mm, periodic), half filled from a lattice; `beads` is
/// the drum's extra YAML (empty for a smooth wall).
fn drum(beads: &str, end_time_s: f64) -> String {
    format!(
        r#"name: glued-beads
domain: {{ lo_m: [-0.021, -0.021, 0.0], hi_m: [0.021, 0.021, 0.0063], periodic: [false, false, true] }}
gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
species:
  - {{ name: glass, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e6, poisson_ratio: 0.3, friction_coefficient: 0.4 }}
  - {{ name: wall, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e6, poisson_ratio: 0.3, friction_coefficient: 1.0 }}
contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
walls:
  - drum: {{ name: drum, species: wall, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: {DRUM_RADIUS_M}, rotation_rpm: {RPM}{beads} }}
fill:
  - lattice: {{ species: glass, spacing_m: 0.00315, lo_m: [-0.02, -0.02, 0.0], hi_m: [0.02, 0.005, 0.0063], origin_m: [0.001575, 0.0, 0.001575], inside_drum: drum }}
time: {{ dt_fraction_of_contact_time: 0.05, end_time_s: {end_time_s} }}
output: {{ series_every_steps: 2000, checkpoint_every_steps: 1000 }}
seed: 1
"#
    )
}

const BEADS: &str = ", glued_beads: { radius_m: 0.0015, count_around: 40, axial_spacing_m: 0.00315 }";

/// (v_x / (Ω R), spin / Ω) of the particles in the bottom of the drum (below −0.6 R) within 2.5 mm of its wall,
/// after `end_time_s`.
fn wall_layer(beads: &str, end_time_s: f64) -> (f64, f64, usize) {
    let b = built(&drum(beads, end_time_s));
    let mut sim = simulation(&b, 1);
    let steps = (end_time_s / b.dt_s).round() as u64;
    sim.run_steps(steps).expect("runs");
    let s = sim.snapshot();
    let omega = RPM * 2.0 * std::f64::consts::PI / 60.0;
    let p = &s.particles;
    let (mut vx, mut spin, mut n) = (0.0, 0.0, 0usize);
    for i in 0..p.position_m.len() {
        let x = p.position_m[i];
        if x.y < -0.6 * DRUM_RADIUS_M && x.x.hypot(x.y) > DRUM_RADIUS_M - 0.0025 {
            vx += p.velocity_m_per_s[i].x;
            spin += p.angular_velocity_rad_per_s[i].z;
            n += 1;
        }
    }
    assert!(n > 5, "only {n} particles at the bottom of the wall");
    (vx / n as f64 / (omega * DRUM_RADIUS_M), spin / n as f64 / omega, n)
}

#[test]
fn glued_beads_turn_the_bed_with_the_drum_where_a_smooth_wall_lets_it_roll() {
    let (smooth_speed, smooth_spin, _) = wall_layer("", 4.0);
    let (rough_speed, rough_spin, n) = wall_layer(BEADS, 4.0);
    // Measured: smooth -0.46 and 21 (the layer rolls, the bed above it slides back); beads 0.79 and 1.0 (a
    // particle resting on the beads has its centre at about 0.82 R).
    assert!(
        smooth_spin > 5.0,
        "smooth wall: spin/Ω = {smooth_spin}, v/(ΩR) = {smooth_speed}"
    );
    assert!(smooth_speed < 0.6, "smooth wall: v/(ΩR) = {smooth_speed}");
    assert!(
        (0.65..=0.95).contains(&rough_speed) && (0.5..=1.5).contains(&rough_spin),
        "beads: v/(ΩR) = {rough_speed}, spin/Ω = {rough_spin} over {n} particles"
    );
}

/// A sphere of radius r resting on top of a glued bead of radius r_b sinks to Hertz's static overlap for the pair,
/// m g = 4/3 E* √R* δ^{3/2} with R* = r r_b / (r + r_b): the bead is a glued particle, not a flat wall (whose
/// R* = r would give an overlap 2^{-1/3} as deep for equal radii).
#[test]
fn a_sphere_resting_on_a_glued_bead_sinks_to_the_pair_hertz_overlap() {
    let (r, r_b, density, e, nu, g) = (0.001, 0.001, 2500.0, 1.0e8, 0.3, 9.81);
    let yaml = format!(
        r#"name: bead-rest
domain: {{ lo_m: [-0.01, -0.01, 0.0], hi_m: [0.01, 0.01, 0.01], periodic: [false, false, false] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, -{g}] }}
species:
  - {{ name: glass, radius_m: {r}, density_kg_per_m3: {density}, youngs_modulus_pa: {e}, poisson_ratio: {nu}, friction_coefficient: 0.5 }}
contact: {{ normal: {{ hertz: {{ restitution: 0.3 }} }}, tangential: mindlin }}
walls:
  - plane: {{ name: floor, species: glass, point_m: [0.0, 0.0, 0.0], normal: [0.0, 0.0, 1.0], glued_beads: {{ radius_m: {r_b}, spacing_m: [0.004, 0.004] }} }}
fill:
  - explicit: {{ species: glass, positions_m: [[0.0, 0.0, {z0}]] }}
time: {{ dt_fraction_of_contact_time: 0.05, end_time_s: 0.02 }}
seed: 1
"#,
        z0 = r + r_b
    );
    let b = built(&yaml);
    let mut sim = simulation(&b, 1);
    sim.run_steps((0.02 / b.dt_s).round() as u64).expect("runs");
    let s = sim.snapshot();
    let x = s.particles.position_m[0];
    assert!(x.x == 0.0 && x.y == 0.0, "the sphere left the bead's top: {x:?}");
    let overlap_m = r + r_b - x.z;
    let weight_n = density * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * g;
    let e_star = e / (2.0 * (1.0 - nu * nu));
    let hertz = |r_star: f64| (weight_n / (4.0 / 3.0 * e_star * r_star.sqrt())).powf(2.0 / 3.0);
    let (pair, flat) = (hertz(r * r_b / (r + r_b)), hertz(r));
    println!("overlap {overlap_m:.6e} m; Hertz for the pair {pair:.6e} m, for a flat wall {flat:.6e} m");
    assert!(
        (overlap_m - pair).abs() < 1e-3 * pair,
        "overlap {overlap_m:e} m against the pair's {pair:e} m (a flat wall's: {flat:e} m)"
    );
}

/// A heated floor heats through its glued beads (`heat.walls.floor` holds for the floor's beads): a sphere resting on
/// a bead at 400 K warms at the rate of the pair's Hertz contact, H = 2 k √(R* δ) (seed 000 eq. 5.4) with R* and δ
/// the pair's: T(t) = T_w − (T_w − T_0) exp(−H t / (m c)).
#[test]
fn a_heated_floor_conducts_through_its_glued_beads_as_a_pair_contact() {
    let (r, r_b, density, e, nu, g): (f64, f64, f64, f64, f64, f64) = (0.001, 0.001, 2500.0, 1.0e8, 0.3, 9.81);
    let (k, c, t_wall, t0, end_s): (f64, f64, f64, f64, f64) = (1.0, 800.0, 400.0, 300.0, 0.02);
    let weight_n = density * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * g;
    let e_star = e / (2.0 * (1.0 - nu * nu));
    let r_star = r * r_b / (r + r_b);
    let overlap_m = (weight_n / (4.0 / 3.0 * e_star * r_star.sqrt())).powf(2.0 / 3.0);
    let yaml = format!(
        r#"name: bead-heat
domain: {{ lo_m: [-0.01, -0.01, 0.0], hi_m: [0.01, 0.01, 0.01], periodic: [false, false, false] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, -{g}] }}
species:
  - {{ name: glass, radius_m: {r}, density_kg_per_m3: {density}, youngs_modulus_pa: {e}, poisson_ratio: {nu}, friction_coefficient: 0.5, thermal_conductivity_w_per_m_k: {k}, heat_capacity_j_per_kg_k: {c} }}
contact: {{ normal: {{ hertz: {{ restitution: 0.3 }} }}, tangential: mindlin }}
walls:
  - plane: {{ name: floor, species: glass, point_m: [0.0, 0.0, 0.0], normal: [0.0, 0.0, 1.0], glued_beads: {{ radius_m: {r_b}, spacing_m: [0.004, 0.004] }} }}
fill:
  - explicit: {{ species: glass, positions_m: [[0.0, 0.0, {z0}]] }}
time: {{ dt_fraction_of_contact_time: 0.05, end_time_s: {end_s} }}
heat: {{ initial_temperature_k: {t0}, walls: {{ floor: {{ temperature_k: {t_wall} }} }} }}
seed: 1
"#,
        z0 = r + r_b - overlap_m
    );
    let b = built(&yaml);
    let mut sim = simulation(&b, 1);
    let steps = (end_s / b.dt_s).round() as u64;
    sim.run_steps(steps).expect("runs");
    let t_end = sim.snapshot().particles.temperature_k[0];
    let mass_kg = weight_n / g;
    let conductance_w_per_k = 2.0 * k * (r_star * overlap_m).sqrt();
    let expected = t_wall - (t_wall - t0) * (-conductance_w_per_k * steps as f64 * b.dt_s / (mass_kg * c)).exp();
    println!("after {end_s} s: {t_end:.9} K, the pair contact's {expected:.9} K");
    assert!(
        ((t_end - t0) - (expected - t0)).abs() < 2e-3 * (expected - t0),
        "warmed by {} K, the pair contact by {} K",
        t_end - t0,
        expected - t0
    );
}

/// One sphere (1 mm, 2500 kg/m³) above the bead at the origin of a floor of glued beads of the same size, with no
/// gravity: the scenario with `cohesion` and the sphere's `z0` and downward speed `v0`.
fn sphere_over_a_bead(cohesion: &str, z0: f64, v0: f64, end_s: f64) -> String {
    format!(
        r#"name: bead-cohesion
domain: {{ lo_m: [-0.01, -0.01, -0.002], hi_m: [0.01, 0.01, 0.01], periodic: [false, false, false] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, 0.0] }}
species:
  - {{ name: glass, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e8, poisson_ratio: 0.3, friction_coefficient: 0.5 }}
contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
cohesion: {cohesion}
walls:
  - plane: {{ name: floor, species: glass, point_m: [0.0, 0.0, 0.0], normal: [0.0, 0.0, 1.0], glued_beads: {{ radius_m: 0.001, spacing_m: [0.004, 0.004] }} }}
fill:
  - explicit: {{ species: glass, positions_m: [[0.0, 0.0, {z0}]], velocities_m_per_s: [[0.0, 0.0, -{v0}]] }}
time: {{ dt_fraction_of_contact_time: 0.05, end_time_s: {end_s} }}
seed: 1
"#
    )
}

/// A glued bead attracts as the glued particle it is: Hamaker's force at a 1 µm gap is A R*/(6 D²) with the pair's
/// R* (half a flat wall's for equal radii), and a square well to it is the pair's, as deep as between particles (a
/// flat wall's is twice as deep: seed 001 §6.2.4.2) and reaching (ratio − 1)(R_i + r_b) beyond contact.
#[test]
fn a_glued_bead_attracts_as_a_glued_particle() {
    let (r, mass_kg) = (0.001, 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.001f64.powi(3));
    let (a_j, gap_m) = (1.0e-19, 1.0e-6);
    let hamaker =
        format!("{{ hamaker: {{ constant_j: {a_j}, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 5.0e-6, walls: true }} }}");
    let b = built(&sphere_over_a_bead(&hamaker, 2.0 * r + gap_m, 0.0, 1.0));
    let mut sim = simulation(&b, 1);
    sim.run_steps(1).expect("runs");
    let dv = -sim.snapshot().particles.velocity_m_per_s[0].z;
    let expected = a_j * (r / 2.0) / (6.0 * gap_m * gap_m) * b.dt_s / mass_kg;
    println!("Hamaker: one step's Δv {dv:.6e} m/s, the pair's A R*/(6 D²) gives {expected:.6e}");
    assert!(
        (dv / expected - 1.0).abs() < 1e-6,
        "Δv {dv} against the pair's {expected}"
    );

    // Square well: ε = 5e-10 J, r_out/r_in = 1.01: the well's edge at a centre distance of 2.02 mm. The sphere starts
    // at 2.03 mm at 0.01 m/s and ends inside the well (at about 2.013 mm, before contact at 2.0 mm).
    let (depth_j, v0) = (5.0e-10, 0.01);
    let well = format!("{{ square_well: {{ depth_j: {depth_j}, outer_to_inner_radius_ratio: 1.01, walls: true }} }}");
    let b = built(&sphere_over_a_bead(&well, 2.03e-3, v0, 1.5e-3));
    let mut sim = simulation(&b, 1);
    sim.run_steps((1.5e-3 / b.dt_s).round() as u64).expect("runs");
    let s = sim.snapshot();
    let (z, v) = (s.particles.position_m[0].z, -s.particles.velocity_m_per_s[0].z);
    let pair = (v0 * v0 + 2.0 * depth_j / mass_kg).sqrt();
    let flat = (v0 * v0 + 4.0 * depth_j / mass_kg).sqrt();
    println!("square well: at {z:.6e} m, {v:.6e} m/s; the pair's well gives {pair:.6e}, a flat wall's {flat:.6e}");
    assert!(
        z < 2.02e-3 && z > 2.0e-3,
        "ends at {z} m, expected inside the well and out of contact"
    );
    assert!((v / pair - 1.0).abs() < 1e-9, "speed {v} m/s, the pair's well {pair}");
}

/// A heated drum's beads are found as its own (`Wall::glued_to`), for the contact arc that E5's h_w divides by: the
/// bead radius on a beaded drum, 0 on a smooth one; another drum's beads do not count.
#[test]
fn a_heated_drum_knows_its_own_glued_beads() {
    let heated = |beads: &str, second_drum: &str| {
        let yaml = drum(beads, 0.01)
            .replace(
                "friction_coefficient: 0.4 }",
                "friction_coefficient: 0.4, thermal_conductivity_w_per_m_k: 1.0, heat_capacity_j_per_kg_k: 800.0 }",
            )
            .replace(
                "friction_coefficient: 1.0 }",
                "friction_coefficient: 1.0, thermal_conductivity_w_per_m_k: 1.0, heat_capacity_j_per_kg_k: 800.0 }",
            )
            .replace("fill:", &format!("{second_drum}fill:"))
            + "heat: { initial_temperature_k: 300.0, walls: { drum: { temperature_k: 400.0 } } }\n";
        granflow::heated_drum::heated_drum(&built(&yaml).config).expect("one heated drum")
    };
    assert_eq!(heated(BEADS, "").bead_radius_m, 0.0015);
    assert_eq!(heated("", "").bead_radius_m, 0.0);
    let other = "  - drum: { name: outer, species: wall, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: 0.0205, rotation_rpm: 6.0, glued_beads: { radius_m: 0.0002, count_around: 40, axial_spacing_m: 0.00315 } }\n";
    let drum = heated("", other);
    assert_eq!((drum.bead_radius_m, drum.wall), (0.0, 0));
}

#[test]
fn a_drum_with_glued_beads_resumes_bit_for_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let (whole, split) = whole_and_resumed(tmp.path(), &drum(BEADS, 0.1), 1700);
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("the resumed run differs from the uninterrupted one: {diff}");
    }
}

#[test]
fn impossible_bead_lattices_are_bad_input_at_their_key() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (
            ", glued_beads: { radius_m: 0.0015, count_around: 41, axial_spacing_m: 0.00315 }",
            "walls[0].drum.glued_beads.count_around",
            "expected an even number",
        ),
        // 2 R sin(2π/44) = 5.7 mm between every other bead: a 3 mm particle could touch two.
        (
            ", glued_beads: { radius_m: 0.0015, count_around: 44, axial_spacing_m: 0.00315 }",
            "walls[0].drum.glued_beads.count_around",
            "at most 40",
        ),
        (
            ", glued_beads: { radius_m: 0.0015, count_around: 40, axial_spacing_m: 0.0021 }",
            "walls[0].drum.glued_beads.axial_spacing_m",
            "between rings",
        ),
        (
            ", glued_beads: { radius_m: 0.0015, count_around: 40, axial_spacing_m: 0.0063 }",
            "walls[0].drum.glued_beads.axial_spacing_m",
            "an even number of rings",
        ),
        (
            ", glued_beads: { radius_m: -0.0015, count_around: 40, axial_spacing_m: 0.00315 }",
            "walls[0].drum.glued_beads.radius_m",
            "expected a finite value > 0",
        ),
    ];
    for (k, (beads, key, message)) in cases.iter().enumerate() {
        let file = format!("bad-{k}.yaml");
        std::fs::write(tmp.path().join(&file), drum(beads, 0.01)).unwrap();
        granflow_fails_with_2(&["simulate", &file, "--out", "out", "--quiet"], tmp.path(), key);
        let out = granflow(&["simulate", &file, "--out", "out", "--quiet"], tmp.path());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(message), "case {k}: expected `{message}` in {stderr}");
        assert!(
            stderr.contains(&format!("{file}:")),
            "case {k}: no file and line in {stderr}"
        );
        assert!(!tmp.path().join("out").exists(), "case {k}: wrote output");
    }
}
