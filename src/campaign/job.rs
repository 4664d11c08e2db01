//! One job: a fully resolved scenario plus what to reduce from it, and its identity.
//!
//! The id is a hash of the canonical JSON of everything that decides the job's results (engine version, resolved
//! scenario, metrics, analysis settings), so re-running a campaign with added sweep values runs only the new jobs,
//! and changing a parameter makes a different job instead of overwriting one. Thread counts and the position in the
//! sweep are not part of it: results are bit-identical for any thread count.

use serde::{Deserialize, Serialize};

use super::metrics::JobMetric;
use super::prepare::Preparation;
use super::spec::AnalysisSpec;
use crate::scenario::ScenarioSpec;

/// Version of the `job.json` format.
pub const JOB_FORMAT: u32 = 1;

/// What `job.json` in a job directory holds (written once, before the job first runs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JobSpec {
    pub format: u32,
    pub job_id: String,
    pub campaign: String,
    pub engine_version: String,
    /// The parameters the sweep set, in sweep order: (path, value).
    pub params: Vec<(String, serde_json::Value)>,
    pub scenario: ScenarioSpec,
    /// Written by name (`"lacey_index"`), so the job's id is that of the names.
    pub metrics: Vec<JobMetric>,
    pub analysis: AnalysisSpec,
    /// The shared preparation the job starts from (`prepare` in the campaign file); not part of the id.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prepared: Option<Preparation>,
}

impl JobSpec {
    /// Hash of everything but the id itself: 16 hex digits of XXH3-128 over canonical JSON (keys sorted).
    pub fn compute_id(&self) -> String {
        let identity = serde_json::json!({
            "engine_version": self.engine_version,
            "campaign": self.campaign,
            "scenario": self.scenario,
            "metrics": self.metrics,
            "analysis": self.analysis,
        });
        let canonical = serde_json::to_string(&identity).expect("a job spec serialises");
        let h = xxhash_rust::xxh3::xxh3_128(canonical.as_bytes());
        format!("{:016x}", (h >> 64) as u64)
    }

    /// The sweep parameters as a JSON object (path → value), for the database and reports.
    pub fn params_json(&self) -> String {
        let map: serde_json::Map<String, serde_json::Value> = self.params.iter().cloned().collect();
        serde_json::to_string(&map).expect("params serialise")
    }

    /// A short description for logs and `granflow status`: `a=1, b=x`, each parameter by its shortest unique name.
    pub fn label(&self) -> String {
        let paths: Vec<&str> = self.params.iter().map(|(k, _)| k.as_str()).collect();
        self.params
            .iter()
            .map(|(k, v)| format!("{}={}", short_name(k, &paths), v))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The last key of a parameter path (`walls[0].drum.rotation_rpm` → `rotation_rpm`), or as many of its last keys as
/// tell it apart from the other `paths` (`species[0].rolling_friction_coefficient` beside `species[1]`'s).
pub fn short_name<'a>(path: &'a str, paths: &[&str]) -> &'a str {
    let ends: Vec<usize> = path.match_indices('.').map(|(at, _)| at + 1).rev().chain([0]).collect();
    for &start in &ends {
        let suffix = &path[start..];
        let shared = paths
            .iter()
            .filter(|other| **other != path)
            .any(|other| *other == suffix || other.ends_with(&format!(".{suffix}")));
        if !shared {
            return suffix;
        }
    }
    path
}

#[cfg(test)]
mod tests {
    use super::short_name;

    #[test]
    fn a_parameter_is_named_by_as_many_last_keys_as_tell_it_apart() {
        let paths = [
            "species[0].rolling_friction_coefficient",
            "species[1].rolling_friction_coefficient",
            "walls[0].drum.rotation_rpm",
            "gas.velocity_m_per_s",
        ];
        assert_eq!(short_name(paths[0], &paths), "species[0].rolling_friction_coefficient");
        assert_eq!(short_name(paths[1], &paths), "species[1].rolling_friction_coefficient");
        assert_eq!(short_name(paths[2], &paths), "rotation_rpm");
        assert_eq!(short_name(paths[3], &paths), "velocity_m_per_s");
        // A path that is the other's tail keeps one key more than the tail.
        let nested = ["a.b.c", "b.c"];
        assert_eq!(short_name(nested[0], &nested), "a.b.c");
        assert_eq!(short_name(nested[1], &nested), "b.c");
        assert_eq!(short_name("named.simulation", &["named.simulation"]), "simulation");
    }
}
