//! The dispatcher: runs a campaign's unfinished jobs as worker processes, at most `max_parallel` at a time, and is
//! the only writer of the campaign database.
//!
//! `run` and `resume` are the same reconciliation: derive the job set from the campaign spec, insert jobs the
//! database lacks, ingest any `result.json` that finished while nobody was listening, put jobs left `running` by a
//! dead dispatcher back to `pending`, then work through the pending jobs in sweep order.
//!
//! Failure classes ([`FailureClass`]) and what happens ([`retry_rule`]; `RetryPolicy` gives the budgets): config →
//! failed at once; numerical, crash, killed, timeout, lost → retried from the job's last checkpoint while the
//! class's budget lasts; preempted (the worker checkpointed and stopped on a signal), interrupted (the dispatcher
//! stopped it) and locked (another worker held the job) → requeued without using an attempt.
//!
//! Ctrl-C (SIGINT) or SIGTERM once: no new jobs start, running workers are asked to checkpoint and stop, and the
//! dispatcher exits when they have; twice: workers are killed at once. Workers are started with `--watch-stdin` on a
//! pipe only the dispatcher holds, so if the dispatcher dies in any way they stop immediately.

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

use tokio::io::{AsyncBufReadExt, BufReader};
use tokio::process::{Child, ChildStdin, Command};
use tokio::sync::mpsc;

use super::progress::Progress;
use crate::campaign::spec::{ExecutorSpec, RetryPolicy};
use crate::campaign::{self, Campaign, JobSpec};
use crate::campaign_dir::{self, database_path, job_dir, job_spec_path, result_path, spec_copy_path, worker_log_path};
use crate::error::Error;
use crate::store::{self, AfterFailure, FailureClass, JobStatus, NewJob, ParamValue, Store};
use crate::util::write_atomic;
use crate::worker;
use crate::worker::protocol::{Event, Message};

/// How to run a campaign (command-line overrides of the campaign's executor settings).
#[derive(Debug, Clone, Default)]
pub struct DispatchOptions {
    pub max_parallel: Option<usize>,
    pub threads_per_job: Option<usize>,
    /// Show progress bars even when stderr is not a terminal (and never when `quiet`).
    pub quiet: bool,
    /// Run even though the campaign directory holds jobs that the campaign file no longer produces.
    pub force: bool,
}

/// What a dispatcher invocation ended with.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    pub done: usize,
    pub failed: usize,
    pub pending: usize,
    pub interrupted: bool,
    /// Jobs whose results were ingested in this invocation.
    pub ingested: usize,
}

/// `asked` jobs at once, or fewer when that many of the campaign's largest job would need more than the machine's
/// memory budget (each job alone fits: validation refuses one that does not); says so when it lowers the number.
fn parallel_within_memory(campaign: &Campaign, asked: usize) -> usize {
    let Some((budget, _)) = crate::machine::memory_budget_bytes() else {
        return asked;
    };
    let largest = campaign
        .jobs
        .iter()
        .map(|j| crate::scenario::estimated_memory_bytes(&j.scenario))
        .fold(0.0, f64::max);
    if largest <= 0.0 {
        return asked;
    }
    let fits = ((budget as f64 / largest).floor() as usize).max(1);
    if fits < asked {
        let note = format!(
            "running at most {fits} job(s) at once instead of {asked}: each needs about {} of the {} memory budget",
            crate::machine::bytes_text(largest),
            crate::machine::bytes_text(budget as f64)
        );
        eprintln!("{note}");
        tracing::warn!("{note}");
    }
    fits.min(asked)
}

/// Validates, prepares and runs a campaign in `out` to the end (or until interrupted).
pub fn run_campaign(campaign: &Campaign, source: &Path, out: &Path, opts: &DispatchOptions) -> Result<Outcome, Error> {
    // Everything that can be wrong with the input is found before anything is written.
    let unfinished: Vec<&JobSpec> = campaign
        .jobs
        .iter()
        .filter(|j| !result_path(&job_dir(out, &j.job_id)).exists())
        .collect();
    campaign::validate_jobs(campaign, unfinished.iter().copied(), source)?;
    if !opts.force {
        check_no_orphans(campaign, source, out)?;
    }
    if let ExecutorSpec::Slurm(slurm) = &campaign.spec.executor
        && !unfinished.is_empty()
    {
        super::slurm::check_submission(slurm, out)?;
    }

    std::fs::create_dir_all(campaign_dir::jobs_path(out)).map_err(|e| Error::io("create directory", out, e))?;
    let _lock = campaign_dir::lock(out)?;
    let copy = spec_copy_path(out);
    if std::fs::read_to_string(&copy).ok().as_deref() != Some(campaign.yaml.as_str()) {
        write_atomic(&copy, campaign.yaml.as_bytes())?;
    }
    let _log_guard = super::log::init(&campaign_dir::log_path(out));
    tracing::info!(campaign = %campaign.spec.name, jobs = campaign.jobs.len(), "dispatcher started");

    let mut store = Store::open(database_path(out))?;
    let spec_hash = format!("{:016x}", xxhash_rust::xxh3::xxh3_64(campaign.yaml.as_bytes()));
    let campaign_id = store.upsert_campaign(
        &campaign.spec.name,
        &campaign.yaml,
        &spec_hash,
        &crate::provenance::build_id(),
    )?;
    if source != copy {
        store.set_campaign_source(campaign_id, &source.display().to_string())?;
    }
    let new_jobs: Vec<NewJob> = campaign
        .jobs
        .iter()
        .enumerate()
        .map(|(ordinal, j)| NewJob {
            job_id: j.job_id.clone(),
            ordinal: ordinal as i64,
            params_json: j.params_json(),
            params: j
                .params
                .iter()
                .map(|(k, v)| (campaign.param_name(k).to_string(), param_value(v)))
                .collect(),
        })
        .collect();
    store.insert_jobs(campaign_id, &new_jobs)?;
    store.reset_running_to_pending(campaign_id)?;

    // Job directories and results that arrived while no dispatcher was listening.
    let rows: HashMap<String, store::JobRow> = store
        .job_summaries(campaign_id)?
        .into_iter()
        .map(|r| (r.job_id.clone(), r))
        .collect();
    let mut outcome = Outcome::default();
    let mut queue = VecDeque::new();
    for job in &campaign.jobs {
        let dir = job_dir(out, &job.job_id);
        let job_json = job_spec_path(&dir);
        if !job_json.exists() {
            std::fs::create_dir_all(&dir).map_err(|e| Error::io("create directory", &dir, e))?;
            let text = serde_json::to_string_pretty(job).expect("job specs serialise");
            write_atomic(&job_json, text.as_bytes())?;
        }
        let row = rows.get(&job.job_id);
        let status = row.map_or(JobStatus::Pending, |r| r.status);
        if status != JobStatus::Done
            && let Some(result) = worker::read_result(&dir)?
        {
            ingest(&mut store, &job.job_id, &result)?;
            outcome.ingested += 1;
            continue;
        }
        if status == JobStatus::Pending {
            queue.push_back(job.clone());
        }
    }

    let ExecutorSpec::Local(local) = &campaign.spec.executor else {
        let ExecutorSpec::Slurm(slurm) = &campaign.spec.executor else {
            unreachable!("two executors")
        };
        let jobs: HashMap<String, JobSpec> = campaign.jobs.iter().map(|j| (j.job_id.clone(), j.clone())).collect();
        let attempts: HashMap<String, u32> = rows.iter().map(|(id, r)| (id.clone(), r.attempt)).collect();
        let retries_used = store.retries_used(campaign_id)?;
        let quiet = opts.quiet;
        let interrupted = super::slurm::dispatch(
            &mut store,
            queue,
            &jobs,
            attempts,
            retries_used,
            &super::slurm::SlurmSettings {
                spec: slurm,
                out,
                campaign: &campaign.spec.name,
                retry: &campaign.spec.retry,
                campaign_id,
            },
            |event| {
                if !quiet {
                    eprintln!("{event}");
                }
            },
        )?;
        return finish(&mut store, campaign, campaign_id, outcome, interrupted);
    };
    // Jobs a Slurm executor submitted are Slurm's until their tasks end: a local run would wait for them forever.
    let in_slurm = store.slurm_running(campaign_id)?;
    if let Some((job_id, _, task)) = in_slurm.first() {
        return Err(Error::Usage(format!(
            "{} job(s) of {} are Slurm tasks still followed as running (e.g. {job_id}, task {task}): resume with the \
             campaign's executor: slurm, or cancel the tasks (scancel) and run `granflow resume` with executor: slurm \
             once to record their ends before switching to executor: local",
            in_slurm.len(),
            out.display()
        )));
    }
    let threads = opts.threads_per_job.unwrap_or(local.threads_per_job).max(1);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let asked_parallel = opts
        .max_parallel
        .or(local.max_parallel)
        .unwrap_or((cores / threads).max(1))
        .max(1);
    let max_parallel = parallel_within_memory(campaign, asked_parallel);
    let settings = Settings {
        out: out.to_path_buf(),
        threads,
        max_parallel,
        retry: campaign.spec.retry.clone(),
        job_timeout: local.job_timeout_s.map(Duration::from_secs_f64),
        heartbeat_timeout: Duration::from_secs_f64(local.heartbeat_timeout_s),
    };
    let total = campaign.jobs.len();
    let already_done = store
        .status_counts(campaign_id)?
        .get(JobStatus::Done.as_str())
        .copied()
        .unwrap_or(0);
    let progress = Progress::new(total, already_done, opts.quiet);
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| Error::External(format!("cannot start the dispatcher's runtime: {e}")))?;
    let attempts: HashMap<String, u32> = rows.iter().map(|(id, r)| (id.clone(), r.attempt)).collect();
    let labels: HashMap<String, String> = campaign
        .jobs
        .iter()
        .map(|j| (j.job_id.clone(), campaign.label(j)))
        .collect();
    let retries_used = store.retries_used(campaign_id)?;
    let interrupted = runtime.block_on(dispatch(
        &mut store,
        queue,
        attempts,
        retries_used,
        &labels,
        &settings,
        progress,
    ))?;

    finish(&mut store, campaign, campaign_id, outcome, interrupted)
}

/// Stores the derived metrics and counts the jobs by state, after the executor returned.
fn finish(
    store: &mut Store,
    campaign: &Campaign,
    campaign_id: i64,
    mut outcome: Outcome,
    interrupted: bool,
) -> Result<Outcome, Error> {
    if !campaign.spec.derived.is_empty() {
        store_derived(store, campaign_id, &campaign.spec.derived)?;
    }
    let counts = store.status_counts(campaign_id)?;
    let count = |s: JobStatus| counts.get(s.as_str()).copied().unwrap_or(0);
    outcome.done = count(JobStatus::Done);
    outcome.failed = count(JobStatus::Failed);
    outcome.pending = count(JobStatus::Pending) + count(JobStatus::Running);
    outcome.interrupted = interrupted;
    tracing::info!(
        done = outcome.done,
        failed = outcome.failed,
        pending = outcome.pending,
        "dispatcher stopped"
    );
    Ok(outcome)
}

/// Computes the campaign-level metrics from the jobs done so far and stores them (replacing earlier values).
pub fn store_derived(
    store: &mut Store,
    campaign_id: i64,
    specs: &[crate::campaign::derived::DerivedSpec],
) -> Result<(), Error> {
    let (header, rows) = store.export_rows(campaign_id)?;
    for d in crate::campaign::derived::compute(specs, &header, &rows) {
        store.insert_derived(campaign_id, &d.group_json, d.name, d.value, d.unit)?;
    }
    Ok(())
}

/// Refuses a campaign file that no longer produces jobs the directory's database holds: their parameters changed,
/// and running would silently leave them behind.
fn check_no_orphans(campaign: &Campaign, source: &Path, out: &Path) -> Result<(), Error> {
    let db = database_path(out);
    if !db.exists() {
        return Ok(());
    }
    let store = Store::open_read_only(&db)?;
    let Some(stored) = store.campaign_by_name(&campaign.spec.name)? else {
        return Ok(());
    };
    let wanted: std::collections::HashSet<&str> = campaign.jobs.iter().map(|j| j.job_id.as_str()).collect();
    let orphans: Vec<String> = store
        .job_summaries(stored.id)?
        .into_iter()
        .filter(|r| !wanted.contains(r.job_id.as_str()))
        .map(|r| r.params_json)
        .collect();
    if orphans.is_empty() {
        return Ok(());
    }
    Err(Error::Config(
        crate::scenario::ConfigError::invalid(
            source,
            "sweep",
            format!(
                "{} job(s) already in {} are not produced by this campaign file any more (changed parameters make \
             new jobs), e.g. {}; use another --out, or --force to run anyway and keep the old jobs' results",
                orphans.len(),
                out.display(),
                orphans[0]
            ),
        )
        .located(&campaign.yaml),
    ))
}

/// A sweep value as stored in the `params` table: numbers as reals, anything else as its JSON text (strings
/// without quotes).
fn param_value(v: &serde_json::Value) -> ParamValue {
    match v {
        serde_json::Value::Number(n) => n
            .as_f64()
            .map_or_else(|| ParamValue::Text(n.to_string()), ParamValue::Real),
        serde_json::Value::String(s) => ParamValue::Text(s.clone()),
        other => ParamValue::Text(other.to_string()),
    }
}

pub(super) fn ingest(store: &mut Store, job_id: &str, result: &worker::JobResult) -> Result<(), Error> {
    store_result(store, job_id, result, store::unix_time_s())?;
    tracing::info!(job = job_id, "result ingested");
    Ok(())
}

fn store_result(store: &mut Store, job_id: &str, result: &worker::JobResult, finished_at: f64) -> Result<(), Error> {
    let stored = store::JobResult {
        metrics: result
            .metrics
            .iter()
            .map(|m| store::Metric {
                name: m.name.clone(),
                value: m.value,
                unit: m.unit.clone(),
            })
            .collect(),
        timings: result.timings.clone(),
        sim_time_s: result.sim_time_s,
        wall_time_s: result.wall_time_s,
        steps: result.steps,
        finished_at,
        build: result.build.clone(),
    };
    store.finish_job(job_id, &stored).map_err(Error::from)
}

/// `granflow reduce <dir>`: recomputes the metrics of every finished job of the campaign in `dir` with this build's
/// reducers (`worker::rereduce`), replaces them in the database (the jobs keep their finish times) and recomputes
/// the derived metrics. Holds the campaign lock, so it cannot run beside a dispatcher. Returns how many jobs.
pub fn reduce_campaign_again(dir: &Path) -> Result<usize, Error> {
    let campaign = campaign_dir::load_stored_campaign(dir)?;
    let _lock = campaign_dir::lock(dir)?;
    let mut store = Store::open(database_path(dir))?;
    let campaign_id = campaign_dir::stored_campaign_id(&store, &campaign, dir)?;
    let done: Vec<(String, f64)> = store
        .job_summaries(campaign_id)?
        .into_iter()
        .filter(|j| j.status == JobStatus::Done)
        .map(|j| (j.job_id, j.finished_at.unwrap_or_else(store::unix_time_s)))
        .collect();
    for (job_id, finished_at) in &done {
        let result = worker::rereduce::reduce_again(&job_dir(dir, job_id))?;
        store_result(&mut store, job_id, &result, *finished_at)?;
    }
    store_derived(&mut store, campaign_id, &campaign.spec.derived)?;
    Ok(done.len())
}

struct Settings {
    out: PathBuf,
    threads: usize,
    max_parallel: usize,
    retry: RetryPolicy,
    job_timeout: Option<Duration>,
    heartbeat_timeout: Duration,
}

/// A worker the dispatcher started.
struct Running {
    job: JobSpec,
    attempt: u32,
    child_pid: Option<u32>,
    /// Held open for the worker's life: closing it tells the worker that the dispatcher is gone.
    _stdin: Option<ChildStdin>,
    started: Instant,
    last_heard: Instant,
    /// Why the dispatcher stopped it, if it did (timeout, lost, interrupted).
    stopped_for: Option<FailureClass>,
    last_error: Option<String>,
}

enum FromWorker {
    Line(String, Message),
    Exited(String, Option<i32>),
}

/// The event loop. Returns whether it was interrupted.
async fn dispatch(
    store: &mut Store,
    mut queue: VecDeque<JobSpec>,
    mut attempts: HashMap<String, u32>,
    mut retries_used: HashMap<(String, FailureClass), u32>,
    labels: &HashMap<String, String>,
    settings: &Settings,
    mut progress: Progress,
) -> Result<bool, Error> {
    let (tx, mut rx) = mpsc::unbounded_channel::<FromWorker>();
    let mut running: BTreeMap<String, Running> = BTreeMap::new();
    let mut interrupts = 0u32;
    let mut sigint = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::interrupt())
        .map_err(|e| Error::External(format!("cannot handle SIGINT: {e}")))?;
    let mut sigterm = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
        .map_err(|e| Error::External(format!("cannot handle SIGTERM: {e}")))?;
    let mut tick = tokio::time::interval(Duration::from_millis(250));
    loop {
        while interrupts == 0 && running.len() < settings.max_parallel {
            let Some(job) = queue.pop_front() else { break };
            let attempt = attempts.get(&job.job_id).copied().unwrap_or(0) + 1;
            attempts.insert(job.job_id.clone(), attempt);
            let dt_halvings = if settings.retry.halve_dt_on_numerical {
                retries_used
                    .get(&(job.job_id.clone(), FailureClass::Numerical))
                    .copied()
                    .unwrap_or(0)
            } else {
                0
            };
            match spawn(&job, settings, dt_halvings, tx.clone()) {
                Ok((child_pid, stdin)) => {
                    store.mark_running(
                        &job.job_id,
                        attempt,
                        &hostname(),
                        store::unix_time_s(),
                        &crate::provenance::build_id(),
                    )?;
                    let label = labels.get(&job.job_id).cloned().unwrap_or_default();
                    tracing::info!(job = %job.job_id, attempt, params = %label, "started");
                    progress.started(&job.job_id, &label);
                    running.insert(
                        job.job_id.clone(),
                        Running {
                            job,
                            attempt,
                            child_pid,
                            _stdin: stdin,
                            started: Instant::now(),
                            last_heard: Instant::now(),
                            stopped_for: None,
                            last_error: None,
                        },
                    );
                }
                Err(e) => return Err(e),
            }
        }
        if running.is_empty() && (queue.is_empty() || interrupts > 0) {
            break;
        }
        tokio::select! {
            Some(msg) = rx.recv() => match msg {
                FromWorker::Line(job_id, m) => {
                    let Some(r) = running.get_mut(&job_id) else { continue };
                    r.last_heard = Instant::now();
                    match m.event {
                        Event::Progress { step, total_steps, time_s, steps_per_s } => {
                            store.heartbeat(&job_id, time_s, step, store::unix_time_s())?;
                            progress.progress(&job_id, step, total_steps, time_s, steps_per_s);
                        }
                        Event::Started { step, total_steps, resumed_from_step, .. } => {
                            if let Some(from) = resumed_from_step {
                                tracing::info!(job = %job_id, from, "resumed from checkpoint");
                            }
                            progress.progress(&job_id, step, total_steps, 0.0, 0.0);
                        }
                        Event::Failed { class, error } => {
                            tracing::warn!(job = %job_id, class = class.as_str(), error, "worker reported a failure");
                            r.last_error = Some(error);
                        }
                        Event::Checkpointed { .. } | Event::Finished { .. } | Event::Stopped { .. } => {}
                    }
                }
                FromWorker::Exited(job_id, code) => {
                    let Some(r) = running.remove(&job_id) else { continue };
                    progress.ended(&job_id);
                    let dir = job_dir(&settings.out, &job_id);
                    match worker::read_result(&dir) {
                        Ok(Some(result)) => {
                            ingest(store, &job_id, &result)?;
                            progress.done();
                            continue;
                        }
                        Ok(None) => {}
                        Err(e) => {
                            tracing::warn!(job = %job_id, error = %e, "unreadable result");
                        }
                    }
                    let class = r.stopped_for.unwrap_or_else(|| worker::protocol::exit_class(code));
                    let error = r.last_error.clone().unwrap_or_else(|| match code {
                        Some(c) => format!("worker exited with code {c} without a result (see {})", worker_log_path(&dir).display()),
                        None => format!("worker was killed by a signal (see {})", worker_log_path(&dir).display()),
                    });
                    let after = after_failure(&settings.retry, &mut retries_used, &job_id, class);
                    store.mark_failed(&job_id, r.attempt, class, &error, store::unix_time_s(), after)?;
                    tracing::warn!(job = %job_id, class = class.as_str(), error, retry = matches!(after, AfterFailure::Retry), "attempt ended without a result");
                    match after {
                        AfterFailure::Retry if interrupts == 0 => {
                            if class == FailureClass::Locked {
                                // Another worker holds it (a dispatcher that died moments ago): try later.
                                tokio::time::sleep(Duration::from_millis(200)).await;
                            }
                            queue.push_back(r.job);
                        }
                        AfterFailure::Retry => {}
                        AfterFailure::Final => progress.failed(),
                    }
                }
            },
            _ = sigint.recv() => interrupts += interrupt(&mut running, interrupts, &mut progress),
            _ = sigterm.recv() => interrupts += interrupt(&mut running, interrupts, &mut progress),
            _ = tick.tick() => {
                for r in running.values_mut() {
                    if r.stopped_for.is_some() { continue; }
                    if settings.job_timeout.is_some_and(|t| r.started.elapsed() > t) {
                        tracing::warn!(job = %r.job.job_id, "timeout: asking the worker to checkpoint and stop");
                        r.stopped_for = Some(FailureClass::Timeout);
                        signal(r.child_pid, nix::sys::signal::Signal::SIGTERM);
                    } else if r.last_heard.elapsed() > settings.heartbeat_timeout {
                        tracing::warn!(job = %r.job.job_id, "no heartbeat: killing the worker");
                        r.stopped_for = Some(FailureClass::Lost);
                        signal(r.child_pid, nix::sys::signal::Signal::SIGKILL);
                    }
                }
                progress.tick();
            }
        }
    }
    progress.finish();
    Ok(interrupts > 0)
}

/// Whether a job whose attempt ended without a result in `class` runs again, using one of the class's retries
/// (counted in `retries_used`) where its rule asks for one.
pub(super) fn after_failure(
    policy: &RetryPolicy,
    retries_used: &mut HashMap<(String, FailureClass), u32>,
    job_id: &str,
    class: FailureClass,
) -> AfterFailure {
    match retry_rule(policy, class) {
        RetryRule::Free => AfterFailure::Retry,
        RetryRule::Never => AfterFailure::Final,
        RetryRule::Budget(budget) => {
            let used = retries_used.entry((job_id.to_string(), class)).or_insert(0);
            if *used < budget {
                *used += 1;
                AfterFailure::Retry
            } else {
                AfterFailure::Final
            }
        }
    }
}

/// What a failed attempt of a class may do: start again without using a retry, or use one of the class's retries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RetryRule {
    /// Requeued without counting: the worker checkpointed and stopped (preempted, interrupted) or never started
    /// (locked).
    Free,
    /// Failed for good at once.
    Never,
    /// Requeued while fewer than this many retries of the class have been used (0: failed for good at once).
    Budget(u32),
}

/// The retry rule of a failure class under `policy` (a configuration error never retries).
fn retry_rule(policy: &RetryPolicy, class: FailureClass) -> RetryRule {
    match class {
        FailureClass::Preempted | FailureClass::Interrupted | FailureClass::Locked => RetryRule::Free,
        FailureClass::Config => RetryRule::Never,
        FailureClass::Numerical => RetryRule::Budget(policy.numerical),
        FailureClass::Crash => RetryRule::Budget(policy.crash),
        FailureClass::Killed => RetryRule::Budget(policy.killed),
        FailureClass::Timeout => RetryRule::Budget(policy.timeout),
        FailureClass::Lost => RetryRule::Budget(policy.lost),
    }
}

/// First interrupt: stop starting jobs and ask workers to checkpoint and stop; second: kill them.
fn interrupt(running: &mut BTreeMap<String, Running>, before: u32, progress: &mut Progress) -> u32 {
    if before == 0 {
        progress.message("interrupted: workers are checkpointing and stopping (Ctrl-C again to kill them)");
        tracing::warn!("interrupted: stopping workers");
        for r in running.values_mut() {
            r.stopped_for = Some(FailureClass::Interrupted);
            signal(r.child_pid, nix::sys::signal::Signal::SIGTERM);
        }
    } else {
        progress.message("interrupted again: killing workers");
        tracing::warn!("interrupted again: killing workers");
        for r in running.values() {
            signal(r.child_pid, nix::sys::signal::Signal::SIGKILL);
        }
    }
    1
}

fn signal(pid: Option<u32>, sig: nix::sys::signal::Signal) {
    if let Some(pid) = pid {
        // The worker may already have exited; its exit is handled when its pipe closes.
        let _ = nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid as i32), sig);
    }
}

fn hostname() -> String {
    nix::unistd::gethostname()
        .ok()
        .and_then(|h| h.into_string().ok())
        .unwrap_or_else(|| "localhost".to_string())
}

/// The running binary, for its workers. On Linux `/proc/self/exe`, which executes this very binary even after its
/// file was replaced (a rebuild or an upgrade during a campaign: `current_exe()` then names a deleted file and no
/// further worker could start), so every worker of a dispatcher runs the dispatcher's own version.
fn own_executable() -> Result<PathBuf, Error> {
    if cfg!(target_os = "linux") {
        return Ok(PathBuf::from("/proc/self/exe"));
    }
    std::env::current_exe().map_err(|e| Error::External(format!("cannot find the granflow binary: {e}")))
}

/// Starts `granflow worker <dir>` and a task that forwards its messages and its exit.
fn spawn(
    job: &JobSpec,
    settings: &Settings,
    dt_halvings: u32,
    tx: mpsc::UnboundedSender<FromWorker>,
) -> Result<(Option<u32>, Option<ChildStdin>), Error> {
    let dir = job_dir(&settings.out, &job.job_id);
    let exe = own_executable()?;
    let log_path = worker_log_path(&dir);
    let log = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&log_path)
        .map_err(|e| Error::io("open", &log_path, e))?;
    let mut command = Command::new(exe);
    // Listed as `granflow worker …` by ps, not as /proc/self/exe.
    #[cfg(unix)]
    command.arg0("granflow");
    let mut child: Child = command
        .arg("worker")
        .arg(&dir)
        .arg("--threads")
        .arg(settings.threads.to_string())
        .arg("--dt-halvings")
        .arg(dt_halvings.to_string())
        .arg("--watch-stdin")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::from(log))
        .kill_on_drop(true)
        .spawn()
        .map_err(|e| Error::External(format!("cannot start a worker for {}: {e}", dir.display())))?;
    let pid = child.id();
    let stdin = child.stdin.take();
    let stdout = child.stdout.take().expect("stdout is piped");
    let job_id = job.job_id.clone();
    tokio::spawn(async move {
        let mut lines = BufReader::new(stdout).lines();
        while let Ok(Some(line)) = lines.next_line().await {
            if let Some(m) = Message::parse(&line) {
                let _ = tx.send(FromWorker::Line(job_id.clone(), m));
            }
        }
        let code = child.wait().await.ok().and_then(|s| s.code());
        let _ = tx.send(FromWorker::Exited(job_id, code));
    });
    Ok((pid, stdin))
}

#[cfg(test)]
mod tests {
    use super::{RetryRule, retry_rule};
    use crate::campaign::spec::RetryPolicy;
    use crate::store::FailureClass;

    #[test]
    fn each_failure_class_has_its_retry_rule() {
        let policy = RetryPolicy {
            numerical: 1,
            crash: 2,
            killed: 3,
            timeout: 4,
            lost: 5,
            halve_dt_on_numerical: true,
        };
        let rules: Vec<(FailureClass, RetryRule)> = FailureClass::ALL
            .into_iter()
            .map(|c| (c, retry_rule(&policy, c)))
            .collect();
        assert_eq!(
            rules,
            [
                (FailureClass::Config, RetryRule::Never),
                (FailureClass::Numerical, RetryRule::Budget(1)),
                (FailureClass::Crash, RetryRule::Budget(2)),
                (FailureClass::Killed, RetryRule::Budget(3)),
                (FailureClass::Timeout, RetryRule::Budget(4)),
                (FailureClass::Lost, RetryRule::Budget(5)),
                (FailureClass::Preempted, RetryRule::Free),
                (FailureClass::Interrupted, RetryRule::Free),
                (FailureClass::Locked, RetryRule::Free),
            ]
        );
    }
}
