//! The layout of a campaign directory (`results/<name>/`, or `--out`), and reading it as a whole.
//!
//! A campaign directory holds `campaign.sqlite` (the results database), `campaign.yaml` (the campaign file as run:
//! what `resume`, `status`, `query`, `export`, `report` and `reduce` load), `campaign.log` (the dispatcher's log),
//! `campaign.lock` (held while one dispatcher, or one `reduce`, works on it) and `jobs/<job id>/`, one directory
//! per job. A job directory holds `job.json` (the job), `result.json` (its metrics; written last, so its presence
//! means done), `worker.log` and `worker.lock` (held while a worker runs the job), besides the run's own files
//! (`crate::simulate`: checkpoints, series, summary).
//!
//! What does not live here: what the files hold (the database is `crate::store`, the campaign file
//! `crate::campaign`, `job.json` and `result.json` are read and written by `crate::worker` and the dispatcher), and
//! who may write what (the dispatcher is the only writer of the database, a worker the only writer of its job's
//! directory once it has started).

use std::fs::File;
use std::path::{Path, PathBuf};

use crate::campaign::{self, Campaign};
use crate::error::Error;
use crate::store::Store;

/// The results database of a campaign directory.
pub fn database_path(dir: &Path) -> PathBuf {
    dir.join("campaign.sqlite")
}

/// The campaign directory's copy of the campaign file (what `resume` runs).
pub fn spec_copy_path(dir: &Path) -> PathBuf {
    dir.join("campaign.yaml")
}

/// The dispatcher's log.
pub fn log_path(dir: &Path) -> PathBuf {
    dir.join("campaign.log")
}

/// The lock file held by the one dispatcher (or `reduce`) working on the campaign.
pub fn lock_path(dir: &Path) -> PathBuf {
    dir.join("campaign.lock")
}

/// The directory holding one directory per job.
pub fn jobs_path(dir: &Path) -> PathBuf {
    dir.join("jobs")
}

/// The directory of one job.
pub fn job_dir(dir: &Path, job_id: &str) -> PathBuf {
    jobs_path(dir).join(job_id)
}

/// The directory of one shared preparation (`campaign::prepare`).
pub fn preparation_dir(dir: &Path, preparation_id: &str) -> PathBuf {
    dir.join("preparations").join(preparation_id)
}

/// A job directory's description of the job (`campaign::JobSpec`).
pub fn job_spec_path(job_dir: &Path) -> PathBuf {
    job_dir.join("job.json")
}

/// A job directory's result (`worker::JobResult`); its presence means the job is done.
pub fn result_path(job_dir: &Path) -> PathBuf {
    job_dir.join("result.json")
}

/// A job directory's worker log (the worker's stderr, appended by every attempt).
pub fn worker_log_path(job_dir: &Path) -> PathBuf {
    job_dir.join("worker.log")
}

/// The lock file held by the worker running the job.
pub fn worker_lock_path(job_dir: &Path) -> PathBuf {
    job_dir.join("worker.lock")
}

/// The campaign stored in a campaign directory (its copy of the campaign file).
pub fn load_stored_campaign(dir: &Path) -> Result<Campaign, Error> {
    let path = spec_copy_path(dir);
    if !path.exists() {
        return Err(Error::External(format!(
            "{} is not a campaign directory (no {})",
            dir.display(),
            path.display()
        )));
    }
    Ok(campaign::load(&path)?)
}

/// The database id of the campaign stored in `dir`.
pub fn stored_campaign_id(store: &Store, campaign: &Campaign, dir: &Path) -> Result<i64, Error> {
    Ok(store
        .campaign_by_name(&campaign.spec.name)?
        .ok_or_else(|| {
            Error::External(format!(
                "{}: no campaign `{}` in the database",
                dir.display(),
                campaign.spec.name
            ))
        })?
        .id)
}

/// Takes the campaign directory's lock (held while the returned file is open): one dispatcher, or one `reduce`, at a
/// time.
pub fn lock(dir: &Path) -> Result<File, Error> {
    let lock_path = lock_path(dir);
    let lock = File::create(&lock_path).map_err(|e| Error::io("create", &lock_path, e))?;
    match lock.try_lock() {
        Ok(()) => Ok(lock),
        Err(std::fs::TryLockError::WouldBlock) => Err(Error::External(format!(
            "another dispatcher is running this campaign ({} is locked)",
            lock_path.display()
        ))),
        Err(std::fs::TryLockError::Error(e)) => Err(Error::io("lock", &lock_path, e)),
    }
}

/// Whether a dispatcher (or `reduce`) holds the campaign's lock right now.
pub fn is_locked(dir: &Path) -> bool {
    match File::open(lock_path(dir)) {
        Ok(f) => matches!(f.try_lock_shared(), Err(std::fs::TryLockError::WouldBlock)),
        Err(_) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names are part of the on-disk layout that README.md documents and `resume` relies on.
    #[test]
    fn the_layout_keeps_its_names() {
        let dir = Path::new("results/c");
        assert_eq!(database_path(dir), Path::new("results/c/campaign.sqlite"));
        assert_eq!(spec_copy_path(dir), Path::new("results/c/campaign.yaml"));
        assert_eq!(log_path(dir), Path::new("results/c/campaign.log"));
        assert_eq!(lock_path(dir), Path::new("results/c/campaign.lock"));
        let job = job_dir(dir, "0123456789abcdef");
        assert_eq!(job, Path::new("results/c/jobs/0123456789abcdef"));
        assert_eq!(job_spec_path(&job), job.join("job.json"));
        assert_eq!(result_path(&job), job.join("result.json"));
        assert_eq!(worker_log_path(&job), job.join("worker.log"));
        assert_eq!(worker_lock_path(&job), job.join("worker.lock"));
    }

    #[test]
    fn the_lock_is_held_once() {
        let tmp = tempfile::tempdir().unwrap();
        assert!(!is_locked(tmp.path()));
        let held = lock(tmp.path()).unwrap();
        assert!(is_locked(tmp.path()));
        let err = lock(tmp.path()).unwrap_err().to_string();
        assert!(
            err.contains("another dispatcher") && err.contains("campaign.lock"),
            "{err}"
        );
        drop(held);
        assert!(!is_locked(tmp.path()));
    }

    #[test]
    fn a_directory_without_a_campaign_is_named() {
        let tmp = tempfile::tempdir().unwrap();
        let err = load_stored_campaign(tmp.path()).unwrap_err().to_string();
        assert!(
            err.contains("is not a campaign directory") && err.contains("campaign.yaml"),
            "{err}"
        );
    }
}
