//! A fluidization cycle (`granflow plot <dir> fluidization`): the pressure drop against the gas velocity through
//! the `gas.inflow_levels` of each chosen job, with u_mf marked.
//!
//! Each level is one point: its mean pressure drop over the second half of its hold divided by the bed's weight per
//! area (seed 001's ΔP* = ΔP/(W/A); with `analysis.cycle_pressure: first_node`, the first node's ΔP over W'/A), the
//! standard deviation as an error bar. The falling branch is dashed with open circles, the rising branch solid with
//! filled ones (the branches the metrics read: `analysis::fluidization::cycle_branches`, seed 001's down-then-up
//! cycle or one that rises first), and ΔP* = 1 is drawn across. The velocities the job's
//! metrics were read from the levels are vertical lines: U_mf,df (falling branch's packed-bed line meets W/A),
//! U_mf,th (the same on the rising branch), U_mf,in (the overshoot peak) and the stepped onset (the slowest level
//! from which σ(ΔP) stays ≥ 1 % of W/A) — each computed by the functions that computed the stored metric, on the
//! same rows, from the job's final state (`worker::rereduce::final_state`).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::phase_diagram::significant;
use super::{DrawResult, err};
use crate::campaign::Campaign;
use crate::error::Error;

/// The picture's size in pixels (PNG) or user units (SVG).
pub const SIZE: (u32, u32) = (1200, 900);

/// One level of a cycle: the velocity and ΔP* with its standard deviation.
#[derive(Debug, Clone, Copy)]
pub struct LevelPoint {
    pub velocity_m_per_s: f64,
    pub pressure_ratio: f64,
    pub pressure_ratio_std: f64,
}

/// One job's cycle: its levels in time order, where the rising branch starts, and the u_mf readings.
#[derive(Debug, Clone)]
pub struct JobCycle {
    pub label: String,
    pub levels: Vec<LevelPoint>,
    /// The falling and rising branches as ranges of `levels` (`analysis::fluidization::cycle_branches`, the split
    /// the metrics are read on).
    pub falling: std::ops::Range<usize>,
    pub rising: std::ops::Range<usize>,
    /// The finite u_mf readings: (name, velocity in m/s).
    pub velocities: Vec<(&'static str, f64)>,
}

/// The cycle of the finished job in `job_dir`. A job without `gas.inflow_levels` is a usage error.
pub fn job_cycle(job_dir: &Path, campaign: &Campaign) -> Result<JobCycle, Error> {
    let (job, built, sim, series, _) = crate::worker::rereduce::final_state(job_dir)?;
    let label = campaign.label(&job);
    let no_cycle = || {
        Error::Usage(format!(
            "job {label} ({}): no fluidization cycle to draw: the scenario has no gas.inflow_levels, or its series no \
             level long enough to average",
            job_dir.display()
        ))
    };
    let stats = crate::worker::reduce::level_stats(&job, &built, &sim, &series).ok_or_else(no_cycle)?;
    if stats.is_empty() {
        return Err(no_cycle());
    }
    let levels: Vec<LevelPoint> = stats
        .iter()
        .map(|l| LevelPoint {
            velocity_m_per_s: l.velocity_m_per_s,
            pressure_ratio: l.pressure_drop_mean_pa / l.weight_per_area_pa,
            pressure_ratio_std: l.pressure_drop_std_pa / l.weight_per_area_pa,
        })
        .collect();
    let (falling, rising) = crate::analysis::fluidization::cycle_branches(
        &levels
            .iter()
            .map(|l| crate::analysis::fluidization::CycleLevel {
                velocity_m_per_s: l.velocity_m_per_s,
                pressure_drop_mean_pa: l.pressure_ratio,
            })
            .collect::<Vec<_>>(),
    );
    let mut velocities = Vec::new();
    if let Some(cycle) = crate::worker::reduce::cycle(&job, &built, &sim, &series) {
        let v = &cycle.velocities;
        velocities.extend([
            ("U_mf,df", v.defluidization_m_per_s),
            ("U_mf,th", v.fluidization_theoretical_m_per_s),
            ("U_mf,in", v.incipient_m_per_s),
        ]);
    }
    velocities.push((
        "stepped onset",
        crate::worker::reduce::stepped_onset_m_per_s(&job, &built, &sim, &series),
    ));
    velocities.retain(|(_, v)| v.is_finite());
    Ok(JobCycle {
        label,
        levels,
        falling,
        rising,
        velocities,
    })
}

/// The dash (length, gap) of each u_mf reading's vertical line; `None` draws it solid.
fn dash_of(name: &str) -> Option<(u32, u32)> {
    match name {
        "U_mf,df" => Some((14, 8)),
        "U_mf,th" => Some((6, 6)),
        "U_mf,in" => Some((2, 5)),
        _ => None,
    }
}

/// The legend's sample of a reading's line: three pieces along 30 pixels, in the line's dash.
fn legend_segments(name: &str) -> [(i32, i32); 3] {
    match dash_of(name) {
        Some((14, _)) => [(0, 12), (18, 30), (30, 30)],
        Some((6, _)) => [(0, 6), (12, 18), (24, 30)],
        Some(_) => [(0, 2), (14, 16), (28, 30)],
        None => [(0, 10), (10, 20), (20, 30)],
    }
}

/// Draws the cycles on `root`, titled `title` with `subtitle` (what the jobs share) under it.
pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    cycles: &[JobCycle],
    title: &str,
    subtitle: &str,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let body = super::draw_heading(root, title, subtitle)?;
    let (mut u_hi, mut p_hi) = (0.0_f64, 1.0_f64);
    for c in cycles {
        for l in &c.levels {
            u_hi = u_hi.max(l.velocity_m_per_s);
            p_hi = p_hi.max(l.pressure_ratio + l.pressure_ratio_std);
        }
        for (_, v) in &c.velocities {
            u_hi = u_hi.max(*v);
        }
    }
    let p_lo = cycles
        .iter()
        .flat_map(|c| &c.levels)
        .map(|l| l.pressure_ratio - l.pressure_ratio_std)
        .fold(0.0_f64, f64::min);
    let u_hi = if u_hi > 0.0 { 1.05 * u_hi } else { 1.0 };
    let (y_lo, y_hi) = (p_lo - 0.05 * (p_hi - p_lo), p_hi + 0.08 * (p_hi - p_lo));
    let mut chart = ChartBuilder::on(&body)
        .margin(20)
        .x_label_area_size(70)
        .y_label_area_size(110)
        .build_cartesian_2d(0.0..u_hi, y_lo..y_hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_label_formatter(&|v| significant(*v, 4))
        .y_label_formatter(&|v| significant(*v, 3))
        .x_desc("gas superficial velocity [m/s]")
        .y_desc("pressure drop over bed weight per area, ΔP/(W/A) [1]")
        .label_style(("sans-serif", 18))
        .axis_desc_style(("sans-serif", 20))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    let grey = RGBColor(120, 120, 120);
    chart
        .draw_series(LineSeries::new([(0.0, 1.0), (u_hi, 1.0)], grey.stroke_width(2)))
        .map_err(err)?
        .label("bed weight per area (ΔP/(W/A) = 1)")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 30, y)], grey.stroke_width(2)));
    for (k, cycle) in cycles.iter().enumerate() {
        let colour = super::curve::LINE_COLOURS[k % super::curve::LINE_COLOURS.len()];
        let point = |l: &LevelPoint| (l.velocity_m_per_s, l.pressure_ratio);
        let prefix = if cycles.len() > 1 {
            format!("{}: ", cycle.label)
        } else {
            String::new()
        };
        // The falling branch's line runs on to the level after it (the slowest one), where the rise starts.
        let falling = &cycle.levels[cycle.falling.start..(cycle.falling.end + 1).min(cycle.levels.len())];
        let rising = &cycle.levels[cycle.rising.clone()];
        if cycle.falling.len() > 1 {
            chart
                .draw_series(DashedLineSeries::new(
                    falling.iter().map(point),
                    10,
                    6,
                    colour.stroke_width(2),
                ))
                .map_err(err)?
                .label(format!("{prefix}falling branch"))
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new([(0, 0), (12, 0)], colour.stroke_width(2))
                        + PathElement::new([(18, 0), (30, 0)], colour.stroke_width(2))
                });
        }
        if rising.len() > 1 {
            chart
                .draw_series(LineSeries::new(rising.iter().map(point), colour.stroke_width(2)))
                .map_err(err)?
                .label(format!("{prefix}rising branch"))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 30, y)], colour.stroke_width(2)));
        }
        // Rising levels filled, the others (falling, or in neither branch) open.
        chart
            .draw_series(cycle.levels.iter().enumerate().map(|(k, l)| {
                let style = if cycle.rising.contains(&k) {
                    colour.filled()
                } else {
                    colour.stroke_width(2)
                };
                Circle::new(point(l), 6, style)
            }))
            .map_err(err)?;
        chart
            .draw_series(cycle.levels.iter().map(|l| {
                ErrorBar::new_vertical(
                    l.velocity_m_per_s,
                    l.pressure_ratio - l.pressure_ratio_std,
                    l.pressure_ratio,
                    l.pressure_ratio + l.pressure_ratio_std,
                    colour.stroke_width(1),
                    10,
                )
            }))
            .map_err(err)?;
        let dark = RGBColor(colour.0 / 2, colour.1 / 2, colour.2 / 2);
        for &(name, u) in &cycle.velocities {
            let ends = [(u, y_lo), (u, y_hi)];
            let label = format!("{prefix}{name} = {} m/s", significant(u, 4));
            let drawn = match dash_of(name) {
                Some((dash, gap)) => chart
                    .draw_series(DashedLineSeries::new(ends, dash, gap, dark.stroke_width(2)))
                    .map_err(err)?,
                None => chart
                    .draw_series(LineSeries::new(ends, dark.stroke_width(1)))
                    .map_err(err)?,
            };
            let [a, b, c] = legend_segments(name);
            drawn.label(label).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new([(a.0, 0), (a.1, 0)], dark.stroke_width(2))
                    + PathElement::new([(b.0, 0), (b.1, 0)], dark.stroke_width(2))
                    + PathElement::new([(c.0, 0), (c.1, 0)], dark.stroke_width(2))
            });
        }
    }
    super::draw_legend(&mut chart, 16, SeriesLabelPosition::LowerRight)
}
