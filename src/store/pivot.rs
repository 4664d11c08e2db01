//! Phase-diagram pivots: one metric of a campaign's done jobs laid out over two swept parameters, rows = values of
//! the y parameter, columns = values of the x parameter, and its renderings (text table, CSV, JSON).
//!
//! When several jobs share an (x, y) pair because other parameters vary, the cell holds their mean and says how
//! many jobs it averages ([`PivotCell::count`]). Axes list every value present in the campaign, so a job that has
//! not finished shows as an empty cell rather than a missing column. What does not live here: plotting
//! (`plot.rs`) and choosing which parameters to pivot over.

use std::cmp::Ordering;

use rusqlite::params;
use serde_json::{Value, json};

use super::Store;
use super::error::{Context, StoreError};
use super::job::{JobStatus, ParamValue};
use super::render::{align, format_real, format_significant, json_real, push_csv_line};

/// One cell of a [`Pivot`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PivotCell {
    /// Mean of the metric over the done jobs at this (x, y) (NaN values, stored as NULL, are left out).
    pub mean: f64,
    /// Number of jobs averaged; more than 1 when parameters other than x and y vary.
    pub count: usize,
    /// Sample standard deviation (n − 1) of the jobs averaged: replicates' scatter; `None` for a single job.
    pub std: Option<f64>,
}

/// A metric over two parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Pivot {
    pub x_param: String,
    pub y_param: String,
    pub metric: String,
    /// Unit of the metric, `""` for dimensionless.
    pub unit: String,
    /// Column values, sorted (numbers numerically, then texts).
    pub x_values: Vec<ParamValue>,
    /// Row values, sorted likewise.
    pub y_values: Vec<ParamValue>,
    /// `cells[row][column]`, indexed like `y_values` and `x_values`; `None` where no done job has a value.
    pub cells: Vec<Vec<Option<PivotCell>>>,
    /// Only jobs with these parameter values were laid out (empty: all).
    pub filters: Vec<(String, ParamValue)>,
}

/// The cell of `values` (the jobs at one x and y, in the database's order): their mean (summed in that order) and
/// sample standard deviation; `None` without any.
fn cell_of(values: &[f64]) -> Option<PivotCell> {
    let count = values.len();
    if count == 0 {
        return None;
    }
    let mean = values.iter().sum::<f64>() / count as f64;
    let std =
        (count > 1).then(|| (values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (count - 1) as f64).sqrt());
    Some(PivotCell { mean, count, std })
}

impl Store {
    /// Lays out `metric` of the campaign's done jobs over `x_param` (columns) and `y_param` (rows). Unknown
    /// parameter or metric names fail with the list of names that exist; jobs lacking either parameter are left
    /// out.
    pub fn pivot(&self, campaign_id: i64, x_param: &str, y_param: &str, metric: &str) -> Result<Pivot, StoreError> {
        self.pivot_where(campaign_id, x_param, y_param, metric, &[])
    }

    /// [`Store::pivot`] of only the jobs whose parameters have the given values (e.g. one particle kind of several:
    /// otherwise a cell averages over them). A filter on a parameter the campaign does not sweep fails with the list
    /// of those it does; a value no job has leaves every cell empty.
    pub fn pivot_where(
        &self,
        campaign_id: i64,
        x_param: &str,
        y_param: &str,
        metric: &str,
        filters: &[(String, ParamValue)],
    ) -> Result<Pivot, StoreError> {
        self.layout(campaign_id, x_param, Some(y_param), metric, filters)
    }

    /// `metric` over `x_param` alone (a curve): [`Store::pivot_where`] with one row, whose parameter is `""` and
    /// whose one value is the text `""`; each cell averages every matching job at that x.
    pub fn curve_where(
        &self,
        campaign_id: i64,
        x_param: &str,
        metric: &str,
        filters: &[(String, ParamValue)],
    ) -> Result<Pivot, StoreError> {
        self.layout(campaign_id, x_param, None, metric, filters)
    }

    fn layout(
        &self,
        campaign_id: i64,
        x_param: &str,
        y_param: Option<&str>,
        metric: &str,
        filters: &[(String, ParamValue)],
    ) -> Result<Pivot, StoreError> {
        self.require_campaign(campaign_id)?;
        if Some(x_param) == y_param {
            return Err(StoreError::InvalidQuery {
                path: self.path.clone(),
                reason: format!("a pivot needs two different parameters, got `{x_param}` for both axes"),
            });
        }
        let action = match y_param {
            Some(y_param) => format!("pivoting `{metric}` over `{x_param}` and `{y_param}` in campaign {campaign_id}"),
            None => format!("laying out `{metric}` over `{x_param}` in campaign {campaign_id}"),
        };

        self.require_parameters(
            campaign_id,
            std::iter::once(x_param)
                .chain(y_param)
                .chain(filters.iter().map(|(name, _)| name.as_str())),
            &action,
        )?;
        let metrics: Vec<String> = self
            .strings(
                "SELECT DISTINCT m.name FROM metrics m JOIN jobs j ON j.job_id = m.job_id
                 WHERE j.campaign_id = ?1 ORDER BY m.name",
                params![campaign_id],
            )
            .context(&self.path, &action)?;
        if !metrics.iter().any(|known| known == metric) {
            return Err(StoreError::UnknownMetric {
                path: self.path.clone(),
                campaign_id,
                name: metric.to_string(),
                available: metrics,
            });
        }
        let mut units: Vec<String> = self
            .strings(
                "SELECT DISTINCT m.unit FROM metrics m JOIN jobs j ON j.job_id = m.job_id
                 WHERE j.campaign_id = ?1 AND m.name = ?2 ORDER BY m.unit",
                params![campaign_id, metric],
            )
            .context(&self.path, &action)?;
        if units.len() > 1 {
            return Err(StoreError::MixedUnits {
                path: self.path.clone(),
                name: metric.to_string(),
                units,
            });
        }
        let unit = units.pop().expect("the metric exists, so it has at least one unit");

        let x_values = self.axis_values(campaign_id, x_param).context(&self.path, &action)?;
        let y_values = match y_param {
            Some(y_param) => self.axis_values(campaign_id, y_param).context(&self.path, &action)?,
            None => vec![ParamValue::Text(String::new())],
        };
        let points = self
            .pivot_points(campaign_id, x_param, y_param, metric)
            .context(&self.path, &action)?;
        let mut kept: Option<std::collections::HashSet<String>> = None;
        for (name, wanted) in filters {
            let matching = self
                .jobs_with_value(campaign_id, name, wanted)
                .context(&self.path, &action)?;
            kept = Some(match kept {
                None => matching,
                Some(k) => k.intersection(&matching).cloned().collect(),
            });
        }
        let mut values = vec![vec![Vec::<f64>::new(); x_values.len()]; y_values.len()];
        for (job, x, y, value) in points {
            if kept.as_ref().is_some_and(|k| !k.contains(&job)) {
                continue;
            }
            // Every point's values are on the axes, which list all values of the campaign.
            let column = x_values.binary_search_by(|probe| probe.axis_cmp(&x));
            let row = y_values.binary_search_by(|probe| probe.axis_cmp(&y));
            let (Ok(column), Ok(row)) = (column, row) else { continue };
            values[row][column].push(value);
        }
        let cells = values
            .into_iter()
            .map(|row| row.into_iter().map(|v| cell_of(&v)).collect())
            .collect();
        Ok(Pivot {
            x_param: x_param.to_string(),
            y_param: y_param.unwrap_or_default().to_string(),
            metric: metric.to_string(),
            unit,
            x_values,
            y_values,
            cells,
            filters: filters.to_vec(),
        })
    }

    /// The done jobs of the campaign whose parameters have the values of `filters` (all of them without filters), in
    /// the sweep's order. A filter on a parameter the campaign does not sweep fails as in [`Store::pivot_where`].
    pub fn done_jobs_where(
        &self,
        campaign_id: i64,
        filters: &[(String, ParamValue)],
    ) -> Result<Vec<String>, StoreError> {
        self.require_campaign(campaign_id)?;
        let action = format!("listing the done jobs of campaign {campaign_id}");
        self.require_parameters(campaign_id, filters.iter().map(|(name, _)| name.as_str()), &action)?;
        let mut jobs: Vec<String> = self
            .strings(
                "SELECT job_id FROM jobs WHERE campaign_id = ?1 AND status = ?2 ORDER BY ordinal",
                params![campaign_id, JobStatus::Done],
            )
            .context(&self.path, &action)?;
        for (name, wanted) in filters {
            let matching = self
                .jobs_with_value(campaign_id, name, wanted)
                .context(&self.path, &action)?;
            jobs.retain(|job| matching.contains(job));
        }
        Ok(jobs)
    }

    /// Fails with [`StoreError::UnknownParameter`] (listing the campaign's parameters) at the first of `names` the
    /// campaign does not sweep; `action` says what was being done, for other errors.
    fn require_parameters<'n>(
        &self,
        campaign_id: i64,
        names: impl IntoIterator<Item = &'n str>,
        action: &str,
    ) -> Result<(), StoreError> {
        let parameters: Vec<String> = self
            .strings(
                "SELECT DISTINCT p.name FROM params p JOIN jobs j ON j.job_id = p.job_id
                 WHERE j.campaign_id = ?1 ORDER BY p.name",
                params![campaign_id],
            )
            .context(&self.path, action)?;
        for name in names {
            if !parameters.iter().any(|known| known == name) {
                return Err(StoreError::UnknownParameter {
                    path: self.path.clone(),
                    campaign_id,
                    name: name.to_string(),
                    available: parameters,
                });
            }
        }
        Ok(())
    }

    /// The jobs of the campaign whose parameter `name` equals `wanted` (a filter of `pivot_where` and
    /// `done_jobs_where`).
    fn jobs_with_value(
        &self,
        campaign_id: i64,
        name: &str,
        wanted: &ParamValue,
    ) -> rusqlite::Result<std::collections::HashSet<String>> {
        Ok(self
            .job_values(campaign_id, name)?
            .into_iter()
            .filter(|(_, value)| value.axis_cmp(wanted) == Ordering::Equal)
            .map(|(job, _)| job)
            .collect())
    }

    /// (job id, value) of parameter `name` for every job of the campaign that has it.
    fn job_values(&self, campaign_id: i64, name: &str) -> rusqlite::Result<Vec<(String, ParamValue)>> {
        let mut stmt = self.conn.prepare_cached(
            "SELECT p.job_id, p.value_real, p.value_text FROM params p JOIN jobs j ON j.job_id = p.job_id
             WHERE j.campaign_id = ?1 AND p.name = ?2",
        )?;
        let rows = stmt.query_map(params![campaign_id, name], |row| {
            let job: String = row.get(0)?;
            Ok(ParamValue::from_columns(row.get(1)?, row.get(2)?).map(|v| (job, v)))
        })?;
        rows.filter_map(Result::transpose).collect()
    }

    /// (job id, x value, y value, metric value) of every done job of the campaign that has both parameters (x alone
    /// without `y_param`, y then the text `""`) and a non-NULL value of the metric.
    fn pivot_points(
        &self,
        campaign_id: i64,
        x_param: &str,
        y_param: Option<&str>,
        metric: &str,
    ) -> rusqlite::Result<Vec<(String, ParamValue, ParamValue, f64)>> {
        let mut stmt = self.conn.prepare_cached(if y_param.is_some() {
            "SELECT px.value_real, px.value_text, py.value_real, py.value_text, m.value, j.job_id
             FROM jobs j
             JOIN params px ON px.job_id = j.job_id AND px.name = ?2
             JOIN params py ON py.job_id = j.job_id AND py.name = ?3
             JOIN metrics m ON m.job_id = j.job_id AND m.name = ?4
             WHERE j.campaign_id = ?1 AND j.status = ?5 AND m.value IS NOT NULL"
        } else {
            "SELECT px.value_real, px.value_text, NULL, ?3, m.value, j.job_id
             FROM jobs j
             JOIN params px ON px.job_id = j.job_id AND px.name = ?2
             JOIN metrics m ON m.job_id = j.job_id AND m.name = ?4
             WHERE j.campaign_id = ?1 AND j.status = ?5 AND m.value IS NOT NULL"
        })?;
        let y_param = y_param.unwrap_or_default();
        let rows = stmt.query_map(params![campaign_id, x_param, y_param, metric, JobStatus::Done], |row| {
            let x = ParamValue::from_columns(row.get(0)?, row.get(1)?);
            let y = ParamValue::from_columns(row.get(2)?, row.get(3)?);
            let value: f64 = row.get(4)?;
            let job: String = row.get(5)?;
            Ok(x.zip(y).map(|(x, y)| (job, x, y, value)))
        })?;
        rows.filter_map(Result::transpose).collect()
    }

    /// The distinct values of parameter `name` in the campaign, sorted by [`ParamValue::axis_cmp`].
    fn axis_values(&self, campaign_id: i64, name: &str) -> rusqlite::Result<Vec<ParamValue>> {
        let mut stmt = self.conn.prepare_cached(
            "SELECT DISTINCT p.value_real, p.value_text FROM params p JOIN jobs j ON j.job_id = p.job_id
             WHERE j.campaign_id = ?1 AND p.name = ?2",
        )?;
        let mut values: Vec<ParamValue> = stmt
            .query_map(params![campaign_id, name], |row| {
                Ok(ParamValue::from_columns(row.get(0)?, row.get(1)?))
            })?
            .filter_map(Result::transpose)
            .collect::<rusqlite::Result<_>>()?;
        values.sort_by(ParamValue::axis_cmp);
        values.dedup_by(|a, b| a.axis_cmp(b) == Ordering::Equal);
        Ok(values)
    }

    /// The first column of every row of `sql`, as text.
    fn strings(&self, sql: &str, params: impl rusqlite::Params) -> rusqlite::Result<Vec<String>> {
        let mut stmt = self.conn.prepare_cached(sql)?;
        stmt.query_map(params, |row| row.get(0))?.collect()
    }
}

impl Pivot {
    /// The cell at row `y` and column `x` (indices into `y_values` and `x_values`).
    pub fn cell(&self, y: usize, x: usize) -> Option<PivotCell> {
        self.cells.get(y).and_then(|row| row.get(x)).copied().flatten()
    }

    /// Whether some cell averages several jobs.
    pub fn has_averaged_cells(&self) -> bool {
        self.cells.iter().flatten().flatten().any(|cell| cell.count > 1)
    }

    fn metric_label(&self) -> String {
        if self.unit.is_empty() {
            self.metric.clone()
        } else {
            format!("{} [{}]", self.metric, self.unit)
        }
    }

    fn corner_label(&self) -> String {
        format!("{} \\ {}", self.y_param, self.x_param)
    }

    /// An aligned text table for terminals: a title line, then rows of y against columns of x, means rounded to 6
    /// significant digits, `-` for empty cells and `(n=K)` after means over K > 1 jobs.
    pub fn to_table(&self) -> String {
        let mut out = format!(
            "{} by {} (rows) and {} (columns)\n",
            self.metric_label(),
            self.y_param,
            self.x_param
        );
        if !self.filters.is_empty() {
            let conditions: Vec<String> = self
                .filters
                .iter()
                .map(|(name, value)| format!("{name} = {value}"))
                .collect();
            out.push_str(&format!("only jobs with {}\n", conditions.join(", ")));
        }
        if self.has_averaged_cells() {
            out.push_str("(n=K): mean over K jobs that differ in other parameters\n");
        }
        let mut header = vec![self.corner_label()];
        header.extend(self.x_values.iter().map(ParamValue::to_string));
        let cells: Vec<Vec<String>> = self
            .y_values
            .iter()
            .zip(&self.cells)
            .map(|(y, row)| {
                let mut line = vec![y.to_string()];
                line.extend(row.iter().map(|cell| match cell {
                    None => "-".to_string(),
                    Some(PivotCell { mean, count: 1, .. }) => format_significant(*mean),
                    Some(PivotCell { mean, count, .. }) => format!("{} (n={count})", format_significant(*mean)),
                }));
                line
            })
            .collect();
        let mut right = vec![true; header.len()];
        right[0] = false;
        out.push_str(&align(&header, &cells, &right));
        out
    }

    /// CSV of the means at full precision: a header of x values after the corner cell `<y> \ <x>`, then one line
    /// per y value; empty fields for empty cells. Counts are in [`Pivot::to_json`] and [`Pivot::to_table`].
    pub fn to_csv(&self) -> String {
        let mut out = String::new();
        let mut header = vec![self.corner_label()];
        header.extend(self.x_values.iter().map(ParamValue::to_string));
        push_csv_line(&mut out, header.iter().map(String::as_str));
        for (y, row) in self.y_values.iter().zip(&self.cells) {
            let mut line = vec![y.to_string()];
            line.extend(
                row.iter()
                    .map(|cell| cell.map_or_else(String::new, |cell| format_real(cell.mean))),
            );
            push_csv_line(&mut out, line.iter().map(String::as_str));
        }
        out
    }

    /// One JSON object: the parameter and metric names, the unit, both axes, and `mean` and `count` matrices
    /// (`mean[row][column]`, null and 0 for empty cells).
    pub fn to_json(&self) -> String {
        let matrix = |value: &dyn Fn(Option<PivotCell>) -> Value| -> Value {
            self.cells
                .iter()
                .map(|row| row.iter().map(|cell| value(*cell)).collect::<Value>())
                .collect()
        };
        let object = json!({
            "x_param": self.x_param,
            "y_param": self.y_param,
            "metric": self.metric,
            "unit": self.unit,
            "x_values": self.x_values.iter().map(ParamValue::to_json).collect::<Value>(),
            "y_values": self.y_values.iter().map(ParamValue::to_json).collect::<Value>(),
            "mean": matrix(&|cell| cell.map_or(Value::Null, |cell| json_real(cell.mean))),
            "count": matrix(&|cell| Value::from(cell.map_or(0, |cell| cell.count))),
            "where": self.filters.iter().map(|(name, value)| (name.clone(), value.to_json())).collect::<serde_json::Map<_, _>>(),
        });
        format!("{object}\n")
    }
}

#[cfg(test)]
mod tests {
    use super::super::NewJob;
    use super::super::test_support::{finish, new_campaign, sample_jobs};
    use super::*;

    /// The 3 × 2 sample sweep with `porosity` for every job but j4 (u = 0.2, fill = 0.5), which stays pending.
    fn sample_pivot_store() -> (tempfile::TempDir, Store, i64) {
        let (dir, mut store, campaign) = new_campaign();
        store.insert_jobs(campaign, &sample_jobs()).unwrap();
        for (job, value) in [("j0", 0.40), ("j1", 0.42), ("j2", 0.44), ("j3", 0.50), ("j5", 0.46)] {
            finish(&mut store, job, &[("porosity", value, ""), ("dp_mean", 1000.0, "Pa")]);
        }
        (dir, store, campaign)
    }

    #[test]
    fn pivot_3x2_with_a_missing_cell() {
        let (_dir, store, campaign) = sample_pivot_store();
        let pivot = store.pivot(campaign, "u_m_per_s", "fill_level", "porosity").unwrap();
        let reals = |values: &[f64]| values.iter().map(|&v| ParamValue::Real(v)).collect::<Vec<_>>();
        assert_eq!(pivot.x_values, reals(&[0.1, 0.2, 0.3]));
        assert_eq!(pivot.y_values, reals(&[0.3, 0.5]));
        let one = |mean| {
            Some(PivotCell {
                mean,
                count: 1,
                std: None,
            })
        };
        assert_eq!(
            pivot.cells,
            vec![vec![one(0.40), one(0.42), one(0.44)], vec![one(0.46), None, one(0.50)]]
        );
        assert!(!pivot.has_averaged_cells());

        assert_eq!(
            pivot.to_table(),
            "porosity by fill_level (rows) and u_m_per_s (columns)\n\
             fill_level \\ u_m_per_s   0.1   0.2   0.3\n\
             ----------------------  ----  ----  ----\n\
             0.3                      0.4  0.42  0.44\n\
             0.5                     0.46     -   0.5\n"
        );
        assert_eq!(
            pivot.to_csv(),
            "fill_level \\ u_m_per_s,0.1,0.2,0.3\n0.3,0.4,0.42,0.44\n0.5,0.46,,0.5\n"
        );
        let json: Value = serde_json::from_str(&pivot.to_json()).unwrap();
        assert_eq!(json["mean"], json!([[0.40, 0.42, 0.44], [0.46, null, 0.50]]));
        assert_eq!(json["count"], json!([[1, 1, 1], [1, 0, 1]]));
        assert_eq!(json["x_values"], json!([0.1, 0.2, 0.3]));

        // Transposed, with a text axis: one column per drag model.
        let pivot = store.pivot(campaign, "drag", "u_m_per_s", "dp_mean").unwrap();
        assert_eq!(pivot.unit, "Pa");
        assert_eq!(pivot.x_values, [ParamValue::Text("di_felice".into())]);
        assert_eq!(
            pivot.cell(0, 0),
            Some(PivotCell {
                mean: 1000.0,
                count: 2,
                std: Some(0.0)
            })
        );
        assert_eq!(
            pivot.cell(1, 0),
            Some(PivotCell {
                mean: 1000.0,
                count: 1,
                std: None
            })
        );
        assert!(pivot.to_table().contains("1000 (n=2)"), "{}", pivot.to_table());
    }

    #[test]
    fn pivot_averages_jobs_that_differ_in_other_parameters() {
        let (_dir, mut store, campaign) = new_campaign();
        let job = |id: &str, u: f64, seed: f64| NewJob {
            job_id: id.to_string(),
            ordinal: 0,
            params_json: "{}".to_string(),
            params: vec![
                ("u".to_string(), ParamValue::Real(u)),
                ("fill".to_string(), ParamValue::Real(0.5)),
                ("seed".to_string(), ParamValue::Real(seed)),
            ],
        };
        // Numeric, not text, order: 10 after 9.
        store
            .insert_jobs(
                campaign,
                &[job("a", 10.0, 1.0), job("b", 10.0, 2.0), job("c", 9.0, 1.0)],
            )
            .unwrap();
        finish(&mut store, "a", &[("k", 1.0, "1/s")]);
        finish(&mut store, "b", &[("k", 2.0, "1/s")]);
        finish(&mut store, "c", &[("k", f64::NAN, "1/s")]);
        let pivot = store.pivot(campaign, "u", "fill", "k").unwrap();
        assert_eq!(pivot.x_values, [ParamValue::Real(9.0), ParamValue::Real(10.0)]);
        assert_eq!(
            pivot.cells,
            vec![vec![
                None,
                Some(PivotCell {
                    mean: 1.5,
                    count: 2,
                    std: Some(0.5f64.sqrt())
                })
            ]]
        );
        // The same jobs as a curve over u alone.
        let curve = store.curve_where(campaign, "u", "k", &[]).unwrap();
        assert_eq!(curve.y_values, [ParamValue::Text(String::new())]);
        assert_eq!(
            curve.cells,
            vec![vec![
                None,
                Some(PivotCell {
                    mean: 1.5,
                    count: 2,
                    std: Some(0.5f64.sqrt())
                })
            ]]
        );
        assert!(pivot.to_table().contains("1.5 (n=2)"));
        assert!(pivot.to_table().contains("(n=K): mean over K jobs"));

        // Filtered to one seed, the cell is that job's alone; the axes still list every value.
        let one_seed = [("seed".to_string(), ParamValue::Real(2.0))];
        let pivot = store.pivot_where(campaign, "u", "fill", "k", &one_seed).unwrap();
        assert_eq!(pivot.x_values, [ParamValue::Real(9.0), ParamValue::Real(10.0)]);
        assert_eq!(
            pivot.cells,
            vec![vec![
                None,
                Some(PivotCell {
                    mean: 2.0,
                    count: 1,
                    std: None
                })
            ]]
        );
        assert!(
            pivot.to_table().contains("only jobs with seed = 2\n"),
            "{}",
            pivot.to_table()
        );
        let json: Value = serde_json::from_str(&pivot.to_json()).unwrap();
        assert_eq!(json["where"], json!({ "seed": 2.0 }));
        // Two filters intersect; a value no job has empties every cell; an unswept parameter is an error.
        let both = [one_seed[0].clone(), ("u".to_string(), ParamValue::Real(9.0))];
        let pivot = store.pivot_where(campaign, "u", "fill", "k", &both).unwrap();
        assert_eq!(pivot.cells, vec![vec![None, None]]);
        let err = store
            .pivot_where(
                campaign,
                "u",
                "fill",
                "k",
                &[("colour".to_string(), ParamValue::Real(1.0))],
            )
            .unwrap_err();
        assert!(
            matches!(&err, StoreError::UnknownParameter { name, .. } if name == "colour"),
            "{err}"
        );
    }

    #[test]
    fn pivot_errors_name_what_is_unknown_and_list_what_exists() {
        let (_dir, store, campaign) = sample_pivot_store();
        let err = store.pivot(campaign, "u_gas", "fill_level", "porosity").unwrap_err();
        assert!(
            matches!(&err, StoreError::UnknownParameter { name, .. } if name == "u_gas"),
            "{err}"
        );
        let message = err.to_string();
        assert!(message.contains("no parameter `u_gas`"), "{message}");
        assert!(
            message.contains("available parameters: drag, fill_level, u_m_per_s"),
            "{message}"
        );
        assert!(message.contains("campaign.sqlite"), "{message}");

        let err = store.pivot(campaign, "u_m_per_s", "fill", "porosity").unwrap_err();
        assert!(err.to_string().contains("no parameter `fill`"), "{err}");

        let err = store.pivot(campaign, "u_m_per_s", "fill_level", "porsity").unwrap_err();
        assert!(
            err.to_string()
                .contains("no metric `porsity`; available metrics: dp_mean, porosity"),
            "{err}"
        );

        let err = store.pivot(campaign, "u_m_per_s", "u_m_per_s", "porosity").unwrap_err();
        assert!(matches!(err, StoreError::InvalidQuery { .. }), "{err}");
        let err = store
            .pivot(campaign + 7, "u_m_per_s", "fill_level", "porosity")
            .unwrap_err();
        assert!(matches!(err, StoreError::UnknownCampaign { .. }), "{err}");

        let (_dir, mut empty, campaign) = new_campaign();
        empty.insert_jobs(campaign, &sample_jobs()).unwrap();
        let err = empty
            .pivot(campaign, "u_m_per_s", "fill_level", "porosity")
            .unwrap_err();
        assert!(
            err.to_string()
                .contains("available metrics: none (no job has finished yet)"),
            "{err}"
        );
    }

    #[test]
    fn pivot_refuses_a_metric_with_mixed_units() {
        let (_dir, mut store, campaign) = new_campaign();
        store.insert_jobs(campaign, &sample_jobs()).unwrap();
        finish(&mut store, "j0", &[("dp", 1.0, "Pa")]);
        finish(&mut store, "j1", &[("dp", 1.0, "kPa")]);
        let err = store.pivot(campaign, "u_m_per_s", "fill_level", "dp").unwrap_err();
        assert!(
            err.to_string().contains("several units") && err.to_string().contains("Pa, kPa"),
            "{err}"
        );
    }
}
