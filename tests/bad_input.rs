//! Bad scenario input through the real binary: one clear message naming the file, the line and column of the
//! edit, and for a value that parses but is not valid its key path; exit code 2, and nothing written.
//! (`tests/campaign_bad_input.rs` does the same for campaign files.)

mod common;

use common::granflow;

const GOOD: &str = r#"
name: ok
domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.02, 0.02, 0.05] }
gravity: { vector_m_per_s2: [0.0, 0.0, -9.81] }
species:
  - { name: glass, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3 }
contact: { normal: { hertz: { restitution: 0.9 } }, tangential: mindlin }
walls:
  - box: { species: glass }
fill:
  - lattice: { species: glass, spacing_m: 0.0025, lo_m: [0.001, 0.001, 0.001], hi_m: [0.019, 0.019, 0.02] }
time: { dt_s: 1.0e-5, end_time_s: 0.001 }
"#;

/// (case, text replaced in GOOD, replacement, fragments the message must contain)
const CASES: &[(&str, &str, &str, &[&str])] = &[
    (
        "yaml syntax error",
        "gravity: {",
        "gravity: {{",
        &["bad.yaml:4:11:", "invalid type"],
    ),
    (
        "unknown key",
        "radius_m: 0.001",
        "radius: 0.001",
        &["bad.yaml:", "unknown field `radius`", "radius_m"],
    ),
    (
        "wrong type",
        "restitution: 0.9",
        "restitution: high",
        &["bad.yaml:", "invalid type"],
    ),
    (
        "missing required field",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }",
        "time: { dt_s: 1.0e-5 }",
        &["missing field `end_time_s`"],
    ),
    (
        "inner skin larger than the skin",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }\nneighbor: { skin_m: 0.0004, inner_skin_m: 0.0005 }",
        &["bad.yaml", "neighbor.inner_skin_m", "<= neighbor.skin_m"],
    ),
    (
        "a spinning particle that cannot rotate",
        "fill:\n  - lattice: { species: glass, spacing_m: 0.0025, lo_m: [0.001, 0.001, 0.001], hi_m: [0.019, 0.019, 0.02] }",
        "rotation: false\nfill:\n  - explicit: { species: glass, positions_m: [[0.01, 0.01, 0.01]], angular_velocities_rad_per_s: [[0.0, 5.0, 0.0]] }",
        &[
            "bad.yaml",
            "fill[0].explicit.angular_velocities_rad_per_s[0]",
            "rotation: false",
        ],
    ),
    (
        "rotation not a boolean",
        "name: ok",
        "name: ok\nrotation: sometimes",
        &["bad.yaml:", "rotation"],
    ),
    (
        "negative radius",
        "radius_m: 0.001",
        "radius_m: -0.001",
        &["species[0].radius_m", "> 0"],
    ),
    (
        "zero density",
        "density_kg_per_m3: 2500.0",
        "density_kg_per_m3: 0.0",
        &["species[0].density_kg_per_m3"],
    ),
    (
        "NaN modulus",
        "youngs_modulus_pa: 1.0e7",
        "youngs_modulus_pa: .nan",
        &["species[0].youngs_modulus_pa"],
    ),
    (
        "Poisson ratio too large",
        "poisson_ratio: 0.3",
        "poisson_ratio: 0.6",
        &["species[0].poisson_ratio"],
    ),
    (
        "restitution above one",
        "restitution: 0.9",
        "restitution: 1.5",
        &["contact.normal.hertz.restitution"],
    ),
    (
        "unknown contact model",
        "tangential: mindlin",
        "tangential: mindlyn",
        &["bad.yaml:", "mindlyn"],
    ),
    (
        "mindlin with linear normal",
        "normal: { hertz: { restitution: 0.9 } }",
        "normal: { linear_spring_dashpot: { stiffness_n_per_m: 800.0, damping_kg_per_s: 0.001 } }",
        &["contact.tangential", "Hertzian"],
    ),
    (
        "unknown species in wall",
        "box: { species: glass }",
        "box: { species: steel }",
        &["walls[0].box.species", "steel"],
    ),
    (
        "inverted domain",
        "hi_m: [0.02, 0.02, 0.05]",
        "hi_m: [0.02, -0.02, 0.05]",
        &["domain.hi_m[1]"],
    ),
    (
        "lattice spacing below diameter",
        "spacing_m: 0.0025",
        "spacing_m: 0.0015",
        &["fill[0].lattice.spacing_m", "diameter"],
    ),
    (
        "lattice jitter wider than half the gap",
        "spacing_m: 0.0025,",
        "spacing_m: 0.0025, jitter_m: 0.0003,",
        &["fill[0].lattice.jitter_m", "overlap"],
    ),
    (
        "particles cannot fit",
        "lo_m: [0.001, 0.001, 0.001], hi_m: [0.019, 0.019, 0.02]",
        "lo_m: [0.03, 0.03, 0.03], hi_m: [0.04, 0.04, 0.04]",
        &["fill[0].lattice", "no particle fits"],
    ),
    (
        "both time steps",
        "dt_s: 1.0e-5,",
        "dt_s: 1.0e-5, dt_fraction_of_contact_time: 0.02,",
        &["time", "exactly one"],
    ),
    (
        "zero end time",
        "end_time_s: 0.001",
        "end_time_s: 0.0",
        &["time.end_time_s"],
    ),
    (
        "liquid without liquid bridges",
        "friction_coefficient: 0.3 }",
        "friction_coefficient: 0.3, liquid_content: 0.01 }",
        &["species[0].liquid_content", "liquid_bridge"],
    ),
    (
        "contact angle of 95 degrees",
        "friction_coefficient: 0.3 }\ncontact:",
        "friction_coefficient: 0.3, contact_angle_deg: 95.0 }\ncohesion: { liquid_bridge: { surface_tension_n_per_m: 0.072 } }\ncontact:",
        &["species[0].contact_angle_deg", "< 90"],
    ),
    (
        "negative surface tension",
        "time: {",
        "cohesion: { liquid_bridge: { surface_tension_n_per_m: -0.072 } }\ntime: {",
        &["cohesion.liquid_bridge.surface_tension_n_per_m", "> 0"],
    ),
    (
        "Hamaker outer cutoff inside the inner one",
        "time: {",
        "cohesion: { hamaker: { constant_j: 1.0e-18, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 1.0e-10 } }\ntime: {",
        &["cohesion.hamaker.outer_cutoff_m", "inner_cutoff_m"],
    ),
    (
        "square well narrower than the particle",
        "time: {",
        "cohesion: { square_well: { depth_j: 1.0e-10, outer_to_inner_radius_ratio: 0.99 } }\ntime: {",
        &["cohesion.square_well.outer_to_inner_radius_ratio", "> 1"],
    ),
    (
        "spray with no liquid",
        "time: {",
        "cohesion: { liquid_bridge: { surface_tension_n_per_m: 0.072, spray: { max_liquid_content: 0.0 } } }\ntime: {",
        &["cohesion.liquid_bridge.spray.max_liquid_content", "> 0"],
    ),
    (
        "unknown cohesion model",
        "time: {",
        "cohesion: { capillary: { surface_tension_n_per_m: 0.072 } }\ntime: {",
        &["bad.yaml:", "capillary"],
    ),
];

#[test]
fn bad_scenarios_fail_cleanly_before_writing_anything() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // The good file runs, so each failure below is due to its one change.
    std::fs::write(dir.join("good.yaml"), GOOD).expect("write");
    let ok = granflow(&["simulate", "good.yaml", "--out", "good-out", "--quiet"], dir);
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));

    for (case, from, to, fragments) in CASES {
        assert!(
            GOOD.contains(from),
            "case '{case}': '{from}' is not in the good scenario"
        );
        std::fs::write(dir.join("bad.yaml"), GOOD.replacen(from, to, 1)).expect("write");
        let out = granflow(&["simulate", "bad.yaml", "--out", "bad-out"], dir);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "case '{case}': exit code, stderr: {stderr}");
        for f in *fragments {
            assert!(stderr.contains(f), "case '{case}': message lacks '{f}': {stderr}");
        }
        // Every message names the line of the edit (or, for an edit of several lines, one of them).
        let first_line = GOOD[..GOOD.find(from).expect("checked above")].matches('\n').count() + 1;
        let lines = first_line..=first_line + to.lines().count().max(1) - 1;
        let line: Option<usize> = stderr
            .strip_prefix("error: bad.yaml:")
            .and_then(|rest| rest.split(':').next())
            .and_then(|l| l.parse().ok());
        assert!(
            line.is_some_and(|l| lines.contains(&l)),
            "case '{case}': expected `error: bad.yaml:<line>:` with a line in {lines:?}: {stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "case '{case}': one message: {stderr}");
        assert!(!dir.join("bad-out").exists(), "case '{case}': wrote output");
    }
}

#[test]
fn missing_file_is_a_config_error() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let out = granflow(&["simulate", "nope.yaml"], tmp.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nope.yaml"));
    assert!(!tmp.path().join("results").exists());
}
