//! `granflow report <campaign-dir>`: the validation report of a validation campaign (one with a `validation:`
//! section) as Markdown — our numbers next to the source's, the command that reproduces them, the choices the
//! source leaves open, the wall time the jobs took (`wall_time`), every job's parameters and metrics, and a last
//! line `verdict: pass` or `verdict: fail (<which checks>)`.

pub(crate) mod wall_time;

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use serde_json::Value;

use crate::campaign::validation::{CheckSpec, CheckValue};
use crate::campaign_dir::{database_path, load_stored_campaign, spec_copy_path};
use crate::error::Error;
use crate::store::Store;
use wall_time::WallTime;

/// One evaluated check.
#[derive(Debug, Clone)]
pub struct CheckResult {
    pub name: String,
    pub ours: f64,
    pub expected: f64,
    pub criterion: String,
    pub samples: usize,
    pub pass: bool,
}

fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        // A whole section (a map, or null for none) is stored as its JSON text.
        (Value::String(text), other) | (other, Value::String(text)) if !other.is_string() => {
            serde_json::from_str::<Value>(text).is_ok_and(|parsed| !parsed.is_string() && same(&parsed, other))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same(v, w)))
        }
        _ => match (a.as_f64(), b.as_f64()) {
            (Some(x), Some(y)) => (x - y).abs() <= 1e-9 * x.abs().max(y.abs()),
            _ => a == b,
        },
    }
}

fn evaluate(
    check: &CheckSpec,
    header: &[String],
    rows: &[Vec<Value>],
    derived: &[(String, String, Option<f64>)],
) -> CheckResult {
    let column = |name: &str| header.iter().position(|h| h == name);
    let metric = |name: &str| {
        header
            .iter()
            .position(|h| h == &format!("metric.{name}") || h.starts_with(&format!("metric.{name} [")))
    };
    // The mean of the value over the jobs (or derived groups) matching `filter`, and how many there were.
    let mean_for = |filter: &BTreeMap<String, Value>| -> (f64, usize) {
        let mut values = Vec::new();
        match &check.value {
            CheckValue::Metric(_) | CheckValue::Ratio(_) => {
                let status = column("status");
                for row in rows {
                    if status.is_some_and(|s| row[s] != Value::String("done".into())) {
                        continue;
                    }
                    let matches = filter
                        .iter()
                        .all(|(k, v)| column(&format!("param.{k}")).is_some_and(|c| same(&row[c], v)));
                    if !matches {
                        continue;
                    }
                    let get = |m: &str| metric(m).and_then(|c| row[c].as_f64()).unwrap_or(f64::NAN);
                    values.push(match &check.value {
                        CheckValue::Metric(m) => get(m),
                        CheckValue::Ratio([a, b]) => get(a) / get(b),
                        CheckValue::Derived(_) => unreachable!(),
                    });
                }
            }
            CheckValue::Derived(name) => {
                for (group, n, value) in derived {
                    if n != name {
                        continue;
                    }
                    let group: BTreeMap<String, Value> = serde_json::from_str(group).unwrap_or_default();
                    if filter.iter().all(|(k, v)| group.get(k).is_some_and(|g| same(g, v))) {
                        values.push(value.unwrap_or(f64::NAN));
                    }
                }
            }
        }
        let mean = if values.is_empty() {
            f64::NAN
        } else {
            values.iter().sum::<f64>() / values.len() as f64
        };
        (mean, values.len())
    };
    let (mut ours, samples) = mean_for(&check.filter);
    if !check.relative_to.is_empty() {
        // The same value with the reference parameters in place of (or beside) the filter's.
        let mut reference = check.filter.clone();
        reference.extend(check.relative_to.clone());
        ours /= mean_for(&reference).0;
    }
    if !check.difference_from.is_empty() {
        let mut reference = check.filter.clone();
        reference.extend(check.difference_from.clone());
        ours -= mean_for(&reference).0;
    }
    let (pass, criterion) = match (check.tolerance_rel, check.range) {
        (Some(t), _) => (
            (ours / check.expected - 1.0).abs() <= t,
            format!("within {:.3} %", 100.0 * t).replace(".000 %", " %"),
        ),
        (None, Some([lo, hi])) => (ours >= lo && ours <= hi, format!("in [{lo}, {hi}]")),
        (None, None) => (false, "no criterion".into()),
    };
    CheckResult {
        name: check.name.clone(),
        ours,
        expected: check.expected,
        criterion,
        samples,
        pass: pass && ours.is_finite(),
    }
}

fn cell(v: &Value) -> String {
    match v {
        Value::Null => "".into(),
        Value::Number(n) => n
            .as_f64()
            .map_or_else(|| n.to_string(), |x| format!("{}", (x * 1e6).round() / 1e6)),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// The campaign file a reader runs to reproduce the campaign: the one the user ran (as recorded at `granflow run`)
/// when it still holds what was run; else, for campaigns recorded before the source was, the validation campaign of
/// that name if it matches; else the stored copy in the campaign directory.
fn reproduce_file(source: Option<&str>, yaml: &str, name: &str, dir: &Path) -> String {
    let holds_it = |file: &Path| std::fs::read_to_string(file).ok().as_deref() == Some(yaml);
    if let Some(source) = source {
        if holds_it(Path::new(source)) {
            return source.to_string();
        }
        return format!(
            "{}  # as run; {source}, the file run, has changed since",
            spec_copy_path(dir).display()
        );
    }
    let file = Path::new("campaigns/validation").join(format!("{name}.yaml"));
    if holds_it(&file) {
        file.display().to_string()
    } else {
        spec_copy_path(dir).display().to_string()
    }
}

/// The paragraph that says which builds finished the jobs, with a warning when there were several: a change of the
/// engine's last bits moves single results (a chaotic bed by tens of per cent), so a report over mixed builds is
/// not one engine's answer.
fn builds_paragraph(builds: &[(String, i64)]) -> String {
    match builds {
        [] => String::new(),
        [(build, n)] => format!("All {n} done jobs were run by granflow {build}.\n\n"),
        several => {
            let list: Vec<String> = several.iter().map(|(b, n)| format!("{b} ({n} jobs)")).collect();
            format!(
                "**The done jobs come from {} builds**: {}. Results of different builds can differ in their last \
                 bits, and chaotic runs by much more; run the campaign again in a new directory for one build's \
                 answer.\n\n",
                several.len(),
                list.join(", ")
            )
        }
    }
}

/// The Markdown report of the validation campaign in `dir`, and whether every check passed.
pub fn report(dir: &Path) -> Result<(String, bool), Error> {
    let campaign = load_stored_campaign(dir)?;
    let Some(validation) = campaign.spec.validation.clone() else {
        return Err(Error::External(format!(
            "campaign `{}` has no `validation:` section; `granflow report` is for validation campaigns",
            campaign.spec.name
        )));
    };
    let store = Store::open_read_only(database_path(dir))?;
    let stored = store
        .campaign_by_name(&campaign.spec.name)?
        .ok_or_else(|| Error::External(format!("{}: no campaign in the database", dir.display())))?;
    let id = stored.id;
    let (header, rows) = store.export_rows(id)?;
    let (_, derived_rows) = store.query_sql(&format!(
        "SELECT group_json, name, value, unit FROM derived WHERE campaign_id = {id} ORDER BY group_json, name"
    ))?;
    let derived: Vec<(String, String, Option<f64>)> = derived_rows
        .iter()
        .map(|r| {
            (
                r[0].as_str().unwrap_or_default().to_string(),
                r[1].as_str().unwrap_or_default().to_string(),
                r[2].as_f64(),
            )
        })
        .collect();
    let results: Vec<CheckResult> = validation
        .checks
        .iter()
        .map(|c| evaluate(c, &header, &rows, &derived))
        .collect();
    let (_, timing_rows) = store.query_sql(&format!(
        "SELECT job_id, sim_time_s FROM jobs WHERE campaign_id = {id} ORDER BY ordinal"
    ))?;
    let wall_time = WallTime::of(&store.attempt_spans(id)?);
    let counts = store.status_counts(id)?;
    // Which builds finished the done jobs (the attempt that ended `done`; NULL before builds were recorded).
    let (_, build_rows) = store.query_sql(&format!(
        "SELECT COALESCE(a.build, 'unknown (finished before builds were recorded)'), COUNT(DISTINCT a.job_id)
             FROM attempts a JOIN jobs j ON j.job_id = a.job_id
             WHERE j.campaign_id = {id} AND j.status = 'done' AND a.outcome = 'done'
             GROUP BY 1 ORDER BY 2 DESC, 1"
    ))?;
    let builds: Vec<(String, i64)> = build_rows
        .iter()
        .map(|r| {
            (
                r[0].as_str().unwrap_or_default().to_string(),
                r[1].as_i64().unwrap_or(0),
            )
        })
        .collect();

    let name = &campaign.spec.name;
    let mut md = String::new();
    let _ = writeln!(md, "# {} {}\n", validation.case, validation.title);
    let _ = writeln!(
        md,
        "Campaign `{name}`: {} of {} jobs done. Reference: {}. Generated by `granflow report` (granflow {}).\n",
        counts.get("done").copied().unwrap_or(0),
        campaign.jobs.len(),
        validation.source,
        crate::provenance::build_id()
    );
    md.push_str(&builds_paragraph(&builds));
    md.push_str(&wall_time.sentence());
    if !campaign.spec.description.trim().is_empty() {
        let _ = writeln!(md, "{}\n", campaign.spec.description.trim());
    }
    let campaign_file = reproduce_file(stored.source_path.as_deref(), &campaign.yaml, name, dir);
    let _ = writeln!(md, "## Reproduce\n\n```sh");
    let _ = writeln!(md, "granflow run {campaign_file} --out {}", dir.display());
    let _ = writeln!(
        md,
        "granflow report {} --out results/validation/{name}/REPORT.md\n```\n",
        dir.display()
    );
    if !validation.choices.is_empty() {
        let _ = writeln!(md, "## Choices the source leaves open\n");
        for c in &validation.choices {
            let _ = writeln!(md, "- {c}");
        }
        md.push('\n');
    }
    let _ = writeln!(md, "## Checks\n");
    let _ = writeln!(md, "| check | ours | source | criterion | jobs/groups | result |");
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    for r in &results {
        let _ = writeln!(
            md,
            "| {} | {:.4} | {} | {} | {} | {} |",
            r.name,
            r.ours,
            r.expected,
            r.criterion,
            r.samples,
            if r.pass { "pass" } else { "FAIL" }
        );
    }
    if !derived.is_empty() {
        let _ = writeln!(md, "\n## Derived metrics\n");
        let _ = writeln!(md, "| group | name | value | unit |");
        let _ = writeln!(md, "|---|---|---|---|");
        for r in &derived_rows {
            let _ = writeln!(
                md,
                "| `{}` | {} | {} | {} |",
                cell(&r[0]),
                cell(&r[1]),
                cell(&r[2]),
                cell(&r[3])
            );
        }
    }
    let _ = writeln!(md, "\n## Jobs\n");
    let shown: Vec<usize> = (0..header.len()).filter(|&k| k != 0).collect();
    let _ = writeln!(
        md,
        "| {} | wall s (all attempts) | wall s per simulated s |",
        shown
            .iter()
            .map(|&k| header[k].as_str())
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(md, "|{}---|---|", "---|".repeat(shown.len()));
    for (row, timing) in rows.iter().zip(&timing_rows) {
        // The job's attempts (a resumed job's result holds only its last attempt's wall time).
        let wall = timing[0].as_str().and_then(|job| wall_time.per_job_s.get(job)).copied();
        let (wall_s, per_s) = match (timing[1].as_f64(), wall) {
            (Some(sim), Some(wall)) if sim > 0.0 => (format!("{wall:.0}"), format!("{:.1}", wall / sim)),
            (_, Some(wall)) => (format!("{wall:.0}"), String::new()),
            _ => (String::new(), String::new()),
        };
        let _ = writeln!(
            md,
            "| {} | {wall_s} | {per_s} |",
            shown.iter().map(|&k| cell(&row[k])).collect::<Vec<_>>().join(" | ")
        );
    }
    let failed: Vec<&str> = results.iter().filter(|r| !r.pass).map(|r| r.name.as_str()).collect();
    let pass = failed.is_empty();
    md.push('\n');
    if pass {
        md.push_str("verdict: pass\n");
    } else {
        let _ = writeln!(md, "verdict: fail ({})", failed.join("; "));
    }
    Ok((md, pass))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A check with `relative_to` divides the matching jobs' mean by the reference jobs' mean (the other filter
    /// entries kept).
    #[test]
    fn relative_checks_divide_by_the_reference_jobs() {
        let header: Vec<String> = ["status", "param.gamma", "param.u", "metric.k [1/s]"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let row = |g: f64, u: f64, k: f64| vec![Value::from("done"), Value::from(g), Value::from(u), Value::from(k)];
        let rows = vec![
            row(0.0, 2.0, 4.0),
            row(0.08, 2.0, 1.0),
            row(0.0, 2.8, 8.0),
            row(0.08, 2.8, 3.0),
        ];
        let de = serde_norway::Deserializer::from_str(
            "{ name: wet over dry, value: { metric: k }, where: { gamma: 0.08, u: 2.8 }, relative_to: { gamma: 0.0 }, expected: 0.5, range: [0.0, 1.0] }",
        );
        let check: CheckSpec = serde_norway::with::singleton_map_recursive::deserialize(de).expect("parses");
        let result = evaluate(&check, &header, &rows, &[]);
        assert_eq!(result.ours, 3.0 / 8.0);
        assert!(result.pass);
    }

    /// A check with `difference_from` subtracts the reference jobs' mean; with both it and `relative_to` the
    /// section is refused.
    #[test]
    fn difference_checks_subtract_the_reference_jobs() {
        let header: Vec<String> = ["status", "param.layout", "metric.m [1]"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let row = |l: &str, m: f64| vec![Value::from("done"), Value::from(l), Value::from(m)];
        let rows = vec![row("unbaffled", 0.5), row("axial", 0.875), row("axial", 0.625)];
        let parse = |yaml: &str| -> CheckSpec {
            serde_norway::with::singleton_map_recursive::deserialize(serde_norway::Deserializer::from_str(yaml))
                .expect("parses")
        };
        let check = parse(
            "{ name: axial above unbaffled, value: { metric: m }, where: { layout: axial }, difference_from: { layout: unbaffled }, expected: 0.25, range: [0.25, 1.0] }",
        );
        let result = evaluate(&check, &header, &rows, &[]);
        assert_eq!((result.ours, result.samples), (0.25, 2));
        assert!(result.pass);
        let both = parse(
            "{ name: both, value: { metric: m }, relative_to: { layout: unbaffled }, difference_from: { layout: unbaffled }, expected: 0.25, range: [0.25, 1.0] }",
        );
        let spec = crate::campaign::validation::ValidationSpec {
            case: "F1".into(),
            title: "t".into(),
            source: "s".into(),
            choices: vec![],
            checks: vec![both],
        };
        let err = spec.check(&["m".to_string()]).expect_err("refused");
        assert_eq!(err.0, "validation.checks[0].difference_from");
    }

    /// A swept section (a map, or null for none) is stored as JSON text; `where` and `relative_to` match it by
    /// value, numbers within 1e-9 and keys in any order.
    #[test]
    fn checks_match_whole_sections_by_value() {
        let header: Vec<String> = ["status", "param.cohesion", "metric.u [m/s]"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let row = |c: &str, u: f64| vec![Value::from("done"), Value::from(c), Value::from(u)];
        let rows = vec![
            row("null", 0.8),
            row(r#"{"square_well":{"depth_j":1e-10,"walls":true}}"#, 1.2),
            row(r#"{"square_well":{"depth_j":1e-11,"walls":true}}"#, 0.9),
        ];
        let de = serde_norway::Deserializer::from_str(
            "{ name: sw over dry, value: { metric: u }, where: { cohesion: { square_well: { walls: true, depth_j: 1.0e-10 } } }, relative_to: { cohesion: null }, expected: 1.5, tolerance_rel: 0.01 }",
        );
        let check: CheckSpec = serde_norway::with::singleton_map_recursive::deserialize(de).expect("parses");
        let result = evaluate(&check, &header, &rows, &[]);
        assert_eq!((result.ours, result.samples), (1.2 / 0.8, 1));
        assert!(result.pass);
        assert!(!same(&Value::from("null"), &serde_json::json!({ "square_well": null })));
        assert!(!same(&Value::from("text"), &Value::Null));
    }

    /// One build is named; several are named with their job counts and a warning.
    #[test]
    fn a_report_over_several_builds_says_so() {
        assert_eq!(
            builds_paragraph(&[("0.1.0+aaaa".into(), 6)]),
            "All 6 done jobs were run by granflow 0.1.0+aaaa.\n\n"
        );
        let mixed = builds_paragraph(&[("0.1.0+aaaa".into(), 4), ("0.1.0+bbbb.dirty".into(), 2)]);
        assert!(
            mixed.starts_with("**The done jobs come from 2 builds**: 0.1.0+aaaa (4 jobs), 0.1.0+bbbb.dirty (2 jobs)."),
            "{mixed}"
        );
        assert_eq!(builds_paragraph(&[]), "");
    }
}
