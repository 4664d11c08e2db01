//! `granflow plot`: pictures of a campaign's results, as PNG and SVG, drawn in Rust (plotters; text by ab_glyph from
//! the embedded DejaVu Sans, so nothing beyond the binary is needed).
//!
//! - `phase_diagram.rs`: one metric over two swept parameters as a coloured map.
//! - `curve.rs`: one metric against one parameter, a line per value of a second, replicates' error bars.
//! - `series.rs`: a series column against time for chosen jobs, with the model their metric was fitted with.
//! - `fluidization.rs`: the pressure drop against the gas velocity through a job's gas cycle, u_mf marked.
//!
//! Every picture is written to a temporary file beside its destination and renamed into place, so a failure leaves
//! nothing half-written; bad requests (an unknown parameter or metric, a campaign with no finished job that has the
//! metric, an output path that cannot be written) fail before anything is drawn, with exit code 2.

pub mod curve;
pub mod fluidization;
pub mod phase_diagram;
pub mod series;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::prelude::*;

use crate::error::Error;

/// A drawing's outcome: plotters' errors as their messages.
pub(crate) type DrawResult = Result<(), String>;

/// A plotters error as its message.
pub(crate) fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// The chart's legend (the series' labels) at `position`, on a white box with a black border.
pub(crate) fn draw_legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    font_px: u32,
    position: SeriesLabelPosition,
) -> DrawResult {
    chart
        .configure_series_labels()
        .label_font(("sans-serif", font_px))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(position)
        .draw()
        .map_err(err)
}

/// Writes `title` (and `subtitle`, what the drawn jobs share, when not empty) centred at the top of `root`;
/// returns the area below.
pub(crate) fn draw_heading<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    subtitle: &str,
) -> Result<DrawingArea<DB, plotters::coord::Shift>, String> {
    let (width, _) = root.dim_in_pixel();
    let (head, body) = root.split_vertically(if subtitle.is_empty() { 56 } else { 86 });
    let centred = |size: u32| {
        TextStyle::from(("sans-serif", size).into_font()).pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Top,
        ))
    };
    head.draw(&Text::new(title, (width as i32 / 2, 14), centred(26)))
        .map_err(err)?;
    if !subtitle.is_empty() {
        head.draw(&Text::new(subtitle, (width as i32 / 2, 52), centred(17)))
            .map_err(err)?;
    }
    Ok(body)
}

/// The picture formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PictureFormat {
    Png,
    Svg,
}

impl PictureFormat {
    fn extension(self) -> &'static str {
        match self {
            PictureFormat::Png => "png",
            PictureFormat::Svg => "svg",
        }
    }
}

/// Makes DejaVu Sans the "sans-serif" every picture uses (once per process).
fn register_fonts() {
    static FONTS: Once = Once::new();
    FONTS.call_once(|| {
        for (style, bytes) in [
            (FontStyle::Normal, dejavu::sans::regular()),
            (FontStyle::Bold, dejavu::sans::bold()),
            (FontStyle::Oblique, dejavu::sans::oblique()),
            (FontStyle::Italic, dejavu::sans::oblique()),
        ] {
            plotters::style::register_font("sans-serif", style, bytes)
                .unwrap_or_else(|_| panic!("the embedded DejaVu Sans is a valid font"));
        }
    });
}

/// The files a picture goes to: `out` as given when it ends in `.png` or `.svg` (that format only), otherwise
/// `out` (or `default_stem` inside the campaign's `plots/` directory) with each extension.
pub fn outputs(dir: &Path, out: Option<&Path>, default_stem: &str) -> Vec<(PathBuf, PictureFormat)> {
    let base = out.map_or_else(|| dir.join("plots").join(default_stem), Path::to_path_buf);
    match base.extension().and_then(|e| e.to_str()) {
        Some("png") => vec![(base, PictureFormat::Png)],
        Some("svg") => vec![(base, PictureFormat::Svg)],
        _ => [PictureFormat::Png, PictureFormat::Svg]
            .into_iter()
            .map(|f| {
                let mut name = base.as_os_str().to_os_string();
                name.push(".");
                name.push(f.extension());
                (PathBuf::from(name), f)
            })
            .collect(),
    }
}

/// A file name part from a metric or parameter name (dots and brackets to dashes).
pub fn file_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '-'
            }
        })
        .collect::<String>()
        .trim_matches('-')
        .to_string()
}

/// Checks before drawing that each output's directory exists or can be made and takes a file (exit 2 otherwise).
fn check_writable(outputs: &[(PathBuf, PictureFormat)]) -> Result<(), Error> {
    for (path, _) in outputs {
        let parent = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).map_err(|e| {
            Error::Usage(format!(
                "cannot write {}: making {}: {e}",
                path.display(),
                parent.display()
            ))
        })?;
        tempfile::NamedTempFile::new_in(parent)
            .and_then(|mut f| f.write_all(b""))
            .map_err(|e| Error::Usage(format!("cannot write {}: {e}", path.display())))?;
        if path.is_dir() {
            return Err(Error::Usage(format!(
                "cannot write {}: it is a directory",
                path.display()
            )));
        }
    }
    Ok(())
}

/// Draws each of `outputs` at `size` (PNG by `draw_png`, SVG by `draw_svg`: the same drawing on two backends)
/// through a temporary file renamed into place.
fn write_pictures(
    outputs: &[(PathBuf, PictureFormat)],
    size: (u32, u32),
    draw_png: impl Fn(&DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> Result<(), String>,
    draw_svg: impl Fn(&DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<(), String>,
) -> Result<Vec<PathBuf>, Error> {
    register_fonts();
    let mut written = Vec::new();
    for (path, format) in outputs {
        let parent = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let temp = tempfile::Builder::new()
            .prefix(".granflow-plot-")
            .suffix(&format!(".{}", format.extension()))
            .tempfile_in(parent)
            .map_err(|e| Error::Usage(format!("cannot write {}: {e}", path.display())))?;
        let drawn = match format {
            PictureFormat::Png => {
                let root = BitMapBackend::new(temp.path(), size).into_drawing_area();
                draw_png(&root).and_then(|()| root.present().map_err(|e| e.to_string()))
            }
            PictureFormat::Svg => {
                let root = SVGBackend::new(temp.path(), size).into_drawing_area();
                draw_svg(&root).and_then(|()| root.present().map_err(|e| e.to_string()))
            }
        };
        drawn.map_err(|e| Error::External(format!("drawing {}: {e}", path.display())))?;
        temp.persist(path).map_err(|e| Error::Io {
            action: "writing picture",
            path: path.clone(),
            source: e.error,
        })?;
        written.push(path.clone());
    }
    Ok(written)
}

/// The "no finished job has a value" usage error (exit 2) of a layout with no value in any cell.
fn require_values(
    pivot: &crate::store::Pivot,
    campaign: &crate::campaign::Campaign,
    metric: &str,
    filters: &[String],
    dir: &Path,
) -> Result<(), Error> {
    if pivot.cells.iter().flatten().flatten().any(|c| c.mean.is_finite()) {
        return Ok(());
    }
    Err(Error::Usage(format!(
        "campaign {}: no finished job has a value of `{metric}`{} (see `granflow status {}`)",
        campaign.spec.name,
        if filters.is_empty() {
            String::new()
        } else {
            format!(" where {}", filters.join(", "))
        },
        dir.display()
    )))
}

/// The picture's title: the metric, the campaign, the filters.
fn title(metric: &str, campaign: &crate::campaign::Campaign, filters: &[String]) -> String {
    let mut title = format!("{metric} — {}", campaign.spec.name);
    if !filters.is_empty() {
        title.push_str(&format!(" ({})", filters.join(", ")));
    }
    title
}

/// `granflow plot <dir> curve`: `metric` against `x`, one line per value of `lines` (one line without), of the
/// done jobs matching `filters`, error bars from the jobs each point averages. Returns the files written.
pub fn curve(
    dir: &Path,
    x: &str,
    lines: Option<&str>,
    metric: &str,
    filters: &[String],
    out: Option<&Path>,
) -> Result<Vec<PathBuf>, Error> {
    let (pivot, campaign) = crate::inspect::layout_of(dir, x, lines, metric, filters)?;
    require_values(&pivot, &campaign, metric, filters, dir)?;
    let mut stem = format!("curve-{}-{}", file_part(metric), file_part(&pivot.x_param));
    if !pivot.y_param.is_empty() {
        stem.push_str(&format!("-by-{}", file_part(&pivot.y_param)));
    }
    let outputs = outputs(dir, out, &stem);
    check_writable(&outputs)?;
    let title = title(&pivot.metric, &campaign, filters);
    write_pictures(
        &outputs,
        curve::SIZE,
        |root| curve::draw(root, &pivot, &title),
        |root| curve::draw(root, &pivot, &title),
    )
}

/// The done jobs matching `filters` that a picture of one line per job draws (at most [`series::MAX_JOBS`]), as
/// their directories, with the campaign, and the stem's filter part; none or too many is a usage error.
fn chosen_jobs(dir: &Path, filters: &[String]) -> Result<(Vec<PathBuf>, crate::campaign::Campaign), Error> {
    let (jobs, campaign) = crate::inspect::done_jobs_of(dir, filters)?;
    let selection = if filters.is_empty() {
        String::new()
    } else {
        format!(" where {}", filters.join(", "))
    };
    if jobs.is_empty() {
        return Err(Error::Usage(format!(
            "campaign {}: no finished job{selection} (see `granflow status {}`)",
            campaign.spec.name,
            dir.display()
        )));
    }
    if jobs.len() > series::MAX_JOBS {
        return Err(Error::Usage(format!(
            "campaign {}: {} finished jobs{selection}; a picture of one line per job draws at most {} (narrow it \
             with --where)",
            campaign.spec.name,
            jobs.len(),
            series::MAX_JOBS
        )));
    }
    let dirs = jobs.iter().map(|job| crate::campaign_dir::job_dir(dir, job)).collect();
    Ok((dirs, campaign))
}

/// A file name stem: `picture`, then the filters.
fn stem_with_filters(picture: &str, filters: &[String]) -> String {
    let mut stem = picture.to_string();
    if !filters.is_empty() {
        stem.push_str(&format!("-{}", file_part(&filters.join("-"))));
    }
    stem
}

/// `granflow plot <dir> series`: `column` against time for the done jobs matching `filters` (at most
/// [`series::MAX_JOBS`]), with the fitted model where the column has one. Returns the files written.
pub fn series(dir: &Path, column: &str, filters: &[String], out: Option<&Path>) -> Result<Vec<PathBuf>, Error> {
    let (jobs, campaign) = chosen_jobs(dir, filters)?;
    let mut lines = jobs
        .iter()
        .map(|job_dir| series::job_line(job_dir, &campaign, column))
        .collect::<Result<Vec<_>, _>>()?;
    let shared = series::distinguish(&mut lines);
    let outputs = outputs(
        dir,
        out,
        &stem_with_filters(&format!("series-{}", file_part(column)), filters),
    );
    check_writable(&outputs)?;
    let title = format!("{column} — {}", campaign.spec.name);
    write_pictures(
        &outputs,
        series::SIZE,
        |root| series::draw(root, &lines, column, &title, &shared),
        |root| series::draw(root, &lines, column, &title, &shared),
    )
}

/// `granflow plot <dir> fluidization`: the pressure drop against the gas velocity through the gas cycle of each
/// done job matching `filters` (at most [`series::MAX_JOBS`]), u_mf marked. Returns the files written.
pub fn fluidization(dir: &Path, filters: &[String], out: Option<&Path>) -> Result<Vec<PathBuf>, Error> {
    let (jobs, campaign) = chosen_jobs(dir, filters)?;
    let mut cycles = jobs
        .iter()
        .map(|job_dir| fluidization::job_cycle(job_dir, &campaign))
        .collect::<Result<Vec<_>, _>>()?;
    let shared = match cycles.as_slice() {
        [only] => only.label.clone(),
        _ => series::distinguish_labels(cycles.iter_mut().map(|c| &mut c.label)),
    };
    let outputs = outputs(dir, out, &stem_with_filters("fluidization", filters));
    check_writable(&outputs)?;
    let title = format!("fluidization cycle — {}", campaign.spec.name);
    write_pictures(
        &outputs,
        fluidization::SIZE,
        |root| fluidization::draw(root, &cycles, &title, &shared),
        |root| fluidization::draw(root, &cycles, &title, &shared),
    )
}

/// `granflow plot <dir> phase`: `metric` over `x` (columns) and `y` (rows) of the done jobs matching `filters`, with
/// the classification `markers` (a second metric of a few distinct values, e.g. wet_phase_mixed) drawn over the
/// cells. Returns the files written.
pub fn phase(
    dir: &Path,
    x: &str,
    y: &str,
    metric: &str,
    markers: Option<&str>,
    filters: &[String],
    out: Option<&Path>,
) -> Result<Vec<PathBuf>, Error> {
    let (pivot, campaign) = crate::inspect::pivot_of(dir, x, y, metric, filters)?;
    require_values(&pivot, &campaign, metric, filters, dir)?;
    let markers = match markers {
        Some(name) => {
            let (classes, _) = crate::inspect::pivot_of(dir, x, y, name, filters)?;
            require_values(&classes, &campaign, name, filters, dir)?;
            debug_assert!(classes.x_values == pivot.x_values && classes.y_values == pivot.y_values);
            Some(phase_diagram::Markers::classify(&classes).map_err(Error::Usage)?)
        }
        None => None,
    };
    let stem = format!(
        "phase-{}-{}-{}",
        file_part(metric),
        file_part(&pivot.x_param),
        file_part(&pivot.y_param)
    );
    let outputs = outputs(dir, out, &stem);
    check_writable(&outputs)?;
    let title = title(&pivot.metric, &campaign, filters);
    write_pictures(
        &outputs,
        phase_diagram::SIZE,
        |root| phase_diagram::draw(root, &pivot, &title, markers.as_ref()),
        |root| phase_diagram::draw(root, &pivot, &title, markers.as_ref()),
    )
}
