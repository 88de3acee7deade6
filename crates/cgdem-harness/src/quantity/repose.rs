//! The repose angle and heap profile: the final state of a collapse. Every code's run
//! leaves them alike (`summary.json`'s `repose_angle_deg`, or why it was not measured, and
//! `profile.csv`, from the core's analysis); here they are grouped over seeds, judged
//! between two groups (the angle: the difference of the seed means against the case's
//! tolerance plus the combined standard error), compared with a reference run (the profile
//! distance, for the accuracy sweeps) and drawn (profiles, angle per level, angle at fixed
//! times).

use std::collections::BTreeMap;
use std::path::Path;

use super::seeds::{group_key, group_label, mean_spread, rule_of, Group, GroupKey};
use crate::code::Code;
use crate::csv_table::{CsvTable, TableError};
use crate::report::{Figure, Series, SeriesStyle};
use crate::runs::{Outcome, RunRecord, ValidateError};
use crate::verdict::{combined_standard_error, mean_sd, Criterion, KnownDifference};
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::Scene;

/// The criterion's name, as a `[[case.known_difference]]` gives it.
pub const CRITERION: &str = "repose angle";

/// Every finished run's repose angle, per group; runs that stopped early or measured none
/// are left out.
pub fn angles_by_group(runs: &[RunRecord]) -> BTreeMap<GroupKey, Vec<f64>> {
    let mut groups: BTreeMap<GroupKey, Vec<f64>> = BTreeMap::new();
    for r in runs.iter().filter(|r| !r.partial) {
        if let Some(a) = r.repose_angle_deg {
            groups.entry(group_key(r)).or_default().push(a);
        }
    }
    groups
}

/// The final-state criterion of two groups' angles (`a`, `b`: one per seed): the difference
/// of their means against `tolerance_deg` plus the combined standard error, or the band of
/// `known`; with the numbers in words. None when a side measured no angle.
pub fn angle_criterion(
    a: &[f64],
    b: &[f64],
    tolerance_deg: f64,
    known: Option<&KnownDifference>,
) -> Option<(Criterion, String)> {
    let ((ma, sa, na), (mb, sb, nb)) = (mean_sd(a)?, mean_sd(b)?);
    let angle = Criterion::judge(
        CRITERION,
        "deg",
        (ma - mb).abs(),
        combined_standard_error((sa, na), (sb, nb)),
        [na, nb],
        tolerance_deg,
        known,
    );
    Some((
        angle,
        format!(
            "repose angle {ma:.1} +- {sa:.1} ({na} seeds) vs {mb:.1} +- {sb:.1} ({nb} seeds) deg"
        ),
    ))
}

/// The `(x_m, height_m)` rows of the heap profile a run in `dir` wrote (`profile.csv`);
/// none when it wrote no profile.
pub fn read_profile(dir: &Path) -> Result<Vec<(f64, f64)>, TableError> {
    let path = dir.join("profile.csv");
    if !path.exists() {
        return Ok(Vec::new());
    }
    let rows = CsvTable::read(&path).and_then(|t| t.numbers(&["x_m", "height_m"]))?;
    Ok(rows.iter().map(|r| (r[0], r[1])).collect())
}

/// RMS gap between two heap profiles `(x, h)` (x ascending), over the reference's largest
/// height: both are interpolated linearly on the union of their abscissae from the first to
/// the last, and a profile is zero beyond its last point (no deposit) and constant before its
/// first (the bins start half a width from the wall).
pub fn profile_distance(reference: &[(f64, f64)], other: &[(f64, f64)]) -> Option<f64> {
    let height = reference.iter().map(|p| p.1).fold(0.0, f64::max);
    if reference.is_empty() || other.is_empty() || height <= 0.0 {
        return None;
    }
    let at = |profile: &[(f64, f64)], x: f64| -> f64 {
        let k = profile.partition_point(|p| p.0 < x);
        if k == 0 {
            profile[0].1
        } else if k == profile.len() {
            0.0
        } else {
            let (a, b) = (profile[k - 1], profile[k]);
            a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
        }
    };
    let mut xs: Vec<f64> = reference.iter().chain(other).map(|p| p.0).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let sum: f64 = xs
        .iter()
        .map(|&x| (at(reference, x) - at(other, x)).powi(2))
        .sum();
    Some((sum / xs.len() as f64).sqrt() / height)
}

/// Heap profiles, averaged over seeds per code, level and rule (`keys`).
/// `case_file` names the case in the error a profile that cannot be read gives.
pub fn profiles_figure(
    scene: &Scene,
    case_file: &Path,
    ok_runs: &[&RunRecord],
    keys: &[Group],
) -> Result<Figure, ValidateError> {
    let mut profiles = Figure::new(
        format!("{}: heap profiles (mean over seeds)", scene.name),
        "distance from the remaining wall x [m]",
        "surface height h(x) [m]",
    );
    for &(rule, lambda, code) in keys {
        let members: Vec<&&RunRecord> = ok_runs
            .iter()
            .filter(|r| (r.cg_rule, r.lambda, r.code) == (rule, lambda, code))
            .collect();
        let mut sum: Vec<(f64, f64)> = Vec::new();
        for r in &members {
            let profile = read_profile(&r.dir).map_err(|e| ValidateError::Case {
                file: case_file.to_path_buf(),
                message: e.to_string(),
            })?;
            for (k, &(x, h)) in profile.iter().enumerate() {
                if k < sum.len() {
                    sum[k].1 += h;
                } else {
                    sum.push((x, h));
                }
            }
        }
        let n = members.len().max(1) as f64;
        profiles.series.push(
            Series::new(
                group_label(code, lambda, rule),
                sum.into_iter().map(|(x, h)| (x, h / n)).collect(),
            )
            .style(SeriesStyle::Line),
        );
    }
    Ok(profiles)
}

/// Repose angle per level with its seed spread, one line per rule and code.
pub fn angles_figure(scene: &Scene, runs: &[RunRecord]) -> Figure {
    let mut angles = Figure::new(
        format!("{}: repose angle per level", scene.name),
        "coarse-graining level lambda",
        "repose angle [deg]",
    )
    .log_x();
    let groups = angles_by_group(runs);
    // (rule, code) -> (lambda, mean angle) points and their seed spreads.
    type AngleSeries = (Vec<(f64, f64)>, Vec<f64>);
    let mut series: BTreeMap<(u8, Code), AngleSeries> = BTreeMap::new();
    for (&(rule, lambda, code), values) in &groups {
        if let Some((mean, spread)) = mean_spread(values) {
            let entry = series.entry((rule, code)).or_default();
            entry.0.push((lambda as f64, mean));
            entry.1.push(spread);
        }
    }
    for ((rule, code), (points, errors)) in series {
        let name = match rule_of(rule) {
            CoarseGrainRule::RelativeOverlap => code.name().to_string(),
            other => format!("{} {}", code.name(), other.name()),
        };
        angles.series.push(
            Series::new(name, points)
                .y_err(errors)
                .style(SeriesStyle::LineMarkers),
        );
    }
    angles
}

/// The repose angle at the fixed times after the gate opens, mean and spread over seeds.
pub fn angle_at_times_figure(scene: &Scene, runs: &[RunRecord]) -> Figure {
    let time_axis = "time after the gate opens t [s]";
    let mut angle = Figure::new(
        format!(
            "{}: repose angle at fixed times (mean over seeds)",
            scene.name
        ),
        time_axis,
        "repose angle [deg]",
    );
    let mut keys: Vec<GroupKey> = runs
        .iter()
        .filter(|r| r.status == Outcome::Ok)
        .map(group_key)
        .collect();
    keys.sort();
    keys.dedup();
    for key in keys {
        let mut by_time: BTreeMap<u64, Vec<f64>> = BTreeMap::new();
        for r in runs
            .iter()
            .filter(|r| r.status == Outcome::Ok && group_key(r) == key)
        {
            for (t, a) in fixed_time_angles(&r.dir) {
                by_time.entry(t.to_bits()).or_default().push(a);
            }
        }
        let (points, errors): (Vec<(f64, f64)>, Vec<f64>) = by_time
            .iter()
            .filter_map(|(t, v)| mean_spread(v).map(|(m, s)| ((f64::from_bits(*t), m), s)))
            .unzip();
        if !points.is_empty() {
            angle.series.push(
                Series::new(group_label(key.2, key.1, rule_of(key.0)), points)
                    .y_err(errors)
                    .style(SeriesStyle::LineMarkers),
            );
        }
    }
    angle
}

/// (time after the stage start, angle) of a run's fixed-time repose samples.
fn fixed_time_angles(dir: &Path) -> Vec<(f64, f64)> {
    let Ok(text) = std::fs::read_to_string(dir.join("summary.json")) else {
        return Vec::new();
    };
    let Ok(value) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Vec::new();
    };
    value
        .get("repose_samples")
        .and_then(|v| v.as_array())
        .map(|samples| {
            samples
                .iter()
                .filter(|s| s.get("trigger").and_then(|v| v.as_str()) == Some("fixed time"))
                .filter_map(|s| {
                    Some((
                        s.get("time_after_start_s")?.as_f64()?,
                        s.get("repose_angle_deg")?.as_f64()?,
                    ))
                })
                .collect()
        })
        .unwrap_or_default()
}
