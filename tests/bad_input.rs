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
        "a sort every zero steps",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }\nneighbor: { sort_every_steps: 0 }",
        &["bad.yaml", "neighbor.sort_every_steps", "at least 1"],
    ),
    (
        "snapshots every zero seconds",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }\noutput: { snapshots_every_s: 0.0 }",
        &["bad.yaml", "output.snapshots_every_s", "expected a finite value > 0"],
    ),
    (
        "more snapshots than a disk should take",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }\noutput: { snapshots_every_s: 1.0e-9 }",
        &[
            "bad.yaml",
            "output.snapshots_every_s",
            "1000000 snapshots",
            "at most 10000",
        ],
    ),
    (
        "a sort period that is not a whole number",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }",
        "time: { dt_s: 1.0e-5, end_time_s: 0.001 }\nneighbor: { sort_every_steps: 2.5 }",
        &["bad.yaml:", "sort_every_steps"],
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
        "a fixed bridge volume beyond Mikami's fit",
        "time: {",
        "cohesion: { liquid_bridge: { surface_tension_n_per_m: 0.072, bridge_volume: { fixed: 0.5 } } }\ntime: {",
        &["cohesion.liquid_bridge.bridge_volume.fixed", "(0, 0.1]"],
    ),
    (
        "spray with no liquid",
        "time: {",
        "cohesion: { liquid_bridge: { surface_tension_n_per_m: 0.072, spray: { max_liquid_content: 0.0 } } }\ntime: {",
        &["cohesion.liquid_bridge.spray.max_liquid_content", "> 0"],
    ),
    // Motions no time step can resolve: more than the smallest radius (1 mm) per step of 1e-5 s.
    (
        "an initial velocity of 1e5 m/s",
        "fill:\n  - lattice: { species: glass, spacing_m: 0.0025, lo_m: [0.001, 0.001, 0.001], hi_m: [0.019, 0.019, 0.02] }",
        "fill:\n  - explicit: { species: glass, positions_m: [[0.01, 0.01, 0.01]], velocities_m_per_s: [[1.0e5, 0.0, 0.0]] }",
        &[
            "fill[0].explicit.velocities_m_per_s[0]",
            "an initial velocity of 1.000e5 m/s moves 1.000e0 m per time step",
            "expected a speed below 1.000e2 m/s",
        ],
    ),
    (
        "an initial spin of 1e6 rad/s",
        "fill:\n  - lattice: { species: glass, spacing_m: 0.0025, lo_m: [0.001, 0.001, 0.001], hi_m: [0.019, 0.019, 0.02] }",
        "fill:\n  - explicit: { species: glass, positions_m: [[0.01, 0.01, 0.01]], angular_velocities_rad_per_s: [[0.0, 1.0e6, 0.0]] }",
        &[
            "fill[0].explicit.angular_velocities_rad_per_s[0]",
            "expected below 1.000e5 rad/s",
        ],
    ),
    (
        "gravity of 1e9 m/s2",
        "vector_m_per_s2: [0.0, 0.0, -9.81]",
        "vector_m_per_s2: [0.0, 0.0, -1.0e9]",
        &["gravity.vector_m_per_s2", "more than the smallest particle radius"],
    ),
    (
        "gravity flip frequency of zero (the zig-zag chute)",
        "vector_m_per_s2: [0.0, 0.0, -9.81]",
        "vector_m_per_s2: [0.0, 0.0, -9.81], flip: { axis: x, frequency_hz: 0.0 }",
        &[
            "bad.yaml:4:",
            "gravity.flip.frequency_hz",
            "expected a finite value > 0, got 0",
        ],
    ),
    (
        "negative gravity flip frequency",
        "vector_m_per_s2: [0.0, 0.0, -9.81]",
        "vector_m_per_s2: [0.0, 0.0, -9.81], flip: { axis: x, frequency_hz: -2.0 }",
        &["bad.yaml:4:", "gravity.flip.frequency_hz"],
    ),
    (
        "a gas inflow of 1e5 m/s",
        "time: {",
        "gas: { density_kg_per_m3: 1.2, viscosity_pa_s: 1.8e-5, cells: [4, 4, 10], dem_steps_per_gas_step: 10, sides: { z_low: { inlet: { superficial_velocity_m_per_s: 1.0e5 } }, z_high: outlet } }\ntime: {",
        &[
            "gas.sides.z_low.inlet.superficial_velocity_m_per_s",
            "a gas inflow of 1.000e5 m/s (at its highest level)",
        ],
    ),
    (
        "a jet of 500 m/s",
        "time: {",
        "gas: { density_kg_per_m3: 1.2, viscosity_pa_s: 1.8e-5, cells: [4, 4, 10], dem_steps_per_gas_step: 10, sides: { z_low: { inlet: { superficial_velocity_m_per_s: 1.0 } }, z_high: outlet }, jets: [{ side: z_low, lo_m: [0.0, 0.0, 0.0], hi_m: [0.01, 0.01, 0.0], superficial_velocity_m_per_s: 500.0 }] }\ntime: {",
        &[
            "gas.jets[0].superficial_velocity_m_per_s",
            "a gas inflow of 5.000e2 m/s",
        ],
    ),
    (
        "a lattice spacing of 1e-300 m",
        "spacing_m: 0.0025",
        "spacing_m: 1.0e-300",
        &["fill[0].lattice.spacing_m"],
    ),
    (
        "a gas grid of 1e21 cells",
        "time: {",
        "gas: { density_kg_per_m3: 1.2, viscosity_pa_s: 1.8e-5, cells: [10000000, 10000000, 10000000], dem_steps_per_gas_step: 10, sides: { z_low: { inlet: { superficial_velocity_m_per_s: 1.0 } }, z_high: outlet } }\ntime: {",
        &[
            "gas.cells",
            "1.000e21 gas cells at ~640 bytes",
            "more than this machine's budget",
        ],
    ),
    (
        "unknown cohesion model",
        "time: {",
        "cohesion: { capillary: { surface_tension_n_per_m: 0.072 } }\ntime: {",
        &["bad.yaml:", "capillary"],
    ),
];

/// A scenario with heat transfer, and its bad variants.
const GOOD_HEAT: &str = r#"
name: ok-heat
domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.02, 0.02, 0.05] }
gravity: { vector_m_per_s2: [0.0, 0.0, -9.81] }
species:
  - { name: glass, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3, thermal_conductivity_w_per_m_k: 1.0, heat_capacity_j_per_kg_k: 800.0 }
contact: { normal: { hertz: { restitution: 0.9 } }, tangential: mindlin }
walls:
  - box: { species: glass }
fill:
  - lattice: { species: glass, spacing_m: 0.0025, lo_m: [0.001, 0.001, 0.001], hi_m: [0.019, 0.019, 0.02] }
time: { dt_s: 1.0e-5, end_time_s: 0.001 }
heat:
  initial_temperature_k: 300.0
  walls: { box_z_lo: { temperature_k: 400.0 } }
"#;

const HEAT_CASES: &[(&str, &str, &str, &[&str])] = &[
    (
        "a negative conductivity",
        "thermal_conductivity_w_per_m_k: 1.0",
        "thermal_conductivity_w_per_m_k: -1.0",
        &[
            "species[0].thermal_conductivity_w_per_m_k",
            "expected a finite value > 0, got -1",
        ],
    ),
    (
        "a zero heat capacity",
        "heat_capacity_j_per_kg_k: 800.0",
        "heat_capacity_j_per_kg_k: 0.0",
        &[
            "species[0].heat_capacity_j_per_kg_k",
            "expected a finite value > 0, got 0",
        ],
    ),
    (
        "an initial temperature below 0 K",
        "initial_temperature_k: 300.0",
        "initial_temperature_k: -5.0",
        &[
            "heat.initial_temperature_k",
            "expected an absolute temperature > 0 K, got -5",
        ],
    ),
    (
        "a fill at 0 K",
        "hi_m: [0.019, 0.019, 0.02] }",
        "hi_m: [0.019, 0.019, 0.02], temperature_k: 0.0 }",
        &[
            "fill[0].lattice.temperature_k",
            "expected an absolute temperature > 0 K, got 0",
        ],
    ),
    (
        "a heated wall without a temperature",
        "walls: { box_z_lo: { temperature_k: 400.0 } }",
        "walls: { box_z_lo: {} }",
        &[
            "heat.walls.box_z_lo",
            "expected the wall's `temperature_k` (a heated wall) or `adiabatic: true`",
        ],
    ),
    (
        "a wall that does not exist",
        "walls: { box_z_lo: { temperature_k: 400.0 } }",
        "walls: { drum: { temperature_k: 400.0 } }",
        &["heat.walls.drum", "no wall named 'drum'", "box_z_lo"],
    ),
    (
        "heat on without thermal properties",
        ", thermal_conductivity_w_per_m_k: 1.0, heat_capacity_j_per_kg_k: 800.0 }",
        " }",
        &[
            "species[0].thermal_conductivity_w_per_m_k",
            "heat transfer is on",
            "or a `material`",
        ],
    ),
    (
        "a gas with a negative conductivity",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }\n  gas: { conductivity_w_per_m_k: -0.02 }",
        &[
            "heat.gas.conductivity_w_per_m_k",
            "expected a finite value > 0, got -0.02",
        ],
    ),
    (
        "a gas lens of negative size",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }\n  gas: { lens_conduction: { lens_radius_fraction: -0.2 } }",
        &[
            "heat.gas.lens_conduction.lens_radius_fraction",
            "expected a finite value > 0, got -0.2",
        ],
    ),
    (
        "a gas lens whose smallest gap is a particle's size",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }\n  gas: { lens_conduction: { min_gap_m: 0.01 } }",
        &[
            "heat.gas.lens_conduction.min_gap_m",
            "expected a gap well below the particles' radius",
        ],
    ),
    (
        "a liquid that does not conduct",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }\n  liquid_conductivity_w_per_m_k: 0.0",
        &[
            "heat.liquid_conductivity_w_per_m_k",
            "expected a finite value > 0, got 0",
        ],
    ),
    (
        "a bed core wider than the distance to the wall",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }",
        "  walls: { box_z_lo: { temperature_k: 400.0 } }\n  bed_core_radius_fraction: 1.5",
        &["heat.bed_core_radius_fraction", "expected 0 < value <= 1", "got 1.5"],
    ),
    (
        "an unknown material",
        "  - { name: glass, radius_m",
        "  - { name: glass, material: granite, radius_m",
        &["unknown variant `granite`", "glass", "steel", "aluminium"],
    ),
];

/// A scenario that dries (wet beads in a closed box of gas, heat transfer on), and its bad variants.
const GOOD_DRYING: &str = r#"
name: ok-drying
domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.012, 0.012, 0.012] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3, thermal_conductivity_w_per_m_k: 1.0, heat_capacity_j_per_kg_k: 800.0, liquid_content: 0.02 }
contact: { normal: { hertz: { restitution: 0.9 } }, tangential: mindlin }
cohesion: { liquid_bridge: { surface_tension_n_per_m: 0.072 } }
walls:
  - box: { species: glass }
fill:
  - lattice: { species: glass, spacing_m: 0.004, lo_m: [0.0, 0.0, 0.0], hi_m: [0.012, 0.012, 0.012], origin_m: [0.002, 0.002, 0.002] }
time: { dt_s: 1.0e-5, end_time_s: 0.001 }
gas: { density_kg_per_m3: 1.2, viscosity_pa_s: 1.8e-5, cells: [3, 3, 3], dem_steps_per_gas_step: 20 }
heat:
  initial_temperature_k: 300.0
drying: { evaporation_coefficient: 1.0, inlet_relative_humidity: 0.5 }
"#;

const DRYING_CASES: &[(&str, &str, &str, &[&str])] = &[
    (
        "a negative evaporation coefficient",
        "evaporation_coefficient: 1.0",
        "evaporation_coefficient: -0.5",
        &["drying.evaporation_coefficient", "expected 0 < α ≤ 1", "got -0.5"],
    ),
    (
        "inlet humidity above saturation",
        "inlet_relative_humidity: 0.5",
        "inlet_relative_humidity: 1.2",
        &["drying.inlet_relative_humidity", "above saturation", "from 0 to 1"],
    ),
    (
        "a zero latent heat",
        "inlet_relative_humidity: 0.5",
        "inlet_relative_humidity: 0.5, latent_heat_j_per_kg: 0.0",
        &["drying.latent_heat_j_per_kg", "expected a finite value > 0"],
    ),
    (
        "drying without heat",
        "heat:\n  initial_temperature_k: 300.0\ndrying:",
        "drying:",
        &["drying", "needs heat transfer", "`heat` section"],
    ),
];

/// A fill temperature without a `heat` section.
const NO_HEAT_CASES: &[(&str, &str, &str, &[&str])] = &[(
    "a fill temperature without heat",
    "hi_m: [0.019, 0.019, 0.02] }",
    "hi_m: [0.019, 0.019, 0.02], temperature_k: 350.0 }",
    &["fill[0].lattice.temperature_k", "needs a `heat` section"],
)];

#[test]
fn bad_scenarios_fail_cleanly_before_writing_anything() {
    check_cases(GOOD, CASES);
    check_cases(GOOD, NO_HEAT_CASES);
}

#[test]
fn bad_heat_input_fails_cleanly_before_writing_anything() {
    check_cases(GOOD_HEAT, HEAT_CASES);
}

#[test]
fn bad_drying_input_fails_cleanly_before_writing_anything() {
    check_cases(GOOD_DRYING, DRYING_CASES);
}

/// Runs `good` (which must succeed) and each case's edit of it (which must fail at the edited line, exit 2, with
/// every fragment in its one-line message, and write nothing).
fn check_cases(good: &str, cases: &[(&str, &str, &str, &[&str])]) {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // The good file runs, so each failure below is due to its one change.
    std::fs::write(dir.join("good.yaml"), good).expect("write");
    let ok = granflow(&["simulate", "good.yaml", "--out", "good-out", "--quiet"], dir);
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));

    for (case, from, to, fragments) in cases {
        assert!(
            good.contains(from),
            "case '{case}': '{from}' is not in the good scenario"
        );
        std::fs::write(dir.join("bad.yaml"), good.replacen(from, to, 1)).expect("write");
        let out = granflow(&["simulate", "bad.yaml", "--out", "bad-out"], dir);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "case '{case}': exit code, stderr: {stderr}");
        for f in *fragments {
            assert!(stderr.contains(f), "case '{case}': message lacks '{f}': {stderr}");
        }
        // Every message names the line of the edit (or, for an edit of several lines, one of them).
        let first_line = good[..good.find(from).expect("checked above")].matches('\n').count() + 1;
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

/// A scenario whose particles or gas cells would need more memory than the machine's budget is refused from its
/// counts, before anything is allocated (`GRANFLOW_MEMORY_BYTES` stands in for a small machine).
#[test]
fn a_run_larger_than_the_memory_budget_is_refused_before_allocating() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    // 32,320 lattice points (about 33 MB at 1 kB each) against a budget of 10 MB.
    let big = GOOD
        .replace("hi_m: [0.02, 0.02, 0.05]", "hi_m: [0.025, 0.025, 1.0]")
        .replace("hi_m: [0.019, 0.019, 0.02]", "hi_m: [0.024, 0.024, 0.999]");
    std::fs::write(dir.join("big.yaml"), &big).expect("write");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(["simulate", "big.yaml", "--out", "big-out"])
        .env(granflow::machine::MEMORY_BUDGET_ENV, "10000000")
        .current_dir(dir)
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for f in [
        "key `fill[0].lattice.spacing_m`",
        "the run would need about 33.1 MB of memory (3.232e4 particles at ~1024 bytes",
        "more than this machine's budget of 10.0 MB (set by GRANFLOW_MEMORY_BYTES)",
    ] {
        assert!(stderr.contains(f), "lacks `{f}`: {stderr}");
    }
    assert!(!dir.join("big-out").exists());
    // The same file within a budget it fits runs.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args([
            "simulate",
            "big.yaml",
            "--out",
            "big-out",
            "--max-steps",
            "1",
            "--quiet",
        ])
        .env(granflow::machine::MEMORY_BUDGET_ENV, "100000000")
        .current_dir(dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn missing_file_is_a_config_error() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let out = granflow(&["simulate", "nope.yaml"], tmp.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nope.yaml"));
    assert!(!tmp.path().join("results").exists());
}
