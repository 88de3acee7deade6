//! The discharge measurement, the same for every code: the mass discharged against time from
//! a run's `timeseries.csv` (the grains counted out of the scene since the gate opened), its
//! rate over the steady window with a block-average standard error, the bulk density of the
//! settled fill from a trajectory frame, and Beverloo's law (reference/silo/PLAN.md, 2-3).

use std::path::Path;

use crate::csv_table::CsvTable;
use crate::decks::{read_dump, Frame};
use cgdem_core::scene::Scene;

/// Gravity in Beverloo's law, m/s2 (the scenes' |g|).
pub const STANDARD_GRAVITY: f64 = 9.81;

/// Beverloo's constants for spheres as published (Nedderman 1992, ch. 10): C and k.
pub const PUBLISHED_C: f64 = 0.58;
pub const PUBLISHED_K: f64 = 1.5;

/// Mass discharged since the stage began: `time_s` after the stage start, `mass_kg`.
#[derive(Clone, Debug, PartialEq)]
pub struct DischargeSeries {
    pub time_s: Vec<f64>,
    pub mass_kg: Vec<f64>,
}

/// The rate over the window `[discard, end]`: the least-squares slope of the mass, and the
/// rates of `blocks` equal blocks of the window, whose spread gives the standard error.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DischargeRate {
    pub rate_kg_s: f64,
    pub std_error_kg_s: f64,
    pub window_s: [f64; 2],
    pub block_rates_kg_s: Vec<f64>,
    /// The fitted change of the block rate across the window (least squares against the
    /// block's mid-time) and whether it exceeds twice its standard error (from the block
    /// rates' scatter about the fitted line).
    pub drift_kg_s: f64,
    pub drifts: bool,
}

/// The discharged mass of a run, from `timeseries.csv` in `dir`: `grain_mass` times the
/// grains gone since the last row before the stage `stage` (the fill's last), one point per
/// row of the stage, with (0, 0) at the stage start `start_s`. Every code writes the column
/// `n_particles` (LIGGGHTS and LAMMPS: the atoms of each dump frame), so every code is
/// measured alike; the grains leave in the delete box below the orifice, so the mass lags the
/// orifice plane by the fall to that box, the same in every code.
pub fn discharge_series(
    dir: &Path,
    stage: &str,
    start_s: f64,
    grain_mass: f64,
) -> Result<DischargeSeries, String> {
    let table = CsvTable::read(&dir.join("timeseries.csv")).map_err(|e| e.to_string())?;
    let (time, stage_column, count) = (
        table.column("time_s").map_err(|e| e.to_string())?,
        table.column("stage").map_err(|e| e.to_string())?,
        table.column("n_particles").map_err(|e| e.to_string())?,
    );
    let mut before: Option<f64> = None;
    let mut series = DischargeSeries {
        time_s: vec![0.0],
        mass_kg: vec![0.0],
    };
    let mut initial = None;
    for row in table.rows() {
        let t: f64 = row.parse(time).map_err(|e| e.to_string())?;
        let n: f64 = row.parse(count).map_err(|e| e.to_string())?;
        if row.text(stage_column).map_err(|e| e.to_string())? != stage {
            if initial.is_none() {
                before = Some(n);
            }
            continue;
        }
        let n0 = *initial.get_or_insert(before.ok_or_else(|| {
            format!(
                "{}: no row before stage `{stage}` gives the grains it starts with",
                table.path().display()
            )
        })?);
        series.time_s.push(t - start_s);
        series.mass_kg.push(grain_mass * (n0 - n));
    }
    if initial.is_none() {
        return Err(format!(
            "{}: no row of stage `{stage}`",
            table.path().display()
        ));
    }
    Ok(series)
}

/// When the flow stopped: the time of the last change of the discharged mass, when nothing
/// left over at least `quiet_s` before the series' end (an arch over the orifice that held:
/// a clog, a measured result); None while grains still leave.
pub fn flow_stopped_at(series: &DischargeSeries, quiet_s: f64) -> Option<f64> {
    let end = *series.time_s.last()?;
    let last_mass = *series.mass_kg.last()?;
    let k = series.mass_kg.iter().rposition(|&m| m != last_mass);
    // The mass holds from the sample after the last change (the stage start if none).
    let since = k.map_or(0.0, |k| series.time_s[k + 1]);
    (end - since >= quiet_s - 1e-9).then_some(since)
}

/// Least-squares slope and intercept of `y` against `x` (at least two distinct x).
fn line_fit(x: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let n = x.len() as f64;
    if x.len() < 2 {
        return None;
    }
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    (sxx > 0.0).then(|| (sxy / sxx, my - sxy / sxx * mx))
}

/// The rate of `series` from `discard_s` on, with the standard error of `blocks` equal blocks
/// (each block's rate the mass it gains over its duration, so the blocks' mean is the
/// window's end-to-end rate): their standard deviation over sqrt(blocks).
pub fn discharge_rate(
    series: &DischargeSeries,
    discard_s: f64,
    blocks: usize,
) -> Result<DischargeRate, String> {
    if blocks < 2 {
        return Err(format!(
            "{blocks} blocks: at least 2 are needed for a standard error"
        ));
    }
    let (t, m): (Vec<f64>, Vec<f64>) = series
        .time_s
        .iter()
        .zip(&series.mass_kg)
        .filter(|(&t, _)| t >= discard_s - 1e-9)
        .map(|(&t, &m)| (t, m))
        .unzip();
    if t.len() < blocks + 1 {
        return Err(format!(
            "{} samples from {discard_s} s after the gate opens (series ends at {:.3} s): {blocks} blocks need at least {}",
            t.len(),
            series.time_s.last().copied().unwrap_or(0.0),
            blocks + 1
        ));
    }
    let (rate, _) = line_fit(&t, &m).ok_or("the window's samples share one time")?;
    let last = t.len() - 1;
    let bounds: Vec<usize> = (0..=blocks)
        .map(|j| (j as f64 * last as f64 / blocks as f64).round() as usize)
        .collect();
    let mut block_rates = Vec::with_capacity(blocks);
    let mut mid_times = Vec::with_capacity(blocks);
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        block_rates.push((m[b] - m[a]) / (t[b] - t[a]));
        mid_times.push(0.5 * (t[a] + t[b]));
    }
    let b = blocks as f64;
    let mean = block_rates.iter().sum::<f64>() / b;
    let var = block_rates.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (b - 1.0);
    let std_error = (var / b).sqrt();
    // The drift: the block rates' fitted slope times the window's span; its standard error
    // from the scatter about that line (B - 2 degrees of freedom; none for two blocks).
    let (slope, intercept) = line_fit(&mid_times, &block_rates).unwrap_or((0.0, mean));
    let mt = mid_times.iter().sum::<f64>() / b;
    let sxx: f64 = mid_times.iter().map(|x| (x - mt).powi(2)).sum();
    let span = mid_times[blocks - 1] - mid_times[0];
    let drift = slope * span;
    let residual: f64 = mid_times
        .iter()
        .zip(&block_rates)
        .map(|(x, r)| (r - intercept - slope * x).powi(2))
        .sum();
    let drifts = blocks > 2 && {
        let drift_se = (residual / (b - 2.0) / sxx).sqrt() * span;
        drift.abs() > 2.0 * drift_se
    };
    Ok(DischargeRate {
        rate_kg_s: rate,
        std_error_kg_s: std_error,
        window_s: [t[0], t[last]],
        block_rates_kg_s: block_rates,
        drift_kg_s: drift,
        drifts,
    })
}

/// Bulk density, kg/m3: the mass of the grains whose centres lie in the box `lo`..`hi`,
/// over its volume (unbiased for a box many grains wide).
pub fn bulk_density(
    positions: impl IntoIterator<Item = ([f64; 3], f64)>,
    lo: [f64; 3],
    hi: [f64; 3],
) -> f64 {
    let volume = (0..3).map(|i| hi[i] - lo[i]).product::<f64>();
    let mass: f64 = positions
        .into_iter()
        .filter(|(x, _)| (0..3).all(|i| x[i] >= lo[i] && x[i] < hi[i]))
        .map(|(_, m)| m)
        .sum();
    mass / volume
}

/// The bulk density of a LIGGGHTS or LAMMPS run in `dir` at its dump frame nearest the step
/// `step` (the gate's opening: the fill at rest), by the scene's species masses.
pub fn dump_bulk_density(
    dir: &Path,
    scene: &Scene,
    step: u64,
    lo: [f64; 3],
    hi: [f64; 3],
) -> Result<f64, String> {
    let path = dir.join(crate::decks::TRAJECTORY_FILE);
    let frames = read_dump(&path).map_err(|e| e.to_string())?;
    let frame: &Frame = frames
        .iter()
        .min_by_key(|f| f.step.abs_diff(step))
        .ok_or_else(|| format!("{}: no frame", path.display()))?;
    let p = crate::decks::postprocess::frame_particles(frame, scene, &path)
        .map_err(|e| e.to_string())?;
    Ok(bulk_density(
        p.position
            .iter()
            .zip(&p.mass)
            .map(|(x, &m)| ([x.x, x.y, x.z], m)),
        lo,
        hi,
    ))
}

/// The bulk density of a cgdem run from a LAMMPS data file it wrote (`[output]
/// data_at_stage_ends`: the fill at rest when the gate opens), each atom's mass from its
/// diameter and density.
pub fn data_bulk_density(path: &Path, lo: [f64; 3], hi: [f64; 3]) -> Result<f64, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let data = cgdem_core::lammps_data::parse_data(&text, path).map_err(|e| e.to_string())?;
    Ok(bulk_density(
        data.atoms.iter().map(|a| {
            let mass = a.density * std::f64::consts::PI / 6.0 * a.diameter.powi(3);
            ([a.position.x, a.position.y, a.position.z], mass)
        }),
        lo,
        hi,
    ))
}

/// Beverloo's rate, kg/s: `C rho_b sqrt(g) (D0 - k d)^(5/2)`; None when the orifice is no
/// wider than `k d` (the law predicts no flow).
pub fn beverloo_rate(
    c: f64,
    bulk_density: f64,
    orifice_diameter: f64,
    grain_diameter: f64,
    k: f64,
) -> Option<f64> {
    let open = orifice_diameter - k * grain_diameter;
    (open > 0.0).then(|| c * bulk_density * STANDARD_GRAVITY.sqrt() * open.powf(2.5))
}

/// C and its standard error from a measured rate and its error, with k fixed.
pub fn beverloo_c(
    rate: f64,
    std_error: f64,
    bulk_density: f64,
    orifice_diameter: f64,
    grain_diameter: f64,
    k: f64,
) -> Option<(f64, f64)> {
    let unit = beverloo_rate(1.0, bulk_density, orifice_diameter, grain_diameter, k)?;
    Some((rate / unit, std_error / unit))
}

/// One C from several orifices' (C, se): the mean weighted by 1/se^2, its error, and
/// chi^2 over n - 1 degrees of freedom (do the orifices agree with the fixed k?).
pub fn combined_c(points: &[(f64, f64)]) -> Option<(f64, f64, f64)> {
    if points.is_empty() || points.iter().any(|&(_, se)| se.is_nan() || se <= 0.0) {
        return None;
    }
    let w: Vec<f64> = points.iter().map(|&(_, se)| 1.0 / (se * se)).collect();
    let sw: f64 = w.iter().sum();
    let c = points.iter().zip(&w).map(|(&(c, _), w)| c * w).sum::<f64>() / sw;
    let chi2: f64 = points.iter().map(|&(ci, se)| ((ci - c) / se).powi(2)).sum();
    let dof = (points.len() - 1).max(1) as f64;
    Some((c, sw.sqrt().recip(), chi2 / dof))
}

/// C and k both free from two orifices (exactly determined): `(W1/W2)^(2/5) = (D1 - k d) /
/// (D2 - k d)`; None when the rates do not order with the orifices.
pub fn fit_c_and_k(
    (d1, w1): (f64, f64),
    (d2, w2): (f64, f64),
    grain_diameter: f64,
    bulk_density: f64,
) -> Option<(f64, f64)> {
    if !(w1 > 0.0 && w2 > 0.0) || d1 == d2 {
        return None;
    }
    let r = (w1 / w2).powf(0.4);
    if (r - 1.0).abs() < 1e-12 {
        return None;
    }
    let k = (d1 - r * d2) / (grain_diameter * (1.0 - r));
    let c = w1 / beverloo_rate(1.0, bulk_density, d1, grain_diameter, k)?;
    Some((c, k))
}
