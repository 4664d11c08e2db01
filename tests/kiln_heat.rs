//! The wall heat transfer coefficient h_w of a heated drum (seed 000 §5.2.4) through the whole product: a small
//! kiln run as a campaign records its core temperatures and contact arc in the series, and the worker turns them
//! into h_w (of the core, the inner core and the whole bed), the log slopes, the contact arc and time, and the
//! convective/conductive ratio of an air and a vacuum run. (The fit itself is checked against Ito's relation in `analysis::wall_heat`'s unit tests; E5 is the
//! seed's kiln, `campaigns/validation/e5-kiln-heat-transfer.yaml`.)

mod common;

use std::collections::BTreeMap;

use common::granflow;

/// A drum of radius 20 mm turning at 30 rpm, a slice 2 diameters long, aluminium (Table 7) filled to about a third,
/// the wall at 400 K from 0.1 s; air and vacuum.
const CAMPAIGN: &str = r#"
name: small-kiln
seed: 3
base:
  domain: { lo_m: [-0.021, -0.021, 0.0], hi_m: [0.021, 0.021, 0.0062], periodic: [false, false, true] }
  gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
  species:
    - { name: bed, material: aluminium, radius_m: 0.0015, youngs_modulus_pa: 1.0e7 }
  contact: { normal: { hertz: { restitution: 0.7 } }, tangential: mindlin }
  walls:
    - drum: { name: drum, species: bed, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: 0.02, rotation_rpm: 30.0 }
  fill:
    - lattice: { species: bed, spacing_m: 0.0031, lo_m: [-0.02, -0.02, 0.0], hi_m: [0.02, -0.004, 0.0062], origin_m: [0.0, 0.0, 0.00155], inside_drum: drum }
  time: { dt_s: 2.0e-5, end_time_s: 0.6 }
  gas:
    density_kg_per_m3: 1.23
    viscosity_pa_s: 1.8e-5
    cells: [10, 10, 1]
    outside_drum: drum
    drag_coupling: semi_implicit
    dem_steps_per_gas_step: 50
  heat:
    initial_temperature_k: 300.0
    walls: { drum: { temperature_k: 400.0, from_s: 0.1 } }
  output: { series_every_steps: 500 }
sweep:
  param: gas.vacuum
  name: vacuum
  values: [false, true]
metrics:
  - wall_heat_transfer_coefficient_w_per_m2_k
  - wall_heat_transfer_coefficient_inner_core_w_per_m2_k
  - wall_heat_transfer_coefficient_bed_w_per_m2_k
  - core_heating_slope_per_s
  - bed_heating_slope_per_s
  - drum_contact_arc_rad
  - drum_wall_contact_time_s
  - mean_temperature_k
derived:
  - convective_to_conductive_ratio: { vacuum_param: vacuum, h_w_metric: wall_heat_transfer_coefficient_bed_w_per_m2_k }
executor: { local: { max_parallel: 2 } }
checkpoint: { every_steps: 10000 }
"#;

#[test]
fn a_heated_drum_campaign_reduces_h_w_and_the_convective_ratio() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("kiln.yaml"), CAMPAIGN).expect("write");
    let run = granflow(&["run", "kiln.yaml", "--out", "out"], dir);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let export = granflow(&["export", "out", "--format", "csv"], dir);
    let text = String::from_utf8(export.stdout).expect("utf-8");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    // metric name -> value, per vacuum flag.
    let mut jobs: BTreeMap<String, BTreeMap<String, f64>> = BTreeMap::new();
    for line in lines {
        let fields: Vec<&str> = line.split(',').collect();
        let get = |prefix: &str| header.iter().position(|h| h.starts_with(prefix)).map(|k| fields[k]);
        let vacuum = get("param.vacuum").expect("the vacuum column").to_string();
        let metrics = header
            .iter()
            .zip(&fields)
            .filter_map(|(h, v)| {
                let name = h.strip_prefix("metric.")?.split(' ').next()?;
                Some((name.to_string(), v.parse::<f64>().unwrap_or(f64::NAN)))
            })
            .collect();
        jobs.insert(vacuum, metrics);
    }
    println!("{jobs:#?}");
    let omega = 30.0 * std::f64::consts::TAU / 60.0;
    for (vacuum, m) in &jobs {
        let h_w = m["wall_heat_transfer_coefficient_w_per_m2_k"];
        let arc = m["drum_contact_arc_rad"];
        assert!(h_w.is_finite() && h_w > 0.0, "vacuum {vacuum}: h_w {h_w}");
        assert!(m["core_heating_slope_per_s"] < 0.0, "vacuum {vacuum}: the core warms");
        assert!(m["wall_heat_transfer_coefficient_inner_core_w_per_m2_k"].is_finite());
        // The bed (a third of the drum, lattice below y = -4 mm) touches about 2.3 rad of wall.
        assert!(arc > 1.6 && arc < 3.0, "vacuum {vacuum}: arc {arc}");
        assert!((m["drum_wall_contact_time_s"] - arc / omega).abs() < 1e-12 * arc / omega);
        assert!(m["mean_temperature_k"] > 300.0 && m["mean_temperature_k"] < 400.0);
        // With the whole bed as the core the fit is the bed's energy balance: its slope carries the mean
        // temperature from 300 K at the wall's start (0.1 s) to the end's (0.6 s), within the free intercept.
        let bed_slope = m["bed_heating_slope_per_s"];
        let end_slope = ((400.0 - m["mean_temperature_k"]) / 100.0).ln() / 0.5;
        assert!(
            (bed_slope / end_slope - 1.0).abs() < 0.15,
            "vacuum {vacuum}: bed slope {bed_slope}, from the end temperature {end_slope}"
        );
        assert!(m["wall_heat_transfer_coefficient_bed_w_per_m2_k"] > 0.0);
    }
    let ratio = granflow(
        &[
            "query",
            "out",
            "--sql",
            "SELECT value FROM derived WHERE name = 'convective_to_conductive_ratio'",
            "--format",
            "csv",
        ],
        dir,
    );
    let text = String::from_utf8(ratio.stdout).expect("utf-8");
    let value: f64 = text.lines().nth(1).expect("one derived row").parse().expect("a number");
    let (air, vacuum) = (
        jobs["false"]["wall_heat_transfer_coefficient_bed_w_per_m2_k"],
        jobs["true"]["wall_heat_transfer_coefficient_bed_w_per_m2_k"],
    );
    assert!(
        (value - (air - vacuum) / vacuum).abs() < 1e-9 * value.abs().max(1e-12),
        "{value}"
    );
}
