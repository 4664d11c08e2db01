//! A phase diagram: one metric over two swept parameters as a coloured map (`granflow plot <dir> phase`), drawn on
//! any plotters backend (PNG and SVG from the same code).
//!
//! One cell per swept value on each axis, in the sweep's sorted order, labelled with the values themselves: for a
//! linspace sweep that is a linear axis, for a logspace sweep a logarithmic one (the caption says "log scale" when
//! the values are geometric), and any other list is shown as the categories it is. Each cell holds the metric's mean
//! over the done jobs that share it, coloured on viridis and written in the cell (with "×n" when it averages n
//! jobs); an empty cell (no done job, or the metric NaN) is grey and marked "–". A colour bar on the right gives
//! the scale and the metric's unit.

use plotters::coord::Shift;
use plotters::coord::ranged1d::SegmentValue;
use plotters::prelude::*;

use super::{DrawResult, err};
use plotters::style::colors::colormaps::ViridisRGB;

use crate::store::{ParamValue, Pivot};
use crate::units::{caption, parameter_unit};

/// The picture's size in pixels (PNG) or user units (SVG).
pub const SIZE: (u32, u32) = (1200, 900);

/// Geometric spacing within this relative tolerance makes a logspace axis.
const GEOMETRIC_TOLERANCE: f64 = 1e-6;

/// A parameter value as the axis writes it: numbers to 4 significant digits, texts as they are.
pub fn value_label(value: &ParamValue) -> String {
    match value {
        ParamValue::Real(v) => significant(*v, 4),
        ParamValue::Text(t) => t.clone(),
    }
}

/// `v` to `digits` significant digits, without trailing zeros; exponent form beyond 1e-3..1e5.
pub fn significant(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs().log10().floor() as i32;
    if !(-3..5).contains(&magnitude) {
        let text = format!("{:.*e}", digits.saturating_sub(1), v);
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exponent}");
    }
    let decimals = (digits as i32 - 1 - magnitude).max(0) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// Whether the numbers of an axis are log-spaced (at least three, all positive, one ratio).
pub(crate) fn is_geometric(values: &[ParamValue]) -> bool {
    let numbers: Vec<f64> = values
        .iter()
        .filter_map(|v| match v {
            ParamValue::Real(x) => Some(*x),
            _ => None,
        })
        .collect();
    if numbers.len() < 3 || numbers.len() != values.len() || numbers.iter().any(|&x| x <= 0.0) {
        return false;
    }
    let ratio = numbers[1] / numbers[0];
    ratio > 1.0 + GEOMETRIC_TOLERANCE
        && numbers
            .windows(2)
            .all(|w| ((w[1] / w[0]) / ratio - 1.0).abs() < GEOMETRIC_TOLERANCE)
}

/// The axis caption: the parameter's name with its unit, and "log scale" for a logspace sweep.
pub(crate) fn axis_caption(name: &str, values: &[ParamValue]) -> String {
    let text = caption(name, parameter_unit(name));
    if is_geometric(values) {
        format!("{text} (log scale)")
    } else {
        text
    }
}

/// The colour of `value` on the map from `lo` to `hi`.
fn colour(value: f64, lo: f64, hi: f64) -> RGBColor {
    if hi > lo {
        ViridisRGB.get_color_normalized(value as f32, lo as f32, hi as f32)
    } else {
        ViridisRGB.get_color(0.5)
    }
}

/// Black or white, whichever reads on `background`.
fn text_colour(background: &RGBColor) -> RGBColor {
    let luminance = 0.299 * f64::from(background.0) + 0.587 * f64::from(background.1) + 0.114 * f64::from(background.2);
    if luminance > 140.0 { BLACK } else { WHITE }
}

/// Most classes a marker metric may have: one marker shape each.
pub const MAX_MARKER_CLASSES: usize = 4;

/// A classification drawn as markers over the map: a second metric's value in each cell (its mean over the cell's
/// jobs, to 3 significant digits), one shape per distinct value.
#[derive(Debug, Clone)]
pub struct Markers {
    /// The classes' values in ascending order; a class's index is its shape.
    pub classes: Vec<f64>,
    /// `class[row][column]`: the index into `classes` of each cell, like the pivot's cells.
    pub class: Vec<Vec<Option<usize>>>,
    /// What each class means, for the legend.
    pub names: Vec<String>,
}

impl Markers {
    /// The classes of `pivot`'s cells; `Err` (a message) when it has more than [`MAX_MARKER_CLASSES`] values.
    pub fn classify(pivot: &Pivot) -> Result<Markers, String> {
        let rounded = |v: f64| significant(v, 3).parse::<f64>().unwrap_or(v);
        let mut classes: Vec<f64> = pivot
            .cells
            .iter()
            .flatten()
            .flatten()
            .map(|c| rounded(c.mean))
            .filter(|v| v.is_finite())
            .collect();
        classes.sort_by(f64::total_cmp);
        classes.dedup();
        if classes.len() > MAX_MARKER_CLASSES {
            return Err(format!(
                "`{}` has {} distinct values over these cells; markers draw a classification of at most {} \
                 (e.g. wet_phase_mixed)",
                pivot.metric,
                classes.len(),
                MAX_MARKER_CLASSES
            ));
        }
        let class = pivot
            .cells
            .iter()
            .map(|row| {
                row.iter()
                    .map(|c| {
                        c.as_ref()
                            .and_then(|c| classes.iter().position(|&v| v == rounded(c.mean)))
                    })
                    .collect()
            })
            .collect();
        let names = classes.iter().map(|&v| class_name(&pivot.metric, v)).collect();
        Ok(Markers { classes, class, names })
    }
}

/// The legend's name of a marker class: seed 000's M and S for its phase rule, otherwise `metric = value`.
fn class_name(metric: &str, value: f64) -> String {
    match (metric, value) {
        ("wet_phase_mixed", 1.0) => "M: more mixed than dry (seed 000's rule on Ca_g11, Ca_g22, Ca_g12)".into(),
        ("wet_phase_mixed", 0.0) => "S: more segregated than dry (the same rule)".into(),
        ("wet_phase_mixed", v) => format!("replicates disagree (mean {})", significant(v, 3)),
        (metric, v) => format!("{metric} = {}", significant(v, 3)),
    }
}

/// Draws marker shape `class` centred at `at` (backend pixels) with half-size `r`.
fn draw_marker<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, class: usize, at: (i32, i32), r: i32) -> DrawResult {
    let (x, y) = at;
    let outline = BLACK.stroke_width(2);
    match class {
        0 => {
            area.draw(&Circle::new(at, r, WHITE.filled())).map_err(err)?;
            area.draw(&Circle::new(at, r, outline)).map_err(err)
        }
        1 => {
            area.draw(&PathElement::new(
                [(x - r, y - r), (x + r, y + r)],
                BLACK.stroke_width(3),
            ))
            .map_err(err)?;
            area.draw(&PathElement::new(
                [(x - r, y + r), (x + r, y - r)],
                BLACK.stroke_width(3),
            ))
            .map_err(err)
        }
        2 => {
            let corners = [(x, y - r), (x + r, y + r), (x - r, y + r)];
            area.draw(&Polygon::new(corners, WHITE.filled())).map_err(err)?;
            area.draw(&PathElement::new(
                [corners[0], corners[1], corners[2], corners[0]],
                outline,
            ))
            .map_err(err)
        }
        _ => area
            .draw(&Rectangle::new([(x - r, y - r), (x + r, y + r)], BLACK.filled()))
            .map_err(err),
    }
}

/// Draws `pivot` (its metric's values over its two parameters) on `root`, titled `title`, with `markers` (a
/// classification over the same cells) in each cell's upper right corner and their legend under the map.
pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pivot: &Pivot,
    title: &str,
    markers: Option<&Markers>,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let (_, height) = root.dim_in_pixel();
    let legend_px = markers.map_or(0, |m| 16 + 30 * m.classes.len() as u32);
    let (root, legend_area) = root.split_vertically(height - legend_px);
    let root = &root;
    let values: Vec<f64> = pivot.cells.iter().flatten().flatten().map(|c| c.mean).collect();
    let (lo, hi) = values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    let (width, _) = root.dim_in_pixel();
    let (map_area, bar_area) = root.split_horizontally(width * 82 / 100);
    // A discrete range is inclusive of its end in plotters: 0..n−1 makes the n cells.
    let (nx, ny) = (pivot.x_values.len().max(1), pivot.y_values.len().max(1));
    let x_labels: Vec<String> = pivot.x_values.iter().map(value_label).collect();
    let y_labels: Vec<String> = pivot.y_values.iter().map(value_label).collect();
    let label = |labels: &[String], v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(i) => labels.get(*i).cloned().unwrap_or_default(),
        _ => String::new(),
    };
    let mut chart = ChartBuilder::on(&map_area)
        .caption(title, ("sans-serif", 26))
        .margin(20)
        .x_label_area_size(70)
        .y_label_area_size(110)
        .build_cartesian_2d((0..nx - 1).into_segmented(), (0..ny - 1).into_segmented())
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(nx + 1)
        .y_labels(ny + 1)
        .x_label_formatter(&|v| label(&x_labels, v))
        .y_label_formatter(&|v| label(&y_labels, v))
        .x_desc(axis_caption(&pivot.x_param, &pivot.x_values))
        .y_desc(axis_caption(&pivot.y_param, &pivot.y_values))
        .label_style(("sans-serif", 18))
        .axis_desc_style(("sans-serif", 20))
        .draw()
        .map_err(err)?;
    let cell_font = if nx.max(ny) > 12 { 12 } else { 18 };
    for (row, cells) in pivot.cells.iter().enumerate() {
        for (column, cell) in cells.iter().enumerate() {
            let corners = [
                (SegmentValue::Exact(column), SegmentValue::Exact(row)),
                (SegmentValue::Exact(column + 1), SegmentValue::Exact(row + 1)),
            ];
            let centre = (SegmentValue::CenterOf(column), SegmentValue::CenterOf(row));
            let (fill, text) = match cell {
                Some(c) => {
                    let fill = colour(c.mean, lo, hi);
                    let mut text = significant(c.mean, 3);
                    if c.count > 1 {
                        text.push_str(&format!(" ×{}", c.count));
                    }
                    (fill, text)
                }
                None => (RGBColor(215, 215, 215), "–".to_string()),
            };
            chart
                .draw_series(std::iter::once(Rectangle::new(corners, fill.filled())))
                .map_err(err)?;
            let ink = text_colour(&fill);
            let style = TextStyle::from(("sans-serif", cell_font).into_font()).color(&ink).pos(
                plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Center,
                    plotters::style::text_anchor::VPos::Center,
                ),
            );
            chart
                .draw_series(std::iter::once(Text::new(text, centre, style)))
                .map_err(err)?;
            if let Some(class) = markers.and_then(|m| m.class.get(row)?.get(column).copied().flatten()) {
                let (x0, y0) = chart.backend_coord(&(SegmentValue::Exact(column), SegmentValue::Exact(row)));
                let (x1, y1) = chart.backend_coord(&(SegmentValue::Exact(column + 1), SegmentValue::Exact(row + 1)));
                let r = ((x1 - x0).abs().min((y1 - y0).abs()) / 10).clamp(4, 11);
                let at = (x0.max(x1) - 2 * r, y0.min(y1) + 2 * r);
                draw_marker(root, class, at, r)?;
            }
        }
    }
    draw_colour_bar(&bar_area, lo, hi, &caption(&pivot.metric, Some(&pivot.unit)))?;
    if let Some(markers) = markers {
        let style = TextStyle::from(("sans-serif", 18).into_font()).pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Left,
            plotters::style::text_anchor::VPos::Center,
        ));
        for (k, name) in markers.names.iter().enumerate() {
            let y = 8 + 15 + 30 * k as i32;
            draw_marker(&legend_area, k, (150, y), 9)?;
            legend_area
                .draw(&Text::new(name.clone(), (170, y), style.clone()))
                .map_err(err)?;
        }
    }
    Ok(())
}

/// A vertical bar of the map from `lo` (bottom) to `hi` (top) with its scale and `label`.
fn draw_colour_bar<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, lo: f64, hi: f64, label: &str) -> DrawResult {
    let (lo, hi) = if hi > lo {
        (lo, hi)
    } else {
        (lo - 0.5 * lo.abs().max(1.0), hi + 0.5 * hi.abs().max(1.0))
    };
    let mut chart = ChartBuilder::on(area)
        .margin_top(70)
        .margin_bottom(90)
        .margin_right(10)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(6)
        .y_label_formatter(&|v| significant(*v, 3))
        .y_desc(label)
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    const STEPS: usize = 100;
    let step = (hi - lo) / STEPS as f64;
    chart
        .draw_series((0..STEPS).map(|k| {
            let v0 = lo + k as f64 * step;
            Rectangle::new([(0.0, v0), (1.0, v0 + step)], colour(v0 + 0.5 * step, lo, hi).filled())
        }))
        .map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_to_significant_digits() {
        assert_eq!(significant(0.0015, 4), "0.0015");
        assert_eq!(significant(373.15, 4), "373.1");
        assert_eq!(significant(1.5e-6, 3), "1.5e-6");
        assert_eq!(significant(2.0, 3), "2");
        assert_eq!(significant(123456.0, 3), "1.23e5");
    }

    #[test]
    fn seed_000s_phase_rule_is_drawn_as_m_and_s_and_a_metric_of_many_values_is_refused() {
        use crate::store::PivotCell;
        let cell = |mean: f64| {
            Some(PivotCell {
                mean,
                count: 1,
                std: None,
            })
        };
        let mut pivot = Pivot {
            x_param: "surface_tension_n_per_m".into(),
            y_param: "u_m_per_s".into(),
            metric: "wet_phase_mixed".into(),
            unit: String::new(),
            x_values: vec![ParamValue::Real(0.01), ParamValue::Real(0.02)],
            y_values: vec![ParamValue::Real(1.0), ParamValue::Real(2.0)],
            cells: vec![vec![cell(1.0), cell(0.0)], vec![None, cell(1.0)]],
            filters: vec![],
        };
        let markers = Markers::classify(&pivot).expect("two classes");
        assert_eq!(markers.classes, [0.0, 1.0]);
        assert_eq!(markers.class, [vec![Some(1), Some(0)], vec![None, Some(1)]]);
        assert!(markers.names[0].starts_with("S: ") && markers.names[1].starts_with("M: "));
        pivot.metric = "coordination_number".into();
        pivot.cells = vec![vec![cell(1.0), cell(2.0)], vec![cell(3.0), cell(4.5)]];
        assert_eq!(
            Markers::classify(&pivot).expect("four classes").names[3],
            "coordination_number = 4.5"
        );
        pivot.cells[1][0] = cell(3.5);
        pivot.cells.push(vec![cell(5.0), None]);
        let refused = Markers::classify(&pivot).expect_err("five classes");
        assert!(refused.contains("has 5 distinct values"), "{refused}");
    }

    #[test]
    fn a_logspace_sweep_is_geometric_and_a_linspace_one_is_not() {
        let reals = |v: &[f64]| v.iter().map(|&x| ParamValue::Real(x)).collect::<Vec<_>>();
        assert!(is_geometric(&reals(&[0.01, 0.1, 1.0, 10.0])));
        assert!(!is_geometric(&reals(&[1.0, 2.0, 3.0])));
        assert!(!is_geometric(&reals(&[0.1, 1.0])));
    }
}
