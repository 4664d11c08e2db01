//! Reducing a finished job again with this build's reducers (`granflow reduce`): after a reducer is fixed or
//! changed, a campaign's metrics can be recomputed without running its simulations again.
//!
//! The job's final state is restored from its last checkpoint (which the worker writes at the end of every job) and
//! its series is read from `series.csv`; the metrics are computed exactly as the worker computes them when a job
//! ends, and `result.json` is replaced (atomically) with the new metrics and everything else kept.

use std::path::Path;

use super::{JobResult, read_job, read_result, reduce};
use crate::campaign::JobSpec;
use crate::campaign_dir::{job_spec_path, result_path};
use crate::checkpoint::CheckpointSeries;
use crate::engine::Simulation;
use crate::error::Error;
use crate::scenario::BuiltScenario;
use crate::simulate::{attach_gas, checkpoint_meta};
use crate::util::write_atomic;

/// Recomputes the metrics of the finished job in `job_dir`, writes them into its `result.json` and returns the new
/// result. Errors name the job directory and what is missing or does not match.
pub fn reduce_again(job_dir: &Path) -> Result<JobResult, Error> {
    let (job, built, sim, series, old) = final_state(job_dir)?;
    let this_build = crate::provenance::build_id();
    let result = JobResult {
        metrics: reduce::metrics(&job, &built, &sim, &series),
        reduced_by: (old.build != this_build).then_some(this_build),
        ..old
    };
    let json = serde_json::to_string_pretty(&result).expect("results serialise");
    write_atomic(&result_path(job_dir), json.as_bytes())?;
    Ok(result)
}

/// A finished job's spec, built scenario, final simulation (restored from its last checkpoint, with its gas),
/// series and result: what its metrics were reduced from (`granflow reduce`, `granflow plot series`'s fits).
pub(crate) fn final_state(
    job_dir: &Path,
) -> Result<(JobSpec, BuiltScenario, Simulation, reduce::Series, JobResult), Error> {
    let fail = |what: String| Error::External(format!("{}: {what}", job_dir.display()));
    let job = read_job(job_dir)?;
    let old = read_result(job_dir)?.ok_or_else(|| fail("the job has no result.json (it has not finished)".into()))?;
    let built = crate::scenario::build(job.scenario.clone(), &job_spec_path(job_dir))?;
    let meta = checkpoint_meta(&built);
    let loaded = CheckpointSeries::new(job_dir, built.spec.output.keep_checkpoints)
        .latest_valid()?
        .ok_or_else(|| fail("no valid checkpoint to restore the final state from".into()))?;
    if loaded.meta.scenario_json != meta.scenario_json {
        return Err(fail(format!(
            "checkpoint {} was written for a different scenario",
            loaded.path.display()
        )));
    }
    if loaded.state.step != old.steps {
        return Err(fail(format!(
            "the last checkpoint holds step {}, the result step {}: the final state is not on disk",
            loaded.state.step, old.steps
        )));
    }
    let mut state = loaded.state;
    let gas = state.gas.take();
    let mut sim = Simulation::restore(built.config.clone(), state, 1)?;
    attach_gas(&built, &mut sim, gas.as_ref())?;
    let series = reduce::Series::read(&job_dir.join("series.csv"))?;
    Ok((job, built, sim, series, old))
}
