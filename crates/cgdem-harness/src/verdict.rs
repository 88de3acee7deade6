//! Verdicts a reader can trust: each comparison is judged by named criteria (repose angle,
//! t_half ratio, front gap, wall-height gap, kinetic-energy gap), each with its value, the
//! noise the seeds themselves show, the stated physical tolerance and its own verdict.
//!
//! The rule (README, "Verdicts"): a criterion passes when
//! `value <= tolerance + K * noise`, where `noise` is the combined standard error of the
//! two sides estimated from their seeds (`sqrt(s_a^2/n_a + s_b^2/n_b)`; for a curve gap, the
//! largest such error over time of the seed-mean curves). A side with one seed has no
//! noise estimate: its noise counts as 0 and the criterion says so. A criterion declared a
//! known difference (the suite's `known_difference`) is judged by its band instead, widened
//! on each side by the same `K * noise` (a band holds the expected value, and a mean over a
//! few seeds scatters around it as much as around a tolerance): inside, "known difference";
//! outside, "fail". The row's verdict is its worst criterion's, and the
//! row names the criterion that decided it.
//!
//! Rates measured over blocks of a steady window (a silo's discharge rate, a screw's mass
//! flow) carry a standard error even from one seed; their criteria have no physical
//! tolerance and pass when the two sides, each widened by `K_NOISE` of its own standard
//! errors, meet. Such a criterion says how its noise was estimated (`noise_rule`).

use serde::Serialize;

use cgdem_core::coarse_graining::CoarseGrainRule;

/// How many combined standard errors a difference may exceed its physical tolerance by.
/// Two: a side-by-side pair of unchanged codes passes about 95% of single criteria by
/// chance alone when the noise is well estimated.
pub const K_NOISE: f64 = 2.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub enum Verdict {
    #[serde(rename = "pass")]
    Pass,
    /// A declared known difference whose value lies inside its band (amber).
    #[serde(rename = "known difference")]
    KnownDifference,
    #[serde(rename = "fail")]
    Fail,
}

impl Verdict {
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::KnownDifference => "known difference",
            Verdict::Fail => "fail",
        }
    }
}

/// A declared known difference: the comparison, the criterion, why, where the evidence is,
/// and the band its value is expected to lie in.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KnownDifference {
    /// The start of the comparison's name, e.g. "cgdem vs lammps" or "cgdem lambda = 8 vs 16".
    pub comparison: String,
    /// The criterion's name, e.g. "repose angle".
    pub criterion: String,
    pub reason: String,
    /// A file in the repository that documents the difference.
    pub evidence: String,
    /// [low, high] of the criterion's value.
    pub band: [f64; 2],
}

impl KnownDifference {
    pub fn applies_to(&self, comparison: &str, criterion: &str) -> bool {
        comparison.starts_with(&self.comparison) && criterion == self.criterion
    }

    /// Whether `value`, with the seeds' `noise`, lies in the band widened by `K_NOISE`
    /// times the noise on each side.
    pub fn holds(&self, value: f64, noise: f64) -> bool {
        let allowance = K_NOISE * noise;
        value >= self.band[0] - allowance && value <= self.band[1] + allowance
    }
}

/// A comparison or metric name with the first name of the `relative-overlap` rule, `seed`,
/// replaced by the current one (`"cgdem lambda = 8 vs 16 (seed)"`, `"... lambda=8 seed:
/// repose angle"`), so that suite files, summaries and nightly histories written before the
/// rename keep matching the comparisons and trends of later runs.
pub(crate) fn renamed_rule(name: &str) -> String {
    let (old, new) = (
        CoarseGrainRule::OLD_RELATIVE_OVERLAP,
        CoarseGrainRule::RelativeOverlap.name(),
    );
    name.replace(&format!("({old})"), &format!("({new})"))
        .replace(&format!(" {old}: "), &format!(" {new}: "))
}

/// One sub-criterion of a comparison with its own verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Criterion {
    /// "repose angle", "t_half ratio", "front gap", "wall height gap", "kinetic energy gap".
    pub name: String,
    /// What the value is, e.g. "deg" or "of the box length, largest over time".
    pub unit: String,
    pub value: f64,
    /// Combined standard error of the two sides, from their seeds (0 when a side has one).
    pub noise: f64,
    /// Seeds behind each side.
    pub seeds: [usize; 2],
    /// The stated physical tolerance.
    pub tolerance: f64,
    /// `tolerance + K_NOISE * noise`.
    pub threshold: f64,
    pub verdict: Verdict,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub known_difference: Option<KnownDifference>,
    /// How the noise was estimated, when not from the seeds' spread alone (e.g. from the
    /// runs' block-average standard errors): said instead of the seeds' note.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_rule: Option<String>,
}

impl Criterion {
    /// Judges `value` against `tolerance + K_NOISE * noise`, or against the band of a
    /// known difference that applies to it.
    pub fn judge(
        name: &str,
        unit: &str,
        value: f64,
        noise: f64,
        seeds: [usize; 2],
        tolerance: f64,
        known: Option<&KnownDifference>,
    ) -> Criterion {
        let threshold = tolerance + K_NOISE * noise;
        let verdict = match known {
            Some(k) if k.holds(value, noise) => Verdict::KnownDifference,
            Some(_) => Verdict::Fail,
            None if value <= threshold => Verdict::Pass,
            None => Verdict::Fail,
        };
        Criterion {
            name: name.into(),
            unit: unit.into(),
            value,
            noise,
            seeds,
            tolerance,
            threshold,
            verdict,
            known_difference: known.cloned(),
            noise_rule: None,
        }
    }

    /// The criterion with `rule` saying how its noise was estimated.
    pub fn with_noise_rule(mut self, rule: impl Into<String>) -> Criterion {
        self.noise_rule = Some(rule.into());
        self
    }

    /// How close the value is to deciding against it: value / threshold (band edge for a
    /// known difference).
    fn margin(&self) -> f64 {
        match &self.known_difference {
            Some(k) if k.holds(self.value, self.noise) => 0.0,
            Some(_) => f64::INFINITY,
            None if self.threshold > 0.0 => self.value / self.threshold,
            None => f64::INFINITY,
        }
    }

    /// "value 0.061 > threshold 0.050 + 2 x 0.004 = 0.058" in words, for tables.
    pub fn describe(&self) -> String {
        let seeds = if let Some(rule) = &self.noise_rule {
            format!(
                " (seeds {}+{}; noise: {rule})",
                self.seeds[0], self.seeds[1]
            )
        } else if self.seeds.iter().any(|&n| n < 2) {
            format!(
                " (seeds {}+{}: a side with one seed has no noise estimate)",
                self.seeds[0], self.seeds[1]
            )
        } else {
            format!(" (seeds {}+{})", self.seeds[0], self.seeds[1])
        };
        match &self.known_difference {
            Some(k) => format!(
                "{} {} {}: {}, band [{}, {}] +- {K_NOISE} x noise {} ({}; evidence {}){seeds}",
                self.name,
                fmt(self.value),
                self.unit,
                self.verdict.name(),
                fmt(k.band[0]),
                fmt(k.band[1]),
                fmt(self.noise),
                k.reason,
                k.evidence
            ),
            None => format!(
                "{} {} {} {} threshold {} = tolerance {} + {K_NOISE} x noise {}{seeds}",
                self.name,
                fmt(self.value),
                self.unit,
                if self.verdict == Verdict::Pass {
                    "<="
                } else {
                    ">"
                },
                fmt(self.threshold),
                fmt(self.tolerance),
                fmt(self.noise),
            ),
        }
    }
}

/// Three significant digits, without exponents for ordinary sizes.
pub fn fmt(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
    format!("{v:.digits$}")
}

/// The worst verdict of `parts` and the criterion that decided it: the failing one furthest
/// beyond its threshold, else a known difference, else the one closest to its threshold.
pub fn decide(parts: &[Criterion]) -> (Verdict, String) {
    let worst = parts
        .iter()
        .map(|c| c.verdict)
        .max()
        .unwrap_or(Verdict::Pass);
    let deciding = parts
        .iter()
        .filter(|c| c.verdict == worst)
        .max_by(|a, b| a.margin().total_cmp(&b.margin()))
        .map(|c| c.name.clone())
        .unwrap_or_default();
    (worst, deciding)
}

/// Mean, sample standard deviation and count.
pub fn mean_sd(values: &[f64]) -> Option<(f64, f64, usize)> {
    let n = values.len();
    if n == 0 {
        return None;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let sd = if n > 1 {
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n as f64 - 1.0)).sqrt()
    } else {
        0.0
    };
    Some((mean, sd, n))
}

/// Standard error of a difference of two means from their sample standard deviations and
/// counts; a side with one value contributes nothing (no estimate).
pub fn combined_standard_error((sa, na): (f64, usize), (sb, nb): (f64, usize)) -> f64 {
    let term = |s: f64, n: usize| if n > 1 { s * s / n as f64 } else { 0.0 };
    (term(sa, na) + term(sb, nb)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn known(band: [f64; 2]) -> KnownDifference {
        KnownDifference {
            comparison: "cgdem vs lammps".into(),
            criterion: "repose angle".into(),
            reason: "r".into(),
            evidence: "e".into(),
            band,
        }
    }

    #[test]
    fn a_difference_passes_within_tolerance_plus_k_standard_errors() {
        let c = Criterion::judge("repose angle", "deg", 2.9, 0.5, [3, 3], 2.0, None);
        assert_eq!(c.threshold, 3.0);
        assert_eq!(c.verdict, Verdict::Pass);
        let c = Criterion::judge("repose angle", "deg", 3.1, 0.5, [3, 3], 2.0, None);
        assert_eq!(c.verdict, Verdict::Fail);
        assert!(
            c.describe().contains("> threshold 3.00"),
            "{}",
            c.describe()
        );
    }

    #[test]
    fn a_known_difference_is_amber_inside_its_band_and_red_outside() {
        let k = known([10.0, 20.0]);
        let c = Criterion::judge("repose angle", "deg", 14.5, 0.5, [2, 2], 5.0, Some(&k));
        assert_eq!(c.verdict, Verdict::KnownDifference);
        let c = Criterion::judge("repose angle", "deg", 25.0, 0.5, [2, 2], 5.0, Some(&k));
        assert_eq!(c.verdict, Verdict::Fail);
        // Leaving the band downwards is a change too: the difference it documents is gone.
        let c = Criterion::judge("repose angle", "deg", 1.0, 0.5, [2, 2], 5.0, Some(&k));
        assert_eq!(c.verdict, Verdict::Fail);
        // The band is widened by the seeds' noise as a tolerance is: 9.5 with noise 0.5 is
        // inside [10 - 1, 20 + 1], 8.5 is not; 21.5 with noise 1 is inside [8, 22].
        let c = Criterion::judge("repose angle", "deg", 9.5, 0.5, [2, 2], 5.0, Some(&k));
        assert_eq!(c.verdict, Verdict::KnownDifference);
        let c = Criterion::judge("repose angle", "deg", 8.5, 0.5, [2, 2], 5.0, Some(&k));
        assert_eq!(c.verdict, Verdict::Fail);
        let c = Criterion::judge("repose angle", "deg", 21.5, 1.0, [2, 2], 5.0, Some(&k));
        assert_eq!(c.verdict, Verdict::KnownDifference);
        assert!(k.applies_to("cgdem vs lammps, lambda = 8 (seed)", "repose angle"));
        assert!(!k.applies_to("cgdem vs liggghts, lambda = 8 (seed)", "repose angle"));
        assert!(!k.applies_to("cgdem vs lammps, lambda = 8 (seed)", "front gap"));
    }

    #[test]
    fn the_row_names_the_criterion_that_decided_it() {
        let parts = [
            Criterion::judge("t_half ratio", "", 0.01, 0.0, [2, 2], 0.1, None),
            Criterion::judge("front gap", "", 0.09, 0.01, [2, 2], 0.05, None),
            Criterion::judge("wall height gap", "", 0.2, 0.0, [2, 2], 0.05, None),
        ];
        assert_eq!(decide(&parts), (Verdict::Fail, "wall height gap".into()));
        assert_eq!(decide(&parts[..1]), (Verdict::Pass, "t_half ratio".into()));
        let amber = Criterion::judge(
            "repose angle",
            "deg",
            14.0,
            0.0,
            [2, 2],
            5.0,
            Some(&known([5.0, 25.0])),
        );
        assert_eq!(
            decide(&[parts[0].clone(), amber]),
            (Verdict::KnownDifference, "repose angle".into())
        );
    }

    #[test]
    fn one_seed_gives_no_noise_estimate() {
        assert_eq!(combined_standard_error((3.0, 1), (4.0, 1)), 0.0);
        let se = combined_standard_error((3.0, 3), (4.0, 4));
        assert!((se - (3.0 + 4.0f64).sqrt()).abs() < 1e-12);
        assert_eq!(mean_sd(&[1.0, 3.0]), Some((2.0, 2f64.sqrt(), 2)));
    }
}
