//! What the database keeps of jobs run by the Slurm executor: each job's array task and the task's last state
//! (`schemas/results-3-slurm.sql`), so that a dispatcher started again follows the tasks Slurm still has.

use rusqlite::params;

use super::Store;
use super::error::{Context, StoreError};
use super::job::JobStatus;

impl Store {
    /// Records that `job_id` (marked running) is array task `task` of a submission, in Slurm state `state`.
    pub fn set_slurm_task(&mut self, job_id: &str, task: &str, state: &str) -> Result<(), StoreError> {
        self.conn
            .execute(
                "UPDATE jobs SET slurm_task = ?2, slurm_state = ?3 WHERE job_id = ?1",
                params![job_id, task, state],
            )
            .context(&self.path, format_args!("recording the Slurm task of job {job_id}"))?;
        Ok(())
    }

    /// Records the Slurm state of a job's task as `squeue` reported it.
    pub fn set_slurm_state(&mut self, job_id: &str, state: &str) -> Result<(), StoreError> {
        self.conn
            .execute(
                "UPDATE jobs SET slurm_state = ?2 WHERE job_id = ?1",
                params![job_id, state],
            )
            .context(&self.path, format_args!("recording the Slurm state of job {job_id}"))?;
        Ok(())
    }

    /// The campaign's `running` jobs that are in Slurm's hands: (job id, attempt, array task).
    pub fn slurm_running(&self, campaign_id: i64) -> Result<Vec<(String, u32, String)>, StoreError> {
        let action = format_args!("listing the Slurm tasks of campaign {campaign_id}");
        let mut stmt = self
            .conn
            .prepare_cached(
                "SELECT job_id, attempt, slurm_task FROM jobs
                 WHERE campaign_id = ?1 AND status = ?2 AND slurm_task IS NOT NULL ORDER BY ordinal",
            )
            .context(&self.path, action)?;
        stmt.query_map(params![campaign_id, JobStatus::Running], |row| {
            Ok((row.get(0)?, row.get(1)?, row.get(2)?))
        })
        .context(&self.path, action)?
        .collect::<Result<Vec<_>, _>>()
        .context(&self.path, action)
    }
}
