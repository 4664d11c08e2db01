//! `granflow worker <job-dir>`: runs one campaign job in its directory.
//!
//! The worker owns the directory and never touches the database. It takes the directory's lock (two workers never
//! run one job), resumes from the newest valid checkpoint if there is one, runs to the end with checkpoints at the
//! campaign's cadence, reduces the metrics, writes `series.h5` and finally `result.json` (atomically, last: its
//! presence means done). It reports on stdout in JSON lines ([`protocol`]).
//!
//! Stopping: SIGTERM or SIGINT make it checkpoint at the next chunk boundary and exit with `EXIT_PREEMPTED`. With
//! `--watch-stdin` (how the dispatcher starts it) it exits at once with `EXIT_ORPHANED` when its stdin closes, which
//! happens when the dispatcher dies, even by `kill -9`; whatever it computed since its last checkpoint is lost, and
//! nothing is corrupted, since every file it writes is written to a temporary name and renamed.

mod height_families;
mod prepared;
pub mod protocol;
pub(crate) mod reduce;
pub mod rereduce;
mod series_h5;
mod shear_column;

use std::fs::File;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::campaign::JobSpec;
use crate::campaign_dir::{job_spec_path, result_path, worker_lock_path};
use crate::error::Error;
use crate::simulate::{RunControl, RunEvent, RunObserver, run_in_dir};
use crate::store::FailureClass;
use crate::util::write_atomic;
use protocol::{EXIT_LOCKED, EXIT_ORPHANED, EXIT_PREEMPTED, Event, Message};

pub use reduce::Metric;

/// Format version of `result.json`: 2 adds `build`, `cpu_path` and `reduced_by` (a version-1 file reads with
/// them empty).
pub const RESULT_FORMAT: u32 = 2;

/// What `result.json` holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobResult {
    pub format: u32,
    pub job_id: String,
    pub metrics: Vec<Metric>,
    /// Seconds per stage of the last invocation: `simulate`, `checkpoint` (part of simulate), `reduce`.
    pub timings: Vec<(String, f64)>,
    pub steps: u64,
    pub sim_time_s: f64,
    /// Wall time of the invocation that finished the job (earlier attempts are in the database).
    pub wall_time_s: f64,
    /// The build that finished the job ([`crate::provenance::build_id`]; empty in results older than format 2).
    #[serde(default)]
    pub build: String,
    /// The compilation of the force loop it ran ([`crate::provenance::cpu_path`]; the same bits either way).
    #[serde(default)]
    pub cpu_path: String,
    /// The build whose reducers last recomputed the metrics (`granflow reduce`), when not the one that ran the job.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reduced_by: Option<String>,
}

/// Options of one worker invocation.
#[derive(Debug, Clone)]
pub struct WorkerOptions {
    pub job_dir: PathBuf,
    pub threads: usize,
    /// Halve the scenario's time step this many times (a retry after a numerical failure).
    pub dt_halvings: u32,
    pub watch_stdin: bool,
    /// Stop (with a checkpoint) after this many steps in this invocation; for tests.
    pub max_steps: Option<u64>,
}

fn emit(event: Event) {
    let mut out = std::io::stdout().lock();
    // A closed stdout means the dispatcher is gone; the stdin watcher ends the process.
    let _ = writeln!(out, "{}", Message::new(event).to_line());
    let _ = out.flush();
}

/// Runs the job and returns the process exit code.
pub fn run_worker(opts: &WorkerOptions) -> i32 {
    match run(opts) {
        Ok(code) => code,
        Err(e) => {
            let class = match &e {
                Error::Config(_) => FailureClass::Config,
                Error::Numerical(_) => FailureClass::Numerical,
                _ => FailureClass::Crash,
            };
            emit(Event::Failed {
                class,
                error: e.to_string(),
            });
            eprintln!("error: {e}");
            e.exit_code()
        }
    }
}

fn run(opts: &WorkerOptions) -> Result<i32, Error> {
    let dir = &opts.job_dir;
    let lock_path = worker_lock_path(dir);
    let lock = File::create(&lock_path).map_err(|e| Error::io("create", &lock_path, e))?;
    match lock.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            let msg = format!("{} is locked by another worker", dir.display());
            emit(Event::Failed {
                class: FailureClass::Locked,
                error: msg.clone(),
            });
            eprintln!("error: {msg}");
            return Ok(EXIT_LOCKED);
        }
        Err(std::fs::TryLockError::Error(e)) => return Err(Error::io("lock", &lock_path, e)),
    }
    if opts.watch_stdin {
        std::thread::spawn(|| {
            let mut buf = [0u8; 64];
            let mut stdin = std::io::stdin();
            // Anything the dispatcher writes is ignored; end of file (or an error) means it is gone.
            while let Ok(n) = stdin.read(&mut buf) {
                if n == 0 {
                    break;
                }
            }
            std::process::exit(EXIT_ORPHANED);
        });
    }
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
        signal_hook::flag::register(signal, Arc::clone(&stop)).map_err(|e| Error::io("install handler", dir, e))?;
    }

    let job = read_job(dir)?;
    let result_path = result_path(dir);
    if result_path.exists() {
        emit(Event::Finished { wall_time_s: 0.0 });
        return Ok(0);
    }
    let built = crate::scenario::build(job.scenario.clone(), &job_spec_path(dir))?;
    let start = Instant::now();
    let mut preparing_s = None;
    if let Some(prep) = &job.prepared {
        match prepared::ensure_started(dir, &job, prep, &built, opts.threads, &stop)? {
            prepared::Start::Ready => preparing_s = Some(start.elapsed().as_secs_f64()),
            prepared::Start::Stopped => {
                emit(Event::Stopped { step: 0 });
                return Ok(EXIT_PREEMPTED);
            }
        }
    }
    let mut observer = WorkerObserver::new(&job, &built, dir)?;
    let (summary, sim) = run_in_dir(
        &built,
        dir,
        RunControl {
            threads: opts.threads,
            dt_halvings: opts.dt_halvings,
            max_steps: opts.max_steps,
            quiet: true,
            stop: Some(&stop),
            observer: &mut observer,
        },
    )?;
    if let Some(e) = observer.failure.take() {
        return Err(e);
    }
    if !summary.finished {
        emit(Event::Stopped { step: summary.step });
        return Ok(if summary.stopped { EXIT_PREEMPTED } else { 0 });
    }
    let simulate_s = start.elapsed().as_secs_f64();
    let t_reduce = Instant::now();
    let series = reduce::Series::read(&dir.join("series.csv"))?;
    let metrics = reduce::metrics(&job, &built, &sim, &series);
    series_h5::write(&dir.join("series.h5"), &series)?;
    let reduce_s = t_reduce.elapsed().as_secs_f64();
    let result = JobResult {
        format: RESULT_FORMAT,
        job_id: job.job_id.clone(),
        metrics,
        // This invocation's engine stages follow (after a resume, only the part since the resume).
        // `prepare` (part of simulate): running, waiting for or adopting the shared preparation.
        timings: [
            ("simulate".into(), simulate_s),
            ("checkpoint".into(), summary.checkpoint_time_s),
            ("reduce".into(), reduce_s),
        ]
        .into_iter()
        .chain(preparing_s.map(|s| ("prepare".to_string(), s)))
        .chain(sim.stage_timings())
        .collect(),
        steps: sim.step,
        sim_time_s: sim.time_s,
        wall_time_s: start.elapsed().as_secs_f64(),
        build: crate::provenance::build_id(),
        cpu_path: crate::provenance::cpu_path().to_string(),
        reduced_by: None,
    };
    let json = serde_json::to_string_pretty(&result).expect("results serialise");
    write_atomic(&result_path, json.as_bytes())?;
    emit(Event::Finished {
        wall_time_s: result.wall_time_s,
    });
    Ok(0)
}

/// Reads and checks `job.json` (its id must match its content).
pub fn read_job(dir: &Path) -> Result<JobSpec, Error> {
    let path = job_spec_path(dir);
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io("read", &path, e))?;
    let job: JobSpec = serde_json::from_str(&text)
        .map_err(|e| Error::External(format!("{}: not a job description: {e}", path.display())))?;
    if job.compute_id() != job.job_id {
        return Err(Error::External(format!(
            "{}: its content does not match its job id {} (edited by hand, or written by another engine version)",
            path.display(),
            job.job_id
        )));
    }
    Ok(job)
}

/// Reads `result.json` of a job directory, if it is there and well formed.
pub fn read_result(dir: &Path) -> Result<Option<JobResult>, Error> {
    let path = result_path(dir);
    match std::fs::read_to_string(&path) {
        Ok(text) => serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| Error::External(format!("{}: not a job result: {e}", path.display()))),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(Error::io("read", &path, e)),
    }
}

/// Reports run events on stdout and adds the mixing columns to the series.
struct WorkerObserver {
    job_id: String,
    total_steps: u64,
    mixing: Option<reduce::MixingSampler>,
    heights: Option<height_families::HeightFamilies>,
    /// The shear-rate column (`shear_column`), when a metric reads it.
    shear: bool,
    /// What stopped a sampler (its families file could not be written): the job fails with it after the run.
    failure: Option<Error>,
    /// False while running a shared preparation: its progress is the job's heartbeat, but the job has not started.
    announce_start: bool,
}

impl WorkerObserver {
    fn new(job: &JobSpec, built: &crate::scenario::BuiltScenario, dir: &Path) -> Result<Self, Error> {
        Ok(WorkerObserver {
            job_id: job.job_id.clone(),
            total_steps: 0,
            mixing: reduce::MixingSampler::new(job, built),
            heights: height_families::HeightFamilies::new(job, Some(dir))?,
            shear: shear_column::wanted(job),
            failure: None,
            announce_start: true,
        })
    }

    /// For a shared preparation of `job`, whose scenario is `built`: the same series columns, no start message.
    fn preparing(job: &JobSpec, built: &crate::scenario::BuiltScenario) -> Self {
        WorkerObserver {
            job_id: job.job_id.clone(),
            total_steps: 0,
            mixing: reduce::MixingSampler::new(job, built),
            heights: height_families::HeightFamilies::new(job, None).ok().flatten(),
            shear: shear_column::wanted(job),
            failure: None,
            announce_start: false,
        }
    }
}

impl RunObserver for WorkerObserver {
    fn extra_columns(&self) -> String {
        let mut columns = match &self.mixing {
            Some(_) => reduce::MIXING_COLUMNS.to_string(),
            None => String::new(),
        };
        if self.heights.is_some() {
            columns += &format!(",{}", height_families::COLUMN);
        }
        if self.shear {
            columns += &format!(",{}", shear_column::COLUMN);
        }
        columns
    }

    fn extra_row(&mut self, sim: &crate::engine::Simulation) -> String {
        let mut row = match &mut self.mixing {
            Some(m) => m.row(sim),
            None => String::new(),
        };
        if let Some(h) = &mut self.heights {
            match h.row(sim) {
                Ok(value) => row += &value,
                Err(e) => {
                    row += ",nan";
                    self.failure.get_or_insert(e);
                }
            }
        }
        if self.shear {
            row += &shear_column::row(sim);
        }
        row
    }

    fn event(&mut self, event: RunEvent) {
        match event {
            RunEvent::Started {
                step,
                total_steps,
                resumed_from_step,
            } => {
                self.total_steps = total_steps;
                if !self.announce_start {
                    return;
                }
                emit(Event::Started {
                    job_id: self.job_id.clone(),
                    step,
                    total_steps,
                    resumed_from_step,
                    pid: std::process::id(),
                });
            }
            RunEvent::Progress {
                step,
                time_s,
                steps_per_s,
            } => emit(Event::Progress {
                step,
                total_steps: self.total_steps,
                time_s,
                steps_per_s,
            }),
            RunEvent::Checkpointed { step } => emit(Event::Checkpointed { step }),
        }
    }
}
