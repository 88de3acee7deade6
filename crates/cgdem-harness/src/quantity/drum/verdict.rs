//! cgdem's verdict on a drum case, one of the suite's comparisons: each zone count and the
//! dynamic angle, cgdem's steady mean over its seeds within the reference codes' spread,
//! each code's mean widened by two standard errors of the mean over its seeds (the silo's
//! rule, `quantity::discharge::verdict`), give or take a stated tolerance. A count's gap is
//! a share of the reference codes' mean count; the angle's is in degrees.

use std::fmt::Write as _;

use super::{DrumRun, DrumSettings, SteadyMeans};
use crate::code::Code;
use crate::quantity::seeds::mean_se;
use crate::verdict::{Criterion, KnownDifference};

/// The comparison's name, as a `[[case.known_difference]]` gives it.
pub const COMPARISON: &str = "cgdem vs reference codes";
/// The criteria's names, as a `[[case.known_difference]]` gives them: the four zone counts
/// (zone 1 M1, zone 1 M2, zone 2 M1, zone 2 M2), then the dynamic angle.
pub const CRITERIA: [&str; 5] = [
    "zone 1 M1 count",
    "zone 1 M2 count",
    "zone 2 M1 count",
    "zone 2 M2 count",
    "dynamic angle",
];

/// One code's steady means over its seeds: per criterion (mean, standard error of the mean,
/// 0 with one seed), and its seeds.
struct CodeMeans {
    code: Code,
    values: [Option<(f64, f64)>; 5],
    seeds: usize,
}

fn code_means(code: Code, runs: &[DrumRun], steady_from_s: f64) -> Option<CodeMeans> {
    let means: Vec<SteadyMeans> = runs
        .iter()
        .filter(|r| r.code == code && r.lambda == 1 && r.problem.is_none())
        .filter_map(|r| r.steady_means(steady_from_s))
        .collect();
    if means.is_empty() {
        return None;
    }
    let of = |values: Vec<f64>| {
        (!values.is_empty()).then(|| {
            let (mean, se) = mean_se(&values);
            (mean, se.unwrap_or(0.0))
        })
    };
    let mut values = [None; 5];
    for (k, v) in values.iter_mut().enumerate().take(4) {
        *v = of(means.iter().map(|m| m.counts[k]).collect());
    }
    values[4] = of(means.iter().filter_map(|m| m.angle_deg).collect());
    Some(CodeMeans {
        code,
        values,
        seeds: means.len(),
    })
}

/// The case's criteria and the means in words; None without cgdem's runs or a reference
/// code's (at lambda = 1). Each criterion passes within the spread, is amber where a known
/// difference of [`COMPARISON`] and its name holds its gap in the band, red otherwise.
pub fn drum_criteria(
    runs: &[DrumRun],
    settings: &DrumSettings,
    known: &[KnownDifference],
) -> Option<(Vec<Criterion>, String)> {
    let steady_from_s = settings.steady_from_s;
    let cgdem = code_means(Code::Cgdem, runs, steady_from_s)?;
    let refs: Vec<CodeMeans> = [Code::Liggghts, Code::Lammps]
        .iter()
        .filter_map(|&c| code_means(c, runs, steady_from_s))
        .collect();
    if refs.is_empty() {
        return None;
    }
    let mut criteria = Vec::new();
    let mut text = String::new();
    for (k, name) in CRITERIA.iter().enumerate() {
        let Some((cg, cg_se)) = cgdem.values[k] else {
            continue;
        };
        let sides: Vec<(Code, f64, f64)> = (refs.iter())
            .filter_map(|r| r.values[k].map(|(m, se)| (r.code, m, se)))
            .collect();
        if sides.is_empty() {
            continue;
        }
        let lo = (sides.iter().map(|s| s.1 - 2.0 * s.2)).fold(f64::INFINITY, f64::min);
        let hi = (sides.iter().map(|s| s.1 + 2.0 * s.2)).fold(f64::NEG_INFINITY, f64::max);
        let outside = (lo - (cg + 2.0 * cg_se))
            .max((cg - 2.0 * cg_se) - hi)
            .max(0.0);
        let angle = k == 4;
        let reference_mean = sides.iter().map(|s| s.1).sum::<f64>() / sides.len() as f64;
        let (gap, unit, tolerance) = if angle {
            (
                outside,
                "deg outside the reference codes' spread",
                settings.angle_tolerance_deg,
            )
        } else {
            (
                outside / reference_mean.max(1.0),
                "of the reference count, outside their spread",
                settings.count_tolerance,
            )
        };
        let digits = if angle { 2 } else { 0 };
        let _ = write!(
            text,
            "{}{name}: cgdem {cg:.digits$} +- {cg_se:.digits$}",
            if text.is_empty() { "" } else { "; " }
        );
        for (c, m, se) in &sides {
            let _ = write!(text, ", {} {m:.digits$} +- {se:.digits$}", c.name());
        }
        let _ = write!(
            text,
            " ({})",
            if outside > 0.0 { "outside" } else { "within" }
        );
        let seeds = [
            cgdem.seeds,
            refs.iter()
                .filter(|r| r.values[k].is_some())
                .map(|r| r.seeds)
                .sum(),
        ];
        let known = known.iter().find(|d| d.applies_to(COMPARISON, name));
        // The noise is already in the gap (each mean widened by two standard errors); a side
        // with one seed has none, which the criterion's description says.
        let criterion = Criterion::judge(name, unit, gap, 0.0, seeds, tolerance, known);
        criteria.push(if seeds.iter().all(|&n| n > 1) {
            criterion.with_noise_rule(
                "in the gap, each code's mean over its seeds widened by 2 standard errors",
            )
        } else {
            criterion
        });
    }
    (!criteria.is_empty()).then_some((criteria, text))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quantity::drum::{FrameMeasure, SurfaceLine, ZoneCounts};
    use crate::verdict::Verdict;

    /// A run whose two steady frames have the counts `c` and the angle `angle`.
    fn run(code: Code, seed: u64, c: [usize; 4], angle: f64) -> DrumRun {
        let frame = |t: f64| FrameMeasure {
            time_s: t,
            counts: ZoneCounts {
                zone1_m1: c[0],
                zone1_m2: c[1],
                zone2_m1: c[2],
                zone2_m2: c[3],
            },
            surface: Some(SurfaceLine {
                angle_deg: angle,
                r2: 0.99,
                bins: 30,
            }),
            lacey: None,
        };
        DrumRun {
            code,
            lambda: 1,
            seed,
            dir: "run".into(),
            frames: vec![frame(-0.1), frame(1.0), frame(1.1)],
            problem: None,
        }
    }

    fn settings(count_tolerance: f64) -> DrumSettings {
        DrumSettings {
            stage: "rotate".into(),
            steady_from_s: 1.0,
            count_tolerance,
            angle_tolerance_deg: 0.5,
        }
    }

    /// Three seeds per code, the counts and angles a few percent apart between seeds.
    fn runs(cgdem_zone2_m1: usize, cgdem_angle: f64) -> Vec<DrumRun> {
        let mut out = Vec::new();
        for (seed, wiggle) in [(1, 0usize), (2, 40), (3, 80)] {
            out.push(run(
                Code::Cgdem,
                seed,
                [
                    1100 + wiggle,
                    200 + wiggle / 4,
                    cgdem_zone2_m1 + wiggle,
                    380 + wiggle / 4,
                ],
                cgdem_angle + wiggle as f64 / 100.0,
            ));
            out.push(run(
                Code::Liggghts,
                seed,
                [
                    1140 + wiggle,
                    205 + wiggle / 4,
                    2800 + wiggle,
                    376 + wiggle / 4,
                ],
                36.5 + wiggle as f64 / 100.0,
            ));
        }
        out
    }

    #[test]
    fn codes_within_each_others_seed_spread_pass() {
        let (criteria, text) = drum_criteria(&runs(2810, 36.4), &settings(0.0), &[]).unwrap();
        assert_eq!(criteria.len(), 5);
        assert!(
            criteria.iter().all(|c| c.verdict == Verdict::Pass),
            "{criteria:?}"
        );
        assert!(text.contains("zone 2 M1 count: cgdem 2850"), "{text}");
        assert!(criteria[0].seeds == [3, 3], "{criteria:?}");
    }

    #[test]
    fn a_count_outside_the_reference_spread_fails_by_its_share_of_the_reference_count() {
        // cgdem's zone 2 M1 at 2540 +- 23.1 over its seeds (2 SE 46.2); LIGGGHTS's 2840
        // +- 23.1: the bands [2493.8, 2586.2] and [2793.8, 2886.2] are 207.6 apart, 7.3% of
        // 2840.
        let (criteria, _) = drum_criteria(&runs(2500, 36.4), &settings(0.0), &[]).unwrap();
        let c = &criteria[2];
        assert_eq!(
            (c.name.as_str(), c.verdict),
            ("zone 2 M1 count", Verdict::Fail)
        );
        let se = 40.0 / 3f64.sqrt();
        assert!(
            (c.value - (300.0 - 4.0 * se) / 2840.0).abs() < 1e-9,
            "{c:?}"
        );
        assert_eq!(crate::verdict::decide(&criteria).1, "zone 2 M1 count");
        // A tolerance of 8% of the count holds it; the angle's 0.5 deg has no gap to hold.
        let (criteria, _) = drum_criteria(&runs(2500, 36.4), &settings(0.08), &[]).unwrap();
        assert_eq!(criteria[2].verdict, Verdict::Pass, "{:?}", criteria[2]);
        assert_eq!(criteria[4].tolerance, 0.5);
    }

    #[test]
    fn an_angle_gap_held_by_a_declared_difference_is_amber() {
        let known = KnownDifference {
            comparison: COMPARISON.into(),
            criterion: "dynamic angle".into(),
            reason: "test".into(),
            evidence: "none".into(),
            band: [1.0, 5.0],
        };
        let (criteria, _) = drum_criteria(&runs(2810, 33.0), &settings(0.0), &[known]).unwrap();
        let angle = &criteria[4];
        assert_eq!(angle.verdict, Verdict::KnownDifference, "{angle:?}");
        assert!(angle.value > 1.0 && angle.value < 5.0, "{angle:?}");
    }

    #[test]
    fn without_a_reference_codes_run_there_is_no_verdict() {
        let only: Vec<DrumRun> = (runs(2810, 36.4).into_iter())
            .filter(|r| r.code == Code::Cgdem)
            .collect();
        assert!(drum_criteria(&only, &settings(0.0), &[]).is_none());
    }
}
