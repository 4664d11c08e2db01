//! The campaign results database (SQLite): campaigns, jobs and their attempts, parameters, metrics, derived metrics
//! and timings, with the queries the CLI needs (status, phase-diagram pivots, exports, read-only SQL).
//!
//! The schema is `schemas/results.sql`, applied by [`migrations`](self::migrations) and tracked by `PRAGMA
//! user_version`. The dispatcher is the single writer ([`Store::open`], WAL mode); `granflow query`, `status` and
//! `export` read through [`Store::open_read_only`] while a campaign runs. Every write that touches several rows is one
//! transaction, and re-ingesting a result replaces it, so a dispatcher that crashes and reconciles never duplicates
//! data. What does not live here: deciding what a job is (campaign expansion, job ids), which failure class an
//! attempt ended with and the retry policy (which failures are final), and reading `result.json`; callers pass those
//! decisions in.
//!
//! Timestamps are unix seconds as `f64` (see [`unix_time_s`]).

mod campaign;
mod error;
mod failure_class;
mod job;
mod lifecycle;
mod migrations;
mod pivot;
mod query;
mod render;
mod slurm;
mod summary;
#[cfg(test)]
mod test_support;

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use rusqlite::{Connection, OpenFlags};

pub use campaign::Campaign;
use error::Context;
pub use error::StoreError;
pub use failure_class::FailureClass;
pub use job::{AfterFailure, AttemptSpan, JobResult, JobRow, JobStatus, Metric, NewJob, ParamValue};
pub use migrations::SCHEMA_VERSION;
pub use pivot::{Pivot, PivotCell};
pub use render::{render_csv, render_json, render_table};

/// How long a connection waits for a lock held by another connection before failing with "database is locked".
// CHOICE: in WAL mode readers never wait for the writer; locks are only held briefly by checkpoints and by the one
// writer's transactions (a finished job is a few hundred rows). 10 s absorbs a slow shared filesystem without
// hiding a second writer forever.
const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

/// A connection to one results database.
///
/// Writing methods take `&mut self`: there is one writer (the dispatcher), and each of them is one transaction.
pub struct Store {
    conn: Connection,
    path: PathBuf,
    read_only: bool,
}

impl Store {
    /// Opens the database at `path` for reading and writing, creating the file if it is missing (not its
    /// directory), and migrates it to [`SCHEMA_VERSION`]. Sets WAL mode, `synchronous = NORMAL` (durable at each
    /// checkpoint, consistent always: a power cut can lose the last transactions, never corrupt the file) and
    /// foreign keys.
    pub fn open(path: impl AsRef<Path>) -> Result<Store, StoreError> {
        let path = path.as_ref().to_path_buf();
        let flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_CREATE | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        let mut conn = Connection::open_with_flags(&path, flags).context(&path, "opening the file")?;
        conn.busy_timeout(BUSY_TIMEOUT)
            .context(&path, "setting the busy timeout")?;
        let mode: String = conn
            .pragma_update_and_check(None, "journal_mode", "wal", |row| row.get(0))
            .context(&path, "switching to WAL mode")?;
        if !mode.eq_ignore_ascii_case("wal") {
            return Err(StoreError::WalUnavailable { path, mode });
        }
        conn.pragma_update(None, "synchronous", "NORMAL")
            .context(&path, "setting synchronous = NORMAL")?;
        conn.pragma_update(None, "foreign_keys", true)
            .context(&path, "enabling foreign keys")?;
        migrations::migrate(&mut conn, &path)?;
        Ok(Store {
            conn,
            path,
            read_only: false,
        })
    }

    /// Opens an existing database without the right to change it (`SQLITE_OPEN_READ_ONLY` and `PRAGMA query_only`),
    /// e.g. for `granflow query` while the dispatcher writes. Fails if the file is missing or its schema version is
    /// not [`SCHEMA_VERSION`] (a read-only connection cannot migrate).
    pub fn open_read_only(path: impl AsRef<Path>) -> Result<Store, StoreError> {
        let path = path.as_ref().to_path_buf();
        let conn = Self::read_only_connection(&path)?;
        let found = migrations::schema_version(&conn, &path)?;
        if found > SCHEMA_VERSION {
            return Err(StoreError::TooNew {
                path,
                found,
                supported: SCHEMA_VERSION,
            });
        }
        if found < SCHEMA_VERSION {
            return Err(StoreError::NeedsMigration {
                path,
                found,
                expected: SCHEMA_VERSION,
            });
        }
        Ok(Store {
            conn,
            path,
            read_only: true,
        })
    }

    fn read_only_connection(path: &Path) -> Result<Connection, StoreError> {
        // An explicit check: SQLite's own message for a missing file is "unable to open database file".
        if !path.exists() {
            return Err(StoreError::NotFound {
                path: path.to_path_buf(),
            });
        }
        let flags = OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        let conn = Connection::open_with_flags(path, flags).context(path, "opening the file read-only")?;
        conn.busy_timeout(BUSY_TIMEOUT)
            .context(path, "setting the busy timeout")?;
        conn.pragma_update(None, "query_only", true)
            .context(path, "setting query_only")?;
        Ok(conn)
    }

    /// The database file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether this store was opened with [`Store::open_read_only`].
    pub fn is_read_only(&self) -> bool {
        self.read_only
    }

    /// The schema version stored in the file (`PRAGMA user_version`).
    pub fn schema_version(&self) -> Result<i64, StoreError> {
        migrations::schema_version(&self.conn, &self.path)
    }

    /// Runs `PRAGMA integrity_check` and returns its report: `"ok"`, or one line per problem found.
    pub fn integrity_check(&self) -> Result<String, StoreError> {
        let mut stmt = self
            .conn
            .prepare("PRAGMA integrity_check")
            .context(&self.path, "checking integrity")?;
        let lines = stmt
            .query_map([], |row| row.get::<_, String>(0))
            .and_then(|rows| rows.collect::<rusqlite::Result<Vec<_>>>())
            .context(&self.path, "checking integrity")?;
        Ok(lines.join("\n"))
    }
}

impl std::fmt::Debug for Store {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Store")
            .field("path", &self.path)
            .field("read_only", &self.read_only)
            .finish_non_exhaustive()
    }
}

/// The current time as unix seconds, the unit of every timestamp in the database.
pub fn unix_time_s() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |since| since.as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::test_support::{new_store, sample_jobs};
    use super::*;

    #[test]
    fn open_sets_wal_and_foreign_keys() {
        let (_dir, store) = new_store();
        let mode: String = store
            .conn
            .pragma_query_value(None, "journal_mode", |row| row.get(0))
            .unwrap();
        assert_eq!(mode, "wal");
        let fk: bool = store
            .conn
            .pragma_query_value(None, "foreign_keys", |row| row.get(0))
            .unwrap();
        assert!(fk);
        assert_eq!(store.integrity_check().unwrap(), "ok");
    }

    #[test]
    fn open_read_only_requires_an_existing_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing.sqlite");
        let err = Store::open_read_only(&path).expect_err("missing file");
        assert!(matches!(err, StoreError::NotFound { .. }));
        assert!(err.to_string().contains("missing.sqlite"), "{err}");
        assert!(!path.exists(), "a read-only open must not create the file");
    }

    #[test]
    fn read_only_store_cannot_write() {
        let (dir, mut store) = new_store();
        let id = store.upsert_campaign("c", "", "h", "0").unwrap();
        drop(store);
        // The writer is closed, so the -wal and -shm files are gone: the reader must cope.
        let mut reader = Store::open_read_only(dir.path().join("campaign.sqlite")).unwrap();
        assert!(reader.is_read_only());
        assert_eq!(reader.job_summaries(id).unwrap().len(), 0);
        let err = reader
            .insert_jobs(id, &sample_jobs())
            .expect_err("a read-only store cannot write");
        assert!(err.to_string().contains("campaign.sqlite"), "{err}");
    }

    #[test]
    fn reader_is_not_blocked_by_an_open_write_transaction() {
        let (dir, mut store) = new_store();
        let campaign = store.upsert_campaign("c", "", "h", "0").unwrap();
        let path = dir.path().join("campaign.sqlite");
        let reader = Store::open_read_only(&path).unwrap();

        // A writer holding the write lock mid-transaction, as the dispatcher does while ingesting a result.
        let mut writer = Connection::open(&path).unwrap();
        let tx = writer
            .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)
            .unwrap();
        tx.execute(
            "INSERT INTO jobs (job_id, campaign_id, ordinal, params_json) VALUES ('a', ?1, 0, '{}')",
            [campaign],
        )
        .unwrap();
        let started = std::time::Instant::now();
        assert_eq!(reader.status_counts(campaign).unwrap()["pending"], 0);
        assert_eq!(
            reader.query_sql("SELECT count(*) FROM jobs").unwrap().1,
            [[serde_json::json!(0)]]
        );
        assert!(
            started.elapsed() < Duration::from_secs(1),
            "the reader waited for the writer"
        );
        tx.commit().unwrap();
        assert_eq!(reader.status_counts(campaign).unwrap()["pending"], 1);
    }

    #[test]
    fn concurrent_reader_while_writing() {
        const JOBS: usize = 200;
        let (dir, mut store) = new_store();
        let campaign = store.upsert_campaign("c", "", "h", "0").unwrap();
        let jobs: Vec<NewJob> = (0..JOBS)
            .map(|i| NewJob {
                job_id: format!("job{i:03}"),
                ordinal: i as i64,
                params_json: "{}".to_string(),
                params: vec![("u".to_string(), ParamValue::Real(i as f64))],
            })
            .collect();
        store.insert_jobs(campaign, &jobs).unwrap();
        let path = dir.path().join("campaign.sqlite");
        let reader = Store::open_read_only(&path).unwrap();

        let writer = std::thread::spawn(move || {
            for job in &jobs {
                store.mark_running(&job.job_id, 1, "node", 1.0, "0.1.0+test").unwrap();
                let result = test_support::job_result(&[("m", 1.0, ""), ("n", 2.0, "Pa")]);
                store.finish_job(&job.job_id, &result).unwrap();
            }
        });
        let mut last_done = 0;
        let mut reads = 0;
        while !writer.is_finished() || last_done < JOBS {
            let counts = reader.status_counts(campaign).unwrap();
            let done = counts["done"];
            assert!(done >= last_done, "done went from {last_done} to {done}");
            assert_eq!(counts.values().sum::<usize>(), JOBS);
            assert!(counts["running"] <= 1, "{counts:?}");
            // Whole transactions only: a done job always has both its metrics.
            let (_, rows) = reader
                .query_sql(
                    "SELECT count(*) FROM jobs j WHERE j.status = 'done'
                     AND (SELECT count(*) FROM metrics m WHERE m.job_id = j.job_id) <> 2",
                )
                .unwrap();
            assert_eq!(rows, [[serde_json::json!(0)]]);
            last_done = done;
            reads += 1;
            if writer.is_finished() && last_done < JOBS {
                last_done = reader.status_counts(campaign).unwrap()["done"];
            }
        }
        writer.join().expect("writer thread");
        assert_eq!(last_done, JOBS);
        assert!(reads > 1);
        assert_eq!(reader.integrity_check().unwrap(), "ok");
    }
}
