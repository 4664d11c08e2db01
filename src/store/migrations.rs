//! Schema migrations, tracked by `PRAGMA user_version`.
//!
//! Migration `i` (1-based) is `MIGRATIONS[i - 1]`; a database at version `v` gets migrations `v + 1 ..=
//! SCHEMA_VERSION`, all in one immediate transaction together with the new `user_version`, so a crash leaves the
//! database at its old version or at the new one, never in between. A database whose version is newer than this
//! build is refused, never touched. What does not live here: connection settings (WAL, foreign keys), see `mod.rs`.

use std::path::Path;

use rusqlite::{Connection, TransactionBehavior};

use super::error::{Context, StoreError};

/// The SQL of each migration, in order. Append only: a released migration is never edited.
const MIGRATIONS: &[&str] = &[
    include_str!("../../schemas/results.sql"),
    include_str!("../../schemas/results-2-build.sql"),
    include_str!("../../schemas/results-3-slurm.sql"),
];

/// The schema version this build reads and writes (the number of migrations).
pub const SCHEMA_VERSION: i64 = MIGRATIONS.len() as i64;

/// The `user_version` of the database behind `conn` (0 for a new, empty file).
pub(crate) fn schema_version(conn: &Connection, path: &Path) -> Result<i64, StoreError> {
    conn.pragma_query_value(None, "user_version", |row| row.get(0))
        .context(path, "reading the schema version")
}

/// Brings the database up to [`SCHEMA_VERSION`]; a no-op when it is already there. Returns the version found.
pub(crate) fn migrate(conn: &mut Connection, path: &Path) -> Result<i64, StoreError> {
    // CHOICE: IMMEDIATE takes the write lock before reading the version, so two processes opening a new file at once
    // cannot both apply migration 1; the second waits (busy timeout), then sees the new version and does nothing.
    let tx = conn
        .transaction_with_behavior(TransactionBehavior::Immediate)
        .context(path, "starting the migration transaction")?;
    let found = schema_version(&tx, path)?;
    if found > SCHEMA_VERSION {
        return Err(StoreError::TooNew {
            path: path.to_path_buf(),
            found,
            supported: SCHEMA_VERSION,
        });
    }
    if found == SCHEMA_VERSION {
        return Ok(found);
    }
    for (index, sql) in MIGRATIONS.iter().enumerate().skip(found as usize) {
        tx.execute_batch(sql)
            .context(path, format_args!("applying migration {}", index + 1))?;
    }
    tx.pragma_update(None, "user_version", SCHEMA_VERSION)
        .context(path, "setting the schema version")?;
    tx.commit().context(path, "committing the migrations")?;
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::store::Store;

    fn table_names(conn: &Connection) -> Vec<String> {
        let mut stmt = conn
            .prepare("SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name")
            .unwrap();
        stmt.query_map([], |row| row.get(0))
            .unwrap()
            .collect::<Result<_, _>>()
            .unwrap()
    }

    #[test]
    fn migrations_are_idempotent() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("campaign.sqlite");
        let mut conn = Connection::open(&path).unwrap();
        assert_eq!(migrate(&mut conn, &path).unwrap(), 0);
        let tables = table_names(&conn);
        assert_eq!(
            tables,
            [
                "attempts",
                "campaigns",
                "derived",
                "jobs",
                "metrics",
                "params",
                "timings"
            ]
        );
        assert_eq!(migrate(&mut conn, &path).unwrap(), SCHEMA_VERSION);
        assert_eq!(table_names(&conn), tables);
        assert_eq!(schema_version(&conn, &path).unwrap(), SCHEMA_VERSION);
        drop(conn);

        // Through Store::open, twice, with data in between: the data survives re-opening.
        let mut store = Store::open(&path).unwrap();
        let id = store.upsert_campaign("c", "a: 1", "h", "0.1.0").unwrap();
        drop(store);
        let store = Store::open(&path).unwrap();
        assert_eq!(store.campaign_by_name("c").unwrap().unwrap().id, id);
        assert_eq!(store.schema_version().unwrap(), SCHEMA_VERSION);
    }

    /// A database written by a build of schema 1 (campaigns, jobs and attempts but no builds) opens, migrates to the
    /// current schema keeping its rows, and reads its missing builds and source as NULL.
    #[test]
    fn a_version_1_database_migrates_keeping_its_rows() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("campaign.sqlite");
        let conn = Connection::open(&path).unwrap();
        conn.execute_batch(MIGRATIONS[0]).unwrap();
        conn.pragma_update(None, "user_version", 1).unwrap();
        conn.execute_batch(
            "INSERT INTO campaigns (name, spec_yaml, spec_hash, created_at, engine_version)
                 VALUES ('old', 'a: 1', 'h', 1.0, '0.1.0');
             INSERT INTO jobs (job_id, campaign_id, ordinal, params_json, status, attempt)
                 VALUES ('j1', 1, 0, '{}', 'done', 1);
             INSERT INTO attempts (job_id, attempt, outcome, started_at, ended_at) VALUES ('j1', 1, 'done', 2.0, 3.0);",
        )
        .unwrap();
        drop(conn);
        let store = Store::open(&path).unwrap();
        assert_eq!(store.schema_version().unwrap(), SCHEMA_VERSION);
        let campaign = store.campaign_by_name("old").unwrap().unwrap();
        assert_eq!(
            (campaign.engine_version.as_str(), campaign.source_path),
            ("0.1.0", None)
        );
        let (_, rows) = store.query_sql("SELECT job_id, build FROM attempts").unwrap();
        assert_eq!(rows, vec![vec![serde_json::json!("j1"), serde_json::Value::Null]]);
    }

    #[test]
    fn newer_database_is_refused_and_left_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("campaign.sqlite");
        drop(Store::open(&path).unwrap());
        let conn = Connection::open(&path).unwrap();
        conn.pragma_update(None, "user_version", SCHEMA_VERSION + 1).unwrap();
        drop(conn);

        let err = Store::open(&path).expect_err("a newer schema must be refused");
        assert!(matches!(err, StoreError::TooNew { found, .. } if found == SCHEMA_VERSION + 1));
        let message = err.to_string();
        assert!(message.contains("newer"), "{message}");
        assert!(message.contains(&path.display().to_string()), "{message}");
        let err = Store::open_read_only(&path).expect_err("read-only open must refuse too");
        assert!(matches!(err, StoreError::TooNew { .. }), "{err}");

        let conn = Connection::open(&path).unwrap();
        assert_eq!(schema_version(&conn, &path).unwrap(), SCHEMA_VERSION + 1);
    }

    #[test]
    fn read_only_open_refuses_an_unmigrated_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("empty.sqlite");
        Connection::open(&path)
            .unwrap()
            .execute_batch("CREATE TABLE t(x)")
            .unwrap();
        let err = Store::open_read_only(&path).expect_err("version 0 is not a results database");
        assert!(err.to_string().contains("not a granflow results database"), "{err}");
    }
}
