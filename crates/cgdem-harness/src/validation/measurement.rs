//! What a suite's cases are judged by: the comparisons of codes and levels (final state and
//! dynamics), each a set of criteria with their noise, tolerance and verdict. Which pairs
//! are compared is this file's; each criterion is its quantity's (`crate::quantity`).

use serde::Serialize;

use crate::quantity::flow::{flow_criteria, flows_by_group};
use crate::quantity::repose::{angle_criterion, angles_by_group};
use crate::quantity::seeds::{rule_of, GroupKey};
use crate::runs::RunRecord;
use crate::suite::SuiteCase;
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
        let angles = |k| groups.get(&k).map_or(&[][..], Vec::as_slice);
        let tolerance = case.angle_tolerance_deg;
        let known_angle = known(&what, crate::quantity::repose::CRITERION);
        if let Some((angle, detail)) = angle_criterion(angles(a), angles(b), tolerance, known_angle)
        {
            out.push(Comparison::judged(
                &scene.name,
                kind,
                "final state",
                &what,
                detail,
                vec![angle],
            ));
        }
        if let (Some(fa), Some(fb)) = (flows.get(&a), flows.get(&b)) {
            let dynamics = flow_criteria(
                fa,
                fb,
                box_length,
                &case.flow_tolerances(),
                |criterion| known(&what, criterion),
                &predicted_time_ratio(kind, a, b),
            );
            if let Some((criteria, detail)) = dynamics {
                out.push(Comparison::judged(
                    &scene.name,
                    kind,
                    "dynamics",
                    &what,
                    detail,
                    criteria,
                ));
            }
        }
    }
    out
}
