//! `cgdem validate`: run a suite, compare the runs, write `summary.json` and `index.html`.
//!
//! Every run, whatever the code, leaves the same files in its own directory (`summary.json`,
//! `profile.csv`, `timeseries.csv`); the comparisons and plots read only those, so the
//! reference codes go through exactly the same post-processing as cgdem.
//!
//! Its phases, one file each: `runs` (every code, level, rule and seed of a case),
//! `measurement` (the comparisons and their verdicts) and `report` (the first screen and a
//! section per case). The suite file is read by `crate::suite`; its accuracy sweeps and
//! stability cases are suite kinds of their own (`crate::accuracy`, `crate::stability`),
//! which this command runs after the cases.

mod measurement;
mod report;
mod runs;
mod status;
#[cfg(test)]
mod tests;

pub use crate::runs::{Outcome, RunRecord, ValidateError, ValidateOptions};
pub use measurement::Comparison;
pub(crate) use report::machine_provenance;
pub use status::{Status, StatusCounts};

use std::collections::BTreeMap;

use serde::Serialize;

use crate::faults::{self, Faults};
use crate::quantity::{discharge, drum, mass_flow};
use crate::report::Report;
use crate::runs::output_error;
use crate::suite::{Suite, SuiteCase};
use cgdem_core::io::write_atomic;
use cgdem_core::scene::Scene;
use measurement::compare;
use report::{provenance, write_case_section, write_code_notes, write_intro};
use runs::run_case;

/// What `cgdem validate` found, as `summary.json` holds it.
#[derive(Clone, Debug, Serialize)]
pub struct ValidationSummary {
    pub suite: String,
    /// The overall status (`Status::of`), set once every part is in.
    pub status: Status,
    pub provenance: BTreeMap<String, String>,
    pub runs: Vec<RunRecord>,
    pub comparisons: Vec<Comparison>,
    /// Error against run time (the suite's `[[accuracy]]` sweeps).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<super::accuracy::AccuracySummary>,
    /// The `[[stability]]` cases' verdicts, one per case and code.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stability: Vec<super::stability::StabilityRecord>,
    /// The `[[chung_ooi]]` benchmark's verdicts, one per law, test and criterion.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub chung_ooi: Vec<super::chung_ooi::ChungOoiVerdict>,
}

/// Runs every case of the suite with every code, level, rule and seed; a run that fails is
/// recorded with its reason and the suite goes on.
pub fn validate(options: &ValidateOptions) -> Result<ValidationSummary, ValidateError> {
    validate_suite(&Suite::load(&options.suite)?, options)
}

/// As [`validate`], for a suite already loaded (`options.suite` names its file in the
/// provenance): `cgdem advise --run` hands it the sweeps of one case.
pub fn validate_suite(
    suite: &Suite,
    options: &ValidateOptions,
) -> Result<ValidationSummary, ValidateError> {
    check_faults(suite, options)?;
    std::fs::create_dir_all(&options.out).map_err(|e| output_error(&options.out, e))?;
    let mut report = Report::new(format!("cgdem validation: suite `{}`", suite.name));
    let mut provenance = provenance(suite, options);
    let warnings = reference_versions(suite, &mut provenance, options.quiet);
    let (runs, comparisons) = run_cases(suite, options, &mut report)?;
    let accuracy =
        super::accuracy::run_sweeps(&suite.accuracy, &suite.source, options, &mut report)?;
    let stability = super::stability::run_stability(&suite.stability, options, &mut report)
        .map_err(|message| ValidateError::Case {
            file: suite.source.clone(),
            message,
        })?;
    let chung_ooi = super::chung_ooi::run_chung_ooi(&suite.chung_ooi, options, &mut report)
        .map_err(|message| ValidateError::Case {
            file: suite.source.clone(),
            message,
        })?;
    let mut summary = ValidationSummary {
        suite: suite.name.clone(),
        status: Status::Green,
        provenance,
        runs,
        comparisons,
        accuracy,
        stability,
        chung_ooi,
    };
    summary.status = Status::of(&summary);
    write_intro(&mut report, &summary, suite, options, &warnings);
    let json_path = options.out.join("summary.json");
    let json = serde_json::to_string_pretty(&summary).map_err(|e| output_error(&json_path, e))?;
    write_atomic(&json_path, json.as_bytes()).map_err(|e| output_error(&json_path, e))?;
    let html_path = options.out.join("index.html");
    report
        .write(&html_path)
        .map_err(|e| output_error(&html_path, e))?;
    Ok(summary)
}

/// A screw case's mass-flow verdicts as the suite's comparisons (one per reference code and
/// speed), counted in the status as every other.
fn screw_comparisons(case: &str, verdicts: mass_flow::FlowVerdicts) -> Vec<Comparison> {
    (verdicts.judged.into_iter())
        .map(|v| {
            Comparison::judged(
                case,
                "codes",
                mass_flow::PART,
                &v.what,
                v.detail,
                vec![v.criterion],
            )
        })
        .collect()
}

/// The planted faults, parsed before any run is made; the screw's speed fault needs a case
/// with a screw (a scene with `[conveying]`), or it would change nothing and say so nowhere.
fn check_faults(suite: &Suite, options: &ValidateOptions) -> Result<(), ValidateError> {
    let error = |message: String| ValidateError::Case {
        file: suite.source.clone(),
        message,
    };
    let faults = Faults::parse(&options.cgdem_faults).map_err(|e| error(e.to_string()))?;
    if faults.rpm_factor.is_some() {
        let conveys = |case: &SuiteCase| case.load_scene().is_ok_and(|s| s.conveying.is_some());
        if !suite.cases.iter().any(conveys) {
            return Err(error(format!(
                "--fault {}: no case of suite `{}` has a screw (a scene with [conveying]) to turn",
                faults::RPM_FACTOR,
                suite.name
            )));
        }
    }
    Ok(())
}

/// Each reference code the suite runs, as found: its release (or that it is missing) in the
/// provenance; a release the decks were not verified against is warned about on the console
/// and returned for the report's first screen.
fn reference_versions(
    suite: &Suite,
    provenance: &mut BTreeMap<String, String>,
    quiet: bool,
) -> Vec<String> {
    let mut warnings = Vec::new();
    for code in suite.codes() {
        let Some(dialect) = crate::decks::dialect(code) else {
            continue;
        };
        let key = format!("{} version", code.label());
        match crate::decks::version::find_version(dialect) {
            Ok(version) => {
                provenance.insert(key, version.describe());
                if let Some(w) = version.warning() {
                    if !quiet {
                        eprintln!("warning: {w}");
                    }
                    warnings.push(w);
                }
            }
            Err(reason) => {
                provenance.insert(key, format!("not available: {reason}"));
            }
        }
    }
    warnings
}

/// Runs and judges the suite's cases, each scene's in one section of `report`; returns every
/// run and comparison.
fn run_cases(
    suite: &Suite,
    options: &ValidateOptions,
    report: &mut Report,
) -> Result<(Vec<RunRecord>, Vec<Comparison>), ValidateError> {
    let mut runs = Vec::new();
    let mut comparisons = Vec::new();
    // Cases of one scene (e.g. its two coarse-graining rules) are compared and reported
    // together: one section, one set of figures, judged by the first case's tolerances and
    // by the known differences any of them declares.
    let mut scenes: Vec<(Scene, SuiteCase, Vec<RunRecord>)> = Vec::new();
    for case in &suite.cases {
        let scene = case.load_scene().map_err(|e| ValidateError::Case {
            file: case.file.clone(),
            message: e.to_string(),
        })?;
        let case_runs = run_case(&scene, case, options)?;
        match scenes.iter_mut().find(|(s, _, _)| s.name == scene.name) {
            Some((_, first, earlier)) => {
                earlier.extend(case_runs);
                first
                    .known_differences
                    .extend(case.known_differences.iter().cloned());
            }
            None => {
                // A scene's own `[discharge]` measures it when the suite gives none.
                let mut case = case.clone();
                if case.discharge.is_none() {
                    case.discharge = scene.discharge.as_ref().map(Into::into);
                }
                scenes.push((scene, case, case_runs))
            }
        }
    }
    let screws: Vec<(&Scene, &[RunRecord])> = scenes
        .iter()
        .filter(|(s, _, _)| s.conveying.is_some())
        .map(|(s, _, r)| (s, r.as_slice()))
        .collect();
    if screws.len() > 1 {
        mass_flow::write_screw_overview(report, &screws, &options.out)?;
    }
    // Silo cases (`[case.discharge]`) are measured once, shown across orifices, then each.
    let silos: Vec<_> = scenes
        .iter()
        .filter_map(|(s, c, r)| {
            let d = c.discharge.as_ref()?;
            Some((s, d, discharge::measure_runs(s, d, r)))
        })
        .collect();
    if !silos.is_empty() {
        discharge::write_silo_overview(report, &silos, &options.out)?;
    }
    let silos: Vec<(String, Vec<discharge::SiloRun>)> = silos
        .into_iter()
        .map(|(s, _, m)| (s.name.clone(), m))
        .collect();
    for (scene, case, case_runs) in scenes {
        if case.drum.is_some() {
            comparisons.extend(report_drum_case(
                report, &scene, &case, &case_runs, options,
            )?);
            runs.extend(case_runs);
            continue;
        }
        if let Some(settings) = &case.discharge {
            let measured = silos.iter().find(|(n, _)| *n == scene.name).map(|(_, m)| m);
            let measured = measured.map_or(&[][..], |m| m.as_slice());
            let verdict = discharge::rate_criterion(measured, &case.known_differences).map(
                |(criterion, text)| {
                    Comparison::judged(
                        &scene.name,
                        "codes",
                        "final state",
                        discharge::COMPARISON,
                        text,
                        vec![criterion],
                    )
                },
            );
            discharge::write_silo_section(
                report,
                &scene,
                &case.origin(),
                settings,
                measured,
                verdict.as_ref().map(|c| (c.verdict, c.detail.as_str())),
                &options.out,
            )?;
            write_code_notes(report, &case_runs);
            runs.extend(case_runs);
            comparisons.extend(verdict);
            continue;
        }
        if scene.conveying.is_some() {
            comparisons.extend(judge_screw_case(
                report, &scene, &case, &case_runs, options,
            )?);
            write_code_notes(report, &case_runs);
            runs.extend(case_runs);
            continue;
        }
        let case_comparisons = compare(&scene, &case, &case_runs);
        write_case_section(
            report,
            &scene,
            &case,
            &case_runs,
            &case_comparisons,
            &options.out,
        )?;
        write_code_notes(report, &case_runs);
        runs.extend(case_runs);
        comparisons.extend(case_comparisons);
    }
    Ok((runs, comparisons))
}

/// A drum case (`[case.drum]`): every run measured from its frames, cgdem's verdict against
/// the reference codes (when both ran), and its section.
fn report_drum_case(
    report: &mut Report,
    scene: &Scene,
    case: &SuiteCase,
    case_runs: &[RunRecord],
    options: &ValidateOptions,
) -> Result<Option<Comparison>, ValidateError> {
    let Some(settings) = &case.drum else {
        return Ok(None);
    };
    let measured = drum::measure_runs(scene, settings, case_runs);
    let verdict = drum::drum_criteria(&measured, settings, &case.known_differences).map(
        |(criteria, text)| {
            Comparison::judged(
                &scene.name,
                "codes",
                "steady rotation",
                drum::COMPARISON,
                text,
                criteria,
            )
        },
    );
    drum::write_drum_section(
        report,
        scene,
        &case.origin(),
        settings,
        &measured,
        verdict.as_ref().map(|c| (c.verdict, c.detail.as_str())),
        &options.out,
    )?;
    write_code_notes(report, case_runs);
    Ok(verdict)
}

/// A screw case: cgdem's mass flow judged against each reference code's, speed by speed,
/// and its section (shown beside Eq. (7), code by code); returns its comparisons.
fn judge_screw_case(
    report: &mut Report,
    scene: &Scene,
    case: &SuiteCase,
    case_runs: &[RunRecord],
    options: &ValidateOptions,
) -> Result<Vec<Comparison>, ValidateError> {
    let Some(conveying) = &scene.conveying else {
        return Ok(Vec::new());
    };
    let own_rpm = (scene.bodies.iter())
        .find(|b| b.name == conveying.body)
        .map(|b| b.rpm.abs());
    let verdicts = mass_flow::flow_verdicts(
        case_runs,
        own_rpm,
        conveying.blocks,
        &case.known_differences,
    );
    mass_flow::write_screw_section(
        report,
        scene,
        &case.origin(),
        case_runs,
        &verdicts,
        &options.out,
    )?;
    Ok(screw_comparisons(&scene.name, verdicts))
}
