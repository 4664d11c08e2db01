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
    /// The convective/conductive split of a heated drum's h_w (seed 000 Fig. 72): (h_w(air) − h_w(vacuum)) /
    /// h_w(vacuum) from the pair of jobs with and without gas that share every other parameter. Needs the h_w
    /// metric it reads (`h_w_metric`) in `metrics`.
    ConvectiveToConductiveRatio {
        /// The sweep parameter (its `name:` or path) switching the gas off: `gas.vacuum`, true or false.
        vacuum_param: String,
        /// Which h_w: `wall_heat_transfer_coefficient_w_per_m2_k` (the core's, the default),
        /// `wall_heat_transfer_coefficient_inner_core_w_per_m2_k` or `wall_heat_transfer_coefficient_bed_w_per_m2_k`.
        #[serde(default = "core_wall_heat_transfer_coefficient")]
        #[schemars(default = "core_wall_heat_transfer_coefficient")]
        h_w_metric: JobMetric,
    },
}

fn core_wall_heat_transfer_coefficient() -> JobMetric {
    JobMetric::WallHeatTransferCoefficient
}

/// The h_w metrics a convective/conductive ratio can read.
const WALL_HEAT_TRANSFER_COEFFICIENTS: [JobMetric; 3] = [
    JobMetric::WallHeatTransferCoefficient,
    JobMetric::WallHeatTransferCoefficientInnerCore,
    JobMetric::WallHeatTransferCoefficientBed,
];

impl DerivedSpec {
    /// The per-job metrics it is computed from.
    pub fn required_metrics(&self) -> Vec<JobMetric> {
        match self {
            DerivedSpec::MinimumFluidizationVelocity { .. } => vec![
                JobMetric::PressureDropMean,
                JobMetric::PressureDropStd,
                JobMetric::BedWeightPerArea,
            ],
            DerivedSpec::ConvectiveToConductiveRatio { h_w_metric, .. } => vec![*h_w_metric],
        }
    }

    /// What is wrong with its own fields, if anything: a key below it and a message.
    pub fn invalid_field(&self) -> Option<(&'static str, String)> {
        match self {
            DerivedSpec::ConvectiveToConductiveRatio { h_w_metric, .. }
                if !WALL_HEAT_TRANSFER_COEFFICIENTS.contains(h_w_metric) =>
            {
                Some((
                    "convective_to_conductive_ratio.h_w_metric",
                    format!(
                        "expected one of {}, got `{}`",
                        WALL_HEAT_TRANSFER_COEFFICIENTS
                            .map(|m| format!("`{}`", m.name()))
                            .join(", "),
                        h_w_metric.name()
                    ),
                ))
            }
            _ => None,
        }
    }

    pub fn param(&self) -> &str {
        match self {
            DerivedSpec::MinimumFluidizationVelocity { velocity_param } => velocity_param,
            DerivedSpec::ConvectiveToConductiveRatio { vacuum_param, .. } => vacuum_param,
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
    // Rows with status `done` grouped by every parameter but `except` (canonical JSON of the rest).
    let groups = |except: &str| -> BTreeMap<String, Vec<&Vec<Value>>> {
        let mut groups: BTreeMap<String, Vec<&Vec<Value>>> = BTreeMap::new();
        for row in rows {
            if status.is_some_and(|s| row[s] != Value::String("done".into())) {
                continue;
            }
            let group: BTreeMap<&str, &Value> = params
                .iter()
                .filter(|(_, n)| n != except)
                .map(|(k, n)| (n.as_str(), &row[*k]))
                .collect();
            groups
                .entry(serde_json::to_string(&group).expect("JSON values serialise"))
                .or_default()
                .push(row);
        }
        groups
    };
    let mut out = Vec::new();
    for spec in specs {
        match spec {
            DerivedSpec::ConvectiveToConductiveRatio {
                vacuum_param,
                h_w_metric,
            } => {
                let vacuum = column(&format!("param.{vacuum_param}"));
                let h_w = metric_column(*h_w_metric);
                for (group_json, rows) in groups(vacuum_param) {
                    // The mean h_w of the group's jobs in air and in vacuum (one each in a plain sweep).
                    let mean_where = |in_vacuum: bool| {
                        let values: Vec<f64> = rows
                            .iter()
                            // The store keeps a boolean parameter as its text.
                            .filter(|row| {
                                vacuum.is_some_and(|v| {
                                    row[v] == Value::Bool(in_vacuum) || row[v] == Value::String(in_vacuum.to_string())
                                })
                            })
                            .map(|row| number(row, h_w))
                            .collect();
                        values.iter().sum::<f64>() / values.len() as f64
                    };
                    let (air, vacuum) = (mean_where(false), mean_where(true));
                    out.push(DerivedValue {
                        group_json,
                        name: "convective_to_conductive_ratio",
                        value: (air - vacuum) / vacuum,
                        unit: "",
                    });
                }
            }
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

#[cfg(test)]
mod tests {
    use serde_json::{Value, json};

    use super::{DerivedSpec, compute};
    use crate::campaign::metrics::JobMetric;

    /// Each (material, speed) group pairs its air and vacuum jobs; the store keeps the boolean as text; a job that
    /// did not finish does not count.
    #[test]
    fn the_convective_ratio_pairs_air_and_vacuum_jobs_of_a_group() {
        let header: Vec<String> = [
            "status",
            "param.material",
            "param.vacuum",
            "metric.wall_heat_transfer_coefficient_w_per_m2_k [W/(m2 K)]",
        ]
        .map(String::from)
        .to_vec();
        let row = |status: &str, material: &str, vacuum: &str, h: f64| -> Vec<Value> {
            vec![json!(status), json!(material), json!(vacuum), json!(h)]
        };
        let rows = vec![
            row("done", "glass", "false", 95.0),
            row("done", "glass", "true", 5.0),
            row("done", "aluminium", "false", 150.0),
            row("done", "aluminium", "true", 100.0),
            row("failed", "aluminium", "true", 1.0),
        ];
        let spec = DerivedSpec::ConvectiveToConductiveRatio {
            vacuum_param: "vacuum".into(),
            h_w_metric: JobMetric::WallHeatTransferCoefficient,
        };
        let out = compute(&[spec], &header, &rows);
        let value = |material: &str| {
            out.iter()
                .find(|d| d.group_json == format!("{{\"material\":\"{material}\"}}"))
                .map(|d| (d.name, d.value))
                .unwrap()
        };
        assert_eq!(value("glass"), ("convective_to_conductive_ratio", 18.0));
        assert_eq!(value("aluminium"), ("convective_to_conductive_ratio", 0.5));
        assert_eq!(out.len(), 2);
    }
}
