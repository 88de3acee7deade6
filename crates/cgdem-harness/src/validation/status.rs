//! The overall status of a validation: the one word a nightly job reads (in `summary.json`,
//! on the report's first screen and as `cgdem validate`'s exit status).
//!
//! Red means something regressed and nothing else: a comparison outside its tolerance, a
//! run that failed, a cgdem stability verdict that failed. A comparison that could not be
//! made (a reference code is missing, or cannot express the case) is not green either: it
//! makes the status "incomplete", with the runs not made listed, so that a machine without
//! the reference codes never reports a validation it did not do.

use serde::{Deserialize, Serialize};

use super::{Outcome, ValidationSummary};
use crate::code::Code;
use crate::verdict::Verdict;

/// The validation's status, worst first: red, then incomplete, then amber, then green.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Every comparison passed.
    Green,
    /// Every comparison passed or is a declared known difference inside its band.
    Amber,
    /// Nothing failed, but some runs were not made, so their comparisons are missing.
    Incomplete,
    /// A comparison failed, a run failed, or a cgdem stability verdict failed.
    Red,
}

impl Status {
    /// The status of a finished validation.
    pub fn of(summary: &ValidationSummary) -> Status {
        let counts = StatusCounts::of(summary);
        if counts.failed_comparisons > 0 || counts.failed_runs > 0 || counts.failed_stability > 0 {
            Status::Red
        } else if counts.skipped_runs + counts.skipped_stability > 0 {
            Status::Incomplete
        } else if counts.known_differences > 0 {
            Status::Amber
        } else {
            Status::Green
        }
    }

    /// The word for it (`green`, `amber`, `incomplete`, `red`).
    pub fn word(self) -> &'static str {
        match self {
            Status::Green => "green",
            Status::Amber => "amber",
            Status::Incomplete => "incomplete",
            Status::Red => "red",
        }
    }

    /// `cgdem validate`'s exit status for it: 0 green or amber, 1 red, 3 incomplete (2 is
    /// taken by a suite or case that could not be run at all).
    pub fn exit_code(self) -> u8 {
        match self {
            Status::Green | Status::Amber => 0,
            Status::Red => 1,
            Status::Incomplete => 3,
        }
    }
}

/// What the status is made of.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StatusCounts {
    pub failed_comparisons: usize,
    pub known_differences: usize,
    pub passed_comparisons: usize,
    pub failed_runs: usize,
    /// Runs not made: the code is missing (skipped) or cannot express the case (unsupported).
    pub skipped_runs: usize,
    /// cgdem's failed stability verdicts (a reference code failing a stiff case is its
    /// own affair, reported but not red).
    pub failed_stability: usize,
    /// Stability runs not made (a reference code missing).
    pub skipped_stability: usize,
}

impl StatusCounts {
    pub fn of(summary: &ValidationSummary) -> StatusCounts {
        let verdicts = |v: Verdict| {
            summary
                .comparisons
                .iter()
                .filter(|c| c.verdict == v)
                .count()
        };
        // A case's runs and an accuracy sweep's runs count alike.
        let runs = |o: Outcome| {
            let points = summary.accuracy.as_ref().map_or(&[][..], |a| &a.points[..]);
            summary.runs.iter().filter(|r| r.status == o).count()
                + points.iter().filter(|p| p.status == o).count()
        };
        // The Chung & Ooi benchmark's criteria count as comparisons with the references.
        let benchmark = |verdict: &str| {
            summary
                .chung_ooi
                .iter()
                .filter(|v| v.verdict == verdict)
                .count()
        };
        StatusCounts {
            failed_comparisons: verdicts(Verdict::Fail) + benchmark("fail"),
            known_differences: verdicts(Verdict::KnownDifference) + benchmark("known difference"),
            passed_comparisons: verdicts(Verdict::Pass) + benchmark("pass"),
            failed_runs: runs(Outcome::Failed),
            // Not made: a code missing, or unable to express the case.
            skipped_runs: runs(Outcome::Skipped) + runs(Outcome::Unsupported),
            failed_stability: summary
                .stability
                .iter()
                .filter(|r| r.code == Code::Cgdem && r.verdict == crate::stability::Verdict::Failed)
                .count(),
            skipped_stability: summary
                .stability
                .iter()
                .filter(|r| r.verdict == crate::stability::Verdict::Skipped)
                .count(),
        }
    }
}

/// The runs that were not made, grouped by case, code and reason (a missing code skips
/// every run of it alike: one line says so).
pub(super) fn not_made(summary: &ValidationSummary) -> Vec<String> {
    let mut lines: Vec<(String, usize)> = Vec::new();
    let mut add = |line: String| match lines.iter_mut().find(|(l, _)| *l == line) {
        Some((_, n)) => *n += 1,
        None => lines.push((line, 1)),
    };
    let not_run = |o: Outcome| matches!(o, Outcome::Skipped | Outcome::Unsupported);
    for r in summary.runs.iter().filter(|r| not_run(r.status)) {
        add(format!(
            "{} in {}: {}",
            r.case,
            r.code.label(),
            r.reason.as_deref().unwrap_or("not run")
        ));
    }
    let points = summary.accuracy.as_ref().map_or(&[][..], |a| &a.points[..]);
    for p in points.iter().filter(|p| not_run(p.status)) {
        add(format!(
            "{} (accuracy sweep) in {}: {}",
            p.case,
            p.code.label(),
            p.reason.as_deref().unwrap_or("not run")
        ));
    }
    for r in &summary.stability {
        if r.verdict == crate::stability::Verdict::Skipped {
            add(format!(
                "{} (stability) in {}: {}",
                r.case,
                r.code.label(),
                r.message
            ));
        }
    }
    lines
        .into_iter()
        .map(|(line, n)| format!("{line} ({n} runs)"))
        .collect()
}
