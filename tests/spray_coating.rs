//! The spray-coating reductions through the real binary (seed 000 §6.3.2, VALIDATION F4): a wet drum sprayed from
//! 10 ms on writes CV_m of the coating mass gains as a series column; the `coating_variability_fit_*` metrics are the
//! least-squares line of that column against 1/√t, t counted from the spray's start and taken from
//! `analysis.coating_fit_from_s` on (recomputed here from the series, so a wrong clock or window fails); the last
//! row's CV_m is the `coating_variability` metric; `intensity_of_segregation_time_avg` is the mean of the IS rows
//! from `analysis.average_from_s`.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::{granflow_ok, only_job_series};

const SPRAY_START_S: f64 = 0.01;
const FIT_FROM_S: f64 = 0.005;
const AVERAGE_FROM_S: f64 = 0.02;

fn campaign() -> String {
    format!(
        r#"name: sprayed-drum
base:
  domain: {{ lo_m: [-0.041, -0.041, 0.0], hi_m: [0.041, 0.041, 0.012], periodic: [false, false, true] }}
  gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
  species:
    - {{ name: a, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.3, friction_coefficient: 0.4, contact_angle_deg: 0.0 }}
    - {{ name: b, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.3, friction_coefficient: 0.4, contact_angle_deg: 30.0 }}
  contact: {{ normal: {{ hertz: {{ restitution: 0.6 }} }}, tangential: mindlin }}
  cohesion: {{ liquid_bridge: {{ surface_tension_n_per_m: 0.02, viscosity_pa_s: 0.001, spray: {{ max_liquid_content: 0.02, start_s: {SPRAY_START_S} }} }} }}
  walls:
    - drum: {{ name: drum, species: a, axis_point_m: [0.0, 0.0, 0.0], axis: [0.0, 0.0, 1.0], radius_m: 0.04, rotation_rpm: 120.0 }}
  fill:
    - lattice: {{ species: a, spacing_m: 0.0032, lo_m: [-0.04, -0.04, 0.0], hi_m: [-0.001, 0.0, 0.0105], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }}
    - lattice: {{ species: b, spacing_m: 0.0032, lo_m: [0.0, -0.04, 0.0], hi_m: [0.04, 0.0, 0.0105], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }}
  time: {{ dt_s: 1.0e-5, end_time_s: 0.04 }}
  output: {{ series_every_steps: 100 }}
sweep:
  param: seed
  values: [1]
metrics: [coating_variability, coating_variability_fit_slope_sqrt_s, coating_variability_fit_intercept, coating_variability_fit_intercept_std_error, coating_variability_fit_r_squared, intensity_of_segregation_time_avg]
analysis: {{ mixing_species: a, mixing_every_steps: 500, average_from_s: {AVERAGE_FROM_S}, coating_fit_from_s: {FIT_FROM_S} }}
"#
    )
}

fn metrics(out: &Path) -> BTreeMap<String, f64> {
    let csv = granflow_ok(
        &[
            "query",
            out.to_str().unwrap(),
            "--sql",
            "SELECT name, value FROM metrics",
            "--format",
            "csv",
        ],
        out.parent().unwrap(),
    )
    .stdout;
    csv.lines()
        .skip(1)
        .map(|l| {
            let (name, value) = l.split_once(',').unwrap();
            (name.to_string(), value.trim().parse().unwrap_or(f64::NAN))
        })
        .collect()
}

#[test]
fn the_coating_line_and_the_time_averaged_segregation_come_from_the_series() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("sprayed.yaml");
    std::fs::write(&file, campaign()).unwrap();
    let out = tmp.path().join("out");
    granflow_ok(
        &["run", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"],
        tmp.path(),
    );
    let s = only_job_series(&out);
    let m = metrics(&out);
    let (t, cv) = (&s["time_s"], &s["coating_variability"]);
    // Before the spray nothing is gained: CV_m is undefined; after it, the sprayed surface stands out.
    for (k, &time) in t.iter().enumerate() {
        if time < SPRAY_START_S - 1e-9 {
            assert!(
                cv[k].is_nan() && s["sprayed_m3"][k] == 0.0,
                "row at {time} s: {}",
                cv[k]
            );
        }
    }
    assert!(cv.last().unwrap() > &0.2, "CV_m at the end: {}", cv.last().unwrap());
    assert_eq!(m["coating_variability"], *cv.last().unwrap());
    // The line, recomputed from the rows with coating time ≥ FIT_FROM_S.
    let (x, y): (Vec<f64>, Vec<f64>) = t
        .iter()
        .zip(cv)
        .map(|(t, cv)| (t - SPRAY_START_S, *cv))
        .filter(|(tc, _)| *tc >= FIT_FROM_S)
        .map(|(tc, cv)| (1.0 / tc.sqrt(), cv))
        .unzip();
    assert!(x.len() >= 20, "{} rows in the fit", x.len());
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(&y).map(|(x, y)| (x - mx) * (y - my)).sum();
    let syy: f64 = y.iter().map(|y| (y - my).powi(2)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let residual: f64 = x.iter().zip(&y).map(|(x, y)| (y - intercept - slope * x).powi(2)).sum();
    let std_error = (residual / (n - 2.0) * (1.0 / n + mx * mx / sxx)).sqrt();
    let close = |name: &str, expected: f64| {
        let got = m[name];
        assert!(
            (got - expected).abs() <= 1e-6 * expected.abs().max(1e-12),
            "{name}: stored {got}, from the series {expected}"
        );
    };
    close("coating_variability_fit_slope_sqrt_s", slope);
    close("coating_variability_fit_intercept", intercept);
    close("coating_variability_fit_intercept_std_error", std_error);
    close("coating_variability_fit_r_squared", sxy * sxy / (sxx * syy));
    // IS averaged over its sampled rows from AVERAGE_FROM_S.
    let samples: Vec<f64> = t
        .iter()
        .zip(&s["intensity_of_segregation"])
        .filter(|(t, is)| **t >= AVERAGE_FROM_S && is.is_finite())
        .map(|(_, is)| *is)
        .collect();
    assert!(samples.len() >= 3, "{} IS samples", samples.len());
    close(
        "intensity_of_segregation_time_avg",
        samples.iter().sum::<f64>() / samples.len() as f64,
    );
}
