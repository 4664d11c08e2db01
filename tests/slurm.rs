//! Campaigns on a real Slurm: a one-node cluster (Debian's `slurm-wlm` and `munge`) started by this test in a
//! temporary directory, on its own ports and socket, so that a Slurm the machine already runs is never touched.
//! Needs root (the daemons run as root) and the packages: `apt-get install slurm-wlm munge` (`.ci/run` installs
//! them).
//!
//! What is checked: a campaign run on Slurm ends with the same metrics, series and final states, bit for bit, as the
//! same campaign run locally; a task warned by Slurm (SIGTERM) checkpoints, requeues itself and ends bit-identical,
//! counted as preempted; a dispatcher killed with `kill -9` while tasks run is resumed without submitting any job
//! twice; jobs wait on a drained node and finish when it is resumed; bad executor settings (an unknown partition, a
//! time limit Slurm rejects, no `sbatch`) exit 2 before anything is written.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use common::final_state;

/// A one-node Slurm cluster in a temporary directory; stopped (its daemons killed) when dropped.
struct Cluster {
    dir: tempfile::TempDir,
    node: String,
}

impl Cluster {
    fn conf(&self) -> PathBuf {
        self.dir.path().join("slurm.conf")
    }

    /// Starts munged, slurmctld and slurmd; waits until the node is idle.
    fn start() -> Cluster {
        for program in ["munged", "slurmctld", "slurmd", "sbatch"] {
            assert!(
                Command::new("sh")
                    .args(["-c", &format!("command -v {program}")])
                    .output()
                    .is_ok_and(|o| o.status.success()),
                "`{program}` is missing: these tests need a Slurm to run on (apt-get install slurm-wlm munge)"
            );
        }
        let dir = tempfile::Builder::new()
            .prefix("granflow-slurm-")
            .tempdir()
            .expect("temp dir");
        let d = dir.path();
        for sub in ["state", "spool", "log"] {
            std::fs::create_dir_all(d.join(sub)).unwrap();
        }
        // A key of our own: the test's munged never shares the machine's.
        let key: Vec<u8> = (0..1024u32).map(|k| (k.wrapping_mul(2654435761) >> 13) as u8).collect();
        std::fs::write(d.join("munge.key"), key).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(d.join("munge.key"), std::fs::Permissions::from_mode(0o400)).unwrap();
        let path = |name: &str| d.join(name).display().to_string();
        let munged = Command::new("munged")
            .arg("--force")
            .arg(format!("--socket={}", path("munge.sock")))
            .arg(format!("--key-file={}", path("munge.key")))
            .arg(format!("--log-file={}", path("log/munged.log")))
            .arg(format!("--pid-file={}", path("munged.pid")))
            .arg(format!("--seed-file={}", path("munged.seed")))
            .status()
            .expect("munged runs");
        assert!(munged.success(), "munged did not start");
        let node = String::from_utf8(Command::new("hostname").output().unwrap().stdout)
            .unwrap()
            .trim()
            .to_string();
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        // Two ports the system has free now (each test starts its own cluster; never Slurm's 6817/6818).
        let free_port = || {
            std::net::TcpListener::bind("0.0.0.0:0")
                .and_then(|l| l.local_addr())
                .expect("a free port")
                .port()
        };
        let (port, node_port) = (free_port(), free_port());
        let conf = format!(
            "ClusterName=granflowtest\nSlurmctldHost={node}\nSlurmctldPort={port}\nSlurmdPort={}\n\
             AuthType=auth/munge\nAuthInfo=socket={}\nCryptoType=crypto/munge\nSlurmUser=root\nSlurmdUser=root\n\
             StateSaveLocation={}\nSlurmdSpoolDir={}\nSlurmctldPidFile={}\nSlurmdPidFile={}\n\
             SlurmctldLogFile={}\nSlurmdLogFile={}\nProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
             SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\nAccountingStorageType=accounting_storage/none\n\
             JobAcctGatherType=jobacct_gather/none\nJobCompType=jobcomp/none\nMpiDefault=none\nReturnToService=2\n\
             SchedulerType=sched/backfill\nMinJobAge=300\nKillWait=30\n\
             NodeName={node} CPUs={cpus} State=UNKNOWN\n\
             PartitionName=debug Nodes={node} Default=YES MaxTime=60 State=UP\n",
            node_port,
            path("munge.sock"),
            path("state"),
            path("spool"),
            path("slurmctld.pid"),
            path("slurmd.pid"),
            path("log/slurmctld.log"),
            path("log/slurmd.log"),
        );
        std::fs::write(d.join("slurm.conf"), conf).unwrap();
        let cluster = Cluster { dir, node };
        for daemon in ["slurmctld", "slurmd"] {
            let ok = Command::new(daemon)
                .arg("-f")
                .arg(cluster.conf())
                .env("SLURM_CONF", cluster.conf())
                .status()
                .expect("the daemon runs");
            assert!(
                ok.success(),
                "{daemon} did not start: see {}",
                cluster.dir.path().join("log").display()
            );
        }
        let started = Instant::now();
        loop {
            let out = cluster.client("sinfo", &["-h", "-o", "%T"]);
            let state = String::from_utf8_lossy(&out.stdout).trim().to_string();
            if state == "idle" {
                break;
            }
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "the test cluster's node is `{state}`, not idle, after 60 s: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            std::thread::sleep(Duration::from_millis(200));
        }
        cluster
    }

    /// Runs a Slurm client command against this cluster.
    fn client(&self, program: &str, args: &[&str]) -> Output {
        Command::new(program)
            .args(args)
            .env("SLURM_CONF", self.conf())
            .output()
            .expect("the Slurm client runs")
    }

    /// A granflow command against this cluster, in `cwd`.
    fn granflow(&self, args: &[&str], cwd: &Path) -> Command {
        let mut command = Command::new(env!("CARGO_BIN_EXE_granflow"));
        command.args(args).current_dir(cwd).env("SLURM_CONF", self.conf());
        command
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        // Every task of this cluster (all of them are the test's), then its daemons.
        let _ = self.client("scancel", &["--full", "--user=root"]);
        std::thread::sleep(Duration::from_millis(500));
        for pid_file in ["slurmd.pid", "slurmctld.pid", "munged.pid"] {
            if let Ok(pid) = std::fs::read_to_string(self.dir.path().join(pid_file)) {
                let _ = Command::new("kill").arg(pid.trim()).status();
            }
        }
        std::thread::sleep(Duration::from_millis(300));
    }
}

/// Three drum jobs of 0.05 s (2,500 steps), checkpointed every 500 steps, with `executor` (a YAML mapping).
fn campaign(name: &str, executor: &str, end_time_s: f64) -> String {
    let base = common::drum_slice_base(0.0, end_time_s, 100);
    format!(
        r#"
name: {name}
seed: 5
{base}sweep:
  grid:
    - {{ param: walls.0.drum.rotation_rpm, name: rotation_rpm, values: [10.0, 20.0, 40.0] }}
metrics: [kinetic_energy_j, coordination_number, mixing_rate_constant_per_s]
analysis: {{ mixing_species: red }}
checkpoint: {{ every_steps: 500, keep: 2 }}
executor: {executor}
"#
    )
}

const SLURM: &str = "{ slurm: { partition: debug, time_limit: \"10\", poll_interval_s: 0.3 } }";

/// The metrics of every job as CSV rows (job id, name, value), in a stable order.
fn metrics(cluster: &Cluster, dir: &Path, campaign_dir: &str) -> String {
    let out = cluster
        .granflow(
            &[
                "query",
                campaign_dir,
                "--sql",
                "SELECT job_id, name, value FROM metrics ORDER BY job_id, name",
                "--format",
                "csv",
            ],
            dir,
        )
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// The job directories of a campaign directory, sorted.
fn job_dirs(campaign_dir: &Path) -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(campaign_dir.join("jobs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    dirs
}

/// Asserts that two campaign directories' jobs end with identical series and final states.
fn assert_same_jobs(a: &Path, b: &Path) {
    let (a_jobs, b_jobs) = (job_dirs(a), job_dirs(b));
    assert_eq!(a_jobs.len(), b_jobs.len());
    for (x, y) in a_jobs.iter().zip(&b_jobs) {
        assert_eq!(x.file_name(), y.file_name(), "the same job ids");
        assert_eq!(
            std::fs::read(x.join("series.csv")).unwrap(),
            std::fs::read(y.join("series.csv")).unwrap(),
            "series of {}",
            x.display()
        );
        assert!(final_state(x) == final_state(y), "final state of {}", x.display());
    }
}

fn sql(cluster: &Cluster, dir: &Path, campaign_dir: &str, query: &str) -> String {
    let out = cluster
        .granflow(&["query", campaign_dir, "--sql", query, "--format", "csv"], dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn campaigns_run_on_a_real_slurm() {
    let cluster = Cluster::start();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();

    // Bad executor settings: exit 2 before anything is written.
    let refused = |executor: &str, message: &str, path: Option<&str>| {
        std::fs::write(dir.join("bad.yaml"), campaign("bad", executor, 0.05)).unwrap();
        let mut command = cluster.granflow(&["run", "bad.yaml", "--out", "bad", "--quiet"], dir);
        if let Some(p) = path {
            command.env("PATH", p);
        }
        let out = command.output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{executor}: {stderr}");
        assert!(stderr.contains(message), "{executor}: expected `{message}` in {stderr}");
        assert!(!dir.join("bad").exists(), "{executor}: nothing written");
    };
    refused(
        "{ slurm: { partition: nosuch } }",
        "invalid partition specified: nosuch",
        None,
    );
    refused(
        "{ slurm: { time_limit: \"soon\" } }",
        "Invalid --time specification",
        None,
    );
    refused("{ slurm: {} }", "`sbatch` is not on the PATH", Some("/nonexistent"));

    // The same campaign locally and on Slurm: the same bits.
    std::fs::write(
        dir.join("local.yaml"),
        campaign("drums", "{ local: { max_parallel: 2 } }", 0.05),
    )
    .unwrap();
    std::fs::write(dir.join("slurm.yaml"), campaign("drums", SLURM, 0.05)).unwrap();
    let run = |file: &str, out: &str| {
        let output = cluster
            .granflow(&["run", file, "--out", out, "--quiet"], dir)
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    };
    let started = Instant::now();
    run("slurm.yaml", "on-slurm");
    println!("3 jobs on Slurm: {:.1} s", started.elapsed().as_secs_f64());
    run("local.yaml", "local");
    let on_slurm = metrics(&cluster, dir, "on-slurm");
    assert_eq!(on_slurm.lines().count(), 1 + 3 * 3, "{on_slurm}");
    assert_eq!(on_slurm, metrics(&cluster, dir, "local"));
    assert_same_jobs(&dir.join("on-slurm"), &dir.join("local"));
    let tasks = sql(
        &cluster,
        dir,
        "on-slurm",
        "SELECT status, slurm_state, slurm_task IS NOT NULL FROM jobs",
    );
    assert_eq!(tasks.lines().filter(|l| *l == "done,ENDED,1").count(), 3, "{tasks}");
    // A finished campaign resumes without asking Slurm anything (e.g. its results copied to a laptop).
    let resumed = cluster
        .granflow(&["resume", "on-slurm", "--quiet"], dir)
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
}

/// Polls `what` every 100 ms until it returns `Some`, failing after `limit_s` with `waiting_for` in the message.
fn wait_for<T>(limit_s: u64, waiting_for: &str, mut what: impl FnMut() -> Option<T>) -> T {
    let started = Instant::now();
    loop {
        if let Some(v) = what() {
            return v;
        }
        assert!(
            started.elapsed() < Duration::from_secs(limit_s),
            "waited {limit_s} s for {waiting_for}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The campaign's tasks as `squeue` lists them: (task, state, reason).
fn tasks_in_queue(cluster: &Cluster) -> Vec<(String, String, String)> {
    let out = cluster.client("squeue", &["-h", "-r", "-o", "%i|%T|%r"]);
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| {
            let mut p = l.trim().split('|');
            Some((p.next()?.to_string(), p.next()?.to_string(), p.next()?.to_string()))
        })
        .collect()
}

/// Whether a worker of the job started from a checkpoint (its `started` message in `messages.jsonl`).
fn resumed_from_checkpoint(job: &Path) -> bool {
    std::fs::read_to_string(job.join("messages.jsonl"))
        .unwrap_or_default()
        .lines()
        .any(|l| l.contains("\"event\":\"started\"") && !l.contains("\"resumed_from_step\":null"))
}

/// Checkpoint files in a job directory.
fn checkpoints(job: &Path) -> usize {
    std::fs::read_dir(job)
        .map(|d| {
            d.filter(|e| {
                e.as_ref()
                    .is_ok_and(|e| e.file_name().to_string_lossy().starts_with("ckpt-"))
            })
            .count()
        })
        .unwrap_or(0)
}

/// `granflow run slurm.yaml --out <out>` in `dir` against the cluster, in the background.
fn spawn_dispatcher(cluster: &Cluster, dir: &Path, out: &str) -> std::process::Child {
    cluster
        .granflow(&["run", "slurm.yaml", "--out", out, "--quiet"], dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap()
}

/// Waits for a running task of the campaign in `dir/<out>` whose job has written at least two checkpoints;
/// returns the task and its job directory.
fn running_task_with_checkpoints(cluster: &Cluster, dir: &Path, out: &str) -> (String, PathBuf) {
    wait_for(120, "a running task with a checkpoint", || {
        let running = tasks_in_queue(cluster)
            .into_iter()
            .find(|(_, state, _)| state == "RUNNING")?;
        let list = std::fs::read_to_string(dir.join(out).join("slurm/array-0.list")).ok()?;
        let index: usize = running.0.rsplit('_').next()?.parse().ok()?;
        let job = PathBuf::from(list.lines().nth(index)?);
        (checkpoints(&job) >= 2).then_some((running.0, job))
    })
}

#[test]
fn slurm_tasks_survive_preemption_a_killed_dispatcher_and_a_drained_node() {
    let cluster = Cluster::start();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Jobs of 0.6 s (30,000 steps, several seconds each), the reference run locally.
    std::fs::write(
        dir.join("local.yaml"),
        campaign("long", "{ local: { max_parallel: 2 } }", 0.6),
    )
    .unwrap();
    std::fs::write(dir.join("slurm.yaml"), campaign("long", SLURM, 0.6)).unwrap();
    let local = cluster
        .granflow(&["run", "local.yaml", "--out", "local", "--quiet"], dir)
        .output()
        .unwrap();
    assert!(local.status.success(), "{}", String::from_utf8_lossy(&local.stderr));

    let clock = Instant::now();
    // 1. Preemption: Slurm's warning (SIGTERM to the batch script) to a running task that has checkpointed.
    let mut dispatcher = spawn_dispatcher(&cluster, dir, "preempted");
    let (task, job) = running_task_with_checkpoints(&cluster, dir, "preempted");
    let warned = cluster.client("scancel", &["--batch", "--signal=TERM", &task]);
    assert!(warned.status.success(), "{}", String::from_utf8_lossy(&warned.stderr));
    // The task records its end (exit 10: checkpointed on the signal) and requeues itself; Slurm holds a requeued
    // task back for about two minutes, which the test cuts short.
    wait_for(60, "the preempted worker's end record", || {
        std::fs::read_to_string(job.join("slurm-attempts.jsonl"))
            .ok()
            .filter(|t| t.contains("\"exit\":10"))
    });
    wait_for(60, "the requeued task to start again", || {
        let _ = cluster.client("scontrol", &["update", &format!("jobid={task}"), "StartTime=now"]);
        tasks_in_queue(&cluster)
            .iter()
            .any(|(t, state, _)| *t == task && state == "RUNNING")
            .then_some(())
            .or_else(|| resumed_from_checkpoint(&job).then_some(()))
    });
    let status = dispatcher.wait().unwrap();
    assert!(status.success(), "the dispatcher ends well");
    assert!(
        resumed_from_checkpoint(&job),
        "the requeued task resumed from its checkpoint"
    );
    assert_same_jobs(&dir.join("preempted"), &dir.join("local"));
    let attempts = sql(
        &cluster,
        dir,
        "preempted",
        "SELECT exit_class, count(*) FROM attempts WHERE exit_class IS NOT NULL GROUP BY exit_class",
    );
    assert_eq!(
        attempts, "exit_class,count(*)\npreempted,1\n",
        "counted as preempted, not failed"
    );
    assert_eq!(
        sql(
            &cluster,
            dir,
            "preempted",
            "SELECT status, count(*) FROM jobs GROUP BY status"
        ),
        "status,count(*)\ndone,3\n"
    );

    println!("{:.1} s", clock.elapsed().as_secs_f64());
    // 2. The dispatcher killed (-9) while its tasks run; `resume` follows them: nothing submitted twice.
    let mut dispatcher = spawn_dispatcher(&cluster, dir, "killed");
    wait_for(120, "a running task", || {
        tasks_in_queue(&cluster)
            .iter()
            .any(|(_, state, _)| state == "RUNNING")
            .then_some(())
    });
    dispatcher.kill().unwrap();
    dispatcher.wait().unwrap();
    let resumed = cluster
        .granflow(&["resume", "killed", "--quiet"], dir)
        .output()
        .unwrap();
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
    let lists = std::fs::read_dir(dir.join("killed/slurm"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().ends_with(".list"))
        .count();
    assert_eq!(lists, 1, "one submission: no job submitted twice");
    assert_eq!(
        sql(
            &cluster,
            dir,
            "killed",
            "SELECT status, attempt, count(*) FROM jobs GROUP BY status, attempt"
        ),
        "status,attempt,count(*)\ndone,1,3\n"
    );
    assert_same_jobs(&dir.join("killed"), &dir.join("local"));

    println!("{:.1} s", clock.elapsed().as_secs_f64());
    // 2b. A worker killed without warning (SIGKILL; its batch script records exit 137): the job is retried under
    // its `killed` budget, in a new submission, and resumes from its last checkpoint.
    let mut dispatcher = spawn_dispatcher(&cluster, dir, "hard");
    let (task, job) = running_task_with_checkpoints(&cluster, dir, "hard");
    // The worker's pid from its `started` message; SIGKILL as a crashed node or the OOM killer would.
    let pid = std::fs::read_to_string(job.join("messages.jsonl"))
        .unwrap()
        .lines()
        .rfind(|l| l.contains("\"event\":\"started\""))
        .and_then(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .and_then(|m| m["pid"].as_u64())
        .expect("the worker's started message");
    let killed = Command::new("kill").args(["-KILL", &pid.to_string()]).status().unwrap();
    assert!(killed.success());
    assert!(dispatcher.wait().unwrap().success());
    assert!(
        std::fs::read_to_string(job.join("slurm-attempts.jsonl"))
            .unwrap()
            .contains(&format!("{{\"task\":\"{task}\",\"exit\":137,")),
        "the batch script recorded the worker's death by SIGKILL"
    );
    let lists = std::fs::read_dir(dir.join("hard/slurm"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().ends_with(".list"))
        .count();
    assert_eq!(lists, 2, "the killed job went out again in a second submission");
    assert_eq!(
        sql(
            &cluster,
            dir,
            "hard",
            "SELECT exit_class, count(*) FROM attempts WHERE exit_class IS NOT NULL GROUP BY exit_class"
        ),
        "exit_class,count(*)\nkilled,1\n"
    );
    assert!(resumed_from_checkpoint(&job), "the retry resumed from a checkpoint");
    assert_same_jobs(&dir.join("hard"), &dir.join("local"));

    println!("{:.1} s", clock.elapsed().as_secs_f64());
    // 3. A node drained mid-campaign: the running tasks finish, the pending one waits; resumed, it runs.
    let mut dispatcher = spawn_dispatcher(&cluster, dir, "drained");
    wait_for(60, "two running tasks and one pending", || {
        let tasks = tasks_in_queue(&cluster);
        let count = |s: &str| tasks.iter().filter(|(_, state, _)| state == s).count();
        (count("RUNNING") == 2 && count("PENDING") == 1).then_some(())
    });
    let node = format!("nodename={}", cluster.node);
    let drained = cluster.client("scontrol", &["update", &node, "state=drain", "reason=granflow-test"]);
    assert!(drained.status.success(), "{}", String::from_utf8_lossy(&drained.stderr));
    wait_for(120, "the running tasks to finish", || {
        let tasks = tasks_in_queue(&cluster);
        (tasks.len() == 1 && tasks[0].1 == "PENDING").then_some(())
    });
    std::thread::sleep(Duration::from_secs(3));
    let waiting = tasks_in_queue(&cluster);
    assert!(
        waiting.len() == 1 && waiting[0].1 == "PENDING" && waiting[0].2.contains("DRAINED"),
        "the last task waits for the drained node: {waiting:?}"
    );
    assert!(dispatcher.try_wait().unwrap().is_none(), "the dispatcher waits");
    let status = cluster.granflow(&["status", "drained"], dir).output().unwrap();
    let status = String::from_utf8_lossy(&status.stdout);
    assert!(
        status.contains("2 done, 1 running") && status.contains(&format!("Slurm task {} PENDING", waiting[0].0)),
        "{status}"
    );
    let resumed = cluster.client("scontrol", &["update", &node, "state=resume"]);
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
    assert!(dispatcher.wait().unwrap().success());
    assert_same_jobs(&dir.join("drained"), &dir.join("local"));
}
