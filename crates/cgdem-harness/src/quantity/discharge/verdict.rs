//! cgdem's verdict on a silo case, one of the suite's comparisons (so that it reaches the
//! report's first screen and the night's status, and a declared known difference can
//! turn it amber): cgdem's rate within the reference codes' spread, each rate widened by
//! two standard errors.

use std::fmt::Write as _;

use super::SiloRun;
use crate::code::Code;
use crate::quantity::seeds::mean_with_block_error;
use crate::verdict::{Criterion, KnownDifference};

/// The comparison's and the criterion's names, as a `[[case.known_difference]]` gives them.
pub const COMPARISON: &str = "cgdem vs reference codes";
pub const CRITERION: &str = "discharge rate";

/// cgdem's rate against the reference codes' in one case.
#[derive(Clone, Debug, PartialEq)]
pub struct RateVerdict {
    /// How far cgdem's rate, widened by two standard errors, lies outside the reference
    /// codes' spread, each rate widened by two of its own, over the reference codes' mean
    /// rate; 0 within.
    pub gap: f64,
    /// Seeds on each side (cgdem, the reference codes).
    pub seeds: [usize; 2],
    /// The rates and the spread in words.
    pub text: String,
}

/// cgdem's verdict on one case: its rate within the reference codes' spread widened by two
/// standard errors on each side, or within two combined standard errors of the one
/// reference code that ran. None without a cgdem or a reference rate.
pub fn cgdem_verdict(runs: &[SiloRun]) -> Option<RateVerdict> {
    // Each code's rates over its seeds, with their block errors.
    let rates = |code: Code| -> Vec<(f64, f64)> {
        runs.iter()
            .filter(|s| s.code == code)
            .filter_map(SiloRun::rate_with_error)
            .collect()
    };
    let cgdem_rates = rates(Code::Cgdem);
    let (cg, cg_se) = mean_with_block_error(&cgdem_rates)?;
    let refs: Vec<(Code, f64, f64, usize)> = [Code::Liggghts, Code::Lammps]
        .iter()
        .filter_map(|&c| {
            let r = rates(c);
            mean_with_block_error(&r).map(|(m, se)| (c, m, se, r.len()))
        })
        .collect();
    if refs.is_empty() {
        return None;
    }
    let lo = refs
        .iter()
        .map(|r| r.1 - 2.0 * r.2)
        .fold(f64::INFINITY, f64::min);
    let hi = refs
        .iter()
        .map(|r| r.1 + 2.0 * r.2)
        .fold(f64::NEG_INFINITY, f64::max);
    let reference_mean = refs.iter().map(|r| r.1).sum::<f64>() / refs.len() as f64;
    let gap = (lo - (cg + 2.0 * cg_se))
        .max((cg - 2.0 * cg_se) - hi)
        .max(0.0)
        / reference_mean;
    let mut text = format!("cgdem {cg:.4} +- {cg_se:.4} kg/s");
    for (c, m, se, _) in &refs {
        let z = (cg - m) / (cg_se * cg_se + se * se).sqrt();
        let _ = write!(text, "; {} {m:.4} +- {se:.4} kg/s ({z:+.1} SE)", c.name());
    }
    let _ = write!(
        text,
        "; reference spread with 2 SE {lo:.4} .. {hi:.4} kg/s: cgdem {}",
        if gap > 0.0 {
            format!("outside (by {:.1}% of the reference rate)", 100.0 * gap)
        } else {
            "within".to_string()
        }
    );
    Some(RateVerdict {
        gap,
        seeds: [cgdem_rates.len(), refs.iter().map(|r| r.3).sum()],
        text,
    })
}

/// The case's criterion, with the rates in words: passes within the spread, amber where a
/// known difference of [`COMPARISON`] and [`CRITERION`] holds the gap in its band, red
/// otherwise (`crate::validation` makes it one of the suite's comparisons).
pub fn rate_criterion(runs: &[SiloRun], known: &[KnownDifference]) -> Option<(Criterion, String)> {
    let v = cgdem_verdict(runs)?;
    let known = known.iter().find(|k| k.applies_to(COMPARISON, CRITERION));
    // The noise is already in the gap (each rate widened by two standard errors).
    let criterion = Criterion::judge(
        CRITERION,
        "of the reference rate, outside their spread",
        v.gap,
        0.0,
        v.seeds,
        0.0,
        known,
    );
    Some((criterion, v.text))
}
