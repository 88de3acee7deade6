//! Figures for validation reports: every figure is written three times with
//! one stem, `stem.png` (embedded in the HTML), `stem.svg` (for papers) and
//! `stem.csv` (the plotted numbers, so a reviewer can re-plot them).
//!
//! Text is drawn with DejaVu Sans embedded in the binary (see
//! `fonts/LICENSE-DejaVu.txt`) through plotters' `ab_glyph` feature, so PNGs
//! have readable labels on a machine without fontconfig or system fonts. Do
//! not enable plotters' `ttf` feature: it would take precedence and bring the
//! fontconfig dependency back.

use std::fmt;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::chart::SeriesAnno;
use plotters::coord::ranged1d::{
    AsRangedCoord, DefaultFormatting, KeyPointHint, Ranged, ValueFormatter,
};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use cgdem_core::io::CsvBuffer;
use serde::{Deserialize, Serialize};

mod axes;
mod draw;
#[cfg(test)]
pub(crate) mod tests;

pub use axes::format_tick;
use axes::*;
use draw::*;

const FONT: &str = "sans-serif";
static DEJAVU_SANS: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");
static REGISTER_FONTS: Once = Once::new();

/// Okabe–Ito colours (distinguishable with the common colour-vision
/// deficiencies); yellow last because it is faint on white.
const PALETTE: [RGBColor; 8] = [
    RGBColor(0x00, 0x72, 0xB2),
    RGBColor(0xD5, 0x5E, 0x00),
    RGBColor(0x00, 0x9E, 0x73),
    RGBColor(0xCC, 0x79, 0xA7),
    RGBColor(0xE6, 0x9F, 0x00),
    RGBColor(0x56, 0xB4, 0xE9),
    RGBColor(0x00, 0x00, 0x00),
    RGBColor(0xC8, 0xB4, 0x00),
];
const GRID: RGBColor = RGBColor(0xDD, 0xDD, 0xDD);
const NOTE: RGBColor = RGBColor(0x66, 0x66, 0x66);
const MARKER_SIZE: i32 = 4;
const LINE_WIDTH: u32 = 2;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum SeriesStyle {
    #[default]
    Line,
    Markers,
    LineMarkers,
    Dashed,
}

/// Where the legend box sits inside the plotting area.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum LegendPosition {
    /// The corner that covers the fewest data points.
    #[default]
    Auto,
    UpperLeft,
    UpperRight,
    LowerLeft,
    LowerRight,
}

/// One curve or point cloud. Points with a non-finite coordinate (or a
/// non-positive one on a log axis) are not drawn, and counted.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Symmetric y error (one standard deviation, say), one per point.
    pub y_err: Option<Vec<f64>>,
    pub style: SeriesStyle,
}

impl Series {
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
            y_err: None,
            style: SeriesStyle::Line,
        }
    }

    pub fn style(mut self, style: SeriesStyle) -> Self {
        self.style = style;
        self
    }

    pub fn y_err(mut self, y_err: Vec<f64>) -> Self {
        self.y_err = Some(y_err);
        self
    }
}

/// A 2-D plot. Axis labels should carry units, e.g. `"time t [s]"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
    /// Fixed axis ranges; `None` fits the data with 5 % padding.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    pub legend: LegendPosition,
    /// Pixel size of the PNG (and the SVG's user units).
    pub width: u32,
    pub height: u32,
}

impl Figure {
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_log: false,
            y_log: false,
            series: Vec::new(),
            x_range: None,
            y_range: None,
            legend: LegendPosition::default(),
            width: 960,
            height: 600,
        }
    }

    pub fn log_x(mut self) -> Self {
        self.x_log = true;
        self
    }

    pub fn log_y(mut self) -> Self {
        self.y_log = true;
        self
    }

    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }
}

/// What [`write_figure`] and [`write_bar_chart`] wrote, and what they left out.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FigureFiles {
    pub title: String,
    pub png: PathBuf,
    pub svg: PathBuf,
    pub csv: PathBuf,
    /// Points drawn, over all series.
    pub plotted: usize,
    /// Points not drawn because x or y was NaN or infinite.
    pub skipped_non_finite: usize,
    /// Points not drawn because x or y was <= 0 on a log axis.
    pub skipped_non_positive: usize,
}

impl FigureFiles {
    /// A sentence for the caption when points were left out, e.g.
    /// "3 points with NaN/inf values not shown."; `None` when all were drawn.
    pub fn note(&self) -> Option<String> {
        let mut parts = Vec::new();
        if self.skipped_non_finite > 0 {
            parts.push(format!(
                "{} with NaN/inf values",
                points(self.skipped_non_finite)
            ));
        }
        if self.skipped_non_positive > 0 {
            parts.push(format!(
                "{} with values <= 0 on a log axis",
                points(self.skipped_non_positive)
            ));
        }
        if parts.is_empty() {
            None
        } else {
            Some(format!("{} not shown (kept in the CSV).", parts.join(", ")))
        }
    }
}

fn points(n: usize) -> String {
    if n == 1 {
        "1 point".to_string()
    } else {
        format!("{n} points")
    }
}

#[derive(Debug)]
pub enum PlotError {
    /// The stem must be a plain file name without extension or separators.
    InvalidStem(String),
    /// A series' `y_err` does not have one entry per point.
    ErrorLengthMismatch {
        series: String,
        points: usize,
        errors: usize,
    },
    Io {
        path: PathBuf,
        source: io::Error,
    },
    /// plotters failed to draw or encode the file.
    Draw {
        path: PathBuf,
        message: String,
    },
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidStem(s) => write!(
                f,
                "invalid figure stem {s:?}: use letters, digits, '-', '_' or '.' only"
            ),
            Self::ErrorLengthMismatch {
                series,
                points,
                errors,
            } => write!(
                f,
                "series {series:?} has {points} points but {errors} y errors"
            ),
            Self::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Self::Draw { path, message } => {
                write!(f, "{}: plotting failed: {message}", path.display())
            }
        }
    }
}

impl std::error::Error for PlotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Registers the embedded font for the generic families plotters asks for.
/// Idempotent; called by every writer.
pub fn register_fonts() {
    REGISTER_FONTS.call_once(|| {
        for family in ["sans-serif", "serif", "monospace"] {
            // The bytes are a valid TrueType file checked in with the source.
            let _ = plotters::style::register_font(family, FontStyle::Normal, DEJAVU_SANS);
        }
    });
}

/// Writes `dir/stem.{png,svg,csv}`. The CSV has the header `series,x,y` (plus
/// `,y_err` when any series has errors) and every point, skipped ones
/// included, at full precision.
pub fn write_figure(dir: &Path, stem: &str, fig: &Figure) -> Result<FigureFiles, PlotError> {
    check_stem(stem)?;
    for s in &fig.series {
        if let Some(err) = &s.y_err {
            if err.len() != s.points.len() {
                return Err(PlotError::ErrorLengthMismatch {
                    series: s.label.clone(),
                    points: s.points.len(),
                    errors: err.len(),
                });
            }
        }
    }
    fs::create_dir_all(dir).map_err(|source| PlotError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    register_fonts();

    let prepared = Prepared::new(fig);
    let mut files = prepared.files(dir, stem, &fig.title);

    let has_err = fig.series.iter().any(|s| s.y_err.is_some());
    let mut csv = data_table(has_err);
    for s in &fig.series {
        for (i, (x, y)) in s.points.iter().enumerate() {
            let err = s.y_err.as_ref().map(|e| e[i]);
            csv.row(data_row(&s.label, x.to_string(), *y, has_err, err));
        }
    }
    write_table(&files.csv, csv)?;

    let size = (fig.width.max(200), fig.height.max(150));
    {
        let root = BitMapBackend::new(&files.png, size).into_drawing_area();
        draw_figure(&root, fig, &prepared).map_err(|m| draw_err(&files.png, m))?;
        root.present().map_err(|e| draw_err(&files.png, e))?;
    }
    {
        let root = SVGBackend::new(&files.svg, size).into_drawing_area();
        draw_figure(&root, fig, &prepared).map_err(|m| draw_err(&files.svg, m))?;
        root.present().map_err(|e| draw_err(&files.svg, e))?;
    }
    files.title = fig.title.clone();
    Ok(files)
}

/// Grouped bar chart: one group per `group` (e.g. a validation case), one
/// colour per `code` (e.g. cgdem, LIGGGHTS, LAMMPS), optional symmetric error.
/// Groups and codes keep their order of first appearance. The CSV uses the
/// same header as [`write_figure`], with `series` = code and `x` = group.
pub fn write_bar_chart(
    dir: &Path,
    stem: &str,
    title: &str,
    y_label: &str,
    bars: &[(String, String, f64, Option<f64>)],
) -> Result<FigureFiles, PlotError> {
    check_stem(stem)?;
    fs::create_dir_all(dir).map_err(|source| PlotError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    register_fonts();

    let mut groups: Vec<&str> = Vec::new();
    let mut codes: Vec<&str> = Vec::new();
    for (g, c, _, _) in bars {
        if !groups.contains(&g.as_str()) {
            groups.push(g);
        }
        if !codes.contains(&c.as_str()) {
            codes.push(c);
        }
    }
    let mut files = FigureFiles {
        title: title.to_string(),
        png: dir.join(format!("{stem}.png")),
        svg: dir.join(format!("{stem}.svg")),
        csv: dir.join(format!("{stem}.csv")),
        plotted: 0,
        skipped_non_finite: 0,
        skipped_non_positive: 0,
    };
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for (_, _, v, e) in bars {
        if v.is_finite() {
            files.plotted += 1;
            let e = e.filter(|e| e.is_finite()).unwrap_or(0.0).abs();
            lo = lo.min(v - e);
            hi = hi.max(v + e);
        } else {
            files.skipped_non_finite += 1;
        }
    }
    if hi == lo {
        hi = 1.0;
    }
    let pad = 0.05 * (hi - lo);
    let y_range = (if lo < 0.0 { lo - pad } else { 0.0 }, hi + pad);

    let has_err = bars.iter().any(|b| b.3.is_some());
    let mut csv = data_table(has_err);
    for (g, c, v, e) in bars {
        csv.row(data_row(c, g.clone(), *v, has_err, *e));
    }
    write_table(&files.csv, csv)?;

    let spec = BarSpec {
        title,
        y_label,
        bars,
        groups: &groups,
        codes: &codes,
        y_range,
        note: files.note(),
    };
    let size = (960, 600);
    {
        let root = BitMapBackend::new(&files.png, size).into_drawing_area();
        draw_bars(&root, &spec).map_err(|m| draw_err(&files.png, m))?;
        root.present().map_err(|e| draw_err(&files.png, e))?;
    }
    {
        let root = SVGBackend::new(&files.svg, size).into_drawing_area();
        draw_bars(&root, &spec).map_err(|m| draw_err(&files.svg, m))?;
        root.present().map_err(|e| draw_err(&files.svg, e))?;
    }
    Ok(files)
}

fn check_stem(stem: &str) -> Result<(), PlotError> {
    let ok = !stem.is_empty()
        && !stem.starts_with('.')
        && stem
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'));
    if ok {
        Ok(())
    } else {
        Err(PlotError::InvalidStem(stem.to_string()))
    }
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), PlotError> {
    let io_err = |source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut f = fs::File::create(path).map_err(io_err)?;
    f.write_all(bytes).map_err(io_err)
}

fn draw_err(path: &Path, e: impl fmt::Display) -> PlotError {
    PlotError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The data table beside a figure: `series,x,y` and `y_err` when some series has errors.
fn data_table(has_err: bool) -> CsvBuffer {
    if has_err {
        CsvBuffer::new(["series", "x", "y", "y_err"])
    } else {
        CsvBuffer::new(["series", "x", "y"])
    }
}

fn data_row(series: &str, x: String, y: f64, has_err: bool, err: Option<f64>) -> Vec<String> {
    let mut row = vec![series.to_string(), x, y.to_string()];
    if has_err {
        row.push(err.map_or(String::new(), |e| e.to_string()));
    }
    row
}

fn write_table(path: &Path, mut table: CsvBuffer) -> Result<(), PlotError> {
    let bytes = table.bytes().map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    write_bytes(path, bytes)
}
