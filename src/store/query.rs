//! Free SQL for `granflow query --sql`: one statement, run on a read-only connection, with rows returned as JSON
//! values ready for [`render_table`](super::render_table), [`render_csv`](super::render_csv) and
//! [`render_json`](super::render_json).
//!
//! Three locks keep a query from changing the database: statements that SQLite reports as writing are refused
//! before they run, the connection is opened `SQLITE_OPEN_READ_ONLY`, and it has `PRAGMA query_only` set. What does
//! not live here: the schema documentation users write queries against (`schemas/results.sql`).

use rusqlite::types::ValueRef;
use rusqlite::{Connection, ErrorCode};
use serde_json::Value;

use super::Store;
use super::error::{Context, StoreError};
use super::render::json_real;

impl Store {
    /// Runs one SQL statement on a read-only connection (this store's own if it was opened read-only, else a new
    /// one to the same file) and returns the column names and the rows. Statements that would modify the database
    /// fail with [`StoreError::WriteInQuery`]. Reals that are not finite come back as the strings `"inf"`, `"-inf"`
    /// and `"NaN"`, blobs as `"x'<hex>'"`.
    pub fn query_sql(&self, sql: &str) -> Result<(Vec<String>, Vec<Vec<Value>>), StoreError> {
        let own_reader;
        let conn: &Connection = if self.read_only {
            &self.conn
        } else {
            own_reader = Self::read_only_connection(&self.path)?;
            &own_reader
        };
        let invalid = |reason: &str| StoreError::InvalidQuery {
            path: self.path.clone(),
            reason: reason.to_string(),
        };
        if sql.trim().is_empty() {
            return Err(invalid("the query is empty"));
        }
        let write_refused = || StoreError::WriteInQuery {
            path: self.path.clone(),
            sql: abbreviate(sql),
        };
        let action = format_args!("running the query `{}`", abbreviate(sql));
        let mut stmt = match conn.prepare(sql) {
            Ok(stmt) => stmt,
            Err(rusqlite::Error::MultipleStatement) => {
                return Err(invalid(
                    "a query must be a single SQL statement (remove the text after the first `;`)",
                ));
            }
            Err(source) => return Err(StoreError::sqlite(&self.path, action, source)),
        };
        if !stmt.readonly() {
            return Err(write_refused());
        }
        let header: Vec<String> = stmt.column_names().map(str::to_string).collect();
        let width = header.len();
        let rows = stmt
            .query_map([], |row| {
                (0..width).map(|col| row.get_ref(col).map(json_value)).collect()
            })
            .and_then(|rows| rows.collect::<rusqlite::Result<Vec<Vec<Value>>>>());
        match rows {
            Ok(rows) => Ok((header, rows)),
            Err(rusqlite::Error::SqliteFailure(error, _)) if error.code == ErrorCode::ReadOnly => Err(write_refused()),
            Err(source) => Err(source).context(&self.path, action),
        }
    }
}

/// A stored value as JSON.
fn json_value(value: ValueRef<'_>) -> Value {
    match value {
        ValueRef::Null => Value::Null,
        ValueRef::Integer(value) => Value::from(value),
        ValueRef::Real(value) => json_real(value),
        ValueRef::Text(bytes) => Value::String(String::from_utf8_lossy(bytes).into_owned()),
        ValueRef::Blob(bytes) => {
            let hex: String = bytes.iter().map(|byte| format!("{byte:02x}")).collect();
            Value::String(format!("x'{hex}'"))
        }
    }
}

/// `sql` on one line, cut to 120 characters, for error messages.
fn abbreviate(sql: &str) -> String {
    const MAX_CHARS: usize = 120;
    let one_line = sql.split_whitespace().collect::<Vec<_>>().join(" ");
    if one_line.chars().count() <= MAX_CHARS {
        one_line
    } else {
        let cut: String = one_line.chars().take(MAX_CHARS - 1).collect();
        format!("{cut}…")
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{finish, new_campaign, sample_jobs};
    use super::*;
    use serde_json::json;

    #[test]
    fn read_only_sql_rejects_delete() {
        let (dir, mut store, campaign) = new_campaign();
        let jobs = sample_jobs();
        store.insert_jobs(campaign, &jobs).unwrap();
        finish(&mut store, "j0", &[("porosity", 0.4, "")]);

        let (header, rows) = store
            .query_sql(
                "SELECT j.job_id, p.value_real AS u, m.value, x'00ff' AS blob FROM jobs j
                 JOIN params p ON p.job_id = j.job_id AND p.name = 'u_m_per_s'
                 LEFT JOIN metrics m ON m.job_id = j.job_id AND m.name = 'porosity'
                 WHERE p.value_real < 0.15 ORDER BY j.ordinal",
            )
            .unwrap();
        assert_eq!(header, ["job_id", "u", "value", "blob"]);
        assert_eq!(
            rows,
            [
                [json!("j0"), json!(0.1), json!(0.4), json!("x'00ff'")],
                [json!("j5"), json!(0.1), Value::Null, json!("x'00ff'")]
            ]
        );

        let reader = Store::open_read_only(dir.path().join("campaign.sqlite")).unwrap();
        for target in [&store, &reader] {
            for sql in [
                "DELETE FROM jobs",
                "delete from metrics where 1",
                "UPDATE jobs SET status = 'done'",
                "DROP TABLE jobs",
                "CREATE TABLE x (a)",
                "PRAGMA user_version = 7",
            ] {
                let err = target.query_sql(sql).unwrap_err();
                assert!(matches!(err, StoreError::WriteInQuery { .. }), "{sql}: {err}");
                assert!(err.to_string().contains("read-only"), "{err}");
            }
            let (_, rows) = target.query_sql("SELECT count(*) FROM jobs; -- all of them\n").unwrap();
            assert_eq!(rows, [[json!(6)]]);
            let err = target.query_sql("SELECT 1; DELETE FROM jobs").unwrap_err();
            assert!(matches!(err, StoreError::InvalidQuery { .. }), "{err}");
            let err = target.query_sql("SELECT nope FROM jobs").unwrap_err();
            assert!(err.to_string().contains("no such column: nope"), "{err}");
        }
        assert_eq!(store.job_summaries(campaign).unwrap().len(), 6);
        assert_eq!(store.schema_version().unwrap(), crate::store::SCHEMA_VERSION);
    }
}
