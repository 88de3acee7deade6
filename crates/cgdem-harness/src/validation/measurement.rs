//! What a suite's cases are judged by: the comparisons of codes and levels (final state and
//! dynamics), each a set of criteria with their noise, tolerance and verdict.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::dynamics::{flow_difference, flow_noise, FlowSeries, FLOW_GRID_S};
use crate::runs::{Outcome, RunRecord};
use crate::suite::{Code, SuiteCase};
use crate::verdict::{combined_standard_error, mean_sd, Criterion};
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::Scene;

/// One judged comparison: a pair of codes or levels, one part (final state or dynamics),
/// judged by its criteria (`verdict::Criterion`), each with its value, noise, threshold
/// and verdict; the comparison's verdict is its worst criterion's, named in `decided_by`.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub case: String,
    /// "codes" (two codes at one level) or "levels" (one code at two levels).
    pub kind: String,
    /// "final state" (repose angle) or "dynamics" (t_half ratio, front, wall-height and
    /// kinetic-energy gaps): a pair is similar only if both pass.
    pub part: String,
    pub what: String,
    /// The numbers behind the verdict, in words.
    pub detail: String,
    /// The deciding criterion's value, physical tolerance and threshold (tolerance + k noise).
    pub difference: f64,
    pub tolerance: f64,
    pub threshold: f64,
    /// "pass", "known difference" or "fail".
    pub verdict: crate::verdict::Verdict,
    /// The criterion that decided the verdict.
    pub decided_by: String,
    pub criteria: Vec<crate::verdict::Criterion>,
    /// Not a fail (a known difference inside its band passes).
    pub pass: bool,
}

impl Comparison {
    /// A comparison judged by `criteria`.
    pub(crate) fn judged(
        case: &str,
        kind: &str,
        part: &str,
        what: &str,
        detail: String,
        criteria: Vec<crate::verdict::Criterion>,
    ) -> Comparison {
        let (verdict, decided_by) = crate::verdict::decide(&criteria);
        let deciding = criteria.iter().find(|c| c.name == decided_by);
        Comparison {
            case: case.into(),
            kind: kind.into(),
            part: part.into(),
            what: what.into(),
            detail,
            difference: deciding.map_or(0.0, |c| c.value),
            tolerance: deciding.map_or(0.0, |c| c.tolerance),
            threshold: deciding.map_or(0.0, |c| c.threshold),
            verdict,
            decided_by,
            criteria,
            pass: verdict != crate::verdict::Verdict::Fail,
        }
    }
}

/// Mean and sample standard deviation.
pub(super) fn mean_spread(values: &[f64]) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let spread = if values.len() > 1 {
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    Some((mean, spread))
}

pub(super) type Group = (CoarseGrainRule, u32, Code);
/// A group of runs: (coarse-graining rule as u8, lambda, code).
pub(super) type GroupKey = (u8, u32, Code);

pub(super) fn angles_by_group(runs: &[RunRecord]) -> BTreeMap<GroupKey, Vec<f64>> {
    let mut groups: BTreeMap<GroupKey, Vec<f64>> = BTreeMap::new();
    for r in runs.iter().filter(|r| !r.partial) {
        if let Some(a) = r.repose_angle_deg {
            groups
                .entry((r.cg_rule as u8, r.lambda, r.code))
                .or_default()
                .push(a);
        }
    }
    groups
}

pub(super) fn rule_of(index: u8) -> CoarseGrainRule {
    CoarseGrainRule::ALL
        .into_iter()
        .find(|r| *r as u8 == index)
        .unwrap_or_default()
}

/// The pairs a case compares: codes against each other at each level and rule ("codes"),
/// and each code's neighbouring levels under each rule ("levels"), finer first.
fn comparison_pairs(keys: &[GroupKey]) -> Vec<(&'static str, GroupKey, GroupKey)> {
    let mut out = Vec::new();
    for &(rule, lambda, code_a) in keys {
        for &(rule_b, lambda_b, code_b) in keys {
            if rule == rule_b && lambda == lambda_b && code_a < code_b {
                out.push(("codes", (rule, lambda, code_a), (rule, lambda, code_b)));
            }
        }
    }
    for &(rule, lambda, code) in keys {
        let finer = keys
            .iter()
            .filter(|&&(r, l, c)| r == rule && c == code && l < lambda)
            .max_by_key(|&&(_, l, _)| l);
        if let Some(&f) = finer {
            out.push(("levels", f, (rule, lambda, code)));
        }
    }
    out
}

fn pair_name(kind: &str, a: GroupKey, b: GroupKey) -> String {
    let rule = rule_of(a.0).name();
    if kind == "codes" {
        format!(
            "{} vs {}, lambda = {} ({rule})",
            a.2.name(),
            b.2.name(),
            a.1
        )
    } else {
        format!("{} lambda = {} vs {} ({rule})", a.2.name(), a.1, b.1)
    }
}

/// The ratio of characteristic times the derivation in reference/COARSE_GRAINING.md
/// predicts between two groups: 1 between codes and under the bulk-viscosity rule; under the
/// seed rule between 1 (inertial collapse) and the lambda ratio (viscous collapse).
fn predicted_time_ratio(kind: &str, a: GroupKey, b: GroupKey) -> String {
    match (kind, rule_of(a.0)) {
        ("levels", CoarseGrainRule::RelativeOverlap) => format!(
            "1 (inertial) to {} (viscous): bulk viscosity ~ lambda gamma/d",
            b.1 as f64 / a.1 as f64
        ),
        _ => "1".into(),
    }
}

pub(super) fn compare(scene: &Scene, case: &SuiteCase, runs: &[RunRecord]) -> Vec<Comparison> {
    let groups = angles_by_group(runs);
    let flows = flows_by_group(scene, runs);
    let mut keys: Vec<GroupKey> = groups.keys().chain(flows.keys()).copied().collect();
    keys.sort();
    keys.dedup();
    let box_length = scene.domain.hi.x - scene.domain.lo.x;
    let known = |what: &str, criterion: &str| {
        case.known_differences
            .iter()
            .find(|k| k.applies_to(what, criterion))
    };
    let mut out = Vec::new();
    for (kind, a, b) in comparison_pairs(&keys) {
        let what = pair_name(kind, a, b);
        let stats = |k| groups.get(&k).and_then(|v| mean_sd(v));
        if let (Some((ma, sa, na)), Some((mb, sb, nb))) = (stats(a), stats(b)) {
            let angle = Criterion::judge(
                "repose angle",
                "deg",
                (ma - mb).abs(),
                combined_standard_error((sa, na), (sb, nb)),
                [na, nb],
                case.angle_tolerance_deg,
                known(&what, "repose angle"),
            );
            out.push(Comparison::judged(
                &scene.name,
                kind,
                "final state",
                &what,
                format!(
                    "repose angle {ma:.1} +- {sa:.1} ({na} seeds) vs {mb:.1} +- {sb:.1} ({nb} seeds) deg"
                ),
                vec![angle],
            ));
        }
        if let (Some(fa), Some(fb)) = (flows.get(&a), flows.get(&b)) {
            if let Some(c) = compare_flows(scene, case, kind, &what, (a, fa), (b, fb), box_length) {
                out.push(c);
            }
        }
    }
    out
}

/// The dynamics part of a comparison, four criteria: the ratio of the seeds' mean `t_half`
/// (judged as |ratio - 1|), and the largest gaps between the seed-mean histories of the
/// front (of the box length), the height at the remaining wall (of its initial height) and
/// the kinetic energy (of its peak); each against its tolerance plus `K_NOISE` times the
/// noise the seeds show.
fn compare_flows(
    scene: &Scene,
    case: &SuiteCase,
    kind: &str,
    what: &str,
    (a, fa): (GroupKey, &Vec<FlowSeries>),
    (b, fb): (GroupKey, &Vec<FlowSeries>),
    box_length: f64,
) -> Option<Comparison> {
    let ta: Vec<f64> = fa.iter().filter_map(FlowSeries::t_half).collect();
    let tb: Vec<f64> = fb.iter().filter_map(FlowSeries::t_half).collect();
    let step = FLOW_GRID_S;
    let mean_a = FlowSeries::mean(fa, step)?;
    let mean_b = FlowSeries::mean(fb, step)?;
    let gap = flow_difference(&mean_a, &mean_b, box_length, step)?;
    let noise = flow_noise(fa, fb, box_length, step)?;
    let seeds = [fa.len(), fb.len()];
    let known = |criterion: &str| {
        case.known_differences
            .iter()
            .find(|k| k.applies_to(what, criterion))
    };
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
                case.time_ratio_tolerance,
                known("t_half ratio"),
            ));
            format!(
                "t_half {ma:.3} +- {sa:.3} s vs {mb:.3} +- {sb:.3} s: ratio {ratio:.2} (predicted {})",
                predicted_time_ratio(kind, a, b)
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
            case.front_tolerance,
            known("front gap"),
        ),
        Criterion::judge(
            "wall height gap",
            "of the initial height",
            gap.wall_height_max,
            noise.wall_height,
            seeds,
            case.wall_height_tolerance,
            known("wall height gap"),
        ),
        Criterion::judge(
            "kinetic energy gap",
            "of the peak",
            gap.kinetic_energy_max,
            noise.kinetic_energy,
            seeds,
            case.kinetic_energy_tolerance,
            known("kinetic energy gap"),
        ),
    ]);
    Some(Comparison::judged(
        &scene.name,
        kind,
        "dynamics",
        what,
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
        criteria,
    ))
}

/// Every successful run's flow during the measured stage, per group.
pub(super) fn flows_by_group(
    scene: &Scene,
    runs: &[RunRecord],
) -> BTreeMap<GroupKey, Vec<FlowSeries>> {
    let mut groups: BTreeMap<GroupKey, Vec<FlowSeries>> = BTreeMap::new();
    let Some(stage) = scene.repose.as_ref().map(|r| r.stage.as_str()) else {
        return groups;
    };
    for r in runs.iter().filter(|r| r.status == Outcome::Ok) {
        if let Some(flow) = FlowSeries::read(&r.dir, stage) {
            groups
                .entry((r.cg_rule as u8, r.lambda, r.code))
                .or_default()
                .push(flow);
        }
    }
    groups
}
