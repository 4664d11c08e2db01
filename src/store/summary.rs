//! Read-side views of a campaign's jobs: the rows for `status`, the counts per status, the done set for
//! reconciliation, and the one-row-per-job export (parameters and metrics side by side).
//!
//! What does not live here: pivots ([`super::Pivot`]) and free SQL ([`Store::query_sql`]).

use std::collections::{BTreeMap, HashMap, HashSet};

use rusqlite::params;
use serde_json::Value;

use super::Store;
use super::error::{Context, StoreError};
use super::failure_class::FailureClass;
use super::job::{AttemptSpan, JobRow, JobStatus, ParamValue};
use super::render::json_real;

impl Store {
    /// Every job of the campaign in sweep order (ordinal, then id).
    pub fn job_summaries(&self, campaign_id: i64) -> Result<Vec<JobRow>, StoreError> {
        let action = format_args!("listing the jobs of campaign {campaign_id}");
        let mut stmt = self
            .conn
            .prepare_cached(
                "SELECT job_id, ordinal, params_json, status, attempt, exit_class, error, host, started_at,
                        finished_at, last_heartbeat, sim_time_s, wall_time_s, steps, slurm_task, slurm_state
                 FROM jobs WHERE campaign_id = ?1 ORDER BY ordinal, job_id",
            )
            .context(&self.path, action)?;
        stmt.query_map([campaign_id], |row| {
            Ok(JobRow {
                job_id: row.get(0)?,
                ordinal: row.get(1)?,
                params_json: row.get(2)?,
                status: row.get(3)?,
                attempt: row.get(4)?,
                exit_class: row.get(5)?,
                error: row.get(6)?,
                host: row.get(7)?,
                started_at: row.get(8)?,
                finished_at: row.get(9)?,
                last_heartbeat: row.get(10)?,
                sim_time_s: row.get(11)?,
                wall_time_s: row.get(12)?,
                steps: row.get::<_, Option<i64>>(13)?.map(|steps| steps.max(0) as u64),
                slurm_task: row.get(14)?,
                slurm_state: row.get(15)?,
            })
        })
        .and_then(|rows| rows.collect())
        .context(&self.path, action)
    }

    /// The number of jobs of the campaign in each status, keyed by [`JobStatus::as_str`]; every status is present,
    /// with 0 when no job has it.
    pub fn status_counts(&self, campaign_id: i64) -> Result<BTreeMap<String, usize>, StoreError> {
        let action = format_args!("counting the jobs of campaign {campaign_id}");
        let mut counts: BTreeMap<String, usize> = JobStatus::ALL
            .iter()
            .map(|status| (status.as_str().to_string(), 0))
            .collect();
        let mut stmt = self
            .conn
            .prepare_cached("SELECT status, count(*) FROM jobs WHERE campaign_id = ?1 GROUP BY status")
            .context(&self.path, action)?;
        let rows = stmt
            .query_map([campaign_id], |row| {
                Ok((row.get::<_, JobStatus>(0)?, row.get::<_, i64>(1)?))
            })
            .and_then(|rows| rows.collect::<rusqlite::Result<Vec<_>>>())
            .context(&self.path, action)?;
        for (status, count) in rows {
            counts.insert(status.as_str().to_string(), count.max(0) as usize);
        }
        Ok(counts)
    }

    /// Retries already used, per (job, failure class): attempts that ended `requeued` with that class. The
    /// dispatcher starts from these counts, so a retry budget is not renewed by restarting the dispatcher.
    pub fn retries_used(&self, campaign_id: i64) -> Result<HashMap<(String, FailureClass), u32>, StoreError> {
        let action = format_args!("counting the retries of campaign {campaign_id}");
        let mut stmt = self
            .conn
            .prepare_cached(
                "SELECT a.job_id, a.exit_class, count(*) FROM attempts a JOIN jobs j ON j.job_id = a.job_id
                 WHERE j.campaign_id = ?1 AND a.outcome = 'requeued' AND a.exit_class IS NOT NULL
                 GROUP BY a.job_id, a.exit_class",
            )
            .context(&self.path, action)?;
        stmt.query_map([campaign_id], |row| {
            Ok((
                (row.get::<_, String>(0)?, row.get::<_, FailureClass>(1)?),
                row.get::<_, i64>(2)?.max(0) as u32,
            ))
        })
        .and_then(|rows| rows.collect())
        .context(&self.path, action)
    }

    /// Every attempt of the campaign's jobs, with its start and end (a resumed job has one per run of the
    /// dispatcher; its result records only the last one's wall time).
    pub fn attempt_spans(&self, campaign_id: i64) -> Result<Vec<AttemptSpan>, StoreError> {
        let action = format_args!("listing the attempts of campaign {campaign_id}");
        let mut stmt = self
            .conn
            .prepare_cached(
                "SELECT a.job_id, a.started_at, a.ended_at FROM attempts a JOIN jobs j ON j.job_id = a.job_id
                 WHERE j.campaign_id = ?1 ORDER BY a.id",
            )
            .context(&self.path, action)?;
        stmt.query_map([campaign_id], |row| {
            Ok(AttemptSpan {
                job_id: row.get(0)?,
                started_s: row.get(1)?,
                ended_s: row.get(2)?,
            })
        })
        .and_then(|rows| rows.collect())
        .context(&self.path, action)
    }

    /// The ids of the campaign's `done` jobs, which `run` and `resume` skip.
    pub fn done_job_ids(&self, campaign_id: i64) -> Result<HashSet<String>, StoreError> {
        let action = format_args!("listing the done jobs of campaign {campaign_id}");
        let mut stmt = self
            .conn
            .prepare_cached("SELECT job_id FROM jobs WHERE campaign_id = ?1 AND status = ?2")
            .context(&self.path, action)?;
        stmt.query_map(params![campaign_id, JobStatus::Done], |row| row.get(0))
            .and_then(|rows| rows.collect())
            .context(&self.path, action)
    }

    /// One row per job of the campaign, in sweep order: `job_id`, `status`, then one column per parameter
    /// (`param.<name>`, sorted by name) and one per metric (`metric.<name> [unit]`, or `metric.<name>` when
    /// dimensionless, sorted by name). Missing values (a parameter some jobs lack, metrics of unfinished jobs) are
    /// null; non-finite metrics are the strings `"inf"`, `"-inf"` and `"NaN"`.
    pub fn export_rows(&self, campaign_id: i64) -> Result<(Vec<String>, Vec<Vec<Value>>), StoreError> {
        self.require_campaign(campaign_id)?;
        let action = format!("exporting campaign {campaign_id}");

        let jobs: Vec<(String, JobStatus)> = self
            .collect(
                "SELECT job_id, status FROM jobs WHERE campaign_id = ?1 ORDER BY ordinal, job_id",
                campaign_id,
                |row| Ok((row.get(0)?, row.get(1)?)),
            )
            .context(&self.path, &action)?;
        let params: Vec<(String, String, Option<ParamValue>)> = self
            .collect(
                "SELECT p.job_id, p.name, p.value_real, p.value_text
             FROM params p JOIN jobs j ON j.job_id = p.job_id WHERE j.campaign_id = ?1",
                campaign_id,
                |row| {
                    Ok((
                        row.get(0)?,
                        row.get(1)?,
                        ParamValue::from_columns(row.get(2)?, row.get(3)?),
                    ))
                },
            )
            .context(&self.path, &action)?;
        let metrics: Vec<(String, (String, String), Option<f64>)> = self
            .collect(
                "SELECT m.job_id, m.name, m.unit, m.value
             FROM metrics m JOIN jobs j ON j.job_id = m.job_id WHERE j.campaign_id = ?1",
                campaign_id,
                |row| Ok((row.get(0)?, (row.get(1)?, row.get(2)?), row.get(3)?)),
            )
            .context(&self.path, &action)?;

        // Column order: fixed columns, parameters by name, metrics by (name, unit). BTreeMaps give the order, then
        // hold each key's column index.
        let mut param_columns: BTreeMap<&str, usize> = params.iter().map(|(_, name, _)| (name.as_str(), 0)).collect();
        let mut metric_columns: BTreeMap<(&str, &str), usize> = metrics
            .iter()
            .map(|(_, (name, unit), _)| ((name.as_str(), unit.as_str()), 0))
            .collect();
        let mut header = vec!["job_id".to_string(), "status".to_string()];
        for (name, column) in &mut param_columns {
            *column = header.len();
            header.push(format!("param.{name}"));
        }
        for ((name, unit), column) in &mut metric_columns {
            *column = header.len();
            header.push(if unit.is_empty() {
                format!("metric.{name}")
            } else {
                format!("metric.{name} [{unit}]")
            });
        }

        let row_of: HashMap<&str, usize> = jobs
            .iter()
            .enumerate()
            .map(|(row, (id, _))| (id.as_str(), row))
            .collect();
        let mut rows: Vec<Vec<Value>> = jobs
            .iter()
            .map(|(id, status)| {
                let mut row = vec![Value::Null; header.len()];
                row[0] = Value::String(id.clone());
                row[1] = Value::String(status.as_str().to_string());
                row
            })
            .collect();
        for (job_id, name, value) in &params {
            let (Some(&row), Some(value)) = (row_of.get(job_id.as_str()), value) else {
                continue;
            };
            rows[row][param_columns[name.as_str()]] = value.to_json();
        }
        for (job_id, (name, unit), value) in &metrics {
            let (Some(&row), Some(value)) = (row_of.get(job_id.as_str()), value) else {
                continue;
            };
            rows[row][metric_columns[&(name.as_str(), unit.as_str())]] = json_real(*value);
        }
        Ok((header, rows))
    }

    /// Runs `sql` with the single parameter `campaign_id` and collects the mapped rows.
    fn collect<T>(
        &self,
        sql: &str,
        campaign_id: i64,
        map: impl FnMut(&rusqlite::Row<'_>) -> rusqlite::Result<T>,
    ) -> rusqlite::Result<Vec<T>> {
        let mut stmt = self.conn.prepare_cached(sql)?;
        stmt.query_map([campaign_id], map)?.collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{finish, new_campaign, sample_jobs};
    use super::*;
    use serde_json::json;

    #[test]
    fn export_has_one_column_per_param_and_metric() {
        let (_dir, mut store, campaign) = new_campaign();
        let jobs = sample_jobs();
        store.insert_jobs(campaign, &jobs).unwrap();
        finish(
            &mut store,
            &jobs[0].job_id,
            &[("porosity", 0.4, ""), ("dp_mean", 1200.0, "Pa")],
        );
        finish(&mut store, &jobs[1].job_id, &[("porosity", f64::INFINITY, "")]);

        let (header, rows) = store.export_rows(campaign).unwrap();
        assert_eq!(
            header,
            [
                "job_id",
                "status",
                "param.drag",
                "param.fill_level",
                "param.u_m_per_s",
                "metric.dp_mean [Pa]",
                "metric.porosity",
            ]
        );
        assert_eq!(rows.len(), 6);
        assert_eq!(
            rows[0],
            vec![
                json!("j0"),
                json!("done"),
                json!("di_felice"),
                json!(0.3),
                json!(0.1),
                json!(1200.0),
                json!(0.4)
            ]
        );
        assert_eq!(rows[1][6], json!("inf"));
        assert_eq!(rows[1][5], Value::Null);
        assert_eq!(rows[5][..2], [json!("j5"), json!("pending")]);

        let counts = store.status_counts(campaign).unwrap();
        assert_eq!(
            counts.into_iter().collect::<Vec<_>>(),
            [
                ("done".to_string(), 2),
                ("failed".to_string(), 0),
                ("pending".to_string(), 4),
                ("running".to_string(), 0)
            ]
        );
        assert_eq!(
            store.done_job_ids(campaign).unwrap(),
            HashSet::from(["j0".to_string(), "j1".to_string()])
        );
    }
}
