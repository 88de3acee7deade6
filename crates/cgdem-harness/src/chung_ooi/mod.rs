//! The Chung & Ooi (2011) benchmark as a suite section (`[[chung_ooi]]`): its eight
//! particle-impact tests, run by cgdem in-process under each contact law the suite names, and
//! judged as Kratos DEM judges them (its points and tolerances), plus two checks of our own:
//! tests 1-4 against their closed forms, and every point of tests 5, 6 and 8 where the
//! contact slides throughout against rigid-body impact theory (1%).
//!
//! A law may declare a known difference (its reason in words): its failing criteria are then
//! shown amber, not red, and do not fail the suite. cgdem only: the reference codes are not
//! run (the references are the paper's closed forms and its digitized curves).
//!
//! Its phases, one file each: `suite` (the `[[chung_ooi]]` entries), `collision` (one
//! impact), `benchmark` (the eight tests and their criteria), `reference` (the digitized
//! curves) and `report` (the section, figures, tables and `chung_ooi.csv`).

mod benchmark;
mod collision;
mod reference;
mod report;
mod suite;
#[cfg(test)]
mod tests;

pub use benchmark::Criterion;
pub use suite::ChungOoiLaw;
pub(crate) use suite::{parse_laws, RawChungOoiLaw};

use serde::Serialize;

use crate::report::Report;
use crate::runs::ValidateOptions;
use benchmark::TestResult;
use cgdem_core::scene::Override;

/// One criterion of one test under one law, with its verdict.
#[derive(Clone, Debug, Serialize)]
pub struct ChungOoiVerdict {
    pub law: String,
    pub test: u8,
    pub criterion: Criterion,
    /// "pass", "known difference" (a failing criterion of a law that declares one) or "fail".
    pub verdict: String,
}

impl ChungOoiVerdict {
    pub fn failed(&self) -> bool {
        self.verdict == "fail"
    }
}

/// One test of the benchmark, run with a runner of impacts.
type Test = fn(&benchmark::Runner) -> Result<TestResult, String>;

/// The eight tests under the overrides `set` (the law, and any planted faults).
pub(crate) fn run_tests(set: &[Override]) -> Result<Vec<TestResult>, String> {
    let run = |impact: &collision::Impact, dt: f64| {
        let scene = impact.scene(dt, set)?;
        // Well past the end of any contact: four Hertz contact times.
        impact.run(&scene, dt, 800)
    };
    let tests: [Test; 8] = [
        benchmark::test1,
        benchmark::test2,
        benchmark::test3,
        benchmark::test4,
        benchmark::test5,
        benchmark::test6,
        benchmark::test7,
        benchmark::test8,
    ];
    tests.iter().map(|t| t(&run)).collect()
}

/// Runs the benchmark under every law of the suite, adds its section to `report`, writes
/// `OUT/chung_ooi/` (a figure and CSV per curve, `chung_ooi.csv`) and returns every verdict.
pub fn run_chung_ooi(
    laws: &[ChungOoiLaw],
    options: &ValidateOptions,
    report: &mut Report,
) -> Result<Vec<ChungOoiVerdict>, String> {
    if laws.is_empty() {
        return Ok(Vec::new());
    }
    // The screw's speed fault has no screw to act on here.
    let faults = crate::faults::Faults::parse(&options.cgdem_faults)
        .map_err(|e| e.to_string())?
        .overrides;
    let mut results = Vec::new();
    let mut verdicts = Vec::new();
    for law in laws {
        let set: Vec<Override> = law.overrides.iter().chain(&faults).cloned().collect();
        let tests = run_tests(&set).map_err(|e| format!("Chung & Ooi, law `{}`: {e}", law.name))?;
        for t in &tests {
            for c in &t.criteria {
                let verdict = match (c.pass, &law.known_difference) {
                    (true, _) => "pass",
                    (false, Some(_)) => "known difference",
                    (false, None) => "fail",
                };
                if !options.quiet {
                    eprintln!(
                        "chung_ooi {} test {}: {}: {:.3} (tolerance {}): {verdict}",
                        law.name, t.number, c.name, c.value, c.tolerance
                    );
                }
                verdicts.push(ChungOoiVerdict {
                    law: law.name.clone(),
                    test: t.number,
                    criterion: c.clone(),
                    verdict: verdict.into(),
                });
            }
        }
        results.push((law.clone(), tests));
    }
    report::write(report, &results, &verdicts, &options.out.join("chung_ooi"))?;
    Ok(verdicts)
}
