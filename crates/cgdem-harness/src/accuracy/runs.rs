//! The runs of a sweep: every setting with every seed and code, made `--jobs` at a time
//! (or reused), each read into an [`AccuracyPoint`]; and the other rules' own matrices from
//! the same runs.

use std::path::{Path, PathBuf};

use super::discharge::measure_discharge;
use super::drum::measure_drum;
use super::{AccuracyPoint, AccuracySweep, Knob, KnobSeries};
use crate::code::Code;
use crate::quantity::discharge::DischargeSettings;
use crate::quantity::drum::DrumSettings;
use crate::quantity::flow::{flow_stage, measured_t_half};
use crate::quantity::mass_flow::conveying_value;
use crate::quantity::porosity::{pore_diameter_in_diameters, porosity};
use crate::runs::{run_concurrently, run_one, Outcome, ValidateError, ValidateOptions};
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::Scene;

/// Each other rule's own matrix, from runs already made: a lambda series under another rule
/// than the reference's that includes the reference's level is also a sweep of its own, with
/// that level as its reference, reported as case `<case>-<rule>-rule`. "How far does lambda
/// 16 move from lambda 8 under this rule" then needs no second set of runs (the scene name
/// is part of a run's digest, so a second sweep of the same runs would make them again).
pub(crate) fn own_rule_sweeps(
    sweep: &AccuracySweep,
    case: &str,
    points: &[AccuracyPoint],
) -> Vec<(AccuracySweep, Vec<AccuracyPoint>)> {
    let Some(&level) = sweep.reference.get(&Knob::Lambda) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for s in sweep
        .series
        .iter()
        .filter(|s| s.knob == Knob::Lambda && s.rule != sweep.rule && s.values.contains(&level))
    {
        let series = s.name(sweep.rule);
        let own_case = format!("{case}-{}-rule", s.rule.name());
        let own_points: Vec<AccuracyPoint> = points
            .iter()
            .filter(|p| p.series == series)
            .map(|p| {
                let (series, setting) = if p.value == level {
                    ("reference".to_string(), "reference".to_string())
                } else {
                    let knob = Knob::Lambda.name();
                    (knob.to_string(), format!("{knob} = {}", p.value))
                };
                AccuracyPoint {
                    case: own_case.clone(),
                    series,
                    setting,
                    ..p.without_errors()
                }
            })
            .collect();
        if own_points.iter().any(|p| p.series == "reference") {
            let own_sweep = AccuracySweep {
                rule: s.rule,
                series: vec![KnobSeries {
                    values: s.values.iter().copied().filter(|&v| v != level).collect(),
                    ..s.clone()
                }],
                ..sweep.clone()
            };
            out.push((own_sweep, own_points));
        }
    }
    out
}

/// One setting of a sweep for one seed: (series, varied knob, value, codes, rule, seed).
type SweepJob = (String, Knob, f64, Vec<Code>, CoarseGrainRule, u64);

/// Every setting of the sweep with every seed, seed by seed: the reference first, then each
/// series point in its order.
fn sweep_jobs(sweep: &AccuracySweep) -> Vec<SweepJob> {
    let mut jobs: Vec<SweepJob> = Vec::new();
    let all = sweep.codes();
    for &seed in &sweep.seeds {
        jobs.push((
            "reference".into(),
            Knob::Lambda,
            0.0,
            all.clone(),
            sweep.rule,
            seed,
        ));
        for s in &sweep.series {
            for &v in &s.values {
                // The reference's own value is the reference, unless the rule differs.
                if v != sweep.reference[&s.knob] || s.rule != sweep.rule {
                    jobs.push((
                        s.name(sweep.rule),
                        s.knob.clone(),
                        v,
                        s.codes.clone(),
                        s.rule,
                        seed,
                    ));
                }
            }
        }
    }
    jobs
}

/// One run of a sweep, prepared: its scene (before coarse-graining), level, code, rule and
/// seed, the labels it is reported under and its directory.
pub(crate) struct PlannedRun {
    pub scene: std::sync::Arc<Scene>,
    pub lambda: u32,
    pub code: Code,
    pub rule: CoarseGrainRule,
    pub seed: u64,
    pub series: String,
    pub setting: String,
    pub value: f64,
    pub dir: PathBuf,
}

/// Every run of the sweep in the order it is made (seed by seed, the reference of every
/// code, then each series point; codes alternate within each point so machine drift hits
/// all alike), with the case's name. `cgdem advise` counts their cost from the same list.
pub(crate) fn planned_runs(
    sweep: &AccuracySweep,
    origin: &Path,
    options: &ValidateOptions,
) -> Result<(String, Vec<PlannedRun>), ValidateError> {
    let case_error = |message: String| ValidateError::Case {
        file: sweep.file.clone(),
        message,
    };
    let (reference_scene, _) = sweep.scene(&sweep.reference, origin).map_err(case_error)?;
    let case = reference_scene.name.clone();
    let mut runs = Vec::new();
    for (series, knob, value, codes, rule, seed) in sweep_jobs(sweep) {
        let mut knobs = sweep.reference.clone();
        let (setting, name) = match series.as_str() {
            "reference" => ("reference".to_string(), format!("reference-seed{seed}")),
            _ => {
                knobs.insert(knob.clone(), value);
                let (setting, rule_dir) = if rule == sweep.rule {
                    (format!("{} = {value}", knob.name()), String::new())
                } else {
                    (
                        format!("{} = {value}, {} rule", knob.name(), rule.name()),
                        format!("-{}", rule.name()),
                    )
                };
                (
                    setting,
                    format!("{}-{value}{rule_dir}-seed{seed}", knob.file_name()),
                )
            }
        };
        let (scene, lambda) = sweep.scene(&knobs, origin).map_err(case_error)?;
        let scene = std::sync::Arc::new(scene);
        for code in codes {
            runs.push(PlannedRun {
                scene: scene.clone(),
                lambda,
                code,
                rule,
                seed,
                series: series.clone(),
                setting: setting.clone(),
                // The reference is plotted at its own value of the knob.
                value: knobs[&knob],
                dir: options
                    .runs_dir()
                    .join(&case)
                    .join("accuracy")
                    .join(format!("{}-{name}", code.name())),
            });
        }
    }
    Ok((case, runs))
}

/// Makes the sweep's runs (`planned_runs`), `--jobs` at a time: the seeds and levels of a
/// sweep are independent runs.
pub(crate) fn run_sweep(
    sweep: &AccuracySweep,
    origin: &Path,
    options: &ValidateOptions,
) -> Result<Vec<AccuracyPoint>, ValidateError> {
    let (case, runs) = planned_runs(sweep, origin, options)?;
    // "[k/n]" in each run's line: how far the sweep has come.
    let finished = std::sync::atomic::AtomicUsize::new(0);
    let points = run_concurrently(&runs, options.jobs, |run| {
        let point = run_point(
            &run.scene,
            (run.code, run.lambda, run.rule, run.seed),
            &run.dir,
            (sweep.discharge.as_ref(), sweep.drum.as_ref()),
            options,
        );
        let p = AccuracyPoint {
            case: case.clone(),
            code: run.code,
            series: run.series.clone(),
            value: run.value,
            setting: run.setting.clone(),
            ..point
        };
        let k = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if !options.quiet {
            eprintln!(
                "[{k}/{}] {case} accuracy {} {} (seed {}): {}{}",
                runs.len(),
                run.code.name(),
                p.setting,
                run.seed,
                p.status,
                p.reason
                    .as_deref()
                    .map_or(String::new(), |r| format!(" ({r})"))
            );
        }
        p
    });
    Ok(points)
}

/// Runs one point (or reuses it) and reads what it measured; with `discharge`, the run is
/// measured as a silo's discharge, with `drum` as a rotating drum.
fn run_point(
    scene: &Scene,
    (code, lambda, rule, seed): (Code, u32, CoarseGrainRule, u64),
    dir: &Path,
    (discharge, drum): (Option<&DischargeSettings>, Option<&DrumSettings>),
    options: &ValidateOptions,
) -> AccuracyPoint {
    let mut record = run_one(scene, code, lambda, rule, seed, dir, options);
    // A run that stopped early (a guard, a time limit) measured nothing comparable.
    if record.partial {
        record.status = Outcome::Failed;
    }
    let summary: serde_json::Value = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default();
    // A run that lost particles (LIGGGHTS and LAMMPS drop atoms that leave the box) may end
    // without a heap or a flow to measure.
    if record.status == Outcome::Ok
        && discharge.is_none()
        && drum.is_none()
        && record.repose_angle_deg.is_none()
        && conveying_value(&summary, "mass_flow_kg_s").is_none()
        && porosity(&summary).is_none()
    {
        record.status = Outcome::Failed;
        record.reason = Some(format!(
            "measured nothing: {} particles at the end",
            record.n_particles.map_or("?".into(), |n| n.to_string())
        ));
    }
    let ok = record.status == Outcome::Ok;
    let conveying = |key: &str| conveying_value(&summary, key).filter(|_| ok);
    let particle_steps = summary["particle_steps"]
        .as_f64()
        .or_else(|| Some(record.n_particles? as f64 * record.steps? as f64));
    let measured = record.clone();
    let mut point = AccuracyPoint {
        case: record.case,
        code,
        series: String::new(),
        value: f64::NAN,
        setting: String::new(),
        lambda,
        cg_rule: rule,
        seed,
        status: record.status,
        reason: record.reason,
        dir: dir.to_path_buf(),
        reused: record.reused,
        n_particles: record.n_particles,
        steps: record.steps,
        particle_steps: particle_steps.filter(|_| ok),
        wall_s: record.wall_s.filter(|_| ok),
        repose_angle_deg: record.repose_angle_deg.filter(|_| ok),
        angle_error_deg: None,
        profile_distance: None,
        mass_flow_kg_s: conveying("mass_flow_kg_s"),
        mass_flow_error: None,
        eq7_mass_flow_kg_s: conveying("eq7_mass_flow_kg_s"),
        eq7_error: None,
        t_half_s: measured_t_half(scene, dir).filter(|_| ok),
        t_half_error: None,
        flow_stage: flow_stage(scene).filter(|_| ok).map(str::to_string),
        front_error: None,
        porosity: porosity(&summary).filter(|_| ok),
        porosity_error: None,
        pore_diameter_d: pore_diameter_in_diameters(&summary, scene, lambda).filter(|_| ok),
        pore_size_error: None,
        discharge_rate_kg_s: None,
        discharge_rate_std_error_kg_s: None,
        discharge_rate_error: None,
        bulk_density_kg_m3: None,
        particle_diameter_m: None,
        flow_stopped_at_s: None,
        dynamic_angle_deg: None,
        dynamic_angle_error_deg: None,
        mixing_period_s: None,
        mixing_period_error: None,
        mixing_index: None,
        mixing_index_error: None,
        large_share_zones: None,
    };
    if let Some(d) = discharge.filter(|_| ok) {
        if let Err(problem) = measure_discharge(scene, d, &measured, &mut point) {
            point.status = Outcome::Failed;
            point.reason = Some(format!("measured no discharge: {problem}"));
        }
    }
    if let Some(d) = drum.filter(|_| ok) {
        if let Err(problem) = measure_drum(scene, d, &measured, &mut point) {
            point.status = Outcome::Failed;
            point.reason = Some(format!("measured no drum: {problem}"));
        }
    }
    point
}
