//! A job's start from its campaign's shared preparation (`campaign::prepare`): run the preparation if no worker has
//! yet, check it, and adopt its end state as the job's first checkpoint.
//!
//! The preparation lives in `<campaign>/preparations/<id>/`: one run directory per scenario (`first/`, `last/`), each
//! an ordinary run (resumable, every file written atomically), and `prepared.json`, written last, holding the
//! verdict of the comparison. Its lock file lets one worker prepare while the others of the group wait (sending
//! heartbeats). A job adopts the preparation by writing the preparation's series rows and end state into its own
//! directory as its series and first checkpoint, under its own scenario; from then on it resumes from its own
//! checkpoints like any job, and the preparation directory may be deleted.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use super::protocol::Event;
use super::{WorkerObserver, emit};
use crate::campaign::JobSpec;
use crate::campaign::prepare::Preparation;
use crate::campaign_dir::{job_spec_path, preparation_dir};
use crate::checkpoint::CheckpointSeries;
use crate::engine::state::first_difference;
use crate::error::Error;
use crate::scenario::{BuiltScenario, ConfigError};
use crate::simulate::{RunControl, checkpoint_meta, run_in_dir};
use crate::util::write_atomic;

/// Names of the preparation's run directories, in the order of `Preparation::scenarios`.
const RUNS: [&str; 2] = ["first", "last"];

/// What `prepared.json` holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Verdict {
    /// The step the preparation ended at.
    step: u64,
    /// The first value that differs between the runs at the first and the last values, if any.
    difference: Option<String>,
}

/// How the job's start went.
pub enum Start {
    /// The job directory holds a checkpoint (adopted now or earlier): run it.
    Ready,
    /// Stopped by a signal while preparing; the job should be requeued.
    Stopped,
}

/// Makes sure the job in `dir` can start: when it has no checkpoint of its own yet, its preparation is run (or
/// waited for) and adopted. `built` is the job's scenario built.
pub fn ensure_started(
    dir: &Path,
    job: &JobSpec,
    prep: &Preparation,
    built: &BuiltScenario,
    threads: usize,
    stop: &AtomicBool,
) -> Result<Start, Error> {
    let own = CheckpointSeries::new(dir, built.spec.output.keep_checkpoints);
    if own.latest_valid()?.is_some() {
        return Ok(Start::Ready);
    }
    let campaign_dir = dir
        .parent()
        .and_then(Path::parent)
        .ok_or_else(|| Error::External(format!("{}: not inside a campaign's jobs directory", dir.display())))?;
    let prep_dir = preparation_dir(campaign_dir, &prep.id);
    std::fs::create_dir_all(&prep_dir).map_err(|e| Error::io("create directory", &prep_dir, e))?;
    let lock_path = prep_dir.join("prepare.lock");
    let lock = File::create(&lock_path).map_err(|e| Error::io("create", &lock_path, e))?;
    if !wait_for_lock(&lock, &lock_path, stop)? {
        return Ok(Start::Stopped);
    }
    let verdict = match read_verdict(&prep_dir)? {
        Some(v) => v,
        None => match prepare(&prep_dir, job, prep, threads, stop)? {
            Some(v) => v,
            None => return Ok(Start::Stopped),
        },
    };
    if let Some(difference) = &verdict.difference {
        return Err(Error::Config(ConfigError::invalid(
            &job_spec_path(dir),
            "prepare.shared_across",
            format!(
                "the preparation to {} s differs between the shared parameters' first and last values ({difference}): \
                 one of {} acts before then; take it out of `prepare.shared_across` or prepare to an earlier time \
                 ({})",
                prep.until_s,
                prep.shared_params.join(", "),
                prep_dir.display()
            ),
        )));
    }
    adopt(dir, &prep_dir, built, verdict.step)?;
    Ok(Start::Ready)
}

/// Takes `lock`, waiting for another worker that holds it and sending a heartbeat every few seconds meanwhile.
/// Returns false when a stop was requested first.
fn wait_for_lock(lock: &File, path: &Path, stop: &AtomicBool) -> Result<bool, Error> {
    let mut last_heartbeat = Instant::now();
    loop {
        match lock.try_lock() {
            Ok(()) => return Ok(true),
            Err(std::fs::TryLockError::WouldBlock) => {}
            Err(std::fs::TryLockError::Error(e)) => return Err(Error::io("lock", path, e)),
        }
        if stop.load(Ordering::Relaxed) {
            return Ok(false);
        }
        if last_heartbeat.elapsed() >= Duration::from_secs(5) {
            last_heartbeat = Instant::now();
            emit(Event::Progress {
                step: 0,
                total_steps: 0,
                time_s: 0.0,
                steps_per_s: 0.0,
            });
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn verdict_path(prep_dir: &Path) -> PathBuf {
    prep_dir.join("prepared.json")
}

fn read_verdict(prep_dir: &Path) -> Result<Option<Verdict>, Error> {
    let path = verdict_path(prep_dir);
    match std::fs::read_to_string(&path) {
        Ok(text) => serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| Error::External(format!("{}: not a preparation verdict: {e}", path.display()))),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(Error::io("read", &path, e)),
    }
}

/// Runs (or resumes) each of the preparation's scenarios to its end, compares their end states and series, and
/// writes the verdict. `None` when stopped by a signal first.
fn prepare(
    prep_dir: &Path,
    job: &JobSpec,
    prep: &Preparation,
    threads: usize,
    stop: &AtomicBool,
) -> Result<Option<Verdict>, Error> {
    let mut ends = Vec::new();
    for (scenario, name) in prep.scenarios.iter().zip(RUNS) {
        let run_dir = prep_dir.join(name);
        let built = crate::scenario::build(scenario.clone(), &run_dir.join("scenario.json"))?;
        let mut observer = WorkerObserver::preparing(job, &built);
        let (summary, _) = run_in_dir(
            &built,
            &run_dir,
            RunControl {
                threads,
                dt_halvings: 0,
                max_steps: None,
                quiet: true,
                stop: Some(stop),
                observer: &mut observer,
            },
        )?;
        if !summary.finished {
            return Ok(None);
        }
        let end = CheckpointSeries::new(&run_dir, built.spec.output.keep_checkpoints)
            .latest_valid()?
            .ok_or_else(|| Error::External(format!("{}: the preparation left no checkpoint", run_dir.display())))?;
        let series_path = run_dir.join("series.csv");
        let series = std::fs::read(&series_path).map_err(|e| Error::io("read", &series_path, e))?;
        ends.push((end.state, series));
    }
    let (state, series) = &ends[0];
    let difference = ends[1..].iter().find_map(|(other_state, other_series)| {
        first_difference(state, other_state).or_else(|| (series != other_series).then(|| "the series rows".to_string()))
    });
    let verdict = Verdict {
        step: state.step,
        difference,
    };
    let json = serde_json::to_string_pretty(&verdict).expect("a verdict serialises");
    write_atomic(&verdict_path(prep_dir), json.as_bytes())?;
    Ok(Some(verdict))
}

/// Writes the preparation's series and end state (of its first run) into the job's directory as the job's own,
/// under the job's scenario: the series first, the checkpoint last (its presence means adopted).
fn adopt(dir: &Path, prep_dir: &Path, built: &BuiltScenario, step: u64) -> Result<(), Error> {
    let run_dir = prep_dir.join(RUNS[0]);
    let end = CheckpointSeries::new(&run_dir, built.spec.output.keep_checkpoints)
        .latest_valid()?
        .filter(|c| c.state.step == step)
        .ok_or_else(|| {
            Error::External(format!(
                "{}: the preparation's checkpoint at step {step} is missing or damaged; delete {} to prepare again",
                run_dir.display(),
                prep_dir.display()
            ))
        })?;
    let from = run_dir.join("series.csv");
    let series = std::fs::read(&from).map_err(|e| Error::io("read", &from, e))?;
    write_atomic(&dir.join("series.csv"), &series)?;
    CheckpointSeries::new(dir, built.spec.output.keep_checkpoints).write(&end.state, &checkpoint_meta(built))?;
    Ok(())
}
