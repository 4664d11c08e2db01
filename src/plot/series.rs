//! Time series of chosen jobs (`granflow plot <dir> series --column C`): the column against time for every done
//! job matching the filters, one line each, and over it, dashed, the model the job's metric was fitted with where
//! the column has one:
//!
//! - `intensity_of_segregation`: the exponential y_∞ + (y_0 − y_∞) e^(−k t) fitted for `mixing_rate_constant_per_s`
//!   (seed 000 §4.1.3; `analysis::fit`), over the rows it was fitted to (from `analysis.mixing_fit_from_s`);
//! - `core_temperature_k`, `inner_core_temperature_k`, `mean_temperature_k`: the line ln((T_w − T)/(T_w − T_0))
//!   fitted for the wall heat transfer coefficient h_w (seed 000 eq. 5.21; `analysis::wall_heat`), turned back into
//!   temperatures, over the rows it was fitted to.
//!
//! The fits are computed exactly as the job's metrics were (the same functions on the same rows), so the legend's k
//! and h_w are the stored metrics' values.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{DrawResult, err};

use super::phase_diagram::significant;
use crate::campaign::Campaign;
use crate::error::Error;
use crate::units::caption;
use crate::worker::reduce::Series;

/// The picture's size in pixels (PNG) or user units (SVG).
pub const SIZE: (u32, u32) = (1200, 900);

/// Jobs drawn at most: more lines than this are not told apart.
pub const MAX_JOBS: usize = 12;

/// One job's line and its fitted model.
#[derive(Debug, Clone)]
pub struct JobLine {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// The model's label (with the fitted constant) and its curve.
    pub fit: Option<(String, Vec<(f64, f64)>)>,
}

/// The series column's rows of one job with its model, read from its directory.
pub fn job_line(job_dir: &Path, campaign: &Campaign, column: &str) -> Result<JobLine, Error> {
    let series = Series::read(&job_dir.join("series.csv"))?;
    let (Some(t), Some(y)) = (series.column("time_s"), series.column(column)) else {
        return Err(Error::Usage(format!(
            "{}: the series has no column `{column}`; it has {}",
            job_dir.display(),
            series.names.join(", ")
        )));
    };
    let points: Vec<(f64, f64)> = t
        .iter()
        .zip(y)
        .filter(|(_, y)| y.is_finite())
        .map(|(&t, &y)| (t, y))
        .collect();
    let job = crate::worker::read_job(job_dir)?;
    let fit = match column {
        "intensity_of_segregation" => {
            let from_s = job.analysis.mixing_fit_from_s.unwrap_or(f64::NEG_INFINITY);
            let (ft, fy): (Vec<f64>, Vec<f64>) = points.iter().filter(|(t, _)| *t >= from_s).copied().unzip();
            crate::analysis::fit::fit_exponential_decay(&ft, &fy).map(|f| {
                (
                    format!(
                        "fit: k = {} 1/s (R² = {})",
                        significant(f.rate_constant_per_s, 3),
                        significant(f.r_squared, 3)
                    ),
                    ft.iter().map(|&t| (t, f.value_at(t))).collect(),
                )
            })
        }
        "core_temperature_k" | "inner_core_temperature_k" | "mean_temperature_k" => {
            let (job, _, sim, series, _) = crate::worker::rereduce::final_state(job_dir)?;
            crate::worker::reduce::wall_heat(&job, &sim, &series, column).map(|(f, _)| {
                let (from, to) = f.span_s;
                (
                    format!(
                        "fit: h_w = {} W/(m² K) (R² = {})",
                        significant(f.coefficient_w_per_m2_k, 3),
                        significant(f.r_squared, 3)
                    ),
                    points
                        .iter()
                        .filter(|(t, _)| *t >= from && *t <= to)
                        .map(|&(t, _)| (t, f.core_temperature_k(t)))
                        .collect(),
                )
            })
        }
        _ => None,
    };
    Ok(JobLine {
        label: campaign.label(&job),
        points,
        fit,
    })
}

/// Shortens the lines' labels (`a=1, b=2`) to the parts that differ between them; returns what they share.
pub fn distinguish(lines: &mut [JobLine]) -> String {
    distinguish_labels(lines.iter_mut().map(|l| &mut l.label))
}

/// Shortens job labels (`a=1, b=2`) to the parts that differ between them; returns what they share (nothing for
/// fewer than two labels, which stay whole).
pub fn distinguish_labels<'a>(labels: impl Iterator<Item = &'a mut String>) -> String {
    let mut labels: Vec<&mut String> = labels.collect();
    if labels.len() < 2 {
        return String::new();
    }
    let parts: Vec<Vec<String>> = labels
        .iter()
        .map(|l| l.split(", ").map(str::to_string).collect())
        .collect();
    let shared: Vec<String> = parts[0]
        .iter()
        .filter(|p| parts.iter().all(|q| q.contains(p)))
        .cloned()
        .collect();
    for (label, own) in labels.iter_mut().zip(&parts) {
        let differing: Vec<&str> = own.iter().filter(|p| !shared.contains(p)).map(String::as_str).collect();
        if !differing.is_empty() {
            **label = differing.join(", ");
        }
    }
    shared.join(", ")
}

/// Draws `lines` of `column` against time on `root`, titled `title` with `subtitle` (what the lines share) under it.
pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    lines: &[JobLine],
    column: &str,
    title: &str,
    subtitle: &str,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let body = super::draw_heading(root, title, subtitle)?;
    let all = lines
        .iter()
        .flat_map(|l| l.points.iter().chain(l.fit.iter().flat_map(|(_, f)| f)));
    let (mut t_lo, mut t_hi, mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for &(t, y) in all {
        (t_lo, t_hi, lo, hi) = (t_lo.min(t), t_hi.max(t), lo.min(y), hi.max(y));
    }
    let pad = |lo: f64, hi: f64| {
        let p = if hi > lo {
            0.05 * (hi - lo)
        } else {
            0.5 * lo.abs().max(1.0)
        };
        (lo - p)..(hi + p)
    };
    let mut chart = ChartBuilder::on(&body)
        .margin(20)
        .x_label_area_size(70)
        .y_label_area_size(110)
        .build_cartesian_2d(t_lo..t_hi.max(t_lo + f64::MIN_POSITIVE), pad(lo, hi))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_label_formatter(&|v| significant(*v, 4))
        .y_label_formatter(&|v| significant(*v, 4))
        .x_desc("time_s [s]")
        .y_desc(caption(column, Some(Series::unit_of(column))))
        .label_style(("sans-serif", 18))
        .axis_desc_style(("sans-serif", 20))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    for (k, line) in lines.iter().enumerate() {
        let colour = super::curve::LINE_COLOURS[k % super::curve::LINE_COLOURS.len()];
        chart
            .draw_series(LineSeries::new(line.points.iter().copied(), colour.stroke_width(2)))
            .map_err(err)?
            .label(line.label.clone())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 30, y)], colour.stroke_width(3)));
        if let Some((label, fit)) = &line.fit {
            let dark = RGBColor(colour.0 / 2, colour.1 / 2, colour.2 / 2);
            chart
                .draw_series(DashedLineSeries::new(fit.iter().copied(), 10, 6, dark.stroke_width(3)))
                .map_err(err)?
                .label(format!("    {label}"))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 30, y)], dark.stroke_width(3)));
        }
    }
    super::draw_legend(&mut chart, 16, SeriesLabelPosition::UpperRight)
}
