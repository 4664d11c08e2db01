//! A metric against one swept parameter, one line per value of a second (`granflow plot <dir> curve`), drawn on
//! any plotters backend (PNG and SVG from the same code).
//!
//! Each point is the metric's mean over the done jobs at that x (and line value): replicates (a swept seed) and any
//! other parameter not on the picture are averaged, and their sample standard deviation is drawn as an error bar
//! (none for a single job). The x axis is the parameter's values: linear for numbers, logarithmic when the sweep is
//! a logspace (the caption says "log scale"), categories for texts. A legend names each line's value.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{DrawResult, err};

use super::phase_diagram::{axis_caption, is_geometric, significant, value_label};
use crate::store::{ParamValue, Pivot};
use crate::units::{caption, parameter_unit};

/// The picture's size in pixels (PNG) or user units (SVG).
pub const SIZE: (u32, u32) = (1200, 900);

/// The lines' colours in order (Tableau 10: distinct, readable on white, kind to colour-blind readers).
pub(crate) const LINE_COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Where each x value sits on the axis: the number itself, its log10 on a logspace axis, or its index for texts.
/// Returns the positions and whether the axis is logarithmic, categorical.
fn positions(values: &[ParamValue]) -> (Vec<f64>, bool, bool) {
    let numbers: Option<Vec<f64>> = values
        .iter()
        .map(|v| match v {
            ParamValue::Real(x) => Some(*x),
            ParamValue::Text(_) => None,
        })
        .collect();
    match numbers {
        Some(n) if is_geometric(values) => (n.iter().map(|x| x.log10()).collect(), true, false),
        Some(n) => (n, false, false),
        None => ((0..values.len()).map(|i| i as f64).collect(), false, true),
    }
}

/// The range `lo..hi` widened by `fraction` of its span on each side (by a unit when it is a point).
fn padded(lo: f64, hi: f64, fraction: f64) -> std::ops::Range<f64> {
    if hi > lo {
        let pad = fraction * (hi - lo);
        (lo - pad)..(hi + pad)
    } else {
        let pad = 0.5 * lo.abs().max(1.0);
        (lo - pad)..(hi + pad)
    }
}

/// Draws `pivot`'s rows as lines over its columns on `root`, titled `title`.
pub fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, pivot: &Pivot, title: &str) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let (x_at, log_x, categorical) = positions(&pivot.x_values);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for cell in pivot.cells.iter().flatten().flatten() {
        let spread = cell.std.unwrap_or(0.0);
        lo = lo.min(cell.mean - spread);
        hi = hi.max(cell.mean + spread);
    }
    let x_range = padded(
        x_at.iter().copied().fold(f64::INFINITY, f64::min),
        x_at.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        0.05,
    );
    // A linear axis takes plotters' round ticks; a logspace or text axis is labelled at the swept values themselves.
    let own_ticks = log_x || categorical;
    let y_range = padded(lo, hi, 0.08);
    let y_bottom = y_range.start;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 26))
        .margin(20)
        .x_label_area_size(70)
        .y_label_area_size(110)
        .build_cartesian_2d(x_range, y_range)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_labels(if own_ticks { 0 } else { 10 })
        .x_label_formatter(&|v| significant(*v, 4))
        .y_label_formatter(&|v| significant(*v, 3))
        .x_desc(axis_caption(&pivot.x_param, &pivot.x_values))
        .y_desc(caption(&pivot.metric, Some(&pivot.unit)))
        .label_style(("sans-serif", 18))
        .axis_desc_style(("sans-serif", 20))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    if own_ticks {
        let style = TextStyle::from(("sans-serif", 18).into_font()).pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Top,
        ));
        for (&x, value) in x_at.iter().zip(&pivot.x_values) {
            let (px, py) = chart.backend_coord(&(x, y_bottom));
            root.draw(&PathElement::new([(px, py), (px, py + 6)], BLACK))
                .map_err(err)?;
            root.draw(&Text::new(value_label(value), (px, py + 10), style.clone()))
                .map_err(err)?;
        }
    }
    let line_caption = caption(&pivot.y_param, parameter_unit(&pivot.y_param));
    let mut drawn = 0;
    for (row, cells) in pivot.cells.iter().enumerate() {
        let points: Vec<(f64, f64, Option<f64>)> = cells
            .iter()
            .zip(&x_at)
            .filter_map(|(cell, &x)| cell.as_ref().map(|c| (x, c.mean, c.std)))
            .collect();
        if points.is_empty() {
            continue;
        }
        let colour = LINE_COLOURS[drawn % LINE_COLOURS.len()];
        drawn += 1;
        let label = if pivot.y_param.is_empty() {
            pivot.metric.clone()
        } else {
            format!("{line_caption} = {}", value_label(&pivot.y_values[row]))
        };
        chart
            .draw_series(LineSeries::new(
                points.iter().map(|&(x, y, _)| (x, y)),
                colour.stroke_width(3),
            ))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 30, y)], colour.stroke_width(3)));
        chart
            .draw_series(points.iter().map(|&(x, y, _)| Circle::new((x, y), 6, colour.filled())))
            .map_err(err)?;
        chart
            .draw_series(points.iter().filter_map(|&(x, y, std)| {
                std.map(|s| ErrorBar::new_vertical(x, y - s, y, y + s, colour.stroke_width(2), 14))
            }))
            .map_err(err)?;
    }
    super::draw_legend(&mut chart, 18, SeriesLabelPosition::UpperRight)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_logspace_axis_sits_at_the_logarithms_and_texts_at_their_indices() {
        let reals = |v: &[f64]| v.iter().map(|&x| ParamValue::Real(x)).collect::<Vec<_>>();
        let (at, log, categorical) = positions(&reals(&[0.01, 0.1, 1.0]));
        assert!(log && !categorical);
        assert!((at[0] + 2.0).abs() < 1e-12 && at[2].abs() < 1e-12);
        let (at, log, categorical) = positions(&reals(&[1.0, 2.0, 4.5]));
        assert!(!log && !categorical);
        assert_eq!(at, [1.0, 2.0, 4.5]);
        let (at, _, categorical) = positions(&[ParamValue::Text("glass".into()), ParamValue::Text("steel".into())]);
        assert!(categorical);
        assert_eq!(at, [0.0, 1.0]);
    }
}
