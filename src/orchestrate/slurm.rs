//! The Slurm executor: the dispatcher submits pending jobs as job arrays with `sbatch` (one array task = one job
//! directory, the task running `granflow worker` on it), follows the tasks with `squeue`, and stays the only writer
//! of the database; workers write their results into their job directories on the shared filesystem, as they do
//! locally. Slurm schedules the nodes; granflow does not.
//!
//! Files in `<campaign dir>/slurm/`: `granflow-<build>` (a copy of the dispatcher's binary, so that rebuilding or
//! upgrading granflow while tasks wait does not change what they run), and per submission `array-<n>.list` (the job
//! directories, line k for task k), `array-<n>.sh` (the batch script) and the tasks' own output
//! `array-<n>_<k>.out`. In each job directory the task appends the worker's messages to `messages.jsonl` (the
//! protocol lines a local worker prints), its log to `worker.log`, and a line per end of a worker to
//! `slurm-attempts.jsonl` (`{"task":"<array>_<k>","exit":<code>,"at":<unix s>}`).
//!
//! Preemption and time limits: every task asks for `--signal=B:TERM@<signal_before_end_s>` and `--requeue`. The
//! batch script passes SIGTERM on to the worker, which checkpoints and exits with `EXIT_PREEMPTED`; the script then
//! requeues its own task (`scontrol requeue`), which starts again from the checkpoint. The dispatcher counts that as
//! preempted (no retry used). A task killed without warning resumes from its last checkpoint when it is retried.
//!
//! A task that leaves the queue without a result and without its script recording an end (killed with its
//! script, its node lost) is retried by the campaign's retry budgets; where the cluster keeps accounting, `sacct`
//! names why it ended (TIMEOUT, OUT_OF_MEMORY, NODE_FAIL, …) and sets its failure class.
//!
//! The dispatcher may die: tasks keep running. `granflow resume` asks `squeue` for the campaign's tasks (by the job
//! name `granflow-<hash of the campaign directory>`), follows those still queued or running instead of submitting
//! them again, ingests results that arrived meanwhile, and retries jobs whose task ended without one. Ctrl-C stops
//! only the dispatcher; the tasks go on.

use std::collections::{HashMap, VecDeque};
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serde::Deserialize;

use crate::campaign::JobSpec;
use crate::campaign::spec::{RetryPolicy, SlurmExecutor};
use crate::campaign_dir::job_dir;
use crate::error::Error;
use crate::store::{self, AfterFailure, FailureClass, Store};
use crate::util::write_atomic;
use crate::worker;
use crate::worker::protocol::{EXIT_PREEMPTED, Event, Message};

/// `squeue` failures in a row the dispatcher waits through before it stops.
const SQUEUE_FAILURES_TOLERATED: u32 = 30;

/// Slurm's default `MaxArraySize` is 1001: arrays of at most 1000 tasks are accepted everywhere.
const MAX_ARRAY_TASKS: usize = 1000;

/// The Slurm job name of a campaign directory's tasks: how `squeue` finds them again.
pub fn slurm_job_name(out: &Path) -> String {
    let absolute = std::fs::canonicalize(out).unwrap_or_else(|_| out.to_path_buf());
    format!(
        "granflow-{:012x}",
        xxhash_rust::xxh3::xxh3_64(absolute.as_os_str().as_encoded_bytes()) >> 16
    )
}

/// The directory of the executor's own files.
fn slurm_dir(out: &Path) -> PathBuf {
    out.join("slurm")
}

/// The `sbatch` options every submission of `spec` carries (the array, output and script are added per submission).
fn sbatch_options(spec: &SlurmExecutor, job_name: &str) -> Vec<String> {
    let mut args = vec![
        format!("--job-name={job_name}"),
        format!("--cpus-per-task={}", spec.cpus_per_task),
        "--ntasks=1".into(),
        "--requeue".into(),
        format!("--signal=B:TERM@{}", spec.signal_before_end_s),
    ];
    let optional = [
        ("--partition", &spec.partition),
        ("--time", &spec.time_limit),
        ("--mem", &spec.memory),
        ("--account", &spec.account),
        ("--qos", &spec.qos),
    ];
    for (flag, value) in optional {
        if let Some(v) = value {
            args.push(format!("{flag}={v}"));
        }
    }
    args.extend(spec.sbatch_options.iter().cloned());
    args
}

/// Runs a Slurm client command; a missing command is a usage error naming it (exit 2).
fn slurm_command(program: &str, args: &[String]) -> Result<std::process::Output, Error> {
    Command::new(program).args(args).output().map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            Error::Usage(format!(
                "`{program}` is not on the PATH: executor: slurm submits and follows its jobs with Slurm's client \
                 commands (sbatch, squeue, scontrol); run where they are, or use executor: local"
            ))
        } else {
            Error::External(format!("cannot run `{program}`: {e}"))
        }
    })
}

/// Asks Slurm whether it would accept the campaign's tasks (`sbatch --test-only`), before anything is written or
/// submitted: an unknown partition, account or QOS, a time limit Slurm rejects, or no `sbatch` are usage errors.
pub fn check_submission(spec: &SlurmExecutor, out: &Path) -> Result<(), Error> {
    let mut args = vec!["--test-only".to_string()];
    args.extend(sbatch_options(spec, &slurm_job_name(out)));
    args.extend(["--output=/dev/null".into(), "--wrap=true".into()]);
    let output = slurm_command("sbatch", &args)?;
    if output.status.success() {
        return Ok(());
    }
    let said = String::from_utf8_lossy(&output.stderr);
    // `--test-only` also says this when the nodes that could run the tasks are drained or down (they will queue);
    // a request no node can ever meet is refused by the submission itself, before any job is marked submitted.
    if said.contains("Requested node configuration is not available") {
        let note = format!(
            "sbatch --test-only: {}; submitting anyway (the nodes may be drained or down: the tasks wait for them)",
            said.trim()
        );
        eprintln!("{note}");
        tracing::warn!("{note}");
        return Ok(());
    }
    Err(Error::Usage(format!(
        "Slurm refuses the campaign's executor.slurm settings (sbatch {}): {}",
        args.join(" "),
        said.trim()
    )))
}

/// The batch script of one submission: task k runs the worker on line k+1 of `list`.
fn batch_script(exe: &Path, list: &Path, threads: usize, campaign: &str) -> String {
    let quote = |p: &Path| format!("'{}'", p.display().to_string().replace('\'', r"'\''"));
    format!(
        r#"#!/bin/bash
# granflow campaign {campaign}: one array task per job directory (line SLURM_ARRAY_TASK_ID + 1 of the list).
# Written by the dispatcher (src/orchestrate/slurm.rs); SIGTERM (Slurm's warning before a time limit or a
# preemption) is passed to the worker, which checkpoints and exits {EXIT_PREEMPTED}; the task then requeues itself.
dir=$(sed -n "$((SLURM_ARRAY_TASK_ID + 1))p" {list})
task="${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}"
{exe} worker "$dir" --threads {threads} >> "$dir/messages.jsonl" 2>> "$dir/worker.log" &
worker=$!
trap 'kill -TERM "$worker" 2>/dev/null' TERM INT
wait "$worker"
code=$?
while kill -0 "$worker" 2>/dev/null; do
  wait "$worker"
  code=$?
done
printf '{{"task":"%s","exit":%d,"at":%d}}\n' "$task" "$code" "$(date +%s)" >> "$dir/slurm-attempts.jsonl"
if [ "$code" -eq {EXIT_PREEMPTED} ]; then
  scontrol requeue "$SLURM_JOB_ID"
fi
exit "$code"
"#,
        exe = quote(exe),
        list = quote(list),
    )
}

/// The dispatcher's binary copied into the campaign's `slurm/` directory once per build (the compute nodes run
/// this copy).
fn task_executable(out: &Path) -> Result<PathBuf, Error> {
    let build: String = crate::provenance::build_id()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '.' { c } else { '-' })
        .collect();
    let copy = std::fs::canonicalize(slurm_dir(out))
        .map_err(|e| Error::io("resolve", slurm_dir(out), e))?
        .join(format!("granflow-{build}"));
    if !copy.exists() {
        let own = std::fs::read("/proc/self/exe")
            .or_else(|_| std::env::current_exe().and_then(std::fs::read))
            .map_err(|e| Error::External(format!("cannot read the granflow binary to copy it for Slurm: {e}")))?;
        write_atomic(&copy, &own)?;
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&copy, std::fs::Permissions::from_mode(0o755))
            .map_err(|e| Error::io("make executable", &copy, e))?;
    }
    Ok(copy)
}

/// Submits `jobs` as one array; returns each job's array task (`<array id>_<k>`), in order.
fn submit(spec: &SlurmExecutor, out: &Path, campaign: &str, jobs: &[JobSpec]) -> Result<Vec<String>, Error> {
    let dir = slurm_dir(out);
    std::fs::create_dir_all(&dir).map_err(|e| Error::io("create directory", &dir, e))?;
    let exe = task_executable(out)?;
    let dir = std::fs::canonicalize(&dir).map_err(|e| Error::io("resolve", &dir, e))?;
    let number = std::fs::read_dir(&dir)
        .map_err(|e| Error::io("list", &dir, e))?
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.file_name().to_string_lossy().ends_with(".list"))
        })
        .count();
    let list = dir.join(format!("array-{number}.list"));
    let lines: Vec<String> = jobs
        .iter()
        .map(|j| {
            std::fs::canonicalize(job_dir(out, &j.job_id))
                .map(|p| p.display().to_string())
                .map_err(|e| Error::io("resolve", job_dir(out, &j.job_id), e))
        })
        .collect::<Result<_, _>>()?;
    write_atomic(&list, (lines.join("\n") + "\n").as_bytes())?;
    let script = dir.join(format!("array-{number}.sh"));
    write_atomic(
        &script,
        batch_script(&exe, &list, spec.cpus_per_task, campaign).as_bytes(),
    )?;
    let mut args = vec!["--parsable".to_string()];
    args.extend(sbatch_options(spec, &slurm_job_name(out)));
    let throttle = spec.array_throttle.map(|n| format!("%{n}")).unwrap_or_default();
    args.push(format!("--array=0-{}{throttle}", jobs.len() - 1));
    args.push(format!(
        "--output={}",
        dir.join(format!("array-{number}_%a.out")).display()
    ));
    args.push(script.display().to_string());
    let output = slurm_command("sbatch", &args)?;
    if !output.status.success() {
        // Nothing was submitted and no job marked: a usage error (exit 2), as the settings are what Slurm refuses.
        return Err(Error::Usage(format!(
            "sbatch refused array {number} ({} jobs): {}",
            jobs.len(),
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    let printed = String::from_utf8_lossy(&output.stdout);
    let array_id = printed.trim().split(';').next().unwrap_or("").to_string();
    if array_id.is_empty() || !array_id.chars().all(|c| c.is_ascii_digit()) {
        return Err(Error::External(format!(
            "sbatch printed no job id for array {number}: {printed:?}"
        )));
    }
    Ok((0..jobs.len()).map(|k| format!("{array_id}_{k}")).collect())
}

/// The campaign's tasks Slurm still has, by job name: task (`<array>_<k>`) → (state, batch script path).
fn queued_tasks(job_name: &str) -> Result<HashMap<String, (String, String)>, Error> {
    let args: Vec<String> = ["-h", "-r", "--name", job_name, "-o", "%i|%T|%o"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let output = slurm_command("squeue", &args)?;
    if !output.status.success() {
        return Err(Error::External(format!(
            "squeue failed: {}",
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    Ok(String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter_map(|line| {
            let mut parts = line.trim().splitn(3, '|');
            let (task, state, script) = (parts.next()?, parts.next()?, parts.next().unwrap_or(""));
            Some((task.to_string(), (state.to_string(), script.to_string())))
        })
        .collect())
}

/// The state Slurm's accounting gives an ended task (`sacct`; `None` where the cluster keeps no accounting or
/// `sacct` is missing).
fn accounted_end(task: &str) -> Option<String> {
    let output = Command::new("sacct")
        .args(["-n", "-P", "-X", "-j", task, "-o", "State"])
        .output()
        .ok()?;
    if !output.status.success() {
        return None;
    }
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .map(str::to_string)
}

/// The failure class of a task Slurm ended, by its accounting state (`TIMEOUT`, `OUT_OF_MEMORY`, `NODE_FAIL`,
/// `CANCELLED by …`, …).
fn class_of_slurm_state(state: &str) -> FailureClass {
    match state.split_whitespace().next().unwrap_or("") {
        "TIMEOUT" | "DEADLINE" => FailureClass::Timeout,
        "OUT_OF_MEMORY" | "FAILED" => FailureClass::Crash,
        "NODE_FAIL" | "BOOT_FAIL" => FailureClass::Lost,
        "PREEMPTED" | "REQUEUED" => FailureClass::Preempted,
        _ => FailureClass::Killed,
    }
}

/// One end of a worker under Slurm, as its batch script recorded it.
#[derive(Debug, Clone, Deserialize)]
struct TaskEnd {
    task: String,
    exit: i32,
}

/// The ends recorded in a job directory, oldest first (a line cut short by a kill is skipped).
fn task_ends(dir: &Path) -> Vec<TaskEnd> {
    std::fs::read_to_string(dir.join("slurm-attempts.jsonl"))
        .unwrap_or_default()
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect()
}

/// The last progress message in the job's `messages.jsonl` (read from its last 4 KiB).
fn last_progress(dir: &Path) -> Option<(u64, f64)> {
    let mut file = std::fs::File::open(dir.join("messages.jsonl")).ok()?;
    let length = file.metadata().ok()?.len();
    file.seek(SeekFrom::Start(length.saturating_sub(4096))).ok()?;
    let mut tail = String::new();
    file.read_to_string(&mut tail).ok()?;
    tail.lines().rev().find_map(|l| match Message::parse(l)?.event {
        Event::Progress { step, time_s, .. } => Some((step, time_s)),
        _ => None,
    })
}

/// A job whose task the dispatcher follows.
struct Followed {
    job: JobSpec,
    attempt: u32,
    task: String,
    state: String,
    /// Task ends already counted (lines of `slurm-attempts.jsonl`).
    ends_seen: usize,
}

/// What the Slurm dispatcher needs besides the store.
pub struct SlurmSettings<'a> {
    pub spec: &'a SlurmExecutor,
    pub out: &'a Path,
    pub campaign: &'a str,
    pub retry: &'a RetryPolicy,
    pub campaign_id: i64,
}

/// Submits `queue` and follows every task (the ones a previous dispatcher submitted too) until each job is done or
/// failed for good, or until SIGINT/SIGTERM (the tasks go on). Returns whether it was interrupted.
pub fn dispatch(
    store: &mut Store,
    mut queue: VecDeque<JobSpec>,
    jobs: &HashMap<String, JobSpec>,
    mut attempts: HashMap<String, u32>,
    mut retries_used: HashMap<(String, FailureClass), u32>,
    settings: &SlurmSettings<'_>,
    mut on_event: impl FnMut(&str),
) -> Result<bool, Error> {
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
        signal_hook::flag::register(signal, Arc::clone(&stop))
            .map_err(|e| Error::External(format!("cannot handle signal {signal}: {e}")))?;
    }
    let job_name = slurm_job_name(settings.out);
    let host = "slurm";
    let build = crate::provenance::build_id();

    // The tasks a previous dispatcher submitted: those Slurm still has are followed, the others have ended.
    let mut following: Vec<Followed> = Vec::new();
    for (job_id, attempt, task) in store.slurm_running(settings.campaign_id)? {
        let Some(job) = jobs.get(&job_id) else { continue };
        following.push(Followed {
            job: job.clone(),
            attempt,
            task,
            state: "UNKNOWN".into(),
            ends_seen: task_ends(&job_dir(settings.out, &job_id)).len(),
        });
    }
    // Tasks submitted by a dispatcher that died before it recorded them: found by their batch script's list.
    let queued = if queue.is_empty() {
        HashMap::new()
    } else {
        queued_tasks(&job_name)?
    };
    for (task, (_, script)) in &queued {
        if following.iter().any(|f| &f.task == task) {
            continue;
        }
        let Some(index) = task.rsplit('_').next().and_then(|k| k.parse::<usize>().ok()) else {
            continue;
        };
        let list = Path::new(script).with_extension("list");
        let Some(line) = std::fs::read_to_string(&list)
            .ok()
            .and_then(|t| t.lines().nth(index).map(str::to_string))
        else {
            continue;
        };
        let Some(job_id) = Path::new(&line).file_name().map(|n| n.to_string_lossy().into_owned()) else {
            continue;
        };
        if let Some(position) = queue.iter().position(|j| j.job_id == job_id) {
            let job = queue.remove(position).expect("the position is in the queue");
            let attempt = attempts.get(&job_id).copied().unwrap_or(0) + 1;
            attempts.insert(job_id.clone(), attempt);
            store.mark_running(&job_id, attempt, host, store::unix_time_s(), &build)?;
            store.set_slurm_task(&job_id, task, "UNKNOWN")?;
            tracing::info!(job = %job_id, task, "found in Slurm's queue: following it");
            following.push(Followed {
                ends_seen: task_ends(&job_dir(settings.out, &job_id)).len(),
                job,
                attempt,
                task: task.clone(),
                state: "UNKNOWN".into(),
            });
        }
    }

    let poll = Duration::from_secs_f64(settings.spec.poll_interval_s);
    let mut first = true;
    let mut squeue_failures = 0;
    loop {
        if !stop.load(Ordering::Relaxed) {
            while !queue.is_empty() {
                let batch: Vec<JobSpec> = queue.drain(..queue.len().min(MAX_ARRAY_TASKS)).collect();
                let tasks = submit(settings.spec, settings.out, settings.campaign, &batch)?;
                for (job, task) in batch.into_iter().zip(tasks) {
                    let attempt = attempts.get(&job.job_id).copied().unwrap_or(0) + 1;
                    attempts.insert(job.job_id.clone(), attempt);
                    store.mark_running(&job.job_id, attempt, host, store::unix_time_s(), &build)?;
                    store.set_slurm_task(&job.job_id, &task, "SUBMITTED")?;
                    tracing::info!(job = %job.job_id, attempt, task, "submitted");
                    on_event(&format!("submitted {} as Slurm task {task}", job.job_id));
                    following.push(Followed {
                        ends_seen: task_ends(&job_dir(settings.out, &job.job_id)).len(),
                        job,
                        attempt,
                        task,
                        state: "SUBMITTED".into(),
                    });
                }
            }
        }
        if following.is_empty() || stop.load(Ordering::Relaxed) {
            break;
        }
        if !first {
            let waited = Instant::now();
            while waited.elapsed() < poll && !stop.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(50).min(poll));
            }
            if stop.load(Ordering::Relaxed) {
                break;
            }
        }
        first = false;
        // A failed `squeue` (slurmctld restarting, a network hiccup) skips this look; only a run of them stops
        // the dispatcher (its tasks go on, and `resume` follows them).
        let queued = match queued_tasks(&job_name) {
            Ok(queued) => {
                squeue_failures = 0;
                queued
            }
            Err(e) if squeue_failures + 1 < SQUEUE_FAILURES_TOLERATED => {
                squeue_failures += 1;
                tracing::warn!(error = %e, failures = squeue_failures, "squeue failed; asking again at the next poll");
                continue;
            }
            Err(e) => return Err(e),
        };
        let mut still = Vec::new();
        for mut f in following.drain(..) {
            let dir = job_dir(settings.out, &f.job.job_id);
            // Ends of this task since the last look: a preempted worker whose task requeued itself.
            let ends = task_ends(&dir);
            for end in ends.iter().skip(f.ends_seen).filter(|e| e.task == f.task) {
                if end.exit == EXIT_PREEMPTED && queued.contains_key(&f.task) {
                    let error = format!("preempted: task {} checkpointed on Slurm's signal and requeued", f.task);
                    store.mark_failed(
                        &f.job.job_id,
                        f.attempt,
                        FailureClass::Preempted,
                        &error,
                        store::unix_time_s(),
                        AfterFailure::Retry,
                    )?;
                    store.mark_running(&f.job.job_id, f.attempt, host, store::unix_time_s(), &build)?;
                    store.set_slurm_task(&f.job.job_id, &f.task, "REQUEUED")?;
                    tracing::info!(job = %f.job.job_id, task = %f.task, "preempted and requeued");
                    on_event(&format!("{} preempted; task {} requeued", f.job.job_id, f.task));
                }
            }
            f.ends_seen = ends.len();
            if let Some((state, _)) = queued.get(&f.task) {
                if *state != f.state {
                    store.set_slurm_state(&f.job.job_id, state)?;
                    f.state = state.clone();
                }
                if let Some((step, time_s)) = last_progress(&dir) {
                    store.heartbeat(&f.job.job_id, time_s, step, store::unix_time_s())?;
                }
                still.push(f);
                continue;
            }
            // The task has left the queue.
            store.set_slurm_state(&f.job.job_id, "ENDED")?;
            match worker::read_result(&dir) {
                Ok(Some(result)) => {
                    super::dispatcher::ingest(store, &f.job.job_id, &result)?;
                    on_event(&format!("done {}", f.job.job_id));
                    continue;
                }
                Ok(None) => {}
                Err(e) => tracing::warn!(job = %f.job.job_id, error = %e, "unreadable result"),
            }
            let last = ends.iter().rev().find(|e| e.task == f.task);
            // The shell's 128 + n: the worker was killed by signal n. Without a record, Slurm's accounting (when
            // the cluster has it) tells why the task ended.
            let accounted = if last.is_none() { accounted_end(&f.task) } else { None };
            let class = match (last, &accounted) {
                (Some(e), _) => worker::protocol::exit_class((e.exit <= 128).then_some(e.exit)),
                (None, Some(state)) => class_of_slurm_state(state),
                (None, None) => FailureClass::Killed,
            };
            let error = match last {
                Some(e) => format!(
                    "Slurm task {} ended without a result: the worker exited with {} (see {})",
                    f.task,
                    e.exit,
                    crate::campaign_dir::worker_log_path(&dir).display()
                ),
                None => format!(
                    "Slurm task {} left the queue without a result and without its batch script recording an \
                     end ({})",
                    f.task,
                    accounted.as_deref().map_or_else(
                        || "killed, cancelled or its node failed; the cluster keeps no accounting to say which".into(),
                        |state| format!("sacct: {state}")
                    )
                ),
            };
            let after = super::dispatcher::after_failure(settings.retry, &mut retries_used, &f.job.job_id, class);
            store.mark_failed(&f.job.job_id, f.attempt, class, &error, store::unix_time_s(), after)?;
            tracing::warn!(job = %f.job.job_id, class = class.as_str(), error, "task ended without a result");
            match after {
                AfterFailure::Retry => queue.push_back(f.job),
                AfterFailure::Final => on_event(&format!("failed {}: {error}", f.job.job_id)),
            }
        }
        following = still;
    }
    Ok(stop.load(Ordering::Relaxed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slurm_states_map_to_failure_classes() {
        assert_eq!(class_of_slurm_state("TIMEOUT"), FailureClass::Timeout);
        assert_eq!(class_of_slurm_state("OUT_OF_MEMORY"), FailureClass::Crash);
        assert_eq!(class_of_slurm_state("NODE_FAIL"), FailureClass::Lost);
        assert_eq!(class_of_slurm_state("PREEMPTED"), FailureClass::Preempted);
        assert_eq!(class_of_slurm_state("CANCELLED by 0"), FailureClass::Killed);
    }

    #[test]
    fn each_submission_asks_for_requeue_and_the_warning_signal() {
        let spec = SlurmExecutor {
            partition: Some("short".into()),
            time_limit: Some("1:00:00".into()),
            cpus_per_task: 4,
            memory: None,
            account: Some("granular".into()),
            qos: None,
            array_throttle: Some(5),
            sbatch_options: vec!["--constraint=skylake".into()],
            signal_before_end_s: 90,
            poll_interval_s: 10.0,
        };
        let args = sbatch_options(&spec, "granflow-0123");
        for wanted in [
            "--job-name=granflow-0123",
            "--cpus-per-task=4",
            "--requeue",
            "--signal=B:TERM@90",
            "--partition=short",
            "--time=1:00:00",
            "--account=granular",
            "--constraint=skylake",
        ] {
            assert!(args.iter().any(|a| a == wanted), "{wanted} missing from {args:?}");
        }
        assert!(!args.iter().any(|a| a.starts_with("--mem") || a.starts_with("--qos")));
    }
}
