//! `granflow plot` through the real binary on a small finished campaign: a phase diagram as PNG (of the stated size,
//! pixels not uniform) and SVG (holding the axis captions, the units and the parameter values as text), the paths
//! printed; and the bad requests (an unknown metric or parameter, a campaign with no finished jobs, an output path
//! that cannot be written) exit 2 with a clear message and write nothing.

mod common;

use common::{granflow_fails_with_2, granflow_ok, png_colours, svg_has};

/// A small drum campaign: 3 log-spaced speeds × 2 fill levels, 5,000 steps each.
const CAMPAIGN: &str = r#"
name: plot-mini
seed: 3
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
  time: { dt_s: 2.0e-5, end_time_s: 0.1 }
  output: { series_every_steps: 100 }
sweep:
  grid:
    - { param: walls.0.drum.rotation_rpm, name: rotation_rpm, values: [10.0, 20.0, 40.0] }
    - zip:
        - { param: fill.0.lattice.hi_m.1, name: fill_top_m, values: [-0.006, 0.0] }
        - { param: fill.1.lattice.hi_m.1, values: [-0.006, 0.0] }
metrics: [kinetic_energy_j, coordination_number, mixing_rate_constant_per_s]
analysis: { mixing_species: red }
executor: { local: { max_parallel: 2 } }
"#;

#[test]
fn a_phase_diagram_is_drawn_as_png_and_svg_and_bad_requests_exit_2() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("c.yaml"), CAMPAIGN).unwrap();
    granflow_ok(&["run", "c.yaml", "--out", "c"], dir);

    let printed = granflow_ok(
        &[
            "plot",
            "c",
            "phase",
            "--x",
            "rotation_rpm",
            "--y",
            "fill_top_m",
            "--metric",
            "kinetic_energy_j",
        ],
        dir,
    )
    .stdout;
    let files: Vec<&str> = printed.lines().collect();
    let stem = "c/plots/phase-kinetic_energy_j-rotation_rpm-fill_top_m";
    assert_eq!(files, [format!("{stem}.png"), format!("{stem}.svg")]);

    // The PNG: the stated size, and a picture (many colours), not a blank page.
    assert!(png_colours(&dir.join(files[0])) > 50);

    // The SVG: axis captions with units, the log-spaced axis said so, the parameter values, the metric's unit.
    let svg = std::fs::read_to_string(dir.join(files[1])).unwrap();
    // (plotters writes each text element's content on a line of its own.)
    for text in [
        "rotation_rpm [rpm] (log scale)",
        "fill_top_m [m]",
        "kinetic_energy_j [J]",
        "10",
        "20",
        "40",
        "-0.006",
        "0",
    ] {
        assert!(svg_has(&svg, text), "the SVG lacks the text `{text}`");
    }

    // A curve: the metric against the speed, a line per fill level; then one line averaging both fills, with the
    // two jobs' standard deviation as error bars.
    let printed = granflow_ok(
        &[
            "plot",
            "c",
            "curve",
            "--x",
            "rotation_rpm",
            "--lines",
            "fill_top_m",
            "--metric",
            "kinetic_energy_j",
        ],
        dir,
    )
    .stdout;
    let stem = "c/plots/curve-kinetic_energy_j-rotation_rpm-by-fill_top_m";
    assert_eq!(
        printed.lines().collect::<Vec<_>>(),
        [format!("{stem}.png"), format!("{stem}.svg")]
    );
    assert!(png_colours(&dir.join(format!("{stem}.png"))) > 10);
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
    for text in [
        "rotation_rpm [rpm] (log scale)",
        "kinetic_energy_j [J]",
        "fill_top_m [m] = -0.006",
        "fill_top_m [m] = 0",
        "10",
        "20",
        "40",
    ] {
        assert!(svg_has(&svg, text), "the curve's SVG lacks the text `{text}`");
    }
    granflow_ok(
        &[
            "plot",
            "c",
            "curve",
            "--x",
            "rotation_rpm",
            "--metric",
            "kinetic_energy_j",
            "--out",
            "one.svg",
        ],
        dir,
    );
    let one = std::fs::read_to_string(dir.join("one.svg")).unwrap();
    assert!(svg_has(&one, "kinetic_energy_j"), "the legend names the metric");
    // Three points, each with an error bar: more line elements than the one-line curve without bars would have.
    let lines_drawn = |svg: &str| svg.matches("<line").count() + svg.matches("<polyline").count();
    assert!(
        lines_drawn(&one) >= lines_drawn(&svg) / 2 + 3,
        "error bars drawn: {} vs {}",
        lines_drawn(&one),
        lines_drawn(&svg)
    );
    granflow_fails_with_2(
        &[
            "plot",
            "c",
            "curve",
            "--x",
            "rotation_rpm",
            "--lines",
            "rotation_rpm",
            "--metric",
            "kinetic_energy_j",
        ],
        dir,
        "two different parameters",
    );

    // A series: IS(t) of the two jobs at 40 rpm, each with the exponential its mixing rate constant was fitted
    // with; the legend's k is the stored metric's.
    let printed = granflow_ok(
        &[
            "plot",
            "c",
            "series",
            "--column",
            "intensity_of_segregation",
            "--where",
            "rotation_rpm=40",
        ],
        dir,
    )
    .stdout;
    let stem = "c/plots/series-intensity_of_segregation-rotation_rpm-40";
    assert_eq!(
        printed.lines().collect::<Vec<_>>(),
        [format!("{stem}.png"), format!("{stem}.svg")]
    );
    assert!(png_colours(&dir.join(format!("{stem}.png"))) > 10);
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
    let stored = granflow_ok(
        &[
            "query",
            "c",
            "--sql",
            "SELECT m.value FROM metrics m JOIN params p ON p.job_id = m.job_id \
             WHERE m.name = 'mixing_rate_constant_per_s' AND p.name LIKE '%rotation_rpm' AND p.value_real = 40",
            "--format",
            "csv",
        ],
        dir,
    )
    .stdout;
    let rates: Vec<f64> = stored.lines().skip(1).map(|l| l.trim().parse().unwrap()).collect();
    assert_eq!(rates.len(), 2, "{stored}");
    for text in [
        "time_s [s]",
        "intensity_of_segregation",
        "fill_top_m=-0.006",
        "fill_top_m=0.0",
    ] {
        assert!(svg_has(&svg, text), "the series SVG lacks the text `{text}`");
    }
    for rate in rates {
        let k = granflow::plot::phase_diagram::significant(rate, 3);
        assert!(
            svg.lines().any(|l| l.trim().starts_with(&format!("fit: k = {k} 1/s"))),
            "the series SVG lacks the fit with k = {k}"
        );
    }
    granflow_fails_with_2(
        &["plot", "c", "series", "--column", "intensity_of_segregaton"],
        dir,
        "has no column `intensity_of_segregaton`",
    );

    // --out with an extension writes that format only; a `where` filter narrows the jobs.
    let printed = granflow_ok(
        &[
            "plot",
            "c",
            "phase",
            "--x",
            "rotation_rpm",
            "--y",
            "fill_top_m",
            "--metric",
            "coordination_number",
            "--out",
            "mine.svg",
        ],
        dir,
    )
    .stdout;
    assert_eq!(printed.trim(), "mine.svg");
    assert!(dir.join("mine.svg").is_file() && !dir.join("mine.png").exists());

    // A classification as markers: the coordination number of the two fills at 10 rpm (two values, two shapes,
    // each named under the map); over all six cells it has six values, too many to be a classification.
    let stored = granflow_ok(
        &[
            "query",
            "c",
            "--sql",
            "SELECT m.value FROM metrics m JOIN params p USING (job_id) WHERE m.name = 'coordination_number' \
             AND p.name = 'rotation_rpm' AND p.value_real = 10.0",
            "--format",
            "csv",
        ],
        dir,
    )
    .stdout;
    let classes: Vec<f64> = stored.lines().skip(1).map(|l| l.parse().unwrap()).collect();
    assert_eq!(classes.len(), 2, "{stored}");
    let printed = granflow_ok(
        &[
            "plot",
            "c",
            "phase",
            "--x",
            "rotation_rpm",
            "--y",
            "fill_top_m",
            "--metric",
            "kinetic_energy_j",
            "--markers",
            "coordination_number",
            "--where",
            "rotation_rpm=10",
            "--out",
            "marked",
        ],
        dir,
    )
    .stdout;
    assert_eq!(printed.lines().collect::<Vec<_>>(), ["marked.png", "marked.svg"]);
    assert!(png_colours(&dir.join("marked.png")) > 50);
    let svg = std::fs::read_to_string(dir.join("marked.svg")).unwrap();
    for value in &classes {
        let text = format!(
            "coordination_number = {}",
            granflow::plot::phase_diagram::significant(*value, 3)
        );
        assert!(svg_has(&svg, &text), "the marked SVG lacks the legend `{text}`");
    }
    granflow_fails_with_2(
        &[
            "plot",
            "c",
            "phase",
            "--x",
            "rotation_rpm",
            "--y",
            "fill_top_m",
            "--metric",
            "kinetic_energy_j",
            "--markers",
            "coordination_number",
        ],
        dir,
        "`coordination_number` has 6 distinct values over these cells; markers draw a classification of at most 4",
    );
    // A fluidization cycle needs gas levels; a drum has none.
    granflow_fails_with_2(
        &["plot", "c", "fluidization", "--where", "rotation_rpm=10"],
        dir,
        "no fluidization cycle to draw",
    );

    // Bad requests: exit 2, a message naming what is wrong, nothing written.
    let before = std::fs::read_dir(dir.join("c/plots")).unwrap().count();
    granflow_fails_with_2(
        &[
            "plot",
            "c",
            "phase",
            "--x",
            "rotation_rpm",
            "--y",
            "fill_top_m",
            "--metric",
            "kinetic_energi_j",
        ],
        dir,
        "kinetic_energi_j",
    );
    granflow_fails_with_2(
        &[
            "plot",
            "c",
            "phase",
            "--x",
            "rotation_rmp",
            "--y",
            "fill_top_m",
            "--metric",
            "kinetic_energy_j",
        ],
        dir,
        "no swept parameter `rotation_rmp`",
    );
    std::fs::write(dir.join("blocker"), "a file").unwrap();
    granflow_fails_with_2(
        &[
            "plot",
            "c",
            "phase",
            "--x",
            "rotation_rpm",
            "--y",
            "fill_top_m",
            "--metric",
            "kinetic_energy_j",
            "--out",
            "blocker/diagram",
        ],
        dir,
        "cannot write blocker/diagram.png",
    );
    assert_eq!(std::fs::read_dir(dir.join("c/plots")).unwrap().count(), before);

    // A campaign with no finished job: its jobs 100 s long, the dispatcher interrupted (Ctrl-C) once they run.
    let unfinished = CAMPAIGN
        .replace("name: plot-mini", "name: plot-none")
        .replace("end_time_s: 0.1", "end_time_s: 100.0");
    std::fs::write(dir.join("none.yaml"), unfinished).unwrap();
    let mut dispatcher = std::process::Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(["run", "none.yaml", "--out", "none", "--quiet"])
        .current_dir(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("the dispatcher starts");
    let started = std::time::Instant::now();
    while !dir.join("none/jobs").is_dir() || std::fs::read_dir(dir.join("none/jobs")).unwrap().count() == 0 {
        assert!(started.elapsed().as_secs() < 120, "the campaign did not start");
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let interrupt = std::process::Command::new("kill")
        .args(["-INT", &dispatcher.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(interrupt.success());
    dispatcher.wait().expect("the dispatcher stops");
    granflow_fails_with_2(
        &[
            "plot",
            "none",
            "phase",
            "--x",
            "rotation_rpm",
            "--y",
            "fill_top_m",
            "--metric",
            "kinetic_energy_j",
        ],
        dir,
        "no job has finished yet",
    );
    assert!(!dir.join("none/plots").exists());
}
