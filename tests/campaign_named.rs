//! Named sets of values (`named:` in a campaign file, swept as `named.<set>`): two baffle layouts taken by name give
//! exactly the jobs, the drums and the results that the same two baffle lists written out in the sweep give (same
//! ids, seeds and scenarios; final states equal bit for bit), and the database stores the layout by its name.

mod common;

use std::path::Path;

use common::{drum_slice_base, final_state, granflow_ok};
use granflow::engine::state::first_difference;

const STRAIGHT: &str = "[ { traditional: { count: 4, length_m: 0.006, half_thickness_m: 0.0006 } } ]";
const AXIAL: &str = "[ { axial: { count: 3, length_m: 0.008, half_thickness_m: 0.0006, inner_radius_m: 0.002 } } ]";

/// A drum slice of red and blue beads at two speeds; `layouts` is the section that sets the baffles (a `named:`
/// section and its sweep axis, or the axis with the lists written out).
fn campaign(named: &str, layout_axis: &str) -> String {
    let base = drum_slice_base(-0.004, 0.04, 100);
    format!(
        r#"name: layouts
seed: 7
{base}{named}sweep:
  grid:
    - {layout_axis}
    - {{ param: walls.0.drum.rotation_rpm, name: rotation_rpm, values: [20.0, 60.0] }}
metrics: [lacey_index, kinetic_energy_j]
analysis: {{ mixing_species: red }}
executor: {{ local: {{ max_parallel: 2 }} }}
checkpoint: {{ every_steps: 500, keep: 2 }}
"#
    )
}

fn by_name() -> String {
    campaign(
        &format!(
            "named:\n  layout:\n    straight: {{ walls.0.drum.baffles: {STRAIGHT} }}\n    three_axial:\n      walls[0].drum.baffles: {AXIAL}\n"
        ),
        "{ param: named.layout, values: [straight, three_axial] }",
    )
}

fn written_out() -> String {
    campaign(
        "",
        &format!("{{ param: walls.0.drum.baffles, name: layout, values: [{STRAIGHT}, {AXIAL}] }}"),
    )
}

#[test]
fn layouts_taken_by_name_are_the_layouts_written_out_bit_for_bit() {
    let path = Path::new("layouts.yaml");
    let named = granflow::campaign::from_yaml(&by_name(), path).expect("the named campaign is valid");
    let written = granflow::campaign::from_yaml(&written_out(), path).expect("the written-out campaign is valid");
    assert_eq!(named.jobs.len(), 4);
    for (a, b) in named.jobs.iter().zip(&written.jobs) {
        assert_eq!(a.job_id, b.job_id, "{:?} against {:?}", a.params, b.params);
        assert_eq!(a.scenario, b.scenario);
        assert_eq!(a.scenario.seed, b.scenario.seed);
    }
    assert_eq!(named.label(&named.jobs[2]), "layout=\"three_axial\", rotation_rpm=20.0");
    // Two different drums: the names did reach the scenario.
    assert_ne!(named.jobs[0].scenario, named.jobs[2].scenario);

    let tmp = tempfile::tempdir().unwrap();
    let mut outs = Vec::new();
    for (name, text) in [("named", by_name()), ("written", written_out())] {
        let file = tmp.path().join(format!("{name}.yaml"));
        std::fs::write(&file, text).unwrap();
        let out = tmp.path().join(name);
        granflow_ok(
            &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
            tmp.path(),
        );
        outs.push(out);
    }
    for job in &named.jobs {
        let (a, b) = (
            outs[0].join("jobs").join(&job.job_id),
            outs[1].join("jobs").join(&job.job_id),
        );
        assert_eq!(
            first_difference(&final_state(&a), &final_state(&b)),
            None,
            "job {}",
            job.job_id
        );
        let series = |d: &Path| std::fs::read_to_string(d.join("series.csv")).unwrap();
        assert_eq!(series(&a), series(&b), "job {}", job.job_id);
    }

    // The layout is stored under the set's name, by member name, and pivots like any axis.
    let pivot = granflow_ok(
        &[
            "query",
            outs[0].to_str().unwrap(),
            "--pivot",
            "layout",
            "rotation_rpm",
            "--metric",
            "kinetic_energy_j",
            "--format",
            "csv",
        ],
        tmp.path(),
    )
    .stdout;
    let rows: Vec<&str> = pivot.lines().collect();
    assert_eq!(rows.len(), 3, "a header and one row per rotation speed:\n{pivot}");
    assert!(
        rows[0].contains("straight") && rows[0].contains("three_axial"),
        "{pivot}"
    );
}
