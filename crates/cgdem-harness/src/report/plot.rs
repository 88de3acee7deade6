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

const FONT: &str = "sans-serif";
static DEJAVU_SANS: &[u8] = include_bytes!("fonts/DejaVuSans.ttf");
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

/// Tick labels: plain decimals in [1e-3, 1e4), otherwise `2.5e-6`, and at
/// most 6 significant digits so float noise (0.30000000000000004) is hidden.
pub fn format_tick(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 {
            "0".to_string()
        } else {
            v.to_string()
        };
    }
    let rounded: f64 = format!("{v:.5e}").parse().unwrap_or(v);
    let a = rounded.abs();
    if (1e-3..1e4).contains(&a) {
        rounded.to_string()
    } else {
        let s = format!("{rounded:e}");
        s.replace("e-0", "e-")
    }
}

/// The drawable subset of a figure's points and the axis ranges.
struct Prepared {
    /// Per series: drawable (x, y) and, where given and finite, the y error.
    points: Vec<Vec<(f64, f64, Option<f64>)>>,
    /// Per series: indices into `points` where a line must restart because
    /// points were skipped just before (a line never bridges missing data).
    breaks: Vec<Vec<usize>>,
    x_range: (f64, f64),
    y_range: (f64, f64),
    plotted: usize,
    non_finite: usize,
    non_positive: usize,
}

impl Prepared {
    fn new(fig: &Figure) -> Self {
        let mut p = Prepared {
            points: Vec::with_capacity(fig.series.len()),
            breaks: Vec::with_capacity(fig.series.len()),
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            plotted: 0,
            non_finite: 0,
            non_positive: 0,
        };
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for s in &fig.series {
            let mut kept = Vec::with_capacity(s.points.len());
            let mut breaks = Vec::new();
            let mut gap = false;
            for (i, &(x, y)) in s.points.iter().enumerate() {
                if !x.is_finite() || !y.is_finite() {
                    p.non_finite += 1;
                    gap = true;
                    continue;
                }
                if (fig.x_log && x <= 0.0) || (fig.y_log && y <= 0.0) {
                    p.non_positive += 1;
                    gap = true;
                    continue;
                }
                if std::mem::take(&mut gap) && !kept.is_empty() {
                    breaks.push(kept.len());
                }
                let err = s
                    .y_err
                    .as_ref()
                    .map(|e| e[i].abs())
                    .filter(|e| e.is_finite() && *e > 0.0);
                xs.push(x);
                ys.push(y);
                if let Some(e) = err {
                    ys.push(y + e);
                    if !fig.y_log || y - e > 0.0 {
                        ys.push(y - e);
                    }
                }
                kept.push((x, y, err));
            }
            p.plotted += kept.len();
            p.points.push(kept);
            p.breaks.push(breaks);
        }
        p.x_range = fig.x_range.unwrap_or_else(|| fit_range(&xs, fig.x_log));
        p.y_range = fig.y_range.unwrap_or_else(|| fit_range(&ys, fig.y_log));
        p
    }

    fn files(&self, dir: &Path, stem: &str, title: &str) -> FigureFiles {
        FigureFiles {
            title: title.to_string(),
            png: dir.join(format!("{stem}.png")),
            svg: dir.join(format!("{stem}.svg")),
            csv: dir.join(format!("{stem}.csv")),
            plotted: self.plotted,
            skipped_non_finite: self.non_finite,
            skipped_non_positive: self.non_positive,
        }
    }
}

/// Data range padded by 5 % of the span each side (in log space on a log
/// axis); a single value gets a span of its own, no data gets a unit range.
fn fit_range(values: &[f64], log: bool) -> (f64, f64) {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if values.is_empty() {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let (l, h) = (lo.log10(), hi.log10());
        let (l, h) = if h - l < 1e-12 {
            (l - 0.5, h + 0.5)
        } else {
            (l, h)
        };
        let pad = 0.05 * (h - l);
        (10f64.powf(l - pad), 10f64.powf(h + pad))
    } else {
        let (l, h) = if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()) {
            let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            (lo - d, hi + d)
        } else {
            (lo, hi)
        };
        let pad = 0.05 * (h - l);
        (l - pad, h + pad)
    }
}

/// A log-scaled axis whose ticks stay useful for any span: decades for wide
/// ranges (thinned when there are too many), 1-2-5 or 1..9 per decade for
/// one or two decades, and plain "nice" linear steps for a narrow range
/// (where plotters' own log axis would show one label or none).
#[derive(Clone, Debug)]
struct LogAxis {
    lo: f64,
    hi: f64,
}

impl LogAxis {
    fn new(lo: f64, hi: f64) -> Self {
        Self { lo, hi }
    }
}

impl Ranged for LogAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let t = (v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln());
        // Clamp far outside values so they cannot overflow pixel arithmetic.
        let t = if t.is_nan() {
            -10.0
        } else {
            t.clamp(-10.0, 10.0)
        };
        limit.0 + (t * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        log_ticks(self.lo, self.hi, hint.max_num_points())
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

fn log_ticks(lo: f64, hi: f64, max_n: usize) -> Vec<f64> {
    let max_n = max_n.max(2);
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let with = |mantissas: &[f64], step: i32| -> Vec<f64> {
        let mut out = Vec::new();
        let mut d = d0;
        while d <= d1 {
            for m in mantissas {
                let v = m * 10f64.powi(d);
                if v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9) {
                    out.push(v);
                }
            }
            d += step;
        }
        out
    };
    let decades = with(&[1.0], 1);
    if decades.len() > max_n {
        let step = decades.len().div_ceil(max_n) as i32;
        return with(&[1.0], step);
    }
    let mut best = decades;
    for mantissas in [
        &[1.0, 2.0, 5.0][..],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    ] {
        if best.len() >= 3 {
            break;
        }
        let t = with(mantissas, 1);
        if t.len() > max_n {
            break;
        }
        best = t;
    }
    if best.len() >= 3 {
        return best;
    }
    linear_ticks(lo, hi, max_n.min(6))
}

/// Ticks at 1, 2 or 5 times a power of ten, at most about `n` of them.
fn linear_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let raw = (hi - lo) / n.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut out = Vec::new();
    let mut k = (lo / step).ceil();
    while k * step <= hi * (1.0 + 1e-12) {
        out.push(k * step);
        k += 1.0;
    }
    out
}

fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
    p: &Prepared,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (x0, x1) = p.x_range;
    let (y0, y1) = p.y_range;
    match (fig.x_log, fig.y_log) {
        (false, false) => draw_chart(root, fig, p, x0..x1, y0..y1),
        (true, false) => draw_chart(root, fig, p, LogAxis::new(x0, x1), y0..y1),
        (false, true) => draw_chart(root, fig, p, x0..x1, LogAxis::new(y0, y1)),
        (true, true) => draw_chart(root, fig, p, LogAxis::new(x0, x1), LogAxis::new(y0, y1)),
    }?;
    let mut notes = Vec::new();
    if fig.series.iter().all(|s| s.points.is_empty()) {
        notes.push("no data".to_string());
    }
    if let Some(n) = p.files(Path::new(""), "", "").note() {
        notes.push(n);
    }
    draw_note(root, &notes.join(" "))
}

fn draw_note<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, note: &str) -> Result<(), String> {
    if note.is_empty() {
        return Ok(());
    }
    let (_, h) = root.dim_in_pixel();
    let style = (FONT, 13).into_font().color(&NOTE);
    root.draw(&Text::new(note.to_string(), (8, h as i32 - 18), style))
        .map_err(|e| e.to_string())
}

fn draw_chart<DB, XS, YS>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
    p: &Prepared,
    x_spec: XS,
    y_spec: YS,
) -> Result<(), String>
where
    DB: DrawingBackend,
    XS: AsRangedCoord<Value = f64>,
    YS: AsRangedCoord<Value = f64>,
    XS::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    YS::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut chart = ChartBuilder::on(root)
        .caption(&fig.title, (FONT, 24))
        .margin_top(10)
        .margin_left(10)
        .margin_right(25)
        .margin_bottom(28)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x_spec, y_spec)
        .map_err(e)?;
    let tick = |v: &f64| format_tick(*v);
    chart
        .configure_mesh()
        .x_desc(&fig.x_label)
        .y_desc(&fig.y_label)
        .axis_desc_style((FONT, 18))
        .label_style((FONT, 14))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .bold_line_style(GRID)
        .light_line_style(WHITE)
        .draw()
        .map_err(e)?;

    let y_floor = p.y_range.0;
    for (i, (s, pts)) in fig.series.iter().zip(&p.points).enumerate() {
        let mut starts = vec![0];
        starts.extend(&p.breaks[i]);
        starts.push(pts.len());
        let segments = starts.windows(2).map(|w| &pts[w[0]..w[1]]);
        let color = PALETTE[i % PALETTE.len()];
        let line = color.stroke_width(LINE_WIDTH);
        let xy = pts.iter().map(|&(x, y, _)| (x, y));
        let label = if pts.is_empty() && !s.label.is_empty() {
            format!("{} (no data)", s.label)
        } else {
            s.label.clone()
        };
        let marker = Marker::for_series(i);
        let has_line = matches!(s.style, SeriesStyle::Line | SeriesStyle::LineMarkers);
        let has_markers = matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers);

        // An empty series carries the legend entry, so every style gets one
        // the same way and legend order follows series order.
        if !label.is_empty() {
            let anno = chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(e)?
                .label(label);
            set_legend(anno, s.style, marker, color);
        }
        match s.style {
            SeriesStyle::Dashed => {
                for seg in segments {
                    let xy = seg.iter().map(|&(x, y, _)| (x, y));
                    chart
                        .draw_series(DashedLineSeries::new(xy, 10, 6, line))
                        .map_err(e)?;
                }
            }
            _ if has_line => {
                for seg in segments {
                    let xy = seg.iter().map(|&(x, y, _)| (x, y));
                    chart.draw_series(LineSeries::new(xy, line)).map_err(e)?;
                }
            }
            _ => {}
        }
        if has_markers {
            let xy: Vec<(f64, f64)> = xy.collect();
            draw_markers(&mut chart, &xy, marker, color)?;
        } else {
            // A line through one point draws nothing: show lone points.
            let lone: Vec<(f64, f64)> = starts
                .windows(2)
                .filter(|w| w[1] - w[0] == 1)
                .map(|w| (pts[w[0]].0, pts[w[0]].1))
                .collect();
            draw_markers(&mut chart, &lone, Marker::Circle, color)?;
        }
        if pts.iter().any(|q| q.2.is_some()) {
            chart
                .draw_series(pts.iter().filter_map(|&(x, y, err)| {
                    let err = err?;
                    let lo = if fig.y_log && y - err <= 0.0 {
                        y_floor
                    } else {
                        y - err
                    };
                    Some(ErrorBar::new_vertical(
                        x,
                        lo,
                        y,
                        y + err,
                        color.stroke_width(1),
                        8,
                    ))
                }))
                .map_err(e)?;
        }
    }

    if fig.series.iter().any(|s| !s.label.is_empty()) {
        chart
            .configure_series_labels()
            .position(match fig.legend {
                LegendPosition::Auto => emptiest_corner(fig, p),
                LegendPosition::UpperLeft => SeriesLabelPosition::UpperLeft,
                LegendPosition::UpperRight => SeriesLabelPosition::UpperRight,
                LegendPosition::LowerLeft => SeriesLabelPosition::LowerLeft,
                LegendPosition::LowerRight => SeriesLabelPosition::LowerRight,
            })
            .label_font((FONT, 15))
            .legend_area_size(36)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.stroke_width(1))
            .draw()
            .map_err(e)?;
    }
    Ok(())
}

/// The plot corner (about a third of the width, a quarter of the height)
/// holding the fewest points; ties keep the conventional upper right.
fn emptiest_corner(fig: &Figure, p: &Prepared) -> SeriesLabelPosition {
    let unit = |v: f64, (lo, hi): (f64, f64), log: bool| {
        if log {
            (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
        } else {
            (v - lo) / (hi - lo)
        }
    };
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let count = |right: bool, upper: bool| {
        p.points
            .iter()
            .flatten()
            .filter(|&&(x, y, _)| {
                let (u, v) = (unit(x, p.x_range, fig.x_log), unit(y, p.y_range, fig.y_log));
                let in_x = if right { u > 0.62 } else { u < 0.38 };
                let in_y = if upper { v > 0.72 } else { v < 0.28 };
                in_x && in_y
            })
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|&(_, r, u)| count(r, u))
        .map(|c| c.0)
        .unwrap_or(SeriesLabelPosition::UpperRight)
}

/// Marker shapes cycle so series stay distinct in greyscale print and when
/// the palette wraps.
#[derive(Clone, Copy, Debug)]
enum Marker {
    Circle,
    Triangle,
    Square,
    Cross,
}

impl Marker {
    fn for_series(i: usize) -> Self {
        match (i + i / PALETTE.len()) % 4 {
            0 => Self::Circle,
            1 => Self::Triangle,
            2 => Self::Square,
            _ => Self::Cross,
        }
    }
}

/// Draws one marker per point.
fn draw_markers<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    pts: &[(f64, f64)],
    marker: Marker,
    color: RGBColor,
) -> Result<(), String>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let r = MARKER_SIZE;
    let fill = color.filled();
    let at = |c: &(f64, f64)| EmptyElement::at(*c);
    let res = match marker {
        Marker::Circle => chart
            .draw_series(pts.iter().map(|c| at(c) + Circle::new((0, 0), r, fill)))
            .map(|_| ()),
        Marker::Triangle => chart
            .draw_series(
                pts.iter()
                    .map(|c| at(c) + TriangleMarker::new((0, 0), r + 1, fill)),
            )
            .map(|_| ()),
        Marker::Square => chart
            .draw_series(
                pts.iter()
                    .map(|c| at(c) + Rectangle::new([(-r, -r), (r, r)], fill)),
            )
            .map(|_| ()),
        Marker::Cross => chart
            .draw_series(
                pts.iter()
                    .map(|c| at(c) + Cross::new((0, 0), r, color.stroke_width(2))),
            )
            .map(|_| ()),
    };
    res.map_err(|e| e.to_string())
}

/// Sets the legend sample: a short stroke in the series' line style and/or
/// its marker. (Each arm has its own element type: plotters' `DynElement`
/// would force `DB: 'static` here.)
fn set_legend<'a, DB: DrawingBackend + 'a>(
    anno: &mut SeriesAnno<'a, DB>,
    style: SeriesStyle,
    marker: Marker,
    color: RGBColor,
) {
    let line = color.stroke_width(LINE_WIDTH);
    let thin = color.stroke_width(2);
    let r = MARKER_SIZE;
    let fill = color.filled();
    macro_rules! glyph {
        ($($part:expr),+) => {{
            anno.legend(move |(x, y)| EmptyElement::at((x + 8, y)) $(+ $part)+);
        }};
    }
    let stroke = move || PathElement::new(vec![(-12, 0), (12, 0)], line);
    match (style, marker) {
        (SeriesStyle::Line, _) => glyph!(stroke()),
        (SeriesStyle::Dashed, _) => glyph!(
            PathElement::new(vec![(-12, 0), (-3, 0)], line),
            PathElement::new(vec![(3, 0), (12, 0)], line)
        ),
        (SeriesStyle::Markers, Marker::Circle) => glyph!(Circle::new((0, 0), r, fill)),
        (SeriesStyle::Markers, Marker::Triangle) => {
            glyph!(TriangleMarker::new((0, 0), r + 1, fill))
        }
        (SeriesStyle::Markers, Marker::Square) => {
            glyph!(Rectangle::new([(-r, -r), (r, r)], fill))
        }
        (SeriesStyle::Markers, Marker::Cross) => glyph!(Cross::new((0, 0), r, thin)),
        (SeriesStyle::LineMarkers, Marker::Circle) => {
            glyph!(stroke(), Circle::new((0, 0), r, fill))
        }
        (SeriesStyle::LineMarkers, Marker::Triangle) => {
            glyph!(stroke(), TriangleMarker::new((0, 0), r + 1, fill))
        }
        (SeriesStyle::LineMarkers, Marker::Square) => {
            glyph!(stroke(), Rectangle::new([(-r, -r), (r, r)], fill))
        }
        (SeriesStyle::LineMarkers, Marker::Cross) => {
            glyph!(stroke(), Cross::new((0, 0), r, thin))
        }
    }
}

struct BarSpec<'a> {
    title: &'a str,
    y_label: &'a str,
    bars: &'a [(String, String, f64, Option<f64>)],
    groups: &'a [&'a str],
    codes: &'a [&'a str],
    y_range: (f64, f64),
    note: Option<String>,
}

fn draw_bars<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, b: &BarSpec) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let n_groups = b.groups.len().max(1) as f64;
    let mut chart = ChartBuilder::on(root)
        .caption(b.title, (FONT, 24))
        .margin_top(10)
        .margin_left(10)
        .margin_right(25)
        .margin_bottom(28)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..n_groups, b.y_range.0..b.y_range.1)
        .map_err(e)?;
    let tick = |v: &f64| format_tick(*v);
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_desc(b.y_label)
        .axis_desc_style((FONT, 18))
        .label_style((FONT, 14))
        .y_label_formatter(&tick)
        .bold_line_style(GRID)
        .light_line_style(WHITE)
        .draw()
        .map_err(e)?;

    let slot = 0.8 / b.codes.len().max(1) as f64;
    let x_of = |g: &str, c: &str| {
        let gi = b.groups.iter().position(|x| *x == g).unwrap_or(0) as f64;
        let ci = b.codes.iter().position(|x| *x == c).unwrap_or(0) as f64;
        gi + 0.1 + ci * slot
    };
    for (ci, code) in b.codes.iter().enumerate() {
        let color = PALETTE[ci % PALETTE.len()];
        let mine = b
            .bars
            .iter()
            .filter(|(_, c, v, _)| c == code && v.is_finite());
        chart
            .draw_series(mine.clone().map(|(g, c, v, _)| {
                let x = x_of(g, c);
                Rectangle::new(
                    [(x + 0.05 * slot, 0.0), (x + 0.95 * slot, *v)],
                    color.filled(),
                )
            }))
            .map_err(e)?
            .label(code.to_string())
            .legend(move |(x, y)| Rectangle::new([(x - 6, y - 6), (x + 6, y + 6)], color.filled()));
        chart
            .draw_series(mine.filter_map(|(g, c, v, err)| {
                let err = err.filter(|e| e.is_finite())?.abs();
                let x = x_of(g, c) + 0.5 * slot;
                Some(ErrorBar::new_vertical(
                    x,
                    v - err,
                    *v,
                    v + err,
                    BLACK.stroke_width(1),
                    8,
                ))
            }))
            .map_err(e)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 15))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.stroke_width(1))
        .draw()
        .map_err(e)?;

    // Group names under the axis, centred on each group.
    let style = (FONT, 15)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Top));
    for (gi, g) in b.groups.iter().enumerate() {
        let (px, py) = chart
            .plotting_area()
            .map_coordinate(&(gi as f64 + 0.5, b.y_range.0));
        root.draw(&Text::new(g.to_string(), (px, py + 10), style.clone()))
            .map_err(e)?;
    }
    let mut notes = Vec::new();
    if b.bars.is_empty() {
        notes.push("no data".to_string());
    }
    notes.extend(b.note.clone());
    draw_note(root, &notes.join(" "))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A fresh directory per test; `CGDEM_KEEP_TEST_OUTPUT=DIR` writes there
    /// instead so the figures can be looked at.
    pub(crate) fn test_dir(name: &str) -> PathBuf {
        let base = std::env::var_os("CGDEM_KEEP_TEST_OUTPUT")
            .map(PathBuf::from)
            .unwrap_or_else(|| {
                std::env::temp_dir().join(format!("cgdem-report-{}", std::process::id()))
            });
        let dir = base.join(name);
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn read_csv(path: &Path) -> (String, Vec<Vec<String>>) {
        let text = fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap().to_string();
        let rows = lines.map(split_csv_line).collect();
        (header, rows)
    }

    /// RFC 4180 fields of one line (no embedded newlines in these tests).
    fn split_csv_line(line: &str) -> Vec<String> {
        let (mut fields, mut cur, mut quoted) = (Vec::new(), String::new(), false);
        let mut chars = line.chars().peekable();
        while let Some(c) = chars.next() {
            match (c, quoted) {
                ('"', true) if chars.peek() == Some(&'"') => {
                    cur.push('"');
                    chars.next();
                }
                ('"', _) => quoted = !quoted,
                (',', false) => fields.push(std::mem::take(&mut cur)),
                _ => cur.push(c),
            }
        }
        fields.push(cur);
        fields
    }

    pub(crate) fn restitution_figure() -> Figure {
        let v: Vec<f64> = (0..12).map(|i| 0.01 * 2f64.powi(i)).collect();
        let dem: Vec<(f64, f64)> = v.iter().map(|&v| (v, 0.9 * v.powf(-0.02))).collect();
        let err: Vec<f64> = v
            .iter()
            .map(|&v| 0.02 + 0.01 * v.ln().abs() / 5.0)
            .collect();
        let theory: Vec<(f64, f64)> = v.iter().map(|&v| (v, 0.88 * v.powf(-0.02))).collect();
        Figure::new(
            "Coefficient of restitution vs impact velocity",
            "impact velocity v [m/s]",
            "restitution e [-]",
        )
        .log_x()
        .log_y()
        .with_series(
            Series::new("cgdem (Hertz + damping)", dem)
                .style(SeriesStyle::LineMarkers)
                .y_err(err),
        )
        .with_series(Series::new("analytic, 1/3 + 1e-17 drift", theory).style(SeriesStyle::Dashed))
    }

    #[test]
    fn two_series_log_axes_error_bars_write_png_svg_and_round_tripping_csv() {
        let dir = test_dir("two_series");
        let fig = restitution_figure();
        let files = write_figure(&dir, "restitution", &fig).unwrap();
        for p in [&files.png, &files.svg, &files.csv] {
            assert!(
                fs::metadata(p).unwrap().len() > 100,
                "{} too small",
                p.display()
            );
        }
        assert_eq!(&fs::read(&files.png).unwrap()[..4], b"\x89PNG");
        let svg = fs::read_to_string(&files.svg).unwrap();
        assert!(svg.contains("<svg") && svg.contains("sans-serif"));
        assert!(svg.contains("impact velocity v [m/s]"));
        assert_eq!(files.plotted, 24);
        assert_eq!(files.note(), None);

        let (header, rows) = read_csv(&files.csv);
        assert_eq!(header, "series,x,y,y_err");
        assert_eq!(rows.len(), 24);
        let mut i = 0;
        for s in &fig.series {
            for (k, &(x, y)) in s.points.iter().enumerate() {
                let row = &rows[i];
                assert_eq!(row[0], s.label);
                // Exact equality: the CSV keeps full precision.
                assert_eq!(row[1].parse::<f64>().unwrap(), x);
                assert_eq!(row[2].parse::<f64>().unwrap(), y);
                match &s.y_err {
                    Some(e) => assert_eq!(row[3].parse::<f64>().unwrap(), e[k]),
                    None => assert_eq!(row[3], ""),
                }
                i += 1;
            }
        }
    }

    #[test]
    fn nan_and_non_positive_points_are_skipped_and_counted_but_kept_in_csv() {
        let dir = test_dir("nan");
        let fig = Figure::new("Kinetic energy", "time t [s]", "kinetic energy E [J]")
            .log_y()
            .with_series(
                Series::new(
                    "run",
                    vec![
                        (0.0, 1.0),
                        (1.0, f64::NAN),
                        (f64::INFINITY, 2.0),
                        (2.0, 0.5),
                        (3.0, 0.0),
                        (4.0, -1.0),
                    ],
                )
                .style(SeriesStyle::Markers),
            );
        let files = write_figure(&dir, "energy", &fig).unwrap();
        assert_eq!(files.plotted, 2);
        assert_eq!(files.skipped_non_finite, 2);
        assert_eq!(files.skipped_non_positive, 2);
        let note = files.note().unwrap();
        assert!(note.contains("2 points with NaN/inf"), "{note}");
        let (_, rows) = read_csv(&files.csv);
        assert_eq!(rows.len(), 6);
        assert!(rows[1][2].parse::<f64>().unwrap().is_nan());
        assert_eq!(rows[2][1].parse::<f64>().unwrap(), f64::INFINITY);
    }

    #[test]
    fn empty_single_point_and_empty_series_still_draw() {
        let dir = test_dir("edge");
        let empty = Figure::new("Nothing yet", "x [m]", "y [m]");
        assert_eq!(write_figure(&dir, "empty", &empty).unwrap().plotted, 0);
        let one = Figure::new("One point", "x [m]", "y [m]")
            .with_series(Series::new("single", vec![(2.0, 3.0)]).style(SeriesStyle::Markers))
            .with_series(Series::new("missing", vec![]));
        assert_eq!(write_figure(&dir, "one", &one).unwrap().plotted, 1);
        let close =
            |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12;
        assert!(close(fit_range(&[3.0], false), (2.67, 3.33)));
        assert!(close(fit_range(&[0.0], false), (-1.1, 1.1)));
        let (lo, hi) = fit_range(&[100.0], true);
        assert!(lo < 100.0 && hi > 100.0);
    }

    #[test]
    fn mismatched_errors_and_bad_stems_are_rejected() {
        let dir = test_dir("reject");
        let fig = Figure::new("t", "x", "y")
            .with_series(Series::new("a", vec![(0.0, 1.0)]).y_err(vec![0.1, 0.2]));
        assert!(matches!(
            write_figure(&dir, "a", &fig),
            Err(PlotError::ErrorLengthMismatch {
                points: 1,
                errors: 2,
                ..
            })
        ));
        for stem in ["", "../x", "a/b", ".hidden", "a b"] {
            assert!(matches!(
                write_figure(&dir, stem, &Figure::new("t", "x", "y")),
                Err(PlotError::InvalidStem(_))
            ));
        }
    }

    #[test]
    fn grouped_bar_chart_writes_all_three_files() {
        let dir = test_dir("bars");
        let mut bars = Vec::new();
        for (case, base) in [
            ("WCA 4k", 2.0e6),
            ("hopper 50k", 8.0e5),
            ("drum, 200k", 3.1e5),
        ] {
            for (code, f) in [("cgdem", 1.0), ("LIGGGHTS", 0.7), ("LAMMPS", 0.8)] {
                bars.push((
                    case.to_string(),
                    code.to_string(),
                    base * f,
                    Some(0.05 * base),
                ));
            }
        }
        bars.push(("drum, 200k".into(), "cgdem".into(), f64::NAN, None));
        let files = write_bar_chart(
            &dir,
            "throughput",
            "Throughput per code and case",
            "throughput [particle steps/s]",
            &bars,
        )
        .unwrap();
        assert_eq!(files.skipped_non_finite, 1);
        let (header, rows) = read_csv(&files.csv);
        assert_eq!(header, "series,x,y,y_err");
        assert_eq!(rows.len(), 10);
        assert_eq!(rows[6][1], "drum, 200k");
        assert!(fs::metadata(&files.png).unwrap().len() > 1000);
    }

    #[test]
    fn log_ticks_suit_wide_and_narrow_spans() {
        assert_eq!(log_ticks(0.008, 25.0, 10), vec![0.01, 0.1, 1.0, 10.0]);
        assert_eq!(log_ticks(1e-12, 1e12, 10).len(), 9);
        assert_eq!(log_ticks(0.15, 2.5, 10), vec![0.2, 0.5, 1.0, 2.0]);
        let narrow = log_ticks(0.75, 1.05, 10);
        assert!(narrow.len() >= 3, "{narrow:?}");
        assert!(narrow.iter().all(|v| (0.75..=1.05).contains(v)));
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(format_tick(0.30000000000000004), "0.3");
        assert_eq!(format_tick(1e-6), "1e-6");
        assert_eq!(format_tick(2.5e7), "2.5e7");
        assert_eq!(format_tick(1000.0), "1000");
        assert_eq!(format_tick(0.0), "0");
    }
}
