//! The writes of a job's life: registration ([`Store::insert_jobs`]), start, heartbeats, failure, result ingestion
//! and the reset after a dispatcher crash. Each is one transaction, and each keeps `jobs` (the current state) and
//! `attempts` (the history) in step.
//!
//! All writers are idempotent where a crashed dispatcher may repeat them: registering known jobs leaves them alone,
//! and ingesting the same result twice replaces it. What does not live here: the retry policy (the caller says
//! whether a failure is final, [`AfterFailure`]) and which [`FailureClass`] an attempt ended with.

use std::collections::HashSet;
use std::path::Path;

use rusqlite::{Connection, TransactionBehavior, params};

use super::Store;
use super::error::{Context, StoreError};
use super::failure_class::FailureClass;
use super::job::{AfterFailure, JobResult, JobStatus, NewJob, ParamValue};

impl Store {
    /// Registers the jobs of campaign `campaign_id` as `pending`, in one transaction, and returns how many were new.
    /// Jobs whose id is already stored are left untouched (status, attempts, parameters and results are kept), which
    /// is what `resume` needs; an id stored under another campaign is an error and nothing is written.
    pub fn insert_jobs(&mut self, campaign_id: i64, jobs: &[NewJob]) -> Result<usize, StoreError> {
        for job in jobs {
            validate_new_job(&self.path, job)?;
        }
        self.require_campaign(campaign_id)?;
        let path = &self.path;
        let action = format!("inserting jobs of campaign {campaign_id}");
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .context(path, &action)?;
        let mut inserted = 0;
        {
            // ON CONFLICT (job_id) DO NOTHING rather than INSERT OR IGNORE: only a known id is skipped, any other
            // constraint violation still fails loudly.
            let mut insert_job = tx
                .prepare(
                    "INSERT INTO jobs (job_id, campaign_id, ordinal, params_json) VALUES (?1, ?2, ?3, ?4)
                     ON CONFLICT (job_id) DO NOTHING",
                )
                .context(path, &action)?;
            let mut owner = tx
                .prepare("SELECT campaign_id FROM jobs WHERE job_id = ?1")
                .context(path, &action)?;
            let mut insert_param = tx
                .prepare("INSERT INTO params (job_id, name, value_real, value_text) VALUES (?1, ?2, ?3, ?4)")
                .context(path, &action)?;
            for job in jobs {
                let new = insert_job
                    .execute(params![job.job_id, campaign_id, job.ordinal, job.params_json])
                    .context(path, &action)?;
                if new == 0 {
                    let existing_campaign_id: i64 = owner
                        .query_row([&job.job_id], |row| row.get(0))
                        .context(path, &action)?;
                    if existing_campaign_id != campaign_id {
                        return Err(StoreError::JobInOtherCampaign {
                            path: path.clone(),
                            job_id: job.job_id.clone(),
                            campaign_id,
                            existing_campaign_id,
                        });
                    }
                    continue;
                }
                inserted += 1;
                for (name, value) in &job.params {
                    let (real, text) = match value {
                        ParamValue::Real(value) => (Some(*value), None),
                        ParamValue::Text(text) => (None, Some(text.as_str())),
                    };
                    insert_param
                        .execute(params![job.job_id, name, real, text])
                        .context(path, &action)?;
                }
            }
        }
        tx.commit().context(path, &action)?;
        Ok(inserted)
    }

    /// Records the start of `attempt` (1-based) of `job_id` on `host` at `started_at` (unix seconds) by the granflow
    /// `build` that runs it: the job becomes `running` and a new row of its attempt history opens. An attempt still
    /// open from before (a dispatcher that died without [`Store::reset_running_to_pending`]) is closed as
    /// interrupted.
    pub fn mark_running(
        &mut self,
        job_id: &str,
        attempt: u32,
        host: &str,
        started_at: f64,
        build: &str,
    ) -> Result<(), StoreError> {
        let path = &self.path;
        let action = format!("marking job {job_id} as running");
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .context(path, &action)?;
        let updated = tx
            .execute(
                "UPDATE jobs SET status = ?2, attempt = ?3, host = ?4, started_at = ?5, last_heartbeat = ?5,
                     finished_at = NULL, exit_class = NULL, error = NULL, wall_time_s = NULL,
                     slurm_task = NULL, slurm_state = NULL
                 WHERE job_id = ?1",
                params![job_id, JobStatus::Running, attempt, host, started_at],
            )
            .context(path, &action)?;
        if updated == 0 {
            return Err(unknown_job(path, job_id));
        }
        tx.execute(
            "UPDATE attempts SET outcome = 'interrupted' WHERE job_id = ?1 AND outcome = 'running'",
            [job_id],
        )
        .context(path, &action)?;
        tx.execute(
            "INSERT INTO attempts (job_id, attempt, host, outcome, started_at, build)
             VALUES (?1, ?2, ?3, 'running', ?4, ?5)",
            params![job_id, attempt, host, started_at, build],
        )
        .context(path, &action)?;
        tx.commit().context(path, &action)
    }

    /// Records the progress of a running job. Returns `false`, and changes nothing, when the job is not `running`
    /// (a late heartbeat after its result or failure was recorded).
    pub fn heartbeat(&mut self, job_id: &str, sim_time_s: f64, steps: u64, at: f64) -> Result<bool, StoreError> {
        let action = format_args!("recording a heartbeat of job {job_id}");
        let updated = self
            .conn
            .execute(
                "UPDATE jobs SET sim_time_s = ?2, steps = ?3, last_heartbeat = ?4 WHERE job_id = ?1 AND status = ?5",
                params![job_id, sim_time_s, steps_sql(steps), at, JobStatus::Running],
            )
            .context(&self.path, action)?;
        if updated == 0 {
            require_job(&self.conn, &self.path, job_id)?;
        }
        Ok(updated > 0)
    }

    /// Records that `attempt` of `job_id` failed at `at` with failure class `exit_class` and message `error`. With
    /// [`AfterFailure::Retry`] the job goes back to `pending` (the attempt stays in its history as requeued); with
    /// [`AfterFailure::Final`] it becomes `failed`.
    pub fn mark_failed(
        &mut self,
        job_id: &str,
        attempt: u32,
        exit_class: FailureClass,
        error: &str,
        at: f64,
        after: AfterFailure,
    ) -> Result<(), StoreError> {
        let path = &self.path;
        let action = format!("marking job {job_id} as failed");
        let (status, outcome, finished_at) = match after {
            AfterFailure::Retry => (JobStatus::Pending, "requeued", None),
            AfterFailure::Final => (JobStatus::Failed, "failed", Some(at)),
        };
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .context(path, &action)?;
        let updated = tx
            .execute(
                "UPDATE jobs SET status = ?2, attempt = ?3, exit_class = ?4, error = ?5, finished_at = ?6
                 WHERE job_id = ?1",
                params![job_id, status, attempt, exit_class, error, finished_at],
            )
            .context(path, &action)?;
        if updated == 0 {
            return Err(unknown_job(path, job_id));
        }
        let closed = tx
            .execute(
                "UPDATE attempts SET outcome = ?3, exit_class = ?4, error = ?5, ended_at = ?6
                 WHERE id = (SELECT max(id) FROM attempts WHERE job_id = ?1 AND attempt = ?2 AND outcome = 'running')",
                params![job_id, attempt, outcome, exit_class, error, at],
            )
            .context(path, &action)?;
        if closed == 0 {
            // A failure without a recorded start (e.g. the worker could not be spawned): still part of the history.
            tx.execute(
                "INSERT INTO attempts (job_id, attempt, host, outcome, exit_class, error, ended_at)
                 SELECT job_id, ?2, host, ?3, ?4, ?5, ?6 FROM jobs WHERE job_id = ?1",
                params![job_id, attempt, outcome, exit_class, error, at],
            )
            .context(path, &action)?;
        }
        tx.commit().context(path, &action)
    }

    /// Ingests the result of `job_id` in one transaction: the job becomes `done`, its metrics and timings are
    /// replaced by `result`'s (so ingesting the same result twice stores it once), and its open attempt is closed.
    /// Invalid results (duplicate or empty names, negative or non-finite times) are refused before anything is
    /// written.
    pub fn finish_job(&mut self, job_id: &str, result: &JobResult) -> Result<(), StoreError> {
        validate_result(&self.path, job_id, result)?;
        let path = &self.path;
        let action = format!("storing the result of job {job_id}");
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .context(path, &action)?;
        let updated = tx
            .execute(
                "UPDATE jobs SET status = ?2, finished_at = ?3, sim_time_s = ?4, wall_time_s = ?5, steps = ?6,
                     exit_class = NULL, error = NULL
                 WHERE job_id = ?1",
                params![
                    job_id,
                    JobStatus::Done,
                    result.finished_at,
                    result.sim_time_s,
                    result.wall_time_s,
                    steps_sql(result.steps)
                ],
            )
            .context(path, &action)?;
        if updated == 0 {
            return Err(unknown_job(path, job_id));
        }
        tx.execute("DELETE FROM metrics WHERE job_id = ?1", [job_id])
            .context(path, &action)?;
        tx.execute("DELETE FROM timings WHERE job_id = ?1", [job_id])
            .context(path, &action)?;
        {
            let mut insert_metric = tx
                .prepare("INSERT INTO metrics (job_id, name, value, unit) VALUES (?1, ?2, ?3, ?4)")
                .context(path, &action)?;
            for metric in &result.metrics {
                insert_metric
                    .execute(params![job_id, metric.name, metric.value, metric.unit])
                    .context(path, &action)?;
            }
            let mut insert_timing = tx
                .prepare("INSERT INTO timings (job_id, stage, seconds) VALUES (?1, ?2, ?3)")
                .context(path, &action)?;
            for (stage, seconds) in &result.timings {
                insert_timing
                    .execute(params![job_id, stage, seconds])
                    .context(path, &action)?;
            }
        }
        tx.execute(
            "UPDATE attempts SET outcome = 'done', ended_at = ?2, build = COALESCE(NULLIF(?3, ''), build)
             WHERE job_id = ?1 AND outcome = 'running'",
            params![job_id, result.finished_at, result.build],
        )
        .context(path, &action)?;
        tx.commit().context(path, &action)
    }

    /// Puts every `running` job of the campaign back to `pending` and closes their open attempts as interrupted;
    /// returns how many jobs were reset. For `resume` after the dispatcher died: the workers it had started are gone
    /// or will be restarted from their checkpoints. Jobs submitted to Slurm (with a `slurm_task`) are left: Slurm
    /// still runs them, and the dispatcher asks it about them.
    pub fn reset_running_to_pending(&mut self, campaign_id: i64) -> Result<usize, StoreError> {
        self.require_campaign(campaign_id)?;
        let path = &self.path;
        let action = format!("resetting the running jobs of campaign {campaign_id}");
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .context(path, &action)?;
        tx.execute(
            "UPDATE attempts SET outcome = 'interrupted'
             WHERE outcome = 'running' AND job_id IN
                 (SELECT job_id FROM jobs WHERE campaign_id = ?1 AND slurm_task IS NULL)",
            [campaign_id],
        )
        .context(path, &action)?;
        let reset = tx
            .execute(
                "UPDATE jobs SET status = ?2 WHERE campaign_id = ?1 AND status = ?3 AND slurm_task IS NULL",
                params![campaign_id, JobStatus::Pending, JobStatus::Running],
            )
            .context(path, &action)?;
        tx.commit().context(path, &action)?;
        Ok(reset)
    }
}

/// `steps` as SQLite's integer type.
// CHOICE: saturate rather than fail; 2^63 steps is beyond any simulation.
fn steps_sql(steps: u64) -> i64 {
    i64::try_from(steps).unwrap_or(i64::MAX)
}

fn unknown_job(path: &Path, job_id: &str) -> StoreError {
    StoreError::UnknownJob {
        path: path.to_path_buf(),
        job_id: job_id.to_string(),
    }
}

/// Fails with [`StoreError::UnknownJob`] unless `job_id` is stored.
fn require_job(conn: &Connection, path: &Path, job_id: &str) -> Result<(), StoreError> {
    let exists: bool = conn
        .query_row(
            "SELECT EXISTS (SELECT 1 FROM jobs WHERE job_id = ?1)",
            [job_id],
            |row| row.get(0),
        )
        .context(path, format_args!("looking up job {job_id}"))?;
    if exists { Ok(()) } else { Err(unknown_job(path, job_id)) }
}

fn invalid(path: &Path, job_id: &str, reason: String) -> StoreError {
    StoreError::InvalidJobData {
        path: path.to_path_buf(),
        job_id: job_id.to_string(),
        reason,
    }
}

fn validate_new_job(path: &Path, job: &NewJob) -> Result<(), StoreError> {
    if job.job_id.is_empty() {
        return Err(invalid(path, "", "the job id is empty".to_string()));
    }
    let mut names = HashSet::new();
    for (name, value) in &job.params {
        if !names.insert(name.as_str()) {
            return Err(invalid(path, &job.job_id, format!("parameter `{name}` is given twice")));
        }
        if let ParamValue::Real(value) = value
            && !value.is_finite()
        {
            return Err(invalid(path, &job.job_id, format!("parameter `{name}` is {value}")));
        }
    }
    Ok(())
}

fn validate_result(path: &Path, job_id: &str, result: &JobResult) -> Result<(), StoreError> {
    let mut names = HashSet::new();
    for metric in &result.metrics {
        if metric.name.is_empty() {
            return Err(invalid(path, job_id, "a metric has an empty name".to_string()));
        }
        if !names.insert(metric.name.as_str()) {
            return Err(invalid(
                path,
                job_id,
                format!("metric `{}` is given twice", metric.name),
            ));
        }
    }
    let mut stages = HashSet::new();
    for (stage, seconds) in &result.timings {
        if !stages.insert(stage.as_str()) {
            return Err(invalid(
                path,
                job_id,
                format!("timing of stage `{stage}` is given twice"),
            ));
        }
        if !(seconds.is_finite() && *seconds >= 0.0) {
            return Err(invalid(
                path,
                job_id,
                format!("timing of stage `{stage}` is {seconds} s"),
            ));
        }
    }
    for (what, value) in [
        ("sim_time_s", result.sim_time_s),
        ("wall_time_s", result.wall_time_s),
        ("finished_at", result.finished_at),
    ] {
        if !value.is_finite() {
            return Err(invalid(path, job_id, format!("{what} is {value}")));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{job_result, new_campaign, sample_jobs};
    use super::super::{JobStatus, Metric};
    use super::*;

    fn count(store: &Store, sql: &str) -> i64 {
        store.conn.query_row(sql, [], |row| row.get(0)).unwrap()
    }

    #[test]
    fn insert_jobs_ignores_known_ids() {
        let (_dir, mut store, campaign) = new_campaign();
        let mut jobs = sample_jobs();
        assert_eq!(store.insert_jobs(campaign, &jobs).unwrap(), 6);
        store
            .mark_running(&jobs[0].job_id, 1, "node1", 10.0, "0.1.0+test")
            .unwrap();

        // Re-registering with changed data for a known id and one new job: only the new job is written.
        jobs[0].params_json = "{\"changed\":true}".to_string();
        jobs[0].params.push(("extra".to_string(), ParamValue::Real(1.0)));
        jobs.push(NewJob {
            job_id: "new".to_string(),
            ordinal: 6,
            params_json: "{}".to_string(),
            params: vec![("u_m_per_s".to_string(), ParamValue::Real(0.4))],
        });
        assert_eq!(store.insert_jobs(campaign, &jobs).unwrap(), 1);
        let rows = store.job_summaries(campaign).unwrap();
        assert_eq!(rows.len(), 7);
        assert_eq!(rows[0].status, JobStatus::Running);
        assert_ne!(rows[0].params_json, "{\"changed\":true}");
        assert_eq!(count(&store, "SELECT count(*) FROM params WHERE name = 'extra'"), 0);
        assert_eq!(count(&store, "SELECT count(*) FROM params"), 6 * 3 + 1);

        // The same id under another campaign is refused, and the transaction leaves nothing behind.
        let other = store.upsert_campaign("other", "", "h", "0").unwrap();
        let clash = [
            NewJob {
                job_id: "x".to_string(),
                ..jobs[6].clone()
            },
            jobs[6].clone(),
        ];
        let err = store.insert_jobs(other, &clash).unwrap_err();
        assert!(matches!(err, StoreError::JobInOtherCampaign { .. }), "{err}");
        assert_eq!(count(&store, "SELECT count(*) FROM jobs WHERE job_id = 'x'"), 0);
        let err = store.insert_jobs(other + 1, &jobs).unwrap_err();
        assert!(matches!(err, StoreError::UnknownCampaign { .. }), "{err}");
    }

    #[test]
    fn insert_jobs_rejects_invalid_params() {
        let (_dir, mut store, campaign) = new_campaign();
        let mut job = sample_jobs().remove(0);
        job.params.push(("bad".to_string(), ParamValue::Real(f64::NAN)));
        let err = store.insert_jobs(campaign, &[job]).unwrap_err();
        assert!(err.to_string().contains("parameter `bad` is NaN"), "{err}");
        assert_eq!(store.job_summaries(campaign).unwrap().len(), 0);
    }

    #[test]
    fn finish_job_is_idempotent() {
        let (_dir, mut store, campaign) = new_campaign();
        let jobs = sample_jobs();
        store.insert_jobs(campaign, &jobs).unwrap();
        let id = &jobs[0].job_id;
        store.mark_running(id, 1, "node1", 100.0, "0.1.0+test").unwrap();
        assert!(store.heartbeat(id, 0.5, 500, 110.0).unwrap());
        let result = job_result(&[("porosity", 0.4, ""), ("dp_mean", 1200.0, "Pa")]);
        store.finish_job(id, &result).unwrap();
        store.finish_job(id, &result).unwrap();
        assert_eq!(count(&store, "SELECT count(*) FROM metrics"), 2);
        assert_eq!(count(&store, "SELECT count(*) FROM timings"), 2);
        assert_eq!(count(&store, "SELECT count(*) FROM attempts WHERE outcome = 'done'"), 1);

        // A corrected result replaces the old one entirely (a dropped metric disappears).
        let corrected = job_result(&[("porosity", 0.41, "")]);
        store.finish_job(id, &corrected).unwrap();
        let (_, rows) = store.query_sql("SELECT name, value FROM metrics").unwrap();
        assert_eq!(rows, [[serde_json::json!("porosity"), serde_json::json!(0.41)]]);

        let row = &store.job_summaries(campaign).unwrap()[0];
        assert_eq!(row.status, JobStatus::Done);
        assert_eq!(
            (row.steps, row.sim_time_s, row.wall_time_s),
            (Some(1000), Some(1.0), Some(20.0))
        );
        // A heartbeat arriving after the result changes nothing.
        assert!(!store.heartbeat(id, 0.7, 700, 130.0).unwrap());
        assert_eq!(store.job_summaries(campaign).unwrap()[0].steps, Some(1000));
        assert!(store.done_job_ids(campaign).unwrap().contains(id));

        let err = store.finish_job("nope", &result).unwrap_err();
        assert!(matches!(err, StoreError::UnknownJob { .. }), "{err}");
        let twice = job_result(&[("a", 1.0, ""), ("a", 2.0, "")]);
        let err = store.finish_job(id, &twice).unwrap_err();
        assert!(err.to_string().contains("metric `a` is given twice"), "{err}");
    }

    #[test]
    fn finish_job_stores_nan_metric_as_null() {
        let (_dir, mut store, campaign) = new_campaign();
        let jobs = sample_jobs();
        store.insert_jobs(campaign, &jobs).unwrap();
        let mut result = job_result(&[]);
        result.metrics.push(Metric {
            name: "k".into(),
            value: f64::NAN,
            unit: "1/s".into(),
        });
        store.finish_job(&jobs[0].job_id, &result).unwrap();
        assert_eq!(count(&store, "SELECT count(*) FROM metrics WHERE value IS NULL"), 1);
    }

    #[test]
    fn failures_retries_and_crash_reset_keep_the_attempt_history() {
        let (_dir, mut store, campaign) = new_campaign();
        let jobs = sample_jobs();
        store.insert_jobs(campaign, &jobs).unwrap();
        let (a, b) = (&jobs[0].job_id, &jobs[1].job_id);

        store.mark_running(a, 1, "node1", 1.0, "0.1.0+test").unwrap();
        store
            .mark_failed(
                a,
                1,
                FailureClass::Numerical,
                "non-finite velocity",
                2.0,
                AfterFailure::Retry,
            )
            .unwrap();
        let row = &store.job_summaries(campaign).unwrap()[0];
        assert_eq!(row.status, JobStatus::Pending);
        assert_eq!(row.exit_class, Some(FailureClass::Numerical));
        store.mark_running(a, 2, "node2", 3.0, "0.1.0+test").unwrap();
        store
            .mark_failed(a, 2, FailureClass::Crash, "signal 9", 4.0, AfterFailure::Final)
            .unwrap();
        let row = &store.job_summaries(campaign).unwrap()[0];
        assert_eq!(
            (row.status, row.attempt, row.finished_at),
            (JobStatus::Failed, 2, Some(4.0))
        );

        store.mark_running(b, 1, "node1", 5.0, "0.1.0+test").unwrap();
        assert_eq!(store.reset_running_to_pending(campaign).unwrap(), 1);
        assert_eq!(store.status_counts(campaign).unwrap()["running"], 0);

        let (_, history) = store
            .query_sql("SELECT job_id, attempt, outcome, exit_class FROM attempts ORDER BY id")
            .unwrap();
        let expected: Vec<Vec<serde_json::Value>> = vec![
            vec![a.as_str().into(), 1.into(), "requeued".into(), "numerical".into()],
            vec![a.as_str().into(), 2.into(), "failed".into(), "crash".into()],
            vec![
                b.as_str().into(),
                1.into(),
                "interrupted".into(),
                serde_json::Value::Null,
            ],
        ];
        assert_eq!(history, expected);

        let err = store.mark_running("nope", 1, "h", 0.0, "0.1.0+test").unwrap_err();
        assert!(err.to_string().contains("has no job nope"), "{err}");
    }
}
