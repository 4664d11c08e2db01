//! Snapshots for ParaView: the particles and the gas of a run at chosen times, as VTK XML files with a time-series
//! index, so that File → Open of `snapshots/particles.pvd` (and `gas.pvd`) shows the whole run.
//!
//! - Particles (`particles_<step>.vtu`): one vertex per particle at its centre, with `id`, `species`, `radius_m`,
//!   `velocity_m_per_s`, and whichever of `angular_velocity_rad_per_s` (a run with rotation), `liquid_m3` (liquid
//!   bridges: the particle's own film, not its bridges' liquid) and `temperature_k` (heat) the run has. In ParaView,
//!   the "Point Gaussian" representation with `radius_m` as its scale array (scale factor 1) draws the spheres.
//! - Gas (`gas_<step>.vti`, a run with a gas): its grid's cells with `porosity`, `pressure_pa`, `velocity_m_per_s`
//!   (the staggered faces' velocities averaged onto the cell centres), `blocked` (1 where no gas flows: a drum's
//!   outside, a blocked region) and each transported scalar by its name (`temperature_k`, `vapour_mass_fraction`).
//! - `particles.pvd`, `gas.pvd`: the time of each file, in step order.
//!
//! Snapshots are written during a run every `output.snapshots_every_s` (and at its start and end), or afterwards
//! from the checkpoints a run kept (`granflow snapshots <dir>`). Every file is written through a temporary file and
//! renamed into place; an index lists only files already complete, and a resumed run rewrites the entries past its
//! checkpoint (identical, as the run is bit-exact on restart). Snapshots are output only: the run never reads them.

pub mod vtk_xml;

use std::path::{Path, PathBuf};

use vtk_xml::DataArray;

use crate::checkpoint::CheckpointSeries;
use crate::engine::Simulation;
use crate::engine::gas::coupled::GasCoupling;
use crate::engine::models::cohesion_law::CohesionModel;
use crate::error::Error;
use crate::util::write_atomic;

/// The snapshots' directory inside a run's (or job's) directory.
pub const SNAPSHOT_DIR: &str = "snapshots";
/// The particles' time-series index.
pub const PARTICLES_INDEX: &str = "particles.pvd";
/// The gas's time-series index.
pub const GAS_INDEX: &str = "gas.pvd";

/// The particles' arrays (see the module's documentation for which).
pub fn particle_arrays(sim: &Simulation) -> Vec<DataArray> {
    let p = &sim.particles;
    let vectors = |v: &[crate::engine::Vec3]| v.iter().flat_map(|x| [x.x, x.y, x.z]).collect::<Vec<f64>>();
    let mut arrays = vec![
        DataArray::i64("id", p.id.iter().map(|id| i64::from(id.0))),
        DataArray::i64("species", p.species.iter().map(|s| s.index() as i64)),
        DataArray::f64("radius_m", 1, p.radius_m.iter().copied()),
        DataArray::f64("velocity_m_per_s", 3, vectors(&p.velocity_m_per_s)),
    ];
    if sim.config.rotation {
        arrays.push(DataArray::f64(
            "angular_velocity_rad_per_s",
            3,
            vectors(&p.angular_velocity_rad_per_s),
        ));
    }
    if sim
        .config
        .cohesion
        .as_ref()
        .is_some_and(|c| matches!(c.model, CohesionModel::LiquidBridge(_)))
    {
        arrays.push(DataArray::f64("liquid_m3", 1, p.liquid_m3.iter().copied()));
    }
    if sim.config.heat.is_some() {
        arrays.push(DataArray::f64("temperature_k", 1, p.temperature_k.iter().copied()));
    }
    arrays
}

/// The gas's cell arrays (see the module's documentation for which).
pub fn gas_arrays(gas: &GasCoupling) -> Vec<DataArray> {
    let grid = &gas.solver.config.grid;
    let state = &gas.solver.state;
    let mut velocity = Vec::with_capacity(3 * grid.cells());
    for k in 0..grid.n[2] {
        for j in 0..grid.n[1] {
            for i in 0..grid.n[0] {
                for axis in 0..3 {
                    let mut upper = [i, j, k];
                    upper[axis] += 1;
                    let faces = &state.velocity_m_per_s[axis];
                    velocity.push(0.5 * (faces[grid.face(axis, [i, j, k])] + faces[grid.face(axis, upper)]));
                }
            }
        }
    }
    let mut arrays = vec![
        DataArray::f64("porosity", 1, state.porosity.iter().copied()),
        DataArray::f64("pressure_pa", 1, state.pressure_pa.iter().copied()),
        DataArray::f64("velocity_m_per_s", 3, velocity),
        DataArray::u8(
            "blocked",
            (0..grid.cells()).map(|c| u8::from(gas.solver.config.blocked.get(c).copied().unwrap_or(false))),
        ),
    ];
    for scalar in gas.scalars() {
        arrays.push(DataArray::f64(scalar.spec.name, 1, scalar.value.iter().copied()));
    }
    arrays
}

/// The step a snapshot file's name carries (`particles_000000001000.vtu` → 1000).
fn step_of(file: &str) -> Option<u64> {
    let stem = file.rsplit_once('.')?.0;
    stem.rsplit_once('_')?.1.parse().ok()
}

/// Adds `(time_s, file)` to the index `index` in `dir`: entries of this step or later (left by a run killed after
/// them, which resumed from an earlier checkpoint) are replaced; the index is rewritten atomically.
fn add_to_index(dir: &Path, index: &str, step: u64, time_s: f64, file: &str) -> Result<(), Error> {
    let path = dir.join(index);
    let mut entries = match std::fs::read_to_string(&path) {
        Ok(text) => vtk_xml::read_collection(&text),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(Error::io("read", &path, e)),
    };
    entries.retain(|(_, f)| step_of(f).is_some_and(|s| s < step));
    entries.push((time_s, file.to_string()));
    write_atomic(&path, vtk_xml::collection_file(&entries).as_bytes())?;
    Ok(())
}

/// Writes the snapshot of `sim` into `dir` (made if missing) and adds it to the indexes. Returns the files written.
pub fn write_snapshot(sim: &Simulation, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io("create directory", dir, e))?;
    let mut written = Vec::new();
    let points: Vec<[f64; 3]> = sim.particles.position_m.iter().map(|x| [x.x, x.y, x.z]).collect();
    let file = format!("particles_{:012}.vtu", sim.step);
    let path = dir.join(&file);
    write_atomic(&path, &vtk_xml::points_file(&points, &particle_arrays(sim), sim.time_s))?;
    add_to_index(dir, PARTICLES_INDEX, sim.step, sim.time_s, &file)?;
    written.push(path);
    if let Some(gas) = &sim.gas {
        let grid = &gas.solver.config.grid;
        let file = format!("gas_{:012}.vti", sim.step);
        let path = dir.join(&file);
        let bytes = vtk_xml::grid_file(grid.origin_m, grid.h_m, grid.n, &gas_arrays(gas), sim.time_s);
        write_atomic(&path, &bytes)?;
        add_to_index(dir, GAS_INDEX, sim.step, sim.time_s, &file)?;
        written.push(path);
    }
    Ok(written)
}

/// Steps between snapshots for `every_s` at time step `dt_s` (at least one).
pub fn every_steps(every_s: f64, dt_s: f64) -> u64 {
    ((every_s / dt_s).round() as u64).max(1)
}

/// `granflow snapshots <dir>`: a snapshot of every valid checkpoint in the run or job directory `dir`, into `out`
/// (default `<dir>/snapshots`), indexed. Returns the files written; fails when `dir` holds no run or no checkpoint.
pub fn from_checkpoints(dir: &Path, out: Option<&Path>) -> Result<Vec<PathBuf>, Error> {
    let spec_path = dir.join("scenario.json");
    let text = std::fs::read_to_string(&spec_path).map_err(|e| {
        Error::Usage(format!(
            "{}: not a run or job directory (no readable scenario.json: {e})",
            dir.display()
        ))
    })?;
    let spec: crate::scenario::ScenarioSpec =
        serde_json::from_str(&text).map_err(|e| Error::Usage(format!("{}: {e}", spec_path.display())))?;
    let built = crate::scenario::build(spec, &spec_path)?;
    let mut checkpoints = CheckpointSeries::new(dir, built.spec.output.keep_checkpoints).list()?;
    // In step order: each snapshot replaces the index's entries from its step on.
    checkpoints.sort_by_key(|(step, _)| *step);
    if checkpoints.is_empty() {
        return Err(Error::Usage(format!(
            "{}: no checkpoint to make snapshots of",
            dir.display()
        )));
    }
    let out = out.map_or_else(|| dir.join(SNAPSHOT_DIR), Path::to_path_buf);
    let mut written = Vec::new();
    for (_, path) in checkpoints {
        // A checkpoint that fails its checks (a torn write) is skipped, as a resume would skip it.
        let Ok((mut state, meta)) = crate::checkpoint::read_checkpoint(&path) else {
            eprintln!("warning: {} does not read back; skipped", path.display());
            continue;
        };
        if meta.scenario_json != text {
            return Err(Error::External(format!(
                "checkpoint {} was written for a different scenario than {}",
                path.display(),
                spec_path.display()
            )));
        }
        let gas = state.gas.take();
        let mut sim = Simulation::restore(built.config.clone(), state, 1)?;
        crate::simulate::attach_gas(&built, &mut sim, gas.as_ref())?;
        written.extend(write_snapshot(&sim, &out)?);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_name_gives_its_step() {
        assert_eq!(step_of("particles_000000001000.vtu"), Some(1000));
        assert_eq!(step_of("gas_000000000000.vti"), Some(0));
        assert_eq!(step_of("gas.vti"), None);
    }
}
