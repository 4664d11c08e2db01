//! Reading a campaign directory: `status`, `query` and `export`. All of it goes through a read-only connection, so
//! it is safe while a dispatcher runs. What does not live here: the directory's layout and loading its stored
//! campaign (`crate::campaign_dir`), and the validation report (`crate::report`).

use std::path::{Path, PathBuf};

use crate::campaign::{self, Campaign};
use crate::campaign_dir::{database_path, load_stored_campaign, stored_campaign_id};
use crate::error::Error;
use crate::report::wall_time::WallTime;
use crate::store::{self, JobStatus, Store};

/// Output formats of `query` and `export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    Table,
    Csv,
    Json,
}

fn open(dir: &Path) -> Result<(Store, i64, Campaign), Error> {
    let campaign = load_stored_campaign(dir)?;
    let store = Store::open_read_only(database_path(dir))?;
    let id = stored_campaign_id(&store, &campaign, dir)?;
    Ok((store, id, campaign))
}

/// `granflow status`: jobs by state, running jobs' progress, failures with reasons, an ETA.
pub fn status(dir: &Path) -> Result<String, Error> {
    let (store, id, campaign) = open(dir)?;
    let rows = store.job_summaries(id)?;
    let count = |s: JobStatus| rows.iter().filter(|r| r.status == s).count();
    let (pending, running, done, failed) = (
        count(JobStatus::Pending),
        count(JobStatus::Running),
        count(JobStatus::Done),
        count(JobStatus::Failed),
    );
    let mut out = format!(
        "campaign {} ({}): {} jobs: {done} done, {running} running, {pending} pending, {failed} failed\n",
        campaign.spec.name,
        dir.display(),
        rows.len()
    );
    let live = crate::campaign_dir::is_locked(dir);
    out += &format!(
        "dispatcher: {}\n",
        if live {
            "running"
        } else {
            "not running (`granflow resume` finishes what is left)"
        }
    );
    let jobs_by_id: std::collections::HashMap<&str, &campaign::JobSpec> =
        campaign.jobs.iter().map(|j| (j.job_id.as_str(), j)).collect();
    let label = |id: &str| jobs_by_id.get(id).map(|j| campaign.label(j)).unwrap_or_default();
    for r in rows.iter().filter(|r| r.status == JobStatus::Running) {
        let end = jobs_by_id
            .get(r.job_id.as_str())
            .map_or(f64::NAN, |j| j.scenario.time.end_time_s);
        let slurm = r
            .slurm_task
            .as_ref()
            .map(|task| format!(", Slurm task {task} {}", r.slurm_state.as_deref().unwrap_or("?")))
            .unwrap_or_default();
        out += &format!(
            "  running {} ({}): t = {:.4} of {} s, attempt {}{slurm}{}\n",
            r.job_id,
            label(&r.job_id),
            r.sim_time_s.unwrap_or(0.0),
            end,
            r.attempt,
            if live || r.slurm_task.is_some() {
                ""
            } else {
                " (stale: no dispatcher)"
            }
        );
    }
    for r in rows.iter().filter(|r| r.status == JobStatus::Failed) {
        out += &format!(
            "  failed {} ({}): {}: {}\n",
            r.job_id,
            label(&r.job_id),
            r.exit_class.map_or("unknown", |class| class.as_str()),
            r.error.as_deref().unwrap_or("")
        );
    }
    // A done job's wall time over all its attempts (its result holds only the last one's).
    let attempts = WallTime::of(&store.attempt_spans(id)?).per_job_s;
    let walls: Vec<f64> = rows
        .iter()
        .filter(|r| r.status == JobStatus::Done)
        .filter_map(|r| attempts.get(&r.job_id).copied().or(r.wall_time_s))
        .collect();
    // Each running job: its completed fraction, and, for a first attempt, the wall time it is on course for.
    let running_jobs: Vec<(f64, Option<f64>)> = rows
        .iter()
        .filter(|r| r.status == JobStatus::Running)
        .map(|r| {
            let end = jobs_by_id
                .get(r.job_id.as_str())
                .map_or(f64::NAN, |j| j.scenario.time.end_time_s);
            let fraction = (r.sim_time_s.unwrap_or(0.0) / end).clamp(0.0, 1.0);
            let on_course = match (r.attempt, r.started_at, r.last_heartbeat) {
                (1, Some(start), Some(beat)) if fraction >= 0.01 => Some((beat - start) / fraction),
                _ => None,
            };
            (if fraction.is_finite() { fraction } else { 0.0 }, on_course)
        })
        .collect();
    let parallel = match &campaign.spec.executor {
        // A live dispatcher runs as many at once as it was told (`--max-parallel` may override the file) and the
        // memory budget allows: the jobs running now, while some are still pending.
        crate::campaign::spec::ExecutorSpec::Local(_) if live && running > 0 && pending > 0 => running,
        crate::campaign::spec::ExecutorSpec::Local(local) => {
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            local
                .max_parallel
                .unwrap_or((cores / local.threads_per_job.max(1)).max(1))
        }
        // As many at once as Slurm runs now (at least one).
        crate::campaign::spec::ExecutorSpec::Slurm(_) => rows
            .iter()
            .filter(|r| r.slurm_state.as_deref() == Some("RUNNING"))
            .count()
            .max(1),
    };
    if let Some((eta, per_job)) = status_eta(&walls, &running_jobs, pending, parallel) {
        out += &format!(
            "ETA: about {eta:.0} s ({} jobs left, {per_job:.1} s of wall time each{}, {parallel} in parallel)\n",
            pending + running,
            if walls.is_empty() {
                " as the running jobs are going"
            } else {
                " as the finished jobs took"
            },
        );
    }
    Ok(out)
}

/// `granflow status`'s estimate of the time left and of one job's wall time: the finished jobs' mean wall time
/// (`done_walls`) or, before any has finished, the mean of what the running jobs are on course for; `running`
/// holds each running job's (completed fraction, wall time it is on course for, if known). `None` when nothing is
/// left or there is nothing to go on.
fn status_eta(
    done_walls: &[f64],
    running: &[(f64, Option<f64>)],
    pending: usize,
    parallel: usize,
) -> Option<(f64, f64)> {
    let on_course: Vec<f64> = running.iter().filter_map(|&(_, w)| w).collect();
    let per_job = match (done_walls, on_course.as_slice()) {
        ([], []) => return None,
        ([], w) | (w, _) => w.iter().sum::<f64>() / w.len() as f64,
    };
    let jobs_left = pending as f64 + running.iter().map(|&(f, _)| 1.0 - f).sum::<f64>();
    (jobs_left > 0.0).then(|| (per_job * jobs_left / parallel.max(1) as f64, per_job))
}

/// Resolves a user's parameter name to a stored parameter path: the exact path, or the unique path ending in it.
fn resolve_param(store: &Store, name: &str) -> Result<String, Error> {
    let (_, rows) = store.query_sql("SELECT DISTINCT name FROM params ORDER BY name")?;
    let names: Vec<String> = rows.iter().filter_map(|r| r[0].as_str().map(str::to_string)).collect();
    if names.iter().any(|n| n == name) {
        return Ok(name.to_string());
    }
    let matches: Vec<&String> = names
        .iter()
        .filter(|n| n.ends_with(&format!(".{name}")) || n.ends_with(&format!("]{name}")))
        .collect();
    match matches.as_slice() {
        [one] => Ok((*one).clone()),
        [] => Err(Error::Usage(format!(
            "no swept parameter `{name}`; the sweep sets: {}",
            names.join(", ")
        ))),
        several => Err(Error::Usage(format!(
            "`{name}` is ambiguous: {}",
            several.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", ")
        ))),
    }
}

/// `granflow query --pivot X Y --metric M`.
pub fn pivot(dir: &Path, x: &str, y: &str, metric: &str, filters: &[String], format: Format) -> Result<String, Error> {
    let (p, _) = pivot_of(dir, x, y, metric, filters)?;
    Ok(match format {
        Format::Table => p.to_table(),
        Format::Csv => p.to_csv(),
        Format::Json => p.to_json(),
    })
}

/// The pivot of `metric` over parameters `x` and `y` (swept paths or their unique last keys) of the campaign in
/// `dir`, of only the jobs matching `filters` (`PARAM=VALUE`), with the campaign: `query --pivot` and `plot`.
/// A name that is not swept, an ambiguous one, an unknown metric or a malformed filter is a usage error (exit 2).
pub(crate) fn pivot_of(
    dir: &Path,
    x: &str,
    y: &str,
    metric: &str,
    filters: &[String],
) -> Result<(store::Pivot, Campaign), Error> {
    layout_of(dir, x, Some(y), metric, filters)
}

/// [`pivot_of`], or without `y` the curve of `metric` over `x` alone (`Store::curve_where`).
pub(crate) fn layout_of(
    dir: &Path,
    x: &str,
    y: Option<&str>,
    metric: &str,
    filters: &[String],
) -> Result<(store::Pivot, Campaign), Error> {
    let (store, id, campaign) = open(dir)?;
    let x = resolve_param(&store, x)?;
    let y = y.map(|y| resolve_param(&store, y)).transpose()?;
    let wanted = parse_filters(&store, filters)?;
    let laid_out = match &y {
        Some(y) => store.pivot_where(id, &x, y, metric, &wanted),
        None => store.curve_where(id, &x, metric, &wanted),
    };
    let p = laid_out.map_err(|e| match e {
        store::StoreError::UnknownParameter { .. }
        | store::StoreError::UnknownMetric { .. }
        | store::StoreError::InvalidQuery { .. } => Error::Usage(e.to_string()),
        other => Error::from(other),
    })?;
    Ok((p, campaign))
}

/// `--where PARAM=VALUE` filters with their parameters resolved (a usage error when malformed or unknown).
fn parse_filters(store: &Store, filters: &[String]) -> Result<Vec<(String, store::ParamValue)>, Error> {
    let mut wanted = Vec::new();
    for filter in filters {
        let Some((name, value)) = filter.split_once('=') else {
            return Err(Error::Usage(format!(
                "--where `{filter}`: expected PARAM=VALUE, e.g. radius_m=0.00135"
            )));
        };
        let value = match value.trim().parse::<f64>() {
            Ok(v) => store::ParamValue::Real(v),
            Err(_) => store::ParamValue::Text(value.trim().to_string()),
        };
        wanted.push((resolve_param(store, name.trim())?, value));
    }
    Ok(wanted)
}

/// The done jobs of the campaign in `dir` matching `filters` (`PARAM=VALUE`), in the sweep's order, with the
/// campaign: `plot series`.
pub(crate) fn done_jobs_of(dir: &Path, filters: &[String]) -> Result<(Vec<String>, Campaign), Error> {
    let (store, id, campaign) = open(dir)?;
    let wanted = parse_filters(&store, filters)?;
    let jobs = store.done_jobs_where(id, &wanted).map_err(|e| match e {
        store::StoreError::UnknownParameter { .. } => Error::Usage(e.to_string()),
        other => Error::from(other),
    })?;
    Ok((jobs, campaign))
}

/// `granflow query --sql`.
pub fn sql(dir: &Path, query: &str, format: Format) -> Result<String, Error> {
    let store = Store::open_read_only(database_path(dir))?;
    let (header, rows) = store.query_sql(query)?;
    Ok(render(&header, &rows, format))
}

/// `granflow export`: parameters and metrics, one row per job.
///
/// Parameter columns follow the sweep's order (a zipped partner right after the axis it is zipped with), each named
/// as it is stored: its axis name, or its parameter path when the sweep gives it none.
pub fn export(dir: &Path, format: Format) -> Result<String, Error> {
    let (store, id, campaign) = open(dir)?;
    let (header, rows) = store.export_rows(id)?;
    let (header, rows) = in_sweep_order(&campaign, header, rows);
    Ok(render(&header, &rows, format))
}

/// Reorders the `param.*` columns of an export by where the sweep sets each parameter (the order of a job's
/// parameters); other columns keep their places.
fn in_sweep_order(
    campaign: &Campaign,
    header: Vec<String>,
    rows: Vec<Vec<serde_json::Value>>,
) -> (Vec<String>, Vec<Vec<serde_json::Value>>) {
    let sweep_order: Vec<String> = campaign
        .jobs
        .first()
        .map(|job| {
            job.params
                .iter()
                .map(|(path, _)| format!("param.{}", campaign.param_name(path)))
                .collect()
        })
        .unwrap_or_default();
    let param_columns: Vec<usize> = (0..header.len()).filter(|&k| header[k].starts_with("param.")).collect();
    let mut sorted = param_columns.clone();
    sorted.sort_by_key(|&k| sweep_order.iter().position(|p| *p == header[k]).unwrap_or(usize::MAX));
    let mut order: Vec<usize> = (0..header.len()).collect();
    for (slot, from) in param_columns.iter().zip(&sorted) {
        order[*slot] = *from;
    }
    let header = order.iter().map(|&k| header[k].clone()).collect();
    let rows = rows
        .into_iter()
        .map(|row| order.iter().map(|&k| row[k].clone()).collect())
        .collect();
    (header, rows)
}

fn render(header: &[String], rows: &[Vec<serde_json::Value>], format: Format) -> String {
    match format {
        Format::Table => store::render_table(header, rows),
        Format::Csv => store::render_csv(header, rows),
        Format::Json => store::render_json(header, rows),
    }
}

/// The directory `run` uses for a campaign file.
pub fn run_dir(campaign: &Campaign, out: Option<&Path>) -> PathBuf {
    campaign::output_dir(&campaign.spec, out)
}

#[cfg(test)]
mod tests {
    use super::status_eta;

    #[test]
    fn status_eta_uses_finished_jobs_then_running_ones() {
        // Two jobs done at 40 s each; one running, half done; two pending; two at a time: 2.5 jobs × 40 s / 2.
        assert_eq!(
            status_eta(&[40.0, 40.0], &[(0.5, Some(90.0))], 2, 2),
            Some((50.0, 40.0))
        );
        // Nothing finished: the running jobs' courses (60 s and 80 s) give the per-job time.
        let (eta, per_job) = status_eta(&[], &[(0.25, Some(60.0)), (0.5, Some(80.0))], 4, 2).unwrap();
        assert_eq!(per_job, 70.0);
        assert!((eta - 70.0 * 5.25 / 2.0).abs() < 1e-12, "{eta}");
        // Nothing to go on (a resumed job has no course of its own), or nothing left.
        assert_eq!(status_eta(&[], &[(0.5, None)], 3, 2), None);
        assert_eq!(status_eta(&[30.0], &[], 0, 2), None);
    }
}
