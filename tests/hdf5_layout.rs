//! The HDF5 files granflow writes, read with h5py using only their documented layout (`schemas/checkpoint.md`,
//! `schemas/series.md`): a campaign job's final checkpoint and its `series.h5` give the same particles, gas,
//! ledger and time series as granflow's own reader and `series.csv`.

mod common;

use std::path::Path;
use std::process::Command;

use common::{granflow, wet_drying_kiln};
use serde_json::Value;

/// Reads `ckpt` and `series` as the documents describe them and prints what it found as JSON.
const H5PY_READ: &str = r#"
import json, sys
import h5py
ckpt, series = sys.argv[1], sys.argv[2]
out = {}
with h5py.File(ckpt, "r") as f:
    a = f.attrs
    out["format"] = str(a["format"])
    out["format_version"] = int(a["format_version"])
    out["step"] = int(a["step"])
    out["time_s"] = float(a["time_s"])
    x = f["/particles/position_m"][:]
    out["particles"] = list(x.shape)
    out["position_units"] = str(f["/particles/position_m"].attrs["units"])
    out["mean_x_m"] = [float(v) for v in x.mean(axis=0)]
    out["temperature_k"] = [float(v) for v in f["/particles/temperature_k"][:]]
    out["liquid_m3"] = float(f["/particles/liquid_m3"][:].sum())
    out["bridge_volume_m3"] = float(f["/contacts/pairs/bridge_volume_m3"][:].sum() + f["/contacts/walls/bridge_volume_m3"][:].sum())
    out["gas_temperature_k"] = [float(v) for v in f["/gas/temperature_k"][:]]
    out["vapour_mass_fraction_max"] = float(f["/gas/vapour_mass_fraction"][:].max())
    out["initial_energy_j"] = float(f["/heat_ledger/initial_energy_j"][0])
with h5py.File(series, "r") as f:
    out["series_format"] = str(f.attrs["format"])
    out["series_columns"] = sorted(f.keys())
    out["series_time_s"] = [float(v) for v in f["time_s"][:]]
    out["series_mean_temperature_k"] = [float(v) for v in f["mean_temperature_k"][:]]
    out["series_units"] = {k: str(f[k].attrs["units"]) for k in ("time_s", "mean_temperature_k", "evaporated_kg", "pair_contacts")}
print(json.dumps(out))
"#;

fn h5py_read(ckpt: &Path, series: &Path) -> Value {
    let out = Command::new("/usr/bin/python3")
        .args(["-c", H5PY_READ])
        .arg(ckpt)
        .arg(series)
        .output()
        .expect("python3 runs (Debian's, with python3-h5py)");
    assert!(
        out.status.success(),
        "h5py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the reader prints JSON")
}

/// Equal bit for bit (through Python's shortest decimal form, read back exactly: serde_json's `float_roundtrip`).
fn same(a: &[f64], b: &[f64], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert_eq!(x.to_bits(), y.to_bits(), "{what}[{k}]: {x} vs {y}");
    }
}

/// One job: the wet, heated, drying kiln for 0.01 s.
fn campaign() -> String {
    let base: String = wet_drying_kiln()
        .replace("end_time_s: 0.2 }", "end_time_s: 0.01 }")
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("name:"))
        .map(|l| format!("  {l}\n"))
        .collect();
    format!(
        "name: layout\nseed: 3\nbase:\n{base}  output: {{ series_every_steps: 100 }}\nsweep:\n  grid:\n    - {{ param: \
         walls.0.drum.rotation_rpm, name: rotation_rpm, values: [30.0] }}\nmetrics: [kinetic_energy_j]\n"
    )
}

#[test]
fn h5py_reads_a_checkpoint_and_a_series_by_their_documented_layout() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("layout.yaml"), campaign()).unwrap();
    let out = granflow(&["run", "layout.yaml", "--out", "c", "--quiet"], dir.path());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let jobs: Vec<_> = std::fs::read_dir(dir.path().join("c/jobs")).unwrap().collect();
    assert_eq!(jobs.len(), 1);
    let job = jobs.into_iter().next().unwrap().unwrap().path();
    let loaded = granflow::checkpoint::CheckpointSeries::new(&job, 2)
        .latest_valid()
        .unwrap()
        .expect("a final checkpoint");
    let state = loaded.state;
    let read = h5py_read(&loaded.path, &job.join("series.h5"));

    assert_eq!(read["format"], "granflow-checkpoint");
    assert_eq!(read["format_version"], 10);
    assert_eq!(read["step"].as_u64().unwrap(), state.step);
    assert_eq!(read["time_s"].as_f64().unwrap(), state.time_s);
    assert_eq!(read["particles"], serde_json::json!([state.particles.len(), 3]));
    assert_eq!(read["position_units"], "m");
    let n = state.particles.len() as f64;
    for axis in 0..3 {
        let mean: f64 = state.particles.position_m.iter().map(|x| x[axis]).sum::<f64>() / n;
        let got = read["mean_x_m"][axis].as_f64().unwrap();
        assert!(
            (got - mean).abs() <= 1e-12 * (1.0 + mean.abs()),
            "axis {axis}: {got} vs {mean}"
        );
    }
    let temperatures: Vec<f64> = read["temperature_k"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    same(&temperatures, &state.particles.temperature_k, "particle temperatures");
    let liquid: f64 = state.particles.liquid_m3.iter().sum();
    assert!((read["liquid_m3"].as_f64().unwrap() / liquid - 1.0).abs() < 1e-12);
    assert!(
        read["bridge_volume_m3"].as_f64().unwrap() > 0.0,
        "the wet beads hold bridges"
    );
    let gas = state.gas.as_ref().unwrap();
    let gas_temperature = &gas.scalars.iter().find(|s| s.name == "temperature_k").unwrap().value;
    let read_gas: Vec<f64> = read["gas_temperature_k"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    same(&read_gas, gas_temperature, "gas temperatures");
    assert!(
        read["vapour_mass_fraction_max"].as_f64().unwrap() > 0.0,
        "vapour has formed"
    );
    assert_eq!(
        read["initial_energy_j"].as_f64().unwrap(),
        state.heat_ledger.unwrap().initial_energy_j
    );

    // series.h5 against series.csv.
    assert_eq!(read["series_format"], "granflow-series");
    let csv = std::fs::read_to_string(job.join("series.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut columns: Vec<String> = header.iter().map(|s| s.to_string()).collect();
    columns.sort();
    let read_columns: Vec<String> = read["series_columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    assert_eq!(read_columns, columns);
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 6, "t = 0, 2, …, 10 ms (500 steps, a row every 100)");
    for (name, key) in [
        ("time_s", "series_time_s"),
        ("mean_temperature_k", "series_mean_temperature_k"),
    ] {
        let k = header.iter().position(|h| *h == name).unwrap();
        let from_csv: Vec<f64> = rows.iter().map(|r| r[k]).collect();
        let from_h5: Vec<f64> = read[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        same(&from_h5, &from_csv, name);
    }
    assert_eq!(
        read["series_units"],
        serde_json::json!({"time_s": "s", "mean_temperature_k": "K", "evaporated_kg": "kg", "pair_contacts": "count"})
    );
}
