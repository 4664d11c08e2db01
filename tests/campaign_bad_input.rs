//! Bad campaign input through the real binary (`granflow run <campaign.yaml> --out DIR`): each case is one small
//! edit of a valid campaign, and must give exit code 2, one message on one line (`error: <file>:<line>:<column>: …`,
//! at the edited line unless the case is listed in [`LOCATED_ELSEWHERE`]; values that parse but are not valid add
//! `key `<path>``) with the expected content, and write nothing — neither the `--out` directory nor anything else in
//! the working directory.
//!
//! All cases run in one test and every failure is reported, not only the first.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use common::granflow;

/// A valid campaign: a drum slice, 2 speeds × 2 fill levels (4 jobs), 100 steps each.
const GOOD: &str = r#"name: mini
seed: 7
base:
  domain: { lo_m: [-0.021, -0.021, 0.0], hi_m: [0.021, 0.021, 0.0064], periodic: [false, false, true] }
  gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
  species:
    - { name: red, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e6, poisson_ratio: 0.3, friction_coefficient: 0.4 }
    - { name: blue, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e6, poisson_ratio: 0.3, friction_coefficient: 0.4 }
  contact: { normal: { hertz: { restitution: 0.7 } }, tangential: mindlin }
  walls:
    - drum: { name: drum, species: red, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: 0.02, rotation_rpm: 30.0 }
  fill:
    - lattice: { species: red, spacing_m: 0.0032, lo_m: [-0.02, -0.02, 0.0], hi_m: [0.0, 0.0, 0.0064], origin_m: [0.0016, 0.0016, 0.0016], inside_drum: drum }
    - lattice: { species: blue, spacing_m: 0.0032, lo_m: [0.0, -0.02, 0.0], hi_m: [0.02, 0.0, 0.0064], origin_m: [0.0016, 0.0016, 0.0016], inside_drum: drum }
  time: { dt_s: 2.0e-5, end_time_s: 0.002 }
  output: { series_every_steps: 50 }
sweep:
  grid:
    - { param: walls.0.drum.rotation_rpm, name: rotation_rpm, values: [20.0, 60.0] }
    - zip:
        - { param: fill.0.lattice.hi_m.1, name: fill_top_m, values: [-0.006, 0.0] }
        - { param: fill.1.lattice.hi_m.1, values: [-0.006, 0.0] }
metrics: [lacey_index, intensity_of_segregation, kinetic_energy_j, coordination_number]
analysis: { mixing_species: red }
executor: { local: { max_parallel: 2 } }
checkpoint: { every_steps: 1000, keep: 2 }
"#;

/// The whole `sweep` section of [`GOOD`].
const SWEEP: &str = "sweep:
  grid:
    - { param: walls.0.drum.rotation_rpm, name: rotation_rpm, values: [20.0, 60.0] }
    - zip:
        - { param: fill.0.lattice.hi_m.1, name: fill_top_m, values: [-0.006, 0.0] }
        - { param: fill.1.lattice.hi_m.1, values: [-0.006, 0.0] }
";

/// A third fill entry is added before this line (the sweep already addresses fill[0] and fill[1]).
const TIME: &str = "  time: {";

/// Written into the message fragments, stands for `bad.yaml:<line>:` with the line of the edit.
const AT_EDIT: &str = "@EDIT";

/// (case, text replaced in GOOD (first occurrence), replacement, fragments the message must contain; a fragment
/// starting with `!` must be absent)
const CASES: &[(&str, &str, &str, &[&str])] = &[
    // YAML: file:line:column.
    (
        "yaml syntax error",
        "seed: 7",
        "seed: 7: 8",
        &[AT_EDIT, "mapping values are not allowed"],
    ),
    (
        "unclosed flow sequence",
        "values: [20.0, 60.0]",
        "values: [20.0, 60.0",
        &[AT_EDIT, "did not find expected ',' or ']'"],
    ),
    (
        "unknown top-level key",
        "seed: 7",
        "sede: 7",
        &[AT_EDIT, "unknown field `sede`", "did you mean `seed`?"],
    ),
    (
        "unknown key inside base",
        "rotation_rpm: 30.0",
        "rotaton_rpm: 30.0",
        &[
            AT_EDIT,
            "base.walls[0].drum",
            "unknown field `rotaton_rpm`",
            "did you mean `rotation_rpm`?",
        ],
    ),
    (
        "unknown model name",
        "tangential: mindlin",
        "tangential: mindlyn",
        &[AT_EDIT, "unknown variant `mindlyn`", "did you mean `mindlin`?"],
    ),
    (
        "string for a number in base",
        "density_kg_per_m3: 2500.0",
        "density_kg_per_m3: heavy",
        &[
            AT_EDIT,
            "base.species[0].density_kg_per_m3",
            "invalid type: string \"heavy\", expected f64",
        ],
    ),
    (
        "negative seed",
        "seed: 7",
        "seed: -7",
        &[AT_EDIT, "seed: invalid type", "expected u64"],
    ),
    (
        "missing base.time",
        "  time: { dt_s: 2.0e-5, end_time_s: 0.002 }\n",
        "",
        &["bad.yaml:4:", "base: missing field `time`"],
    ),
    ("missing sweep", SWEEP, "", &["bad.yaml:1:1:", "missing field `sweep`"]),
    // Physical values of the base: key paths.
    (
        "negative radius",
        "radius_m: 0.0015",
        "radius_m: -0.0015",
        &[
            "key `base.species[0].radius_m`",
            "expected a finite value > 0, got -0.0015",
            // The base alone fails so: the sweep has nothing to do with it.
            "!at sweep point",
        ],
    ),
    (
        "zero density",
        "density_kg_per_m3: 2500.0",
        "density_kg_per_m3: 0.0",
        &[
            "key `base.species[0].density_kg_per_m3`",
            "expected a finite value > 0, got 0",
        ],
    ),
    (
        "NaN Young's modulus",
        "youngs_modulus_pa: 5.0e6",
        "youngs_modulus_pa: .nan",
        &[
            "key `base.species[0].youngs_modulus_pa`",
            "expected a finite number, got NaN",
        ],
    ),
    (
        "negative Young's modulus",
        "youngs_modulus_pa: 5.0e6",
        "youngs_modulus_pa: -5.0e6",
        &[
            "key `base.species[0].youngs_modulus_pa`",
            "expected a finite value > 0, got -5000000",
        ],
    ),
    (
        "Poisson ratio 0.5",
        "poisson_ratio: 0.3",
        "poisson_ratio: 0.5",
        &["key `base.species[0].poisson_ratio`", "expected 0 <= ν < 0.5, got 0.5"],
    ),
    (
        "negative friction",
        "friction_coefficient: 0.4",
        "friction_coefficient: -0.4",
        &[
            "key `base.species[0].friction_coefficient`",
            "expected a finite value >= 0, got -0.4",
        ],
    ),
    (
        "zero restitution",
        "restitution: 0.7",
        "restitution: 0.0",
        &[
            "key `base.contact.normal.hertz.restitution`",
            "expected 0 < e <= 1, got 0",
        ],
    ),
    (
        "negative restitution",
        "restitution: 0.7",
        "restitution: -0.7",
        &[
            "key `base.contact.normal.hertz.restitution`",
            "expected 0 < e <= 1, got -0.7",
        ],
    ),
    (
        "NaN restitution",
        "restitution: 0.7",
        "restitution: .nan",
        &[
            "key `base.contact.normal.hertz.restitution`",
            "expected a finite number, got NaN",
        ],
    ),
    (
        "zero dt",
        "dt_s: 2.0e-5",
        "dt_s: 0.0",
        &["key `base.time.dt_s`", "expected a finite value > 0, got 0"],
    ),
    (
        "NaN dt",
        "dt_s: 2.0e-5",
        "dt_s: .nan",
        &["key `base.time.dt_s`", "expected a finite number, got NaN"],
    ),
    (
        "negative end time",
        "end_time_s: 0.002",
        "end_time_s: -1.0",
        &["key `base.time.end_time_s`", "expected a finite value > 0, got -1"],
    ),
    (
        "infinite end time",
        "end_time_s: 0.002",
        "end_time_s: .inf",
        &["key `base.time.end_time_s`", "expected a finite number, got inf"],
    ),
    (
        "inverted domain",
        "lo_m: [-0.021, -0.021, 0.0]",
        "lo_m: [-0.021, 0.03, 0.0]",
        &[
            "key `base.domain.hi_m[1]`",
            "expected hi > lo, got lo 0.03 and hi 0.021",
        ],
    ),
    (
        "unknown species in a wall",
        "species: red, axis_point_m",
        "species: green, axis_point_m",
        &["key `base.walls[0].drum.species`", "unknown species 'green'"],
    ),
    // Particles that cannot fit.
    (
        "lattice fill outside the domain",
        "lo_m: [-0.02, -0.02, 0.0], hi_m: [0.0, 0.0, 0.0064]",
        "lo_m: [0.05, -0.02, 0.0], hi_m: [0.08, 0.0, 0.0064]",
        &["key `base.fill[0].lattice`", "no particle fits"],
    ),
    (
        "drum larger than the domain",
        "radius_m: 0.02",
        "radius_m: 0.05",
        &[
            "key `base.walls[0].drum.radius_m`",
            "expected the drum inside the domain along x",
            "got -0.05 to 0.05 m",
        ],
    ),
    (
        "random fill with far too many particles",
        TIME,
        "    - random: { species: blue, count: 100000, lo_m: [-0.02, -0.02, 0.0], hi_m: [0.02, 0.02, 0.0064] }\n  time: {",
        &["key `base.fill[2].random.count`", "100000 particles", "60 % packing"],
    ),
    (
        "random fill outside the domain",
        TIME,
        "    - random: { species: blue, count: 100, lo_m: [0.04, 0.04, 0.0], hi_m: [0.06, 0.06, 0.0064] }\n  time: {",
        &["key `base.fill[2].random`", "no particle fits"],
    ),
    // The sweep.
    (
        "empty grid",
        SWEEP,
        "sweep: { grid: [] }\n",
        &["key `sweep.grid`", "expected at least one sweep, got an empty list"],
    ),
    (
        "empty list of points",
        SWEEP,
        "sweep: { list: [] }\n",
        &["key `sweep.list`", "expected at least one point, got an empty list"],
    ),
    (
        "empty values",
        "values: [20.0, 60.0]",
        "values: []",
        &[
            "key `sweep.grid[0].values`",
            "expected at least one value, got an empty list",
        ],
    ),
    (
        "axis without values",
        ", values: [20.0, 60.0]",
        "",
        &[
            "key `sweep.grid[0]`",
            "expected exactly one of `values`, `linspace`, `logspace`, found none",
        ],
    ),
    (
        "linspace with num 0",
        "values: [20.0, 60.0]",
        "linspace: { start: 10.0, stop: 60.0, num: 0 }",
        &["key `sweep.grid[0].linspace.num`", "expected at least one point, got 0"],
    ),
    (
        "logspace through 0",
        "values: [20.0, 60.0]",
        "logspace: { start: -10.0, stop: 60.0, num: 3 }",
        &[
            "key `sweep.grid[0].logspace`",
            "expected start and stop > 0",
            "got -10 and 60",
        ],
    ),
    (
        "logspace from 0",
        "values: [20.0, 60.0]",
        "logspace: { start: 0.0, stop: 60.0, num: 3 }",
        &[
            "key `sweep.grid[0].logspace`",
            "expected start and stop > 0",
            "got 0 and 60",
        ],
    ),
    (
        "string for a number in the sweep",
        "values: [20.0, 60.0]",
        "values: [20.0, fast]",
        &[
            "key `base.walls[0].drum.rotation_rpm`",
            "invalid type: string \"fast\", expected f64",
        ],
    ),
    (
        "NaN in the sweep",
        "values: [20.0, 60.0]",
        "values: [20.0, .nan]",
        &["key `sweep.grid[0].values[1]`", "expected a finite number, got NaN"],
    ),
    (
        "misspelt parameter path",
        "walls.0.drum.rotation_rpm",
        "walls.0.drum.rotaton_rpm",
        &[
            "key `sweep.grid[0].param`",
            "the scenario has no `rotaton_rpm` at `walls[0].drum`",
            "did you mean `rotation_rpm`?",
        ],
    ),
    (
        "parameter path not in the scenario",
        "walls.0.drum.rotation_rpm",
        "rotation_rpm",
        &[
            "key `sweep.grid[0].param`",
            "no `rotation_rpm` at the top level (there: cohesion, cohesion_off, contact, domain, drying, fill, gas,",
        ],
    ),
    (
        "misspelt path in a list point",
        SWEEP,
        "sweep: { list: [{ walls.0.drum.radius_m: 0.019 }, { walls.0.drum.radus_m: 0.018 }] }\n",
        &[
            "key `sweep.list[1]`",
            "no `radus_m` at `walls[0].drum`",
            "did you mean `radius_m`?",
        ],
    ),
    (
        "malformed parameter path",
        "walls.0.drum.rotation_rpm",
        "walls..drum.rotation_rpm",
        &["key `sweep.grid[0].param`", "has an empty segment"],
    ),
    (
        "list index out of range",
        "walls.0.drum.rotation_rpm",
        "walls.1.drum.rotation_rpm",
        &[
            "key `sweep.grid[0].param`",
            "`walls` has 1 element(s); index 1 is out of range",
        ],
    ),
    (
        "coordinate index out of range",
        "fill.1.lattice.hi_m.1",
        "fill.1.lattice.hi_m.3",
        &[
            "key `sweep.grid[1].zip[1].param`",
            "`fill[1].lattice.hi_m` has 3 element(s); index 3 is out of range",
        ],
    ),
    (
        "a drum at 1e30 rpm",
        "values: [20.0, 60.0]",
        "values: [20.0, 1.0e30]",
        &[
            "key `base.walls[0].drum.rotation_rpm`",
            "the drum's surface speed (2.094e27 m/s at 1.000e30 rpm)",
            "more than the smallest particle radius 1.5e-3 m",
            "expected |rotation_rpm| below 3.581e4",
            "(at sweep point walls[0].drum.rotation_rpm = 1e+30,",
        ],
    ),
    (
        "same value twice",
        "values: [20.0, 60.0]",
        "values: [20.0, 20.0]",
        &["key `sweep.grid[0].values[1]`", "got 20.0 twice (also at values[0])"],
    ),
    (
        "same value spelt twice",
        "values: [20.0, 60.0]",
        "values: [20, 20.0]",
        &[
            "key `sweep`",
            "sweep points 0 and 2 give the same job",
            "remove the duplicate",
        ],
    ),
    (
        "zip of unequal lengths",
        "values: [-0.006, 0.0] }\n        - { param: fill.1",
        "values: [-0.006] }\n        - { param: fill.1",
        &[
            "key `sweep.grid[1].zip[1]`",
            "zip expects sweeps of equal length",
            "has 1 points, this one 2",
        ],
    ),
    (
        "two kinds in one sweep node",
        "sweep:\n  grid:",
        "sweep:\n  list: [{ seed: 1 }]\n  grid:",
        &[
            "key `sweep`",
            "expected exactly one of `param`, `grid`, `zip`, `list`; found grid, list",
        ],
    ),
    (
        "values and linspace on one axis",
        "values: [20.0, 60.0]",
        "values: [20.0, 60.0], linspace: { start: 10.0, stop: 60.0, num: 2 }",
        &["key `sweep.grid[0]`", "found values, linspace"],
    ),
    (
        "one axis name for two parameters",
        "name: fill_top_m",
        "name: rotation_rpm",
        &["key `sweep`", "axis name `rotation_rpm` is given to two parameters"],
    ),
    (
        "sweeping the name",
        "walls.0.drum.rotation_rpm, name: rotation_rpm",
        "name, name: rotation_rpm",
        &["key `sweep.grid[0].param`", "cannot be swept"],
    ),
    (
        "more jobs than max_jobs",
        "seed: 7\n",
        "seed: 7\nmax_jobs: 3\n",
        &[
            "key `sweep.grid[0].values`",
            "the sweep expands into 4 jobs (its largest axis has 2 points), more than max_jobs = 3",
            "raise `max_jobs`",
        ],
    ),
    (
        "max_jobs beyond its ceiling",
        "seed: 7\n",
        "seed: 7\nmax_jobs: 100000000000\n",
        &["key `max_jobs`", "expected at most 1000000 jobs per campaign"],
    ),
    // Sweeps far too large: refused from their counts, before anything is expanded (tests/campaign_size.rs
    // measures the time and memory of such refusals).
    (
        "a grid of 1e8 points",
        "values: [20.0, 60.0]",
        "linspace: { start: 1.0, stop: 60.0, num: 50000000 }",
        &[
            AT_EDIT,
            "key `sweep.grid[0].linspace.num`",
            "the sweep expands into 100000000 jobs (its largest axis has 50000000 points), more than max_jobs = 10000",
            "raise `max_jobs` at the top level",
        ],
    ),
    (
        "a grid of 1e12 points",
        "    - { param: walls.0.drum.rotation_rpm, name: rotation_rpm, values: [20.0, 60.0] }\n",
        "    - { param: walls.0.drum.rotation_rpm, name: rotation_rpm, linspace: { start: 1.0, stop: 60.0, num: 1000000 } }\n    - { param: species.0.radius_m, linspace: { start: 0.001, stop: 0.0015, num: 500000 } }\n",
        &[
            AT_EDIT,
            "key `sweep.grid[0].linspace.num`",
            "the sweep expands into 1000000000000 jobs (its largest axis has 1000000 points)",
        ],
    ),
    (
        "a single linspace of 1e9 points",
        SWEEP,
        "sweep: { param: walls.0.drum.rotation_rpm, linspace: { start: 1.0, stop: 60.0, num: 1000000000 } }\n",
        &[
            AT_EDIT,
            "key `sweep.linspace.num`",
            "the sweep expands into 1000000000 jobs (its largest axis has 1000000000 points)",
        ],
    ),
    (
        "a single logspace of 1e9 points",
        SWEEP,
        "sweep: { param: walls.0.drum.rotation_rpm, logspace: { start: 1.0, stop: 60.0, num: 1000000000 } }\n",
        &[
            AT_EDIT,
            "key `sweep.logspace.num`",
            "the sweep expands into 1000000000 jobs (its largest axis has 1000000000 points)",
        ],
    ),
    // Metrics, analysis, executor, checkpoints, name.
    (
        "unknown metric",
        "kinetic_energy_j",
        "kinetic_energi_j",
        &[
            "key `metrics[2]`",
            "unknown metric `kinetic_energi_j`",
            "did you mean `kinetic_energy_j`?",
        ],
    ),
    (
        "metric listed twice",
        "kinetic_energy_j",
        "lacey_index",
        &["key `metrics[2]`", "metric `lacey_index` is listed twice"],
    ),
    (
        "mixing metric without mixing_species",
        "analysis: { mixing_species: red }\n",
        "",
        &["key `metrics[0]`", "`lacey_index` needs `analysis.mixing_species`"],
    ),
    // What a metric needs from the scenario (the drum has no gas, no liquid and two species).
    (
        "gas metric without a gas",
        "coordination_number]",
        "coordination_number, pressure_drop_mean_pa]",
        &["key `metrics[4]`", "`pressure_drop_mean_pa` needs a gas"],
    ),
    (
        "wet metric without liquid bridges",
        "coordination_number]",
        "coordination_number, granular_bond_number_22]",
        &["key `metrics[4]`", "`granular_bond_number_22` needs liquid bridges"],
    ),
    (
        "coating variability without a spray",
        "coordination_number]",
        "coordination_number, coating_variability]",
        &["key `metrics[4]`", "`coating_variability` needs a spray"],
    ),
    (
        "net-force metric without a gas",
        "coordination_number]",
        "coordination_number, overshoot_sidewall_friction_per_weight]",
        &[
            "key `metrics[4]`",
            "`overshoot_sidewall_friction_per_weight` needs a gas",
        ],
    ),
    (
        "wall heat metric without a heated drum",
        "coordination_number]",
        "coordination_number, wall_heat_transfer_coefficient_w_per_m2_k]",
        &[
            "key `metrics[4]`",
            "`wall_heat_transfer_coefficient_w_per_m2_k` needs one drum wall held at a temperature",
            "the scenario has 0",
        ],
    ),
    (
        "a convective ratio of a metric that is not an h_w",
        "analysis: { mixing_species: red }",
        "derived: [ { convective_to_conductive_ratio: { vacuum_param: rotation_rpm, h_w_metric: lacey_index } } ]\nanalysis: { mixing_species: red }",
        &[
            "key `derived[0].convective_to_conductive_ratio.h_w_metric`",
            "expected one of `wall_heat_transfer_coefficient_w_per_m2_k`",
            "`wall_heat_transfer_coefficient_bed_w_per_m2_k`, got `lacey_index`",
        ],
    ),
    (
        "a preparation to after the jobs' end",
        "checkpoint: { every_steps: 1000, keep: 2 }",
        "checkpoint: { every_steps: 1000, keep: 2 }\nprepare: { until_s: 0.002, shared_across: [rotation_rpm] }",
        &[
            "key `prepare.until_s`",
            "expected a time before the jobs end (time.end_time_s = 0.002 s), got 0.002 s",
        ],
    ),
    (
        "a preparation shared across an axis the sweep does not have",
        "checkpoint: { every_steps: 1000, keep: 2 }",
        "checkpoint: { every_steps: 1000, keep: 2 }\nprepare: { until_s: 0.001, shared_across: [rotation_rmp] }",
        &[
            "key `prepare.shared_across[0]`",
            "`rotation_rmp` is not a sweep axis; the sweep has",
            "rotation_rpm",
            "fill_top_m",
        ],
    ),
    (
        "a preparation of no time",
        "checkpoint: { every_steps: 1000, keep: 2 }",
        "checkpoint: { every_steps: 1000, keep: 2 }\nprepare: { until_s: -0.001, shared_across: [rotation_rpm] }",
        &["key `prepare.until_s`", "expected a time > 0 s, got -0.001"],
    ),
    (
        "heating fit after the end",
        "analysis: { mixing_species: red }",
        "analysis: { mixing_species: red, heating_fit_from_s: 0.5 }",
        &[
            "analysis.heating_fit_from_s",
            "expected 0 <= value < the end time (0.002 s), got 0.5",
        ],
    ),
    (
        "coating fit from before the start",
        "analysis: { mixing_species: red }",
        "analysis: { mixing_species: red, coating_fit_from_s: -1.0 }",
        &[
            "analysis.coating_fit_from_s",
            "expected 0 <= value < the end time (0.002 s), got -1",
        ],
    ),
    (
        "a misspelt field that the base leaves at its default (not written out)",
        "  grid:\n",
        "  grid:\n    - { param: output.net_force, values: [true] }\n",
        &[
            "key `sweep.grid[0].param`",
            "parameter `output.net_force`: the scenario has no `net_force` at `output`",
            "unknown field `net_force`, expected one of",
            "`net_forces`",
        ],
    ),
    (
        "cohesion switched off without a cohesion model",
        "  time: {",
        "  cohesion_off: { between_particles: true }\n  time: {",
        &["key `base.cohesion_off`", "expected a `cohesion` model to switch off"],
    ),
    (
        "cohesion switched off at a wall that does not exist",
        "  time: {",
        "  cohesion: { hamaker: { constant_j: 1.0e-19, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 1.0e-5 } }\n  cohesion_off: { walls: [drum, box_y_lo] }\n  time: {",
        &[
            "key `base.cohesion_off.walls[1]`",
            "no wall named 'box_y_lo'; the walls are: drum",
        ],
    ),
    (
        "cohesion switched off at a wall it does not act on",
        "  time: {",
        "  cohesion: { hamaker: { constant_j: 1.0e-19, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 1.0e-5, walls: false } }\n  cohesion_off: { walls: [drum] }\n  time: {",
        &["key `base.cohesion_off.walls[0]`", "does not act on walls"],
    ),
    (
        "net_forces not a boolean",
        "output: { series_every_steps: 50 }",
        "output: { series_every_steps: 50, net_forces: sometimes }",
        &["base.output.net_forces", "expected a boolean"],
    ),
    (
        "unknown cycle pressure reading",
        "analysis: { mixing_species: red }",
        "analysis: { mixing_species: red, cycle_pressure: first_nod }",
        &["unknown variant `first_nod`", "`column` or `first_node`"],
    ),
    (
        "unknown mixing species",
        "mixing_species: red",
        "mixing_species: green",
        &[
            "key `analysis.mixing_species`",
            "unknown species `green`; the scenario defines red, blue",
        ],
    ),
    (
        "zero threads_per_job",
        "local: { max_parallel: 2 }",
        "local: { max_parallel: 2, threads_per_job: 0 }",
        &["key `executor.local.threads_per_job`", "expected at least 1"],
    ),
    (
        "zero max_parallel",
        "local: { max_parallel: 2 }",
        "local: { max_parallel: 0 }",
        &["key `executor.local.max_parallel`", "expected at least 1"],
    ),
    (
        "negative heartbeat timeout",
        "local: { max_parallel: 2 }",
        "local: { max_parallel: 2, heartbeat_timeout_s: -1.0 }",
        &[
            "key `executor.local.heartbeat_timeout_s`",
            "expected a time > 0, got -1",
        ],
    ),
    (
        "Slurm task without cpus",
        "local: { max_parallel: 2 }",
        "slurm: { cpus_per_task: 0 }",
        &["key `executor.slurm.cpus_per_task`", "expected at least 1"],
    ),
    (
        "Slurm option granflow sets itself",
        "local: { max_parallel: 2 }",
        "slurm: { sbatch_options: [\"--array=0-9\"] }",
        &[
            "key `executor.slurm.sbatch_options[0]`",
            "--array is set by granflow itself",
        ],
    ),
    (
        "Slurm partition with a space",
        "local: { max_parallel: 2 }",
        "slurm: { partition: \"a b\" }",
        &["key `executor.slurm.partition`", "expected a word without spaces"],
    ),
    (
        "Slurm poll interval of zero",
        "local: { max_parallel: 2 }",
        "slurm: { poll_interval_s: 0.0 }",
        &["key `executor.slurm.poll_interval_s`", "expected 0.1 to 3600 s, got 0"],
    ),
    (
        "zero checkpoint.every_steps",
        "every_steps: 1000",
        "every_steps: 0",
        &["key `checkpoint.every_steps`", "expected a number of steps > 0"],
    ),
    (
        "zero checkpoint.keep",
        "keep: 2",
        "keep: 0",
        &["key `checkpoint.keep`", "expected at least 1"],
    ),
    (
        "campaign name with a path",
        "name: mini",
        "name: ../x",
        &["key `name`", "expected a name of letters, digits", "got `../x`"],
    ),
    // Named sets (`named:`, swept as `named.<set>`): the edit adds the section and an axis over it.
    (
        "unknown baffle layout name",
        "sweep:\n  grid:\n",
        "named:\n  layout:\n    straight: { walls.0.drum.baffles: [ { traditional: { count: 4, length_m: 0.006, half_thickness_m: 0.0006 } } ] }\n    angled: { walls.0.drum.baffles: [ { traditional: { count: 4, length_m: 0.006, half_thickness_m: 0.0006, tilt_deg: 30.0 } } ] }\nsweep:\n  grid:\n    - { param: named.layout, values: [straight, angld] }\n",
        &[
            "key `sweep.grid[0].values`",
            "`angld` is not a member of the named set `layout`",
            "did you mean `angled`?",
        ],
    ),
    (
        "unknown named set",
        "sweep:\n  grid:\n",
        "named:\n  layout:\n    straight: { walls.0.drum.baffles: [ { traditional: { count: 4, length_m: 0.006, half_thickness_m: 0.0006 } } ] }\nsweep:\n  grid:\n    - { param: named.layuot, values: [straight] }\n",
        &[
            "key `sweep.grid[0].param`",
            "no named set `layuot`",
            "did you mean `named.layout`?",
        ],
    ),
    (
        "baffle longer than the drum radius in a named layout",
        "sweep:\n  grid:\n",
        "named:\n  layout:\n    none: { walls.0.drum.baffles: [] }\n    long: { walls.0.drum.baffles: [ { traditional: { count: 2, length_m: 0.025, half_thickness_m: 0.0006 } } ] }\nsweep:\n  grid:\n    - { param: named.layout, values: [none, long] }\n",
        &[
            "key `base.walls[0].drum.baffles[0].length_m`",
            "a wall baffle must be shorter than the drum radius 0.02 m",
            "layout = \"long\"",
        ],
    ),
    (
        "baffle outside the drum in a named layout",
        "sweep:\n  grid:\n",
        "named:\n  layout:\n    none: { walls.0.drum.baffles: [] }\n    outside: { walls.0.drum.baffles: [ { segment: { start_m: [0.0, 0.0], end_m: [0.0, 0.03], half_thickness_m: 0.0006 } } ] }\nsweep:\n  grid:\n    - { param: named.layout, values: [none, outside] }\n",
        &[
            "key `base.walls[0].drum.baffles[0]`",
            "plate 0 reaches 0.03 m from the axis: outside the drum radius 0.02 m",
        ],
    ),
    (
        "tilted wall baffle leaving the drum",
        "rotation_rpm: 30.0 }",
        "rotation_rpm: 30.0, baffles: [ { traditional: { count: 2, length_m: 0.015, half_thickness_m: 0.0006, tilt_deg: 75.0 } } ] }",
        &["key `base.walls[0].drum.baffles[0]`", "outside the drum radius 0.02 m"],
    ),
    (
        "named member without values",
        "sweep:\n  grid:\n",
        "named:\n  layout:\n    none: {}\nsweep:\n  grid:\n    - { param: named.layout, values: [none] }\n",
        &[
            "key `named.layout.none`",
            "expected at least one parameter path and its value",
        ],
    ),
];

/// Cases whose message rightly names a line other than the edit's: the edit deleted a key, and the message names
/// the line of its parent, or of the metric that needs it; or the case lowers a limit.
const LOCATED_ELSEWHERE: &[&str] = &[
    "missing base.time",
    "missing sweep",
    "mixing metric without mixing_species",
    // Lowering max_jobs makes the sweep too large; the message names the sweep's largest axis, where a typo of a
    // few zeros would be.
    "more jobs than max_jobs",
];

/// The line of `error: bad.yaml:<line>:<column>: …`.
fn located_line(stderr: &str) -> Option<usize> {
    stderr.strip_prefix("error: bad.yaml:")?.split(':').next()?.parse().ok()
}

/// The names in `dir`.
fn listing(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .expect("read temp dir")
        .map(|e| e.expect("dir entry").file_name().to_string_lossy().into_owned())
        .collect()
}

/// Why `stderr` is not one `error: bad.yaml:<line>:<column>: …` line, if it is not.
fn shape_problem(stderr: &str) -> Option<String> {
    if stderr.lines().count() != 1 || !stderr.ends_with('\n') {
        return Some("expected exactly one line".into());
    }
    let Some(rest) = stderr.strip_prefix("error: bad.yaml:") else {
        return Some("expected it to start with `error: bad.yaml:`".into());
    };
    let mut parts = rest.splitn(3, ':');
    let numbers = (parts.next(), parts.next(), parts.next());
    match numbers {
        (Some(line), Some(column), Some(_))
            if line.parse::<usize>().is_ok_and(|l| l > 0) && column.parse::<usize>().is_ok_and(|c| c > 0) =>
        {
            None
        }
        _ => Some("expected `bad.yaml:<line>:<column>:`".into()),
    }
}

#[test]
fn bad_campaigns_fail_cleanly_before_writing_anything() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();

    // The good campaign runs, so each failure below is due to its one change.
    std::fs::write(dir.join("good.yaml"), GOOD).expect("write");
    let ok = granflow(&["run", "good.yaml", "--out", "good-out", "--quiet"], dir);
    assert!(
        ok.status.success(),
        "the good campaign fails: {}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let before = listing(dir);

    assert!(CASES.len() >= 28, "{} cases", CASES.len());
    let mut failures = Vec::new();
    for (case, from, to, fragments) in CASES {
        let Some(at) = GOOD.find(from) else {
            failures.push(format!("case '{case}': `{from}` is not in the good campaign"));
            continue;
        };
        let edit_line = GOOD[..at].matches('\n').count() + 1;
        std::fs::write(dir.join("bad.yaml"), GOOD.replacen(from, to, 1)).expect("write");
        let out = granflow(&["run", "bad.yaml", "--out", "bad-out"], dir);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let mut problems = Vec::new();
        if out.status.code() != Some(2) {
            problems.push(format!("exit code {:?}, expected 2", out.status.code()));
        }
        if let Some(p) = shape_problem(&stderr) {
            problems.push(p);
        }
        let last_edited_line = edit_line + to.lines().count().max(1) - 1;
        if let Some(line) = located_line(&stderr)
            && !LOCATED_ELSEWHERE.contains(case)
            && !(edit_line..=last_edited_line).contains(&line)
        {
            problems.push(format!(
                "located at line {line}, not at the edit (lines {edit_line}-{last_edited_line})"
            ));
        }
        for f in *fragments {
            if let Some(absent) = f.strip_prefix('!') {
                if stderr.contains(absent) {
                    problems.push(format!("has `{absent}`"));
                }
                continue;
            }
            let f = f.replace(AT_EDIT, &format!("bad.yaml:{edit_line}:"));
            if !stderr.contains(&f) {
                problems.push(format!("lacks `{f}`"));
            }
        }
        std::fs::remove_file(dir.join("bad.yaml")).expect("remove");
        let written: Vec<String> = listing(dir).difference(&before).cloned().collect();
        if !written.is_empty() {
            problems.push(format!("wrote {written:?}"));
            for name in &written {
                let p = dir.join(name);
                let _ = std::fs::remove_dir_all(&p).or_else(|_| std::fs::remove_file(&p));
            }
        }
        if !problems.is_empty() {
            failures.push(format!(
                "case '{case}': {}\n    stderr: {}",
                problems.join("; "),
                stderr.trim_end()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        CASES.len(),
        failures.join("\n")
    );
}
