//! cgdem's mass flow against each reference code's that ran the same screw, speed by speed:
//! one of the suite's comparisons each (so it reaches the report's first screen and the
//! night's status, and a declared known difference can turn it amber). Judged as the silo's
//! discharge rate is: each side's flow, widened by two of its standard errors, must meet
//! the other's, i.e. `|cgdem - reference| <= 2 (SE_cgdem + SE_reference)`, taken over the
//! reference code's flow. No physical tolerance: the codes run the same grains, screw and
//! window, so a difference beyond the noise is a finding, or a declared known difference.

use crate::code::Code;
use crate::quantity::seeds::mean_with_noise;
use crate::runs::{Outcome, RunRecord};
use crate::verdict::{Criterion, KnownDifference, K_NOISE};
use cgdem_core::coarse_graining::CoarseGrainRule;

/// The criterion's name, as a `[[case.known_difference]]` gives it.
pub const CRITERION: &str = "mass flow";
/// The part of the comparison it judges, as the report's tables name it.
pub const PART: &str = "steady flow";
/// What the criterion's value is.
const UNIT: &str = "of the reference code's flow";

/// One code's mass flow at one speed, level and rule: the mean over its seeds and its noise.
#[derive(Clone, Debug, PartialEq)]
pub struct FlowSide {
    pub code: Code,
    /// Mean over seeds, kg/s.
    pub mass_flow_kg_s: f64,
    /// The noise of that mean ([`mean_with_noise`]): the runs' block errors combined, or
    /// with several seeds the standard error of their spread if larger, kg/s.
    pub std_error_kg_s: f64,
    pub seeds: usize,
}

/// cgdem against one reference code at one speed: the judged criterion and its numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct FlowVerdict {
    /// "cgdem vs liggghts, lambda = 1, 100 rpm": a known difference names its start.
    pub what: String,
    pub rpm: f64,
    pub cgdem: FlowSide,
    pub reference: FlowSide,
    pub criterion: Criterion,
    /// The flows and the band in words.
    pub detail: String,
}

/// Every comparison of a screw case, and the speeds at which one side had no measured flow.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlowVerdicts {
    pub judged: Vec<FlowVerdict>,
    /// (comparison, why it was not made).
    pub not_compared: Vec<(String, String)>,
    /// The blocks of each run's window, which a one-seed band rests on.
    pub blocks: u32,
}

/// cgdem's flow against each reference code's at every speed, level and rule both ran.
/// `default_rpm`: the scene's own speed, for runs made without a suite's `rpms`; `blocks`:
/// the blocks of the conveying window (the report says what a one-seed band rests on).
pub fn flow_verdicts(
    runs: &[RunRecord],
    default_rpm: Option<f64>,
    blocks: u32,
    known: &[KnownDifference],
) -> FlowVerdicts {
    let speed = |r: &RunRecord| r.rpm.or(default_rpm);
    let mut out = FlowVerdicts {
        blocks,
        ..FlowVerdicts::default()
    };
    let mut groups: Vec<(CoarseGrainRule, u32)> = runs
        .iter()
        .filter(|r| r.code == Code::Cgdem)
        .map(|r| (r.cg_rule, r.lambda))
        .collect();
    groups.sort_by_key(|g| (g.0 as u8, g.1));
    groups.dedup();
    for (rule, lambda) in groups {
        let in_group = |r: &&RunRecord| (r.cg_rule, r.lambda) == (rule, lambda);
        for reference in [Code::Liggghts, Code::Lammps] {
            if !runs.iter().filter(in_group).any(|r| r.code == reference) {
                continue;
            }
            let mut speeds: Vec<f64> = runs
                .iter()
                .filter(in_group)
                .filter(|r| r.code == Code::Cgdem || r.code == reference)
                .filter_map(speed)
                .collect();
            speeds.sort_by(f64::total_cmp);
            speeds.dedup();
            for rpm in speeds {
                let what = comparison_name(reference, lambda, rule, rpm);
                let at = |code: Code| -> Vec<&RunRecord> {
                    runs.iter()
                        .filter(in_group)
                        .filter(|r| r.code == code && speed(r) == Some(rpm))
                        .collect()
                };
                let (cgdem_runs, reference_runs) = (at(Code::Cgdem), at(reference));
                match (
                    side(Code::Cgdem, &cgdem_runs),
                    side(reference, &reference_runs),
                ) {
                    (Some(cgdem), Some(reference)) => {
                        out.judged
                            .push(judge(what, rpm, cgdem, reference, blocks, known));
                    }
                    (cgdem, _) => {
                        let (code, missing) = match cgdem {
                            None => (Code::Cgdem, &cgdem_runs),
                            Some(_) => (reference, &reference_runs),
                        };
                        out.not_compared.push((what, why_not(code, missing, rpm)));
                    }
                }
            }
        }
    }
    out
}

fn comparison_name(reference: Code, lambda: u32, rule: CoarseGrainRule, rpm: f64) -> String {
    let rule = match rule {
        CoarseGrainRule::RelativeOverlap => String::new(),
        other => format!(" ({})", other.name()),
    };
    format!(
        "cgdem vs {}, lambda = {lambda}{rule}, {rpm} rpm",
        reference.name()
    )
}

/// A code's measured flow over the seeds of `runs` (finished, not stopped early, with a
/// block error); None without one.
fn side(code: Code, runs: &[&RunRecord]) -> Option<FlowSide> {
    let flows: Vec<(f64, f64)> = runs
        .iter()
        .filter(|r| r.status == Outcome::Ok && !r.partial)
        .filter_map(|r| Some((r.mass_flow_kg_s?, r.mass_flow_std_error_kg_s?)))
        .filter(|(m, se)| m.is_finite() && se.is_finite())
        .collect();
    let (mass_flow_kg_s, std_error_kg_s) = mean_with_noise(&flows)?;
    Some(FlowSide {
        code,
        mass_flow_kg_s,
        std_error_kg_s,
        seeds: flows.len(),
    })
}

/// Why `code` has no flow at `rpm`: its runs' reasons, or that it ran none there.
fn why_not(code: Code, runs: &[&RunRecord], rpm: f64) -> String {
    if runs.is_empty() {
        return format!("{} has no run at {rpm} rpm", code.label());
    }
    let reasons: Vec<String> = runs
        .iter()
        .map(|r| match (r.status, r.partial) {
            (Outcome::Ok, true) => format!("seed {} stopped early", r.seed),
            (Outcome::Ok, false) => format!("seed {} measured no mass flow", r.seed),
            (status, _) => format!(
                "seed {} {status}: {}",
                r.seed,
                r.reason.as_deref().unwrap_or("no reason given")
            ),
        })
        .collect();
    format!("{}: {}", code.label(), reasons.join("; "))
}

/// The criterion: `|cgdem - reference|` over the reference's flow, against a threshold of
/// `K_NOISE` times the two standard errors added (over the same flow), or a known
/// difference's band. A reference code that conveyed nothing gives no ratio: red.
fn judge(
    what: String,
    rpm: f64,
    cgdem: FlowSide,
    reference: FlowSide,
    blocks: u32,
    known: &[KnownDifference],
) -> FlowVerdict {
    let scale = if reference.mass_flow_kg_s > 0.0 {
        reference.mass_flow_kg_s
    } else {
        f64::NAN
    };
    let difference = cgdem.mass_flow_kg_s - reference.mass_flow_kg_s;
    let added = cgdem.std_error_kg_s + reference.std_error_kg_s;
    let basis = if cgdem.seeds == 1 && reference.seeds == 1 {
        format!(
            "the band rests on one seed per code: each side's standard error is its run's \
             block-average standard error over {blocks} blocks"
        )
    } else {
        "each side's standard error is its runs' block errors combined, or the standard \
         error of its seeds' spread when larger"
            .to_string()
    };
    let rule = format!(
        "{basis}; the two added and taken over the reference code's flow, so that the \
         threshold is where the two flows, each widened by {K_NOISE} of its standard \
         errors, stop meeting"
    );
    let criterion = Criterion::judge(
        CRITERION,
        UNIT,
        difference.abs() / scale,
        added / scale,
        [cgdem.seeds, reference.seeds],
        0.0,
        known.iter().find(|k| k.applies_to(&what, CRITERION)),
    )
    .with_noise_rule(rule);
    let side = |s: &FlowSide| {
        format!(
            "{} {:.3} +- {:.3} kg/s ({} seed{})",
            s.code.name(),
            s.mass_flow_kg_s,
            s.std_error_kg_s,
            s.seeds,
            if s.seeds == 1 { "" } else { "s" }
        )
    };
    let detail = format!(
        "{rpm} rpm: {}, {}: cgdem {:+.1}% ({:+.3} kg/s, {:.1} standard errors added; the \
         flows widened by {K_NOISE} standard errors each {})",
        side(&cgdem),
        side(&reference),
        100.0 * difference / scale,
        difference,
        difference.abs() / added,
        if difference.abs() <= K_NOISE * added {
            "meet"
        } else {
            "do not meet"
        }
    );
    FlowVerdict {
        what,
        rpm,
        cgdem,
        reference,
        criterion,
        detail,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verdict::Verdict;
    use std::path::PathBuf;

    /// A finished screw run of `code` at `rpm` that measured `flow` with block error `se`.
    fn run(code: Code, seed: u64, rpm: f64, flow: f64, se: f64) -> RunRecord {
        let mut r = RunRecord::ok(
            "screw_feeder_hertz".into(),
            code,
            1,
            CoarseGrainRule::RelativeOverlap,
            seed,
            PathBuf::from("unused"),
        );
        r.rpm = Some(rpm);
        r.mass_flow_kg_s = Some(flow);
        r.mass_flow_std_error_kg_s = Some(se);
        r
    }

    #[test]
    fn a_flow_inside_the_band_is_green_and_one_outside_is_red() {
        // The nightly's mesh screw (reports/screw_three_codes/NOTE.md, one seed each): at
        // 110 rpm cgdem 4.706 +- 0.034, LIGGGHTS 4.788 +- 0.019 kg/s; 0.082 apart, within
        // 2 x (0.034 + 0.019) = 0.106.
        let runs = [
            run(Code::Cgdem, 1, 110.0, 4.706, 0.034),
            run(Code::Liggghts, 1, 110.0, 4.788, 0.019),
            // cgdem's screw turning 0.8 times as fast: 20% less flow, far outside.
            run(Code::Cgdem, 1, 140.0, 0.8 * 5.938, 0.086),
            run(Code::Liggghts, 1, 140.0, 5.896, 0.146),
        ];
        let v = flow_verdicts(&runs, None, 2, &[]);
        assert!(v.not_compared.is_empty(), "{:?}", v.not_compared);
        let [inside, outside] = &v.judged[..] else {
            panic!("{:?}", v.judged)
        };
        assert_eq!(inside.what, "cgdem vs liggghts, lambda = 1, 110 rpm");
        assert_eq!(inside.criterion.verdict, Verdict::Pass, "{inside:?}");
        assert!((inside.criterion.value - 0.082 / 4.788).abs() < 1e-12);
        assert!((inside.criterion.threshold - 2.0 * 0.053 / 4.788).abs() < 1e-12);
        assert_eq!(inside.criterion.seeds, [1, 1]);
        assert!(
            inside
                .criterion
                .describe()
                .contains("rests on one seed per code"),
            "{}",
            inside.criterion.describe()
        );
        assert_eq!(outside.criterion.verdict, Verdict::Fail, "{outside:?}");
        assert!(outside.detail.contains("do not meet"), "{}", outside.detail);
        // Just beyond the band at 110 rpm is red too: the threshold is sharp.
        let beyond = [
            run(Code::Cgdem, 1, 110.0, 4.788 - 0.107, 0.034),
            run(Code::Liggghts, 1, 110.0, 4.788, 0.019),
        ];
        let v = flow_verdicts(&beyond, None, 2, &[]);
        assert_eq!(v.judged[0].criterion.verdict, Verdict::Fail);
    }

    #[test]
    fn a_declared_difference_is_amber_in_its_band_and_a_missing_side_is_not_compared() {
        let runs = [
            run(Code::Cgdem, 1, 140.0, 3.0, 0.02),
            run(Code::Lammps, 1, 140.0, 3.426, 0.02),
            // cgdem alone at 40 rpm; LAMMPS failed at 100 rpm.
            run(Code::Cgdem, 1, 40.0, 1.2, 0.02),
            run(Code::Cgdem, 1, 100.0, 2.5, 0.02),
            {
                let mut r = run(Code::Lammps, 1, 100.0, f64::NAN, 0.0);
                r.status = Outcome::Failed;
                r.reason = Some("timed out".into());
                r.mass_flow_kg_s = None;
                r
            },
        ];
        let declared = KnownDifference {
            comparison: "cgdem vs lammps".into(),
            criterion: CRITERION.into(),
            reason: "test".into(),
            evidence: "reports/screw_three_codes/NOTE.md".into(),
            band: [0.10, 0.15],
        };
        let v = flow_verdicts(&runs, None, 2, std::slice::from_ref(&declared));
        assert_eq!(v.judged.len(), 1);
        // 0.426 / 3.426 = 0.124: inside [0.10, 0.15].
        assert_eq!(v.judged[0].criterion.verdict, Verdict::KnownDifference);
        let plain = flow_verdicts(&runs, None, 2, &[]);
        assert_eq!(plain.judged[0].criterion.verdict, Verdict::Fail);
        let why: Vec<&str> = v.not_compared.iter().map(|(_, w)| w.as_str()).collect();
        assert_eq!(v.not_compared.len(), 2, "{why:?}");
        assert!(why[0].contains("LAMMPS has no run at 40 rpm"), "{why:?}");
        assert!(why[1].contains("timed out"), "{why:?}");
    }

    #[test]
    fn several_seeds_give_the_noise_of_their_spread_when_it_is_larger() {
        // Seeds 4.0 and 4.4 agree within their block errors 0.01 but not with each other:
        // the spread's standard error 0.2 sets cgdem's side, and 0.2 apart is inside.
        let runs = [
            run(Code::Cgdem, 1, 100.0, 4.0, 0.01),
            run(Code::Cgdem, 2, 100.0, 4.4, 0.01),
            run(Code::Liggghts, 1, 100.0, 4.0, 0.01),
            run(Code::Liggghts, 2, 100.0, 4.0, 0.01),
        ];
        let v = flow_verdicts(&runs, None, 2, &[]);
        let c = &v.judged[0];
        assert!((c.cgdem.std_error_kg_s - 0.2).abs() < 1e-12, "{c:?}");
        assert_eq!(c.criterion.verdict, Verdict::Pass);
        assert!(!c.criterion.describe().contains("one seed"));
        // A run without a speed of its own takes the scene's.
        let mut alone = runs.clone();
        for r in &mut alone {
            r.rpm = None;
        }
        let v = flow_verdicts(&alone, Some(100.0), 2, &[]);
        assert_eq!(v.judged[0].rpm, 100.0);
    }
}
