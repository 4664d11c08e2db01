//! Snapshots for ParaView, read back by VTK's own XML readers (Debian's `python3-vtk9`, the readers ParaView uses):
//! the particle count, the fields' ranges and the number of time steps equal what granflow holds; snapshots made
//! afterwards from the checkpoints are the same bytes as those written during the run; a resumed run's index lists
//! every snapshot once.

mod common;

use std::path::Path;
use std::process::Command;

use common::{final_state, granflow_ok, wet_drying_kiln};
use serde_json::Value;

/// Reads each index (`particles.pvd`, `gas.pvd`) and every file it lists with VTK's readers; prints, per index, one
/// entry per dataset: its time, its point (particles) or cell (gas) count, each array's range (component 0 of a
/// scalar, the magnitude of a vector) and the `TimeValue` the file carries.
const VTK_READ: &str = r#"
import json, os, sys
import xml.etree.ElementTree as ET
import vtk
d = sys.argv[1]
out = {}
for index, reader, particles in (("particles.pvd", vtk.vtkXMLUnstructuredGridReader, True),
                                 ("gas.pvd", vtk.vtkXMLImageDataReader, False)):
    entries = []
    for s in ET.parse(os.path.join(d, index)).getroot().find("Collection").findall("DataSet"):
        r = reader()
        r.SetFileName(os.path.join(d, s.get("file")))
        r.Update()
        o = r.GetOutput()
        data = o.GetPointData() if particles else o.GetCellData()
        ranges = {}
        for i in range(data.GetNumberOfArrays()):
            a = data.GetArray(i)
            ranges[a.GetName()] = list(a.GetRange(0 if a.GetNumberOfComponents() == 1 else -1))
        entries.append({
            "time_s": float(s.get("timestep")),
            "count": o.GetNumberOfPoints() if particles else o.GetNumberOfCells(),
            "ranges": ranges,
            "time_value": o.GetFieldData().GetArray("TimeValue").GetValue(0),
        })
    out[index] = entries
print(json.dumps(out))
"#;

fn vtk_read(dir: &Path) -> Value {
    let out = Command::new("/usr/bin/python3")
        .args(["-c", VTK_READ])
        .arg(dir)
        .output()
        .expect("python3 runs (Debian's, with python3-vtk9: `apt-get install python3-vtk9`)");
    assert!(
        out.status.success(),
        "VTK's readers failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the reader prints JSON")
}

fn range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

/// The wet, heated, drying kiln for 0.02 s with a snapshot every 5 ms.
fn scenario() -> String {
    wet_drying_kiln().replace("end_time_s: 0.2 }", "end_time_s: 0.02 }")
        + "output: { checkpoint_every_steps: 500, keep_checkpoints: 5, snapshots_every_s: 0.005 }\n"
}

#[test]
fn snapshots_read_back_in_vtk_with_the_counts_ranges_and_times_granflow_holds() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("kiln.yaml"), scenario()).unwrap();
    granflow_ok(&["simulate", "kiln.yaml", "--out", "run", "--quiet"], dir.path());
    let run = dir.path().join("run");
    let state = final_state(&run);
    let read = vtk_read(&run.join("snapshots"));

    let particles = read["particles.pvd"].as_array().expect("entries");
    let gas = read["gas.pvd"].as_array().expect("entries");
    assert_eq!(particles.len(), 5, "t = 0, 5, 10, 15, 20 ms");
    assert_eq!(gas.len(), 5);
    for (k, entry) in particles.iter().chain(gas).enumerate() {
        let t = entry["time_s"].as_f64().unwrap();
        assert!((t - 0.005 * (k % 5) as f64).abs() < 1e-12, "entry {k}: t = {t}");
        assert_eq!(entry["time_value"].as_f64().unwrap(), t);
    }
    let last = &particles[4];
    assert_eq!(last["count"].as_u64().unwrap(), state.particles.len() as u64);
    let p = &state.particles;
    for (name, expected) in [
        ("temperature_k", range(p.temperature_k.iter().copied())),
        ("liquid_m3", range(p.liquid_m3.iter().copied())),
        ("radius_m", range(p.radius_m.iter().copied())),
        ("velocity_m_per_s", range(p.velocity_m_per_s.iter().map(|v| v.norm()))),
        ("id", range(p.id.iter().map(|id| f64::from(id.0)))),
    ] {
        let got = &last["ranges"][name];
        let lo = got[0]
            .as_f64()
            .unwrap_or_else(|| panic!("{name} in the particles' snapshot"));
        let hi = got[1].as_f64().unwrap();
        assert!(
            (lo - expected.0).abs() <= 1e-12 * expected.0.abs() && (hi - expected.1).abs() <= 1e-12 * expected.1.abs(),
            "{name}: VTK reads {lo}..{hi}, granflow holds {expected:?}"
        );
    }
    let gas_state = state.gas.as_ref().expect("a gas");
    assert_eq!(gas[4]["count"].as_u64().unwrap(), gas_state.porosity.len() as u64);
    let gas_temperature = gas_state
        .scalars
        .iter()
        .find(|s| s.name == "temperature_k")
        .expect("a gas temperature");
    let expected = range(gas_temperature.value.iter().copied());
    assert_eq!(
        (
            gas[4]["ranges"]["temperature_k"][0].as_f64().unwrap(),
            gas[4]["ranges"]["temperature_k"][1].as_f64().unwrap()
        ),
        expected
    );
    assert!(expected.1 > expected.0, "the gas has warmed unevenly: {expected:?}");
    for field in [
        "porosity",
        "pressure_pa",
        "velocity_m_per_s",
        "blocked",
        "vapour_mass_fraction",
    ] {
        assert!(gas[4]["ranges"].get(field).is_some(), "{field} in the gas's snapshot");
    }

    // The same snapshots made afterwards from the checkpoints: the same bytes.
    granflow_ok(&["snapshots", "run", "--out", "again"], dir.path());
    let mut compared = 0;
    for entry in std::fs::read_dir(dir.path().join("again")).unwrap() {
        let name = entry.unwrap().file_name();
        let name = name.to_str().unwrap();
        if name.ends_with(".vtu") || name.ends_with(".vti") {
            let again = std::fs::read(dir.path().join("again").join(name)).unwrap();
            let during = std::fs::read(run.join("snapshots").join(name)).unwrap();
            assert!(again == during, "{name} differs");
            compared += 1;
        }
    }
    assert_eq!(
        compared,
        2 * 3,
        "checkpoints at steps 0, 500 and 1000 (both kept and snapshotted)"
    );
}

#[test]
fn a_resumed_run_lists_every_snapshot_once_with_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("kiln.yaml"), scenario()).unwrap();
    granflow_ok(&["simulate", "kiln.yaml", "--out", "whole", "--quiet"], dir.path());
    granflow_ok(
        &[
            "simulate",
            "kiln.yaml",
            "--out",
            "split",
            "--max-steps",
            "600",
            "--quiet",
        ],
        dir.path(),
    );
    // As if killed after the snapshot at step 750 (written) but before any later checkpoint.
    granflow_ok(
        &[
            "simulate",
            "kiln.yaml",
            "--out",
            "split-ahead",
            "--max-steps",
            "750",
            "--quiet",
        ],
        dir.path(),
    );
    for name in [
        "particles_000000000750.vtu",
        "gas_000000000750.vti",
        "particles.pvd",
        "gas.pvd",
    ] {
        std::fs::copy(
            dir.path().join("split-ahead/snapshots").join(name),
            dir.path().join("split/snapshots").join(name),
        )
        .unwrap();
    }
    granflow_ok(&["simulate", "kiln.yaml", "--out", "split", "--quiet"], dir.path());
    for name in [
        "particles.pvd",
        "gas.pvd",
        "particles_000000001000.vtu",
        "gas_000000000750.vti",
    ] {
        let whole = std::fs::read(dir.path().join("whole/snapshots").join(name)).unwrap();
        let split = std::fs::read(dir.path().join("split/snapshots").join(name)).unwrap();
        assert!(whole == split, "{name} differs between the whole and the resumed run");
    }
}
