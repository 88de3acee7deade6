//! How a collapse unfolds, not only where it ends: the flow time series every run writes
//! (`timeseries.csv`: front position, height at the remaining wall, kinetic energy), their
//! mean over seeds, the characteristic time `t_half`, the differences between two runs'
//! series after normalising and their noise over seeds; the dynamics criteria of two groups
//! of runs, the front-history gap to a reference run (for the accuracy sweeps) and the
//! figures of the histories.

use std::collections::BTreeMap;
use std::path::Path;

use super::seeds::{group_key, group_label, rule_of, GroupKey};
use crate::csv_table::CsvTable;
use crate::report::{Figure, Series, SeriesStyle};
use crate::runs::{Outcome, RunRecord};
use crate::verdict::{combined_standard_error, mean_sd, Criterion, KnownDifference};
use cgdem_core::scene::Scene;

/// Spacing of the common time grid on which flow histories are averaged and compared.
pub const FLOW_GRID_S: f64 = 0.01;

/// One run's (or a mean over seeds') flow during the measured stage, time from its start.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlowSeries {
    pub time_s: Vec<f64>,
    /// Furthest x where the deposit is at least two diameters deep.
    pub front_m: Vec<f64>,
    /// Column height at the remaining wall.
    pub wall_height_m: Vec<f64>,
    pub kinetic_energy_per_mass: Vec<f64>,
}

impl FlowSeries {
    /// Reads the rows of `stage` from `dir/timeseries.csv`; None when the file or its
    /// columns are missing or the stage has no rows.
    pub fn read(dir: &Path, stage: &str) -> Option<FlowSeries> {
        let table = CsvTable::read(&dir.join("timeseries.csv")).ok()?;
        let col = |name: &str| table.column(name).ok();
        let (t, st, x, h, ke) = (
            col("time_s")?,
            col("stage")?,
            col("front_m")?,
            col("wall_height_m")?,
            col("kinetic_energy_per_mass_j_kg")?,
        );
        let mut out = FlowSeries::default();
        let mut t0 = None;
        for row in table.rows() {
            if row.text(st).ok() != Some(stage) {
                continue;
            }
            // Rows without a front (no deposit yet) are not part of the flow.
            let num = |c| row.parse::<f64>(c).ok();
            let (Some(time), Some(front), Some(height), Some(energy)) =
                (num(t), num(x), num(h), num(ke))
            else {
                continue;
            };
            let start = *t0.get_or_insert(time);
            out.time_s.push(time - start);
            out.front_m.push(front);
            out.wall_height_m.push(height);
            out.kinetic_energy_per_mass.push(energy);
        }
        (!out.time_s.is_empty()).then_some(out)
    }

    /// What the gaps are normalised by: the initial height at the wall and the peak kinetic
    /// energy per mass; None for an empty series.
    fn scales(&self) -> Option<(f64, f64)> {
        let h0 = *self.wall_height_m.first()?;
        let e_peak = self
            .kinetic_energy_per_mass
            .iter()
            .copied()
            .fold(0.0, f64::max);
        Some((h0, e_peak))
    }

    pub fn duration(&self) -> f64 {
        self.time_s.last().copied().unwrap_or(0.0)
    }

    /// Time for the front to advance half of its largest advance beyond its start (the
    /// collapse's characteristic time); None if the front never moves.
    pub fn t_half(&self) -> Option<f64> {
        let start = *self.front_m.first()?;
        let largest = self.front_m.iter().map(|x| x - start).fold(0.0, f64::max);
        if largest <= 0.0 {
            return None;
        }
        let k = self
            .front_m
            .iter()
            .position(|x| x - start >= 0.5 * largest)?;
        Some(self.time_s[k])
    }

    /// Linear interpolation of every column at `t`; past the end the last value holds (the
    /// run stopped because the heap came to rest).
    fn at(&self, t: f64) -> (f64, f64, f64) {
        let n = self.time_s.len();
        let k = self.time_s.partition_point(|&s| s <= t);
        let pick = |v: &[f64]| -> f64 {
            if k == 0 {
                v[0]
            } else if k >= n {
                v[n - 1]
            } else {
                let (t0, t1) = (self.time_s[k - 1], self.time_s[k]);
                let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
                v[k - 1] + w * (v[k] - v[k - 1])
            }
        };
        (
            pick(&self.front_m),
            pick(&self.wall_height_m),
            pick(&self.kinetic_energy_per_mass),
        )
    }

    /// The mean of several runs on a common grid of spacing `step` up to the longest run.
    pub fn mean(runs: &[FlowSeries], step: f64) -> Option<FlowSeries> {
        let end = runs.iter().map(FlowSeries::duration).fold(0.0, f64::max);
        if runs.is_empty() || step <= 0.0 {
            return None;
        }
        let n = (end / step).round() as usize + 1;
        let mut out = FlowSeries::default();
        for i in 0..n {
            let t = i as f64 * step;
            let (mut x, mut h, mut e) = (0.0, 0.0, 0.0);
            for r in runs {
                let v = r.at(t);
                x += v.0;
                h += v.1;
                e += v.2;
            }
            let k = runs.len() as f64;
            out.time_s.push(t);
            out.front_m.push(x / k);
            out.wall_height_m.push(h / k);
            out.kinetic_energy_per_mass.push(e / k);
        }
        Some(out)
    }
}

/// Differences between two flows after normalising: the front by the box length, the wall
/// height by the reference's initial height, the kinetic energy per mass by the reference's
/// peak; largest and time-averaged over the longer of the two (the ended one holds its last
/// value).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FlowDifference {
    pub front_max: f64,
    pub front_mean: f64,
    pub wall_height_max: f64,
    pub wall_height_mean: f64,
    pub kinetic_energy_max: f64,
    pub kinetic_energy_mean: f64,
}

pub fn flow_difference(
    reference: &FlowSeries,
    other: &FlowSeries,
    box_length: f64,
    step: f64,
) -> Option<FlowDifference> {
    let (h0, e_peak) = reference.scales()?;
    if other.time_s.is_empty() || h0 <= 0.0 || e_peak <= 0.0 || box_length <= 0.0 || step <= 0.0 {
        return None;
    }
    let end = reference.duration().max(other.duration());
    let n = (end / step).round() as usize + 1;
    let mut d = FlowDifference {
        front_max: 0.0,
        front_mean: 0.0,
        wall_height_max: 0.0,
        wall_height_mean: 0.0,
        kinetic_energy_max: 0.0,
        kinetic_energy_mean: 0.0,
    };
    for i in 0..n {
        let t = i as f64 * step;
        let (a, b) = (reference.at(t), other.at(t));
        let dx = (a.0 - b.0).abs() / box_length;
        let dh = (a.1 - b.1).abs() / h0;
        let de = (a.2 - b.2).abs() / e_peak;
        d.front_max = d.front_max.max(dx);
        d.wall_height_max = d.wall_height_max.max(dh);
        d.kinetic_energy_max = d.kinetic_energy_max.max(de);
        d.front_mean += dx / n as f64;
        d.wall_height_mean += dh / n as f64;
        d.kinetic_energy_mean += de / n as f64;
    }
    Some(d)
}

/// The seeds' own noise in the gap between two groups' seed-mean flows: at each time the
/// combined standard error of the two means, `sqrt(s_a^2/n_a + s_b^2/n_b)` (s the
/// seed-to-seed sample standard deviation), normalised as in [`flow_difference`] (the
/// reference being the mean of `a`), largest over time. A group of one run adds nothing (no
/// estimate). What an unchanged pair of codes may differ by from the packing alone.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FlowNoise {
    pub front: f64,
    pub wall_height: f64,
    pub kinetic_energy: f64,
}

pub fn flow_noise(
    a: &[FlowSeries],
    b: &[FlowSeries],
    box_length: f64,
    step: f64,
) -> Option<FlowNoise> {
    let (h0, e_peak) = FlowSeries::mean(a, step)?.scales()?;
    if b.is_empty() || h0 <= 0.0 || e_peak <= 0.0 || box_length <= 0.0 || step <= 0.0 {
        return None;
    }
    let end = a
        .iter()
        .chain(b)
        .map(FlowSeries::duration)
        .fold(0.0, f64::max);
    let n = (end / step).round() as usize + 1;
    // Squared standard error of one group's mean of each column at t.
    let se2 = |runs: &[FlowSeries], t: f64| -> [f64; 3] {
        let k = runs.len();
        if k < 2 {
            return [0.0; 3];
        }
        let values: Vec<(f64, f64, f64)> = runs.iter().map(|r| r.at(t)).collect();
        let column = |f: &dyn Fn(&(f64, f64, f64)) -> f64| {
            let mean = values.iter().map(f).sum::<f64>() / k as f64;
            let var = values.iter().map(|v| (f(v) - mean).powi(2)).sum::<f64>() / (k as f64 - 1.0);
            var / k as f64
        };
        [column(&|v| v.0), column(&|v| v.1), column(&|v| v.2)]
    };
    let mut out = FlowNoise {
        front: 0.0,
        wall_height: 0.0,
        kinetic_energy: 0.0,
    };
    for i in 0..n {
        let t = i as f64 * step;
        let (sa, sb) = (se2(a, t), se2(b, t));
        out.front = out.front.max((sa[0] + sb[0]).sqrt() / box_length);
        out.wall_height = out.wall_height.max((sa[1] + sb[1]).sqrt() / h0);
        out.kinetic_energy = out.kinetic_energy.max((sa[2] + sb[2]).sqrt() / e_peak);
    }
    Some(out)
}

/// The stage whose flow a scene measures (its `[repose]` stage); None without one.
pub fn flow_stage(scene: &Scene) -> Option<&str> {
    scene.repose.as_ref().map(|r| r.stage.as_str())
}

/// The characteristic time of the run in `dir` of `scene` ([`FlowSeries::t_half`] of its
/// measured stage); None without a flow or where the front never moved.
pub fn measured_t_half(scene: &Scene, dir: &Path) -> Option<f64> {
    FlowSeries::read(dir, flow_stage(scene)?)?.t_half()
}

/// Every successful run's flow during the measured stage, per group.
pub fn flows_by_group(scene: &Scene, runs: &[RunRecord]) -> BTreeMap<GroupKey, Vec<FlowSeries>> {
    let mut groups: BTreeMap<GroupKey, Vec<FlowSeries>> = BTreeMap::new();
    let Some(stage) = flow_stage(scene) else {
        return groups;
    };
    for r in runs.iter().filter(|r| r.status == Outcome::Ok) {
        if let Some(flow) = FlowSeries::read(&r.dir, stage) {
            groups.entry(group_key(r)).or_default().push(flow);
        }
    }
    groups
}

/// The tolerances of the dynamics criteria (a suite case's `time_ratio_tolerance`,
/// `front_tolerance`, `wall_height_tolerance`, `kinetic_energy_tolerance`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlowTolerances {
    /// Largest |ratio - 1| of the two groups' mean t_half.
    pub time_ratio: f64,
    /// Largest gap of the front histories, of the box length.
    pub front: f64,
    /// Largest gap of the wall-height histories, of the initial height.
    pub wall_height: f64,
    /// Largest gap of the kinetic-energy histories, of the peak.
    pub kinetic_energy: f64,
}

/// The dynamics of two groups of runs (`fa`, `fb`: one flow per seed), four criteria: the
/// ratio of the seeds' mean `t_half` (judged as |ratio - 1|), and the largest gaps between
/// the seed-mean histories of the front (of the box length), the height at the remaining
/// wall (of its initial height) and the kinetic energy (of its peak); each against its
/// tolerance plus `K_NOISE` times the noise the seeds show, or the band of the known
/// difference `known(criterion)` names. With the numbers in words, the t_half ratio beside
/// `predicted_ratio`; None when a side has no flow to compare.
pub fn flow_criteria<'a>(
    fa: &[FlowSeries],
    fb: &[FlowSeries],
    box_length: f64,
    tolerances: &FlowTolerances,
    known: impl Fn(&str) -> Option<&'a KnownDifference>,
    predicted_ratio: &str,
) -> Option<(Vec<Criterion>, String)> {
    let ta: Vec<f64> = fa.iter().filter_map(FlowSeries::t_half).collect();
    let tb: Vec<f64> = fb.iter().filter_map(FlowSeries::t_half).collect();
    let step = FLOW_GRID_S;
    let mean_a = FlowSeries::mean(fa, step)?;
    let mean_b = FlowSeries::mean(fb, step)?;
    let gap = flow_difference(&mean_a, &mean_b, box_length, step)?;
    let noise = flow_noise(fa, fb, box_length, step)?;
    let seeds = [fa.len(), fb.len()];
    let mut criteria = Vec::new();
    // t_half exists only where the front moved; without it on a side, the gaps still judge.
    let t_half_text = match (mean_sd(&ta), mean_sd(&tb)) {
        (Some((ma, sa, na)), Some((mb, sb, nb))) => {
            let ratio = mb / ma;
            // Standard error of the ratio from the relative standard errors of the means.
            let ratio_noise = ratio * combined_standard_error((sa / ma, na), (sb / mb, nb));
            criteria.push(Criterion::judge(
                "t_half ratio",
                "|ratio - 1|",
                (ratio - 1.0).abs(),
                ratio_noise,
                [na, nb],
                tolerances.time_ratio,
                known("t_half ratio"),
            ));
            format!(
                "t_half {ma:.3} +- {sa:.3} s vs {mb:.3} +- {sb:.3} s: ratio {ratio:.2} (predicted {predicted_ratio})"
            )
        }
        _ => format!(
            "t_half not measured (the front did not move in {} of {} and {} of {} runs)",
            fa.len() - ta.len(),
            fa.len(),
            fb.len() - tb.len(),
            fb.len()
        ),
    };
    criteria.extend([
        Criterion::judge(
            "front gap",
            "of the box length",
            gap.front_max,
            noise.front,
            seeds,
            tolerances.front,
            known("front gap"),
        ),
        Criterion::judge(
            "wall height gap",
            "of the initial height",
            gap.wall_height_max,
            noise.wall_height,
            seeds,
            tolerances.wall_height,
            known("wall height gap"),
        ),
        Criterion::judge(
            "kinetic energy gap",
            "of the peak",
            gap.kinetic_energy_max,
            noise.kinetic_energy,
            seeds,
            tolerances.kinetic_energy,
            known("kinetic energy gap"),
        ),
    ]);
    Some((
        criteria,
        format!(
            "{t_half_text}; gaps, largest over time (mean): front {:.3} ({:.3}) of the box \
             length, wall height {:.3} ({:.3}) of the initial height, kinetic energy {:.3} \
             ({:.3}) of the peak",
            gap.front_max,
            gap.front_mean,
            gap.wall_height_max,
            gap.wall_height_mean,
            gap.kinetic_energy_max,
            gap.kinetic_energy_mean,
        ),
    ))
}

/// The flow histories (front, height at the wall, kinetic energy), mean over seeds, one
/// line per code, level and rule.
pub fn flow_figures(scene: &Scene, runs: &[RunRecord]) -> [Figure; 3] {
    let flows = flows_by_group(scene, runs);
    let time_axis = "time after the gate opens t [s]";
    let mut front = Figure::new(
        format!("{}: front position (mean over seeds)", scene.name),
        time_axis,
        "front position x_f [m]",
    );
    let mut height = Figure::new(
        format!(
            "{}: height at the remaining wall (mean over seeds)",
            scene.name
        ),
        time_axis,
        "wall height h_w [m]",
    );
    let mut energy = Figure::new(
        format!("{}: kinetic energy (mean over seeds)", scene.name),
        time_axis,
        "kinetic energy per mass [J/kg]",
    )
    .log_y();
    for (&(rule, lambda, code), series) in &flows {
        let Some(mean) = FlowSeries::mean(series, FLOW_GRID_S) else {
            continue;
        };
        let name = group_label(code, lambda, rule_of(rule));
        let points = |v: &[f64]| {
            mean.time_s
                .iter()
                .copied()
                .zip(v.iter().copied())
                .collect::<Vec<_>>()
        };
        front
            .series
            .push(Series::new(name.clone(), points(&mean.front_m)).style(SeriesStyle::Line));
        height
            .series
            .push(Series::new(name.clone(), points(&mean.wall_height_m)).style(SeriesStyle::Line));
        let positive = points(&mean.kinetic_energy_per_mass)
            .into_iter()
            .filter(|p| p.1 > 0.0)
            .collect();
        energy
            .series
            .push(Series::new(name, positive).style(SeriesStyle::Line));
    }
    [front, height, energy]
}

/// The front history's gap: each run's front as the fraction of its own largest advance it
/// has covered, and the largest difference of the two fractions over the flow (on a common
/// time grid; the run that ended first holds its last value). 0.1 means "a tenth of the
/// run-out apart at worst". How far the fronts get is the heap's (angle, profile); this is
/// how they get there. Each run's own advance also takes out the front's definition in
/// particle diameters (where the deposit is two diameters deep), which puts a coarser
/// level's front further back by about two diameters over the toe's slope. None when a
/// front never advanced.
pub fn front_history_gap(reference: &FlowSeries, other: &FlowSeries) -> Option<f64> {
    let covered = |flow: &FlowSeries| -> Option<FlowSeries> {
        let start = *flow.front_m.first()?;
        let advance = flow.front_m.iter().map(|x| x - start).fold(0.0, f64::max);
        (advance > 0.0).then(|| FlowSeries {
            front_m: flow.front_m.iter().map(|x| (x - start) / advance).collect(),
            ..flow.clone()
        })
    };
    Some(flow_difference(&covered(reference)?, &covered(other)?, 1.0, FLOW_GRID_S)?.front_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(f: impl Fn(f64) -> f64, end: f64) -> FlowSeries {
        let time_s: Vec<f64> = (0..=(end * 100.0) as usize)
            .map(|i| i as f64 * 0.01)
            .collect();
        FlowSeries {
            front_m: time_s.iter().map(|&t| f(t)).collect(),
            wall_height_m: time_s.iter().map(|&t| 0.2 - 0.1 * f(t)).collect(),
            kinetic_energy_per_mass: time_s.iter().map(|&t| (t * (2.0 - t)).max(0.0)).collect(),
            time_s,
        }
    }

    #[test]
    fn t_half_is_when_the_front_covers_half_its_largest_advance() {
        // x_f = 0.1 + 0.2 (1 - exp(-t / 0.5)): half the advance at t = 0.5 ln 2.
        let s = series(|t| 0.1 + 0.2 * (1.0 - (-t / 0.5).exp()), 5.0);
        let t = s.t_half().unwrap();
        assert!((t - 0.5 * 2f64.ln()).abs() <= 0.01, "{t}");
        assert_eq!(series(|_| 0.1, 1.0).t_half(), None);
    }

    #[test]
    fn a_flow_twice_as_slow_doubles_t_half_and_shows_in_the_front_difference() {
        let fast = series(|t| 0.1 + 0.2 * (1.0 - (-t / 0.5).exp()), 6.0);
        let slow = series(|t| 0.1 + 0.2 * (1.0 - (-t / 1.0).exp()), 6.0);
        let ratio = slow.t_half().unwrap() / fast.t_half().unwrap();
        assert!((ratio - 2.0).abs() < 0.05, "{ratio}");
        let d = flow_difference(&fast, &slow, 0.5, 0.01).unwrap();
        // Largest gap 0.2 (e^-x - e^-2x) at e^-x = 1/2: 0.05 m, 0.1 of a 0.5 m box.
        assert!((d.front_max - 0.1).abs() < 0.002, "{d:?}");
        assert!(d.front_mean > 0.0 && d.front_mean < d.front_max);
        let same = flow_difference(&fast, &fast, 0.5, 0.01).unwrap();
        assert_eq!(same.front_max, 0.0);
    }

    #[test]
    fn the_mean_holds_a_finished_run_at_its_last_value() {
        let a = series(|t| t, 1.0);
        let b = series(|t| 2.0 * t, 2.0);
        let m = FlowSeries::mean(&[a, b], 0.5).unwrap();
        assert_eq!(m.time_s, vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        assert!(
            (m.front_m[4] - 0.5 * (1.0 + 4.0)).abs() < 1e-12,
            "{:?}",
            m.front_m
        );
    }

    #[test]
    fn the_noise_of_a_gap_comes_from_the_seed_to_seed_spread() {
        // Two seeds whose fronts differ by 0.02 m at all times: s = 0.02/sqrt(2), the
        // standard error of each mean 0.01 m, combined sqrt(2) * 0.01 m; a 0.5 m box.
        let a = [series(|t| t, 1.0), series(|t| t + 0.02, 1.0)];
        let b = [series(|t| t + 0.005, 1.0), series(|t| t + 0.025, 1.0)];
        let n = flow_noise(&a, &b, 0.5, 0.01).unwrap();
        assert!((n.front - 2f64.sqrt() * 0.01 / 0.5).abs() < 1e-9, "{n:?}");
        // One run per side: no estimate.
        let n = flow_noise(&a[..1], &b[..1], 0.5, 0.01).unwrap();
        assert_eq!(n.front, 0.0);
    }
}
