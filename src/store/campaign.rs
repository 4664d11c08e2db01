//! Campaign rows: recording the campaign file a run used, finding it again on `resume`, and campaign-level
//! (derived) metrics.
//!
//! What does not live here: deciding whether a changed campaign file may reuse a stored campaign (the caller
//! compares [`Campaign::spec_hash`] before calling [`Store::upsert_campaign`]).

use rusqlite::{OptionalExtension, params};

use super::error::{Context, StoreError};
use super::{Store, unix_time_s};

/// A stored campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Campaign {
    pub id: i64,
    pub name: String,
    /// The campaign file, verbatim.
    pub spec_yaml: String,
    pub spec_hash: String,
    /// Unix seconds of the first run.
    pub created_at: f64,
    /// granflow build of the latest run (its version before schema 2).
    pub engine_version: String,
    /// The campaign file as the user named it at the latest `granflow run`, if recorded.
    pub source_path: Option<String>,
}

impl Store {
    /// Records campaign `name` and returns its id. A campaign that already exists keeps its id and `created_at`;
    /// its spec, hash and engine version are replaced by the given ones.
    pub fn upsert_campaign(
        &mut self,
        name: &str,
        spec_yaml: &str,
        spec_hash: &str,
        engine_version: &str,
    ) -> Result<i64, StoreError> {
        self.conn
            .query_row(
                "INSERT INTO campaigns (name, spec_yaml, spec_hash, created_at, engine_version)
                 VALUES (?1, ?2, ?3, ?4, ?5)
                 ON CONFLICT (name) DO UPDATE SET
                     spec_yaml = excluded.spec_yaml,
                     spec_hash = excluded.spec_hash,
                     engine_version = excluded.engine_version
                 RETURNING id",
                params![name, spec_yaml, spec_hash, unix_time_s(), engine_version],
                |row| row.get(0),
            )
            .context(&self.path, format_args!("recording campaign `{name}`"))
    }

    /// Records the campaign file the user ran (as named on the command line) for campaign `id`.
    pub fn set_campaign_source(&mut self, id: i64, source_path: &str) -> Result<(), StoreError> {
        self.conn
            .execute(
                "UPDATE campaigns SET source_path = ?2 WHERE id = ?1",
                params![id, source_path],
            )
            .context(&self.path, format_args!("recording the source of campaign {id}"))?;
        Ok(())
    }

    /// The campaign called `name`, if stored.
    pub fn campaign_by_name(&self, name: &str) -> Result<Option<Campaign>, StoreError> {
        self.conn
            .query_row(
                "SELECT id, name, spec_yaml, spec_hash, created_at, engine_version, source_path FROM campaigns
                 WHERE name = ?1",
                [name],
                |row| {
                    Ok(Campaign {
                        id: row.get(0)?,
                        name: row.get(1)?,
                        spec_yaml: row.get(2)?,
                        spec_hash: row.get(3)?,
                        created_at: row.get(4)?,
                        engine_version: row.get(5)?,
                        source_path: row.get(6)?,
                    })
                },
            )
            .optional()
            .context(&self.path, format_args!("looking up campaign `{name}`"))
    }

    /// Stores a campaign-level metric for the group of jobs described by `group_json` (canonical JSON of the
    /// parameters shared by the group, `"{}"` for the whole campaign), replacing an earlier value of the same
    /// (campaign, group, name). NaN is stored as NULL.
    pub fn insert_derived(
        &mut self,
        campaign_id: i64,
        group_json: &str,
        name: &str,
        value: f64,
        unit: &str,
    ) -> Result<(), StoreError> {
        self.require_campaign(campaign_id)?;
        self.conn
            .execute(
                "INSERT INTO derived (campaign_id, group_json, name, value, unit) VALUES (?1, ?2, ?3, ?4, ?5)
                 ON CONFLICT (campaign_id, group_json, name) DO UPDATE SET value = excluded.value, unit = excluded.unit",
                params![campaign_id, group_json, name, value, unit],
            )
            .context(&self.path, format_args!("storing derived metric `{name}` of campaign {campaign_id}"))?;
        Ok(())
    }

    /// Fails with [`StoreError::UnknownCampaign`] unless campaign `campaign_id` exists.
    pub(crate) fn require_campaign(&self, campaign_id: i64) -> Result<(), StoreError> {
        let exists: bool = self
            .conn
            .query_row(
                "SELECT EXISTS (SELECT 1 FROM campaigns WHERE id = ?1)",
                [campaign_id],
                |row| row.get(0),
            )
            .context(&self.path, format_args!("looking up campaign {campaign_id}"))?;
        if exists {
            Ok(())
        } else {
            Err(StoreError::UnknownCampaign {
                path: self.path.clone(),
                campaign_id,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::new_store;
    use super::*;
    use serde_json::json;

    #[test]
    fn upsert_campaign_keeps_id_and_created_at() {
        let (_dir, mut store) = new_store();
        let id = store.upsert_campaign("drum", "a: 1", "h1", "0.1.0").unwrap();
        let first = store.campaign_by_name("drum").unwrap().unwrap();
        let again = store.upsert_campaign("drum", "a: 2", "h2", "0.2.0").unwrap();
        assert_eq!(again, id);
        let second = store.campaign_by_name("drum").unwrap().unwrap();
        assert_eq!(second.created_at, first.created_at);
        assert_eq!((second.spec_yaml.as_str(), second.spec_hash.as_str()), ("a: 2", "h2"));
        assert_eq!(second.engine_version, "0.2.0");
        assert_ne!(store.upsert_campaign("bed", "", "h", "0.1.0").unwrap(), id);
        assert!(store.campaign_by_name("kiln").unwrap().is_none());
    }

    #[test]
    fn insert_derived_replaces_the_same_group_and_name() {
        let (_dir, mut store) = new_store();
        let id = store.upsert_campaign("bed", "", "h", "0").unwrap();
        store.insert_derived(id, "{}", "u_mf", 0.3, "m/s").unwrap();
        store.insert_derived(id, "{}", "u_mf", 0.31, "m/s").unwrap();
        store
            .insert_derived(id, "{\"d_p_m\":0.001}", "u_mf", 0.2, "m/s")
            .unwrap();
        let (_, rows) = store
            .query_sql("SELECT group_json, value FROM derived ORDER BY group_json")
            .unwrap();
        assert_eq!(
            rows,
            [[json!("{\"d_p_m\":0.001}"), json!(0.2)], [json!("{}"), json!(0.31)]]
        );
        let err = store.insert_derived(id + 1, "{}", "u_mf", 0.3, "m/s").unwrap_err();
        assert!(matches!(err, StoreError::UnknownCampaign { .. }), "{err}");
    }
}
