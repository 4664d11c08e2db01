//! Rendering a result set (a header and rows of JSON values) as an aligned text table, CSV or JSON, and the number
//! formats they share.
//!
//! Numbers keep full precision (shortest round-trip) in CSV and JSON; tables of means round to 6 significant
//! digits (see [`Pivot::to_table`](super::Pivot::to_table)). JSON has no infinities or NaN, so non-finite reals
//! travel as the strings `"inf"`, `"-inf"` and `"NaN"` everywhere, which keeps them visible instead of turning
//! them into null.

use serde_json::Value;

/// Renders `rows` under `header` as a text table: numbers right-aligned, other values left-aligned, NULL shown as
/// `NULL`.
pub fn render_table(header: &[String], rows: &[Vec<Value>]) -> String {
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|row| row.iter().map(|value| display_value(value, "NULL")).collect())
        .collect();
    let right: Vec<bool> = (0..header.len())
        .map(|col| {
            rows.iter()
                .all(|row| matches!(row.get(col), Some(Value::Number(_) | Value::Null) | None))
                && rows.iter().any(|row| matches!(row.get(col), Some(Value::Number(_))))
        })
        .collect();
    align(header, &cells, &right)
}

/// Renders `rows` under `header` as CSV (RFC 4180 quoting, `\n` line ends, NULL as an empty field).
pub fn render_csv(header: &[String], rows: &[Vec<Value>]) -> String {
    let mut out = String::new();
    push_csv_line(&mut out, header.iter().map(String::as_str));
    for row in rows {
        let fields: Vec<String> = row.iter().map(|value| display_value(value, "")).collect();
        push_csv_line(&mut out, fields.iter().map(String::as_str));
    }
    out
}

/// Renders `rows` under `header` as one JSON object `{"columns": [...], "rows": [[...], ...]}`, one row per line.
/// Rows are arrays rather than objects so that column order and repeated column names survive.
pub fn render_json(header: &[String], rows: &[Vec<Value>]) -> String {
    let mut out = format!("{{\"columns\":{},\"rows\":[", Value::from(header.to_vec()));
    for (index, row) in rows.iter().enumerate() {
        out.push_str(if index == 0 { "\n" } else { ",\n" });
        out.push_str(&Value::Array(row.clone()).to_string());
    }
    out.push_str(if rows.is_empty() { "]}\n" } else { "\n]}\n" });
    out
}

/// `value` as a cell of a table or CSV file; `null` as given.
fn display_value(value: &Value, null: &str) -> String {
    match value {
        Value::Null => null.to_string(),
        Value::String(text) => text.clone(),
        other => other.to_string(),
    }
}

/// Lays out `header` and `cells` in columns separated by two spaces, with a dashed rule under the header.
pub(crate) fn align(header: &[String], cells: &[Vec<String>], right: &[bool]) -> String {
    let width = |text: &str| text.chars().count();
    let mut widths: Vec<usize> = header.iter().map(|name| width(name)).collect();
    for row in cells {
        for (col, cell) in row.iter().enumerate() {
            if col < widths.len() {
                widths[col] = widths[col].max(width(cell));
            }
        }
    }
    let mut out = String::new();
    let mut push_line = |fields: &mut dyn Iterator<Item = &str>| {
        let mut line = String::new();
        for (col, field) in fields.enumerate() {
            if col > 0 {
                line.push_str("  ");
            }
            let pad = " ".repeat(widths.get(col).copied().unwrap_or(0).saturating_sub(width(field)));
            if right.get(col).copied().unwrap_or(false) {
                line.push_str(&pad);
                line.push_str(field);
            } else {
                line.push_str(field);
                line.push_str(&pad);
            }
        }
        out.push_str(line.trim_end());
        out.push('\n');
    };
    push_line(&mut header.iter().map(String::as_str));
    let rule: Vec<String> = widths.iter().map(|&w| "-".repeat(w)).collect();
    push_line(&mut rule.iter().map(String::as_str));
    for row in cells {
        push_line(&mut row.iter().map(String::as_str));
    }
    out
}

/// Appends one CSV record.
pub(crate) fn push_csv_line<'a>(out: &mut String, fields: impl Iterator<Item = &'a str>) {
    for (index, field) in fields.enumerate() {
        if index > 0 {
            out.push(',');
        }
        if field.contains([',', '"', '\n', '\r']) {
            out.push('"');
            out.push_str(&field.replace('"', "\"\""));
            out.push('"');
        } else {
            out.push_str(field);
        }
    }
    out.push('\n');
}

/// A real as JSON: a number when finite, else `"inf"`, `"-inf"` or `"NaN"`.
pub(crate) fn json_real(value: f64) -> Value {
    serde_json::Number::from_f64(value).map_or_else(|| Value::String(non_finite(value).to_string()), Value::Number)
}

fn non_finite(value: f64) -> &'static str {
    if value.is_nan() {
        "NaN"
    } else if value > 0.0 {
        "inf"
    } else {
        "-inf"
    }
}

/// A real at full precision (shortest string that reads back to the same `f64`): plain notation for magnitudes in
/// [1e-4, 1e15), exponent notation outside (`2.5e-7`, `6.9e10`), `inf`/`-inf`/`NaN` for non-finite values.
pub(crate) fn format_real(value: f64) -> String {
    if !value.is_finite() {
        return non_finite(value).to_string();
    }
    let magnitude = value.abs();
    if magnitude == 0.0 || (1e-4..1e15).contains(&magnitude) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

/// A real rounded to 6 significant digits, for tables read by people (`0.612346`, `1.5e-7`, `123457`).
pub(crate) fn format_significant(value: f64) -> String {
    const DIGITS: i32 = 6;
    if !value.is_finite() {
        return non_finite(value).to_string();
    }
    if value == 0.0 {
        return "0".to_string();
    }
    let exponent = value.abs().log10().floor() as i32;
    if (-4..DIGITS).contains(&exponent) {
        let decimals = (DIGITS - 1 - exponent).max(0) as usize;
        let text = format!("{value:.decimals$}");
        let text = if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.')
        } else {
            &text
        };
        text.to_string()
    } else {
        let text = format!("{value:.prec$e}", prec = (DIGITS - 1) as usize);
        let (mantissa, exp) = text.split_once('e').expect("`{:e}` output contains an `e`");
        let mantissa = if mantissa.contains('.') {
            mantissa.trim_end_matches('0').trim_end_matches('.')
        } else {
            mantissa
        };
        format!("{mantissa}e{exp}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn formats_reals() {
        assert_eq!(format_real(0.1), "0.1");
        assert_eq!(format_real(3.0), "3");
        assert_eq!(format_real(2.5e-7), "2.5e-7");
        assert_eq!(format_real(6.9e16), "6.9e16");
        assert_eq!(format_real(f64::NEG_INFINITY), "-inf");
        assert_eq!(format_significant(0.61234567), "0.612346");
        assert_eq!(format_significant(123456.7), "123457");
        assert_eq!(format_significant(1234567.0), "1.23457e6");
        assert_eq!(format_significant(12345.67), "12345.7");
        assert_eq!(format_significant(1.5e-7), "1.5e-7");
        assert_eq!(format_significant(2.0), "2");
        assert_eq!(format_significant(-0.25), "-0.25");
        assert_eq!(json_real(f64::INFINITY), json!("inf"));
    }

    #[test]
    fn renders_table_csv_and_json() {
        let header = vec!["name".to_string(), "value".to_string()];
        let rows = vec![vec![json!("a,\"b\""), json!(1.5)], vec![json!("c"), Value::Null]];
        assert_eq!(
            render_table(&header, &rows),
            "name   value\n-----  -----\na,\"b\"    1.5\nc       NULL\n"
        );
        assert_eq!(render_csv(&header, &rows), "name,value\n\"a,\"\"b\"\"\",1.5\nc,\n");
        let parsed: Value = serde_json::from_str(&render_json(&header, &rows)).unwrap();
        assert_eq!(
            parsed,
            json!({"columns": ["name", "value"], "rows": [["a,\"b\"", 1.5], ["c", null]]})
        );
        let parsed: Value = serde_json::from_str(&render_json(&header, &[])).unwrap();
        assert_eq!(parsed, json!({"columns": ["name", "value"], "rows": []}));
    }
}
