//! Campaign-level metrics computed from several jobs (the `derived:` section of a campaign file), stored in the
//! `derived` table per group of jobs that share every other parameter.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::metrics::JobMetric;
use crate::analysis::fluidization::{SweepPoint, minimum_fluidization};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum DerivedSpec {
    /// u_mf from a sweep of inlet velocities (seed 000 §4.1.2: the jump of σ(ΔP); seed 001: the packed-bed line
    /// meeting W/A), one value per group of the other parameters. Needs the metrics `pressure_drop_mean_pa`,
    /// `pressure_drop_std_pa` and `bed_weight_per_area_pa`.
    MinimumFluidizationVelocity {
        /// The sweep parameter (its `name:` or path) holding the superficial inlet velocity, m/s.
        velocity_param: String,
    },
}

impl DerivedSpec {
    /// The per-job metrics it is computed from.
    pub fn required_metrics(&self) -> &'static [JobMetric] {
        match self {
            DerivedSpec::MinimumFluidizationVelocity { .. } => &[
                JobMetric::PressureDropMean,
                JobMetric::PressureDropStd,
                JobMetric::BedWeightPerArea,
            ],
        }
    }

    pub fn param(&self) -> &str {
        match self {
            DerivedSpec::MinimumFluidizationVelocity { velocity_param } => velocity_param,
        }
    }
}

/// One derived value: the group (canonical JSON of the other parameters), name, value, unit.
#[derive(Debug, Clone, PartialEq)]
pub struct DerivedValue {
    pub group_json: String,
    pub name: &'static str,
    pub value: f64,
    pub unit: &'static str,
}

/// Computes every derived metric from the export rows of a campaign (`Store::export_rows`: `param.<name>` and
/// `metric.<name> [unit]` columns); only jobs with status `done` count.
pub fn compute(specs: &[DerivedSpec], header: &[String], rows: &[Vec<Value>]) -> Vec<DerivedValue> {
    let column = |name: &str| header.iter().position(|h| h == name);
    let metric_column = |metric: JobMetric| {
        let name = metric.name();
        header
            .iter()
            .position(|h| h == &format!("metric.{name}") || h.starts_with(&format!("metric.{name} [")))
    };
    let params: Vec<(usize, String)> = header
        .iter()
        .enumerate()
        .filter_map(|(k, h)| h.strip_prefix("param.").map(|n| (k, n.to_string())))
        .collect();
    let status = column("status");
    let number = |row: &[Value], k: Option<usize>| k.and_then(|k| row[k].as_f64()).unwrap_or(f64::NAN);
    let mut out = Vec::new();
    for spec in specs {
        match spec {
            DerivedSpec::MinimumFluidizationVelocity { velocity_param } => {
                let u = column(&format!("param.{velocity_param}"));
                let (mean, std, weight) = (
                    metric_column(JobMetric::PressureDropMean),
                    metric_column(JobMetric::PressureDropStd),
                    metric_column(JobMetric::BedWeightPerArea),
                );
                let mut groups: BTreeMap<String, Vec<SweepPoint>> = BTreeMap::new();
                for row in rows {
                    if status.is_some_and(|s| row[s] != Value::String("done".into())) {
                        continue;
                    }
                    let group: BTreeMap<&str, &Value> = params
                        .iter()
                        .filter(|(_, n)| n != velocity_param)
                        .map(|(k, n)| (n.as_str(), &row[*k]))
                        .collect();
                    let key = serde_json::to_string(&group).expect("JSON values serialise");
                    groups.entry(key).or_default().push(SweepPoint {
                        velocity_m_per_s: number(row, u),
                        pressure_drop_mean_pa: number(row, mean),
                        pressure_drop_std_pa: number(row, std),
                        bed_weight_per_area_pa: number(row, weight),
                    });
                }
                for (group_json, points) in groups {
                    let m = minimum_fluidization(&points);
                    let get = |f: fn(&crate::analysis::fluidization::MinimumFluidization) -> f64| {
                        m.as_ref().map_or(f64::NAN, f)
                    };
                    for (name, value, unit) in [
                        (
                            "u_mf_pressure_fluctuation_m_per_s",
                            get(|m| m.from_fluctuations_m_per_s),
                            "m/s",
                        ),
                        ("u_mf_below_jump_m_per_s", get(|m| m.below_jump_m_per_s), "m/s"),
                        (
                            "u_mf_sustained_fluctuation_m_per_s",
                            get(|m| m.from_sustained_fluctuations_m_per_s),
                            "m/s",
                        ),
                        ("u_mf_fluctuation_jump_ratio", get(|m| m.jump_ratio), ""),
                        ("u_mf_ergun_line_m_per_s", get(|m| m.from_ergun_line_m_per_s), "m/s"),
                    ] {
                        out.push(DerivedValue {
                            group_json: group_json.clone(),
                            name,
                            value,
                            unit,
                        });
                    }
                }
            }
        }
    }
    out
}
