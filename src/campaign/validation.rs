//! The `validation:` section of a validation campaign: which VALIDATION case it reproduces, and the checks that
//! `granflow report` evaluates against the stored results (our number next to the source's, with a tolerance).

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ValidationSpec {
    /// The case id of `VALIDATION.md`, e.g. `D2`.
    pub case: String,
    /// A short title, e.g. `dry u_mf`.
    pub title: String,
    /// Where the reference numbers come from, e.g. `seed 000 Table 4`.
    pub source: String,
    /// Every choice the source leaves open, one per entry (printed in the report).
    #[serde(default)]
    pub choices: Vec<String>,
    pub checks: Vec<CheckSpec>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CheckSpec {
    /// What is checked, e.g. `u_mf, R = 1.35 mm, rho = 2000 kg/m3`.
    pub name: String,
    pub value: CheckValue,
    /// Only jobs (or derived groups) whose parameters have these values (by parameter name); numbers compare
    /// with a relative tolerance of 1e-9.
    #[serde(default, rename = "where")]
    pub filter: std::collections::BTreeMap<String, serde_json::Value>,
    /// Divide by the same value for the jobs (or groups) matching `where` with these parameter values put in: e.g.
    /// a wet run's u_mf over the dry run's. Empty: no division.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub relative_to: std::collections::BTreeMap<String, serde_json::Value>,
    /// Subtract the same value for the jobs (or groups) matching `where` with these parameter values put in: e.g.
    /// a baffled drum's Lacey index less the unbaffled drum's ("25 points above"). Empty: no subtraction; not
    /// together with `relative_to`.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub difference_from: std::collections::BTreeMap<String, serde_json::Value>,
    /// The source's number.
    pub expected: f64,
    /// Pass when |ours/expected − 1| ≤ this ...
    #[serde(default)]
    pub tolerance_rel: Option<f64>,
    /// ... or when ours lies in [min, max].
    #[serde(default)]
    pub range: Option<[f64; 2]>,
}

/// Where our number comes from. With several matching jobs, their mean.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum CheckValue {
    /// A per-job metric.
    Metric(String),
    /// The ratio of two per-job metrics (of the same job).
    Ratio([String; 2]),
    /// A campaign-level derived metric.
    Derived(String),
}

impl ValidationSpec {
    /// Checks the section's shape; errors are (key path, message).
    pub fn check(&self, metrics: &[String]) -> Result<(), (String, String)> {
        if self.case.trim().is_empty() {
            return Err(("validation.case".into(), "expected a case id such as D2".into()));
        }
        if self.checks.is_empty() {
            return Err(("validation.checks".into(), "expected at least one check".into()));
        }
        for (k, c) in self.checks.iter().enumerate() {
            let key = |f: &str| format!("validation.checks[{k}].{f}");
            match (c.tolerance_rel, c.range) {
                (Some(t), None) if t.is_finite() && t > 0.0 => {}
                (None, Some([lo, hi])) if lo.is_finite() && hi.is_finite() && lo <= hi => {}
                _ => {
                    return Err((
                        key("tolerance_rel"),
                        "give exactly one of tolerance_rel (> 0) and range ([min, max])".into(),
                    ));
                }
            }
            if !c.relative_to.is_empty() && !c.difference_from.is_empty() {
                return Err((
                    key("difference_from"),
                    "give at most one of relative_to (a ratio) and difference_from (a difference)".into(),
                ));
            }
            let needed: Vec<&String> = match &c.value {
                CheckValue::Metric(m) => vec![m],
                CheckValue::Ratio([a, b]) => vec![a, b],
                CheckValue::Derived(_) => vec![],
            };
            for m in needed {
                if !metrics.contains(m) {
                    return Err((key("value"), format!("metric `{m}` is not in the campaign's metrics")));
                }
            }
        }
        Ok(())
    }
}
