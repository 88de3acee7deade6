//! Axis ranges and ticks: the drawable points of a figure, padded ranges, and a log axis
//! whose ticks stay useful for any span.

use super::*;

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
pub(super) struct Prepared {
    /// Per series: drawable (x, y) and, where given and finite, the y error.
    pub(super) points: Vec<Vec<(f64, f64, Option<f64>)>>,
    /// Per series: indices into `points` where a line must restart because
    /// points were skipped just before (a line never bridges missing data).
    pub(super) breaks: Vec<Vec<usize>>,
    pub(super) x_range: (f64, f64),
    pub(super) y_range: (f64, f64),
    pub(super) plotted: usize,
    pub(super) non_finite: usize,
    pub(super) non_positive: usize,
}

impl Prepared {
    pub(super) fn new(fig: &Figure) -> Self {
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

    pub(super) fn files(&self, dir: &Path, stem: &str, title: &str) -> FigureFiles {
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
pub(super) fn fit_range(values: &[f64], log: bool) -> (f64, f64) {
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
pub(super) struct LogAxis {
    lo: f64,
    hi: f64,
}

impl LogAxis {
    pub(super) fn new(lo: f64, hi: f64) -> Self {
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

pub(super) fn log_ticks(lo: f64, hi: f64, max_n: usize) -> Vec<f64> {
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
pub(super) fn linear_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
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
