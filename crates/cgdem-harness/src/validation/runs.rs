//! The runs of a case: every code, level, rule and seed, made `--jobs` at a time (or
//! reused), each in its own directory under the runs directory.

use std::path::{Path, PathBuf};

use crate::faults::Faults;
use crate::runs::{run_concurrently, run_one, RunRecord, ValidateError, ValidateOptions};
use crate::suite::{Code, SuiteCase};
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::Scene;

fn run_dir(
    runs: &Path,
    scene: &Scene,
    code: Code,
    lambda: u32,
    rule: CoarseGrainRule,
    seed: u64,
) -> PathBuf {
    let mut name = format!("{}-lambda{lambda}", code.name());
    if rule != CoarseGrainRule::RelativeOverlap {
        name += &format!("-{}", rule.name());
    }
    runs.join(&scene.name).join(format!("{name}-seed{seed}"))
}

pub(super) fn run_case(
    scene: &Scene,
    case: &SuiteCase,
    options: &ValidateOptions,
) -> Result<Vec<RunRecord>, ValidateError> {
    // A conveying case runs once per listed screw speed, the scene at its own otherwise.
    let speeds: Vec<Option<f64>> = match &scene.conveying {
        Some(_) if !case.rpms.is_empty() => case.rpms.iter().map(|&r| Some(r)).collect(),
        _ => vec![None],
    };
    // Planted faults change cgdem's scene only; it keeps its name, so its runs are compared
    // with the reference codes' runs of the unchanged case.
    let case_error = |message: String| ValidateError::Case {
        file: case.file.clone(),
        message,
    };
    let faults = Faults::parse(&options.cgdem_faults).map_err(|e| case_error(e.to_string()))?;
    let faulted = if faults.overrides.is_empty() {
        None
    } else {
        let overrides: Vec<_> = (case.overrides.iter())
            .chain(&faults.overrides)
            .cloned()
            .collect();
        let mut s = crate::suite::load_variant(&case.file, &overrides, case.variant.as_deref())
            .map_err(|e| case_error(e.to_string()))?;
        s.name = scene.name.clone();
        Some(s)
    };
    // Alternate the codes within each seed and speed, so machine drift hits all alike.
    let mut settings = Vec::new();
    for &rule in &case.cg_rules {
        for &lambda in &case.lambdas {
            for &seed in &case.seeds {
                for &rpm in &speeds {
                    for &code in &case.codes {
                        settings.push((rule, lambda, seed, rpm, code));
                    }
                }
            }
        }
    }
    let records = run_concurrently(
        &settings,
        options.jobs,
        |&(rule, lambda, seed, rpm, code)| {
            let scene = match (&faulted, code) {
                (Some(f), Code::Cgdem) => f,
                _ => scene,
            };
            let mut dir = run_dir(&options.runs_dir(), scene, code, lambda, rule, seed);
            let at_speed;
            let scene = match (rpm, &scene.conveying) {
                (Some(rpm), Some(c)) => {
                    dir.set_file_name(format!(
                        "{}-rpm{rpm}",
                        dir.file_name().unwrap_or_default().to_string_lossy()
                    ));
                    at_speed = crate::sweep::at_speed(scene, &c.body, rpm);
                    &at_speed
                }
                _ => scene,
            };
            // The screw's speed fault acts on the speed the run is made at.
            let at_faulty_speed = match code {
                Code::Cgdem => faults.at_faulty_speed(scene),
                _ => None,
            };
            let scene = at_faulty_speed.as_ref().unwrap_or(scene);
            let options = &ValidateOptions {
                keep_going: options.keep_going || case.keep_going,
                ..options.clone()
            };
            let mut record = run_one(scene, code, lambda, rule, seed, &dir, options);
            record.rpm = rpm;
            if !options.quiet {
                eprintln!(
                    "{} {} lambda={lambda} rule={} seed={seed}{}: {}{}",
                    scene.name,
                    code.name(),
                    rule.name(),
                    rpm.map_or(String::new(), |r| format!(" rpm={r}")),
                    record.status,
                    record
                        .reason
                        .as_deref()
                        .map_or(String::new(), |r| format!(" ({r})"))
                );
            }
            record
        },
    );
    Ok(records)
}
