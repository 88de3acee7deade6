//! Runs that differ only by their insertion seed, and the statistics over them: the noise
//! that every quantity's verdict and error bars are calibrated by.

use crate::code::Code;
use crate::runs::RunRecord;
use crate::verdict::mean_sd;
use cgdem_core::coarse_graining::CoarseGrainRule;

/// A group of runs that differ only by their seed: (coarse-graining rule, lambda, code).
pub type Group = (CoarseGrainRule, u32, Code);
/// A group as a sortable key: (coarse-graining rule as u8, lambda, code).
pub type GroupKey = (u8, u32, Code);

/// The group of a run.
pub fn group_key(r: &RunRecord) -> GroupKey {
    (r.cg_rule as u8, r.lambda, r.code)
}

/// The rule a [`GroupKey`] holds.
pub fn rule_of(index: u8) -> CoarseGrainRule {
    CoarseGrainRule::ALL
        .into_iter()
        .find(|r| *r as u8 == index)
        .unwrap_or_default()
}

/// A group's name in figure legends: "cgdem lambda=8", the rule added when not the default.
pub fn group_label(code: Code, lambda: u32, rule: CoarseGrainRule) -> String {
    match rule {
        CoarseGrainRule::RelativeOverlap => format!("{} lambda={lambda}", code.name()),
        other => format!("{} lambda={lambda} {}", code.name(), other.name()),
    }
}

/// Mean and sample standard deviation (0 for one value): a point and its error bar.
pub fn mean_spread(values: &[f64]) -> Option<(f64, f64)> {
    mean_sd(values).map(|(mean, sd, _)| (mean, sd))
}

/// Mean and standard error of the mean (None for one value: no estimate); NaN for none.
pub fn mean_se(values: &[f64]) -> (f64, Option<f64>) {
    let (mean, sd, n) = mean_sd(values).unwrap_or((f64::NAN, 0.0, 0));
    (mean, (n > 1).then(|| sd / (n as f64).sqrt()))
}

/// The mean over seeds of measurements that each carry their own block-average standard
/// error `(value, se)`, and the standard error of that mean, `sqrt(sum se^2) / n` (the seeds
/// are independent runs); None without a measurement.
pub fn mean_with_block_error(measurements: &[(f64, f64)]) -> Option<(f64, f64)> {
    if measurements.is_empty() {
        return None;
    }
    let n = measurements.len() as f64;
    let mean = measurements.iter().map(|m| m.0).sum::<f64>() / n;
    let se = measurements.iter().map(|m| m.1 * m.1).sum::<f64>().sqrt() / n;
    Some((mean, se))
}

/// The mean over seeds of block-averaged measurements `(value, se)` and the noise of that
/// mean: the block errors combined ([`mean_with_block_error`]), or, with two or more seeds,
/// the standard error of the seeds' spread when that is larger. Both estimate the same noise;
/// the larger is taken so that a few blocks or a few seeds that happen to agree do not
/// narrow a verdict's band. None without a measurement.
pub fn mean_with_noise(measurements: &[(f64, f64)]) -> Option<(f64, f64)> {
    let (mean, block_se) = mean_with_block_error(measurements)?;
    let values: Vec<f64> = measurements.iter().map(|m| m.0).collect();
    let seeds_se = mean_se(&values).1.unwrap_or(0.0);
    Some((mean, block_se.max(seeds_se)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn independent_seeds_add_their_block_errors_in_quadrature() {
        // Two seeds with errors 0.3 and 0.4: sqrt(0.09 + 0.16) / 2 = 0.25.
        let (mean, se) = mean_with_block_error(&[(1.0, 0.3), (2.0, 0.4)]).unwrap();
        assert_eq!(mean, 1.5);
        assert!((se - 0.25).abs() < 1e-15, "{se}");
        assert_eq!(mean_with_block_error(&[]), None);
    }

    #[test]
    fn the_noise_of_a_mean_is_the_larger_of_its_block_and_seed_errors() {
        // One seed: its block error alone.
        assert_eq!(mean_with_noise(&[(4.0, 0.05)]), Some((4.0, 0.05)));
        // Seeds 4.0 and 4.2 (standard error of the spread 0.1) with block errors 0.03 and
        // 0.04 (combined 0.025): the spread's.
        let (mean, se) = mean_with_noise(&[(4.0, 0.03), (4.2, 0.04)]).unwrap();
        assert!(
            (mean - 4.1).abs() < 1e-12 && (se - 0.1).abs() < 1e-12,
            "{se}"
        );
        // Seeds that agree to the last digit keep their block errors: sqrt(0.3^2 + 0.4^2) / 2.
        let (_, se) = mean_with_noise(&[(4.0, 0.3), (4.0, 0.4)]).unwrap();
        assert!((se - 0.25).abs() < 1e-12, "{se}");
        assert_eq!(mean_with_noise(&[]), None);
    }

    #[test]
    fn one_seed_has_a_spread_of_zero_and_no_standard_error() {
        assert_eq!(mean_spread(&[2.0]), Some((2.0, 0.0)));
        assert_eq!(mean_se(&[2.0]), (2.0, None));
        let (mean, se) = mean_se(&[1.0, 3.0]);
        assert_eq!(mean, 2.0);
        assert!((se.unwrap() - 1.0).abs() < 1e-15);
        assert!(mean_se(&[]).0.is_nan());
    }
}
