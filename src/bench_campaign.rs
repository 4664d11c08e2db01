//! `granflow bench campaign`: the dispatcher's own cost. Runs a campaign of one-step jobs (one particle in a box,
//! so the simulation itself costs nothing) and reports the wall time per job, process spawn, checkpoints, series,
//! result and database ingestion included; then times `resume` of the same campaign with every job done. With
//! `--slurm` the same campaign also runs on the Slurm the environment points to (`executor: slurm`, one array, its
//! default partition), and both figures are printed side by side.

use std::time::Instant;

use crate::campaign;
use crate::error::{Error, Result};
use crate::orchestrate::dispatcher::{DispatchOptions, run_campaign};

#[derive(Debug, Clone)]
pub struct CampaignBenchOptions {
    pub jobs: usize,
    pub max_parallel: usize,
    /// Also run the campaign on Slurm and compare.
    pub slurm: bool,
}

/// The Slurm executor of the comparison: the cluster's defaults, polled twice a second.
const SLURM_EXECUTOR: &str = "executor: { slurm: { poll_interval_s: 0.5 } }\n";

fn campaign_yaml(jobs: usize) -> String {
    format!(
        r#"
name: dispatcher-overhead
seed: 1
max_jobs: {jobs}
base:
  domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.01, 0.01, 0.01] }}
  gravity: {{ vector_m_per_s2: [0.0, 0.0, -9.81] }}
  species:
    - {{ name: g, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3 }}
  contact: {{ normal: {{ hertz: {{ restitution: 0.9 }} }}, tangential: mindlin }}
  walls: [ {{ box: {{ species: g }} }} ]
  fill: [ {{ explicit: {{ species: g, positions_m: [[0.005, 0.005, 0.005]] }} }} ]
  time: {{ dt_s: 1.0e-6, end_time_s: 1.0e-6 }}
sweep:
  param: fill.0.explicit.positions_m.0.0
  linspace: {{ start: 0.002, stop: 0.008, num: {jobs} }}
metrics: [kinetic_energy_j]
"#
    )
}

/// CPU seconds this process (the dispatcher, not its workers) has used.
fn own_cpu_s() -> f64 {
    nix::sys::resource::getrusage(nix::sys::resource::UsageWho::RUSAGE_SELF).map_or(f64::NAN, |u| {
        let t = |tv: nix::sys::time::TimeVal| tv.tv_sec() as f64 + 1e-6 * tv.tv_usec() as f64;
        t(u.user_time()) + t(u.system_time())
    })
}

/// Runs the campaign `file` into `out` to the end; returns its wall seconds and the dispatcher's own CPU
/// milliseconds per job. Fails unless every job finished.
fn timed_run(
    file: &std::path::Path,
    out: &std::path::Path,
    dispatch: &DispatchOptions,
    jobs: usize,
    where_: &str,
) -> Result<(f64, f64)> {
    let (t, cpu) = (Instant::now(), own_cpu_s());
    let loaded = campaign::load(file)?;
    let outcome = run_campaign(&loaded, file, out, dispatch)?;
    let wall_s = t.elapsed().as_secs_f64();
    let cpu_ms = 1e3 * (own_cpu_s() - cpu) / jobs as f64;
    if outcome.done != jobs {
        return Err(Error::External(format!(
            "{where_}only {} of {} jobs finished ({} failed); see {}",
            outcome.done,
            jobs,
            outcome.failed,
            out.join("campaign.log").display()
        )));
    }
    Ok((wall_s, cpu_ms))
}

pub fn bench_campaign(opts: &CampaignBenchOptions) -> Result<()> {
    let tmp = tempfile::tempdir().map_err(|e| Error::External(format!("cannot create a temporary directory: {e}")))?;
    let file = tmp.path().join("overhead.yaml");
    std::fs::write(&file, campaign_yaml(opts.jobs)).map_err(|e| Error::io("write", &file, e))?;
    let out = tmp.path().join("out");
    let dispatch = DispatchOptions {
        max_parallel: Some(opts.max_parallel),
        threads_per_job: Some(1),
        quiet: true,
        force: false,
    };

    // A failed run keeps the temporary directory for its campaign.log.
    let (run_s, local_cpu_ms) = match timed_run(&file, &out, &dispatch, opts.jobs, "") {
        Ok(times) => times,
        Err(e) => {
            let _ = tmp.keep();
            return Err(e);
        }
    };
    let per_job_ms = 1e3 * run_s / opts.jobs as f64;
    println!(
        "run: {} one-step jobs, {} at a time: {:.2} s, {:.1} ms per job; each job held a worker slot {:.1} ms \
         (spawn, checkpoints, series, result, ingestion)",
        opts.jobs,
        opts.max_parallel,
        run_s,
        per_job_ms,
        per_job_ms * opts.max_parallel as f64
    );

    let t = Instant::now();
    let loaded = campaign::load(&file)?;
    let outcome = run_campaign(&loaded, &file, &out, &dispatch)?;
    let resume_s = t.elapsed().as_secs_f64();
    if outcome.done != opts.jobs || outcome.ingested != 0 {
        return Err(Error::External("resume of a finished campaign changed it".into()));
    }
    println!("resume: {} jobs all done: {:.3} s", opts.jobs, resume_s);
    println!("dispatcher_ms_per_job: {per_job_ms:.2}");
    println!("dispatcher_cpu_ms_per_job: {local_cpu_ms:.2}");
    println!("resume_all_done_s: {resume_s:.3}");
    if opts.slurm {
        let file = tmp.path().join("overhead-slurm.yaml");
        std::fs::write(&file, campaign_yaml(opts.jobs) + SLURM_EXECUTOR).map_err(|e| Error::io("write", &file, e))?;
        let out = tmp.path().join("out-slurm");
        let (slurm_s, slurm_cpu_ms) = match timed_run(&file, &out, &dispatch, opts.jobs, "on Slurm ") {
            Ok(times) => times,
            Err(e) => {
                let _ = tmp.keep();
                return Err(e);
            }
        };
        let slurm_ms = 1e3 * slurm_s / opts.jobs as f64;
        println!(
            "slurm: the same {} jobs as one array on the cluster's default partition: {:.2} s, {:.1} ms per job \
             (submission, Slurm's scheduling and task start, squeue polls every 0.5 s, ingestion)",
            opts.jobs, slurm_s, slurm_ms
        );
        println!("slurm_ms_per_job: {slurm_ms:.2}");
        println!(
            "dispatcher CPU per job (its own process, not the workers or Slurm): local {local_cpu_ms:.2} ms, \
             slurm {slurm_cpu_ms:.2} ms"
        );
        println!("slurm_dispatcher_cpu_ms_per_job: {slurm_cpu_ms:.2}");
        println!("slurm_over_local: {:.2}", slurm_ms / per_job_ms);
    }
    Ok(())
}
