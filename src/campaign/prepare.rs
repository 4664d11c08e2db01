//! Shared preparations: the first seconds of a sweep's jobs run once for every group of jobs that cannot differ
//! before then (a bed settling before its gas or liquid bridges start), and each job continues from that state.
//!
//! The campaign file names the swept parameters that do not act before `until_s` (`prepare.shared_across`). Jobs
//! equal in every other parameter form a group; the group's preparation is the job's own scenario cut at `until_s`,
//! run twice: with each shared parameter at the first value the sweep gives it and at the last. The worker that first
//! needs a preparation runs both, checks that they end in the same state to the bit (every particle, contact, gas
//! and random-generator value, and every series row), and only then lets jobs start from it; when they differ, a
//! shared parameter acted before `until_s` and every job of the group fails as a configuration error naming the
//! first differing value. A job started from its preparation therefore ends bit-identical to the same job run from
//! the start (what `tests/campaign_prepare.rs` checks against `granflow simulate` of the job's own scenario).
//!
//! The jobs of a group must also share their random numbers, so with `prepare` a job's seed derives from the
//! campaign seed and the parameters that are not shared (without `prepare`, from all of them, as before).
//! LIGGGHTS users do the same by hand: one settling run writes a restart file that every case reads.

use serde::{Deserialize, Serialize};

use super::sweep;
use crate::scenario::ScenarioSpec;

/// `prepare:` in the campaign file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PrepareSpec {
    /// The preparation runs from the start to this time, s; it must end before every job does.
    pub until_s: f64,
    /// Sweep axes (their `name`, or their parameter path) that do not act before `until_s`: jobs differing only in
    /// these share one preparation. Checked by running each preparation at the first and the last value of each.
    pub shared_across: Vec<String>,
}

/// What a job records about the preparation it starts from (in `job.json`; not part of the job's id, since the job
/// ends in the same bits either way).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Preparation {
    /// Hash of the two scenarios below: the directory `preparations/<id>/` of the campaign.
    pub id: String,
    pub until_s: f64,
    /// The shared parameters' paths (for messages).
    pub shared_params: Vec<String>,
    /// The job's scenario cut at `until_s` with the shared parameters at their first values, then at their last.
    /// The second is left out when it is the first (a sweep giving each shared parameter one value).
    pub scenarios: Vec<ScenarioSpec>,
}

/// The shared parameters' paths, from the names or paths written in `prepare.shared_across`; errors are (key,
/// message).
pub fn shared_paths(
    spec: &PrepareSpec,
    swept: &[String],
    names: &[(String, String)],
) -> Result<Vec<String>, (String, String)> {
    if !(spec.until_s.is_finite() && spec.until_s > 0.0) {
        return Err((
            "prepare.until_s".into(),
            format!("expected a time > 0 s, got {}", spec.until_s),
        ));
    }
    if spec.shared_across.is_empty() {
        return Err((
            "prepare.shared_across".into(),
            "expected at least one sweep axis (without one, every job is its own preparation: leave `prepare` out)"
                .into(),
        ));
    }
    let mut paths = Vec::new();
    for (k, entry) in spec.shared_across.iter().enumerate() {
        let key = format!("prepare.shared_across[{k}]");
        let by_name = names.iter().find(|(_, n)| n == entry).map(|(p, _)| p.clone());
        let path = by_name.or_else(|| sweep::canonical_path(entry).ok().filter(|p| swept.contains(p)));
        let Some(path) = path else {
            let known: Vec<String> = swept
                .iter()
                .map(|p| names.iter().find(|(q, _)| q == p).map_or(p.clone(), |(_, n)| n.clone()))
                .collect();
            return Err((
                key,
                format!("`{entry}` is not a sweep axis; the sweep has {}", known.join(", ")),
            ));
        };
        if path == "seed" {
            return Err((
                key,
                "the seed acts from the first step; it cannot be shared by a preparation".into(),
            ));
        }
        if paths.contains(&path) {
            return Err((key, format!("`{entry}` is listed twice")));
        }
        paths.push(path);
    }
    Ok(paths)
}

/// The preparation of one job: its scenario cut at `until_s` with each shared path at `first` and at `last` (the
/// values the sweep's first and last jobs give it). Errors are (key, message).
pub fn preparation(
    scenario: &ScenarioSpec,
    until_s: f64,
    shared: &[String],
    first: &[serde_json::Value],
    last: &[serde_json::Value],
) -> Result<Preparation, (String, String)> {
    if until_s >= scenario.time.end_time_s {
        return Err((
            "prepare.until_s".into(),
            format!(
                "expected a time before the jobs end (time.end_time_s = {} s), got {until_s} s",
                scenario.time.end_time_s
            ),
        ));
    }
    let with = |values: &[serde_json::Value]| -> Result<ScenarioSpec, (String, String)> {
        let mut doc = serde_json::to_value(scenario).expect("a scenario serialises");
        for (path, value) in shared.iter().zip(values) {
            sweep::set_path(&mut doc, path, value.clone()).map_err(|m| ("prepare.shared_across".to_string(), m))?;
        }
        let mut cut: ScenarioSpec = serde_json::from_value(doc).map_err(|e| {
            (
                "prepare.shared_across".to_string(),
                format!("the preparation's scenario: {e}"),
            )
        })?;
        cut.time.end_time_s = until_s;
        Ok(cut)
    };
    let mut scenarios = vec![with(first)?];
    let at_last = with(last)?;
    if at_last != scenarios[0] {
        scenarios.push(at_last);
    }
    let canonical = serde_json::to_string(&(&scenarios, until_s)).expect("scenarios serialise");
    let h = xxhash_rust::xxh3::xxh3_128(canonical.as_bytes());
    Ok(Preparation {
        id: format!("{:016x}", (h >> 64) as u64),
        until_s,
        shared_params: shared.to_vec(),
        scenarios,
    })
}
