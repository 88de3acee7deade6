//! `cgdem validate`: run a suite, compare the runs, write `summary.json` and `index.html`.
//!
//! Every run, whatever the code, leaves the same files in its own directory (`summary.json`,
//! `profile.csv`, `timeseries.csv`); the comparisons and plots read only those, so the
//! reference codes go through exactly the same post-processing as cgdem.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::suite::{Code, Suite, SuiteCase};
use crate::coarse_graining::{coarse_grain_by, CoarseGrainRule};
use crate::io::write_atomic;
use crate::report::{
    write_bar_chart, write_figure, Cell, Figure, Report, Series, SeriesStyle, Table,
};
use crate::run::{run, RunOptions};
use crate::scene::Scene;

/// One run of one code, as recorded in the suite's `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct RunRecord {
    pub case: String,
    pub code: Code,
    pub lambda: u32,
    pub cg_rule: CoarseGrainRule,
    pub seed: u64,
    /// "ok", "failed" or "skipped".
    pub status: String,
    pub reason: Option<String>,
    pub dir: PathBuf,
    pub n_particles: Option<u64>,
    pub steps: Option<u64>,
    pub wall_s: Option<f64>,
    pub particle_steps_per_s: Option<f64>,
    pub repose_angle_deg: Option<f64>,
    pub repose_fit_r2: Option<f64>,
    pub runout_m: Option<f64>,
}

/// One judged comparison.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub case: String,
    /// "codes" (two codes at one level) or "levels" (one code at two levels).
    pub kind: String,
    pub what: String,
    pub difference: f64,
    pub combined_spread: f64,
    pub tolerance: f64,
    pub within_spread: bool,
    pub pass: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct ValidationSummary {
    pub suite: String,
    pub provenance: BTreeMap<String, String>,
    pub runs: Vec<RunRecord>,
    pub comparisons: Vec<Comparison>,
}

#[derive(Debug, thiserror::Error)]
pub enum ValidateError {
    #[error(transparent)]
    Suite(#[from] super::suite::SuiteError),
    #[error("{file}: {message}")]
    Case { file: PathBuf, message: String },
    #[error("cannot write {path}: {message}")]
    Output { path: PathBuf, message: String },
}

fn output_error(path: &Path, e: impl std::fmt::Display) -> ValidateError {
    ValidateError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

pub struct ValidateOptions {
    pub suite: PathBuf,
    pub out: PathBuf,
    pub quiet: bool,
    /// Time limit of one reference-code run, seconds.
    pub reference_timeout_s: u64,
    /// cgdem's guards only warn instead of stopping a run (`--keep-going`).
    pub keep_going: bool,
}

/// Runs every case of the suite with every code, level, rule and seed; a run that fails is
/// recorded with its reason and the suite goes on.
pub fn validate(options: &ValidateOptions) -> Result<ValidationSummary, ValidateError> {
    let suite = Suite::load(&options.suite)?;
    std::fs::create_dir_all(&options.out).map_err(|e| output_error(&options.out, e))?;
    let mut runs = Vec::new();
    let mut comparisons = Vec::new();
    let mut report = Report::new(format!("cgdem validation: suite `{}`", suite.name));
    let provenance = provenance(&suite, options);
    for case in &suite.cases {
        let scene = Scene::load(&case.file).map_err(|e| ValidateError::Case {
            file: case.file.clone(),
            message: e.to_string(),
        })?;
        let case_runs = run_case(&scene, case, options)?;
        let case_comparisons = compare(&scene, case, &case_runs);
        write_case_section(
            &mut report,
            &scene,
            case,
            &case_runs,
            &case_comparisons,
            &options.out,
        )?;
        runs.extend(case_runs);
        comparisons.extend(case_comparisons);
    }
    let summary = ValidationSummary {
        suite: suite.name.clone(),
        provenance,
        runs,
        comparisons,
    };
    let intro = report.intro();
    intro.paragraph(format!(
        "{} {}",
        suite.description,
        "Each run's files are under runs/; figures have their data as CSV beside them."
    ));
    let mut table = Table::new([
        "case",
        "comparison",
        "what",
        "difference",
        "combined seed spread",
        "tolerance",
        "verdict",
    ])
    .caption("Summary: every comparison against its stated tolerance");
    for c in &summary.comparisons {
        table.row(std::iter::once(Cell::text(&c.case)).chain(comparison_cells(c)));
    }
    let mut run_table = Table::new([
        "case",
        "code",
        "lambda",
        "rule",
        "seed",
        "status",
        "particles",
        "wall s",
        "particle-steps/s",
    ])
    .caption("Runs");
    for r in &summary.runs {
        let status = match r.status.as_str() {
            "ok" => Cell::pass("ok"),
            "skipped" => {
                Cell::skipped(format!("skipped: {}", r.reason.clone().unwrap_or_default()))
            }
            _ => Cell::fail(format!("failed: {}", r.reason.clone().unwrap_or_default())),
        };
        run_table.row([
            Cell::text(&r.case),
            Cell::text(r.code.name()),
            Cell::num(r.lambda.to_string()),
            Cell::text(rule_name(r.cg_rule)),
            Cell::num(r.seed.to_string()),
            status,
            Cell::num(opt(r.n_particles.map(|n| n as f64), 0)),
            Cell::num(opt(r.wall_s, 1)),
            Cell::num(
                r.particle_steps_per_s
                    .map_or(String::from("-"), |v| format!("{v:.3e}")),
            ),
        ]);
    }
    intro.table(table);
    intro.table(run_table);
    intro.key_values(
        Some("Provenance"),
        summary
            .provenance
            .iter()
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect::<Vec<_>>(),
    );
    let json_path = options.out.join("summary.json");
    let json = serde_json::to_string_pretty(&summary).map_err(|e| output_error(&json_path, e))?;
    write_atomic(&json_path, json.as_bytes()).map_err(|e| output_error(&json_path, e))?;
    let html_path = options.out.join("index.html");
    report
        .write(&html_path)
        .map_err(|e| output_error(&html_path, e))?;
    Ok(summary)
}

/// A comparison's table cells: kind, what, difference, spread, tolerance, verdict.
fn comparison_cells(c: &Comparison) -> [Cell; 6] {
    [
        Cell::text(&c.kind),
        Cell::text(&c.what),
        Cell::num(format!("{:.2}", c.difference)),
        Cell::num(format!("{:.2}", c.combined_spread)),
        Cell::num(format!("{:.2}", c.tolerance)),
        if c.pass {
            Cell::pass("pass")
        } else {
            Cell::fail("fail")
        },
    ]
}

fn rule_name(rule: CoarseGrainRule) -> &'static str {
    match rule {
        CoarseGrainRule::Seed => "seed",
        CoarseGrainRule::BulkViscosity => "bulk-viscosity",
    }
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or(String::from("-"), |x| format!("{x:.digits$}"))
}

fn provenance(suite: &Suite, options: &ValidateOptions) -> BTreeMap<String, String> {
    let command = |program: &str, args: &[&str]| -> String {
        std::process::Command::new(program)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_else(|| "unknown".into())
    };
    let mut p = BTreeMap::new();
    p.insert("cgdem version".into(), env!("CARGO_PKG_VERSION").into());
    p.insert(
        "cgdem commit".into(),
        command("git", &["rev-parse", "--short", "HEAD"]),
    );
    p.insert(
        "machine".into(),
        format!(
            "{} ({} cores)",
            command("uname", &["-srm"]),
            std::thread::available_parallelism().map_or(0, |n| n.get())
        ),
    );
    p.insert(
        "date".into(),
        command("date", &["-u", "+%Y-%m-%dT%H:%M:%SZ"]),
    );
    p.insert(
        "command".into(),
        std::env::args().collect::<Vec<_>>().join(" "),
    );
    p.insert("suite file".into(), suite.source.display().to_string());
    p.insert("output".into(), options.out.display().to_string());
    p.insert("threads".into(), rayon::current_num_threads().to_string());
    p
}

fn run_dir(
    out: &Path,
    scene: &Scene,
    code: Code,
    lambda: u32,
    rule: CoarseGrainRule,
    seed: u64,
) -> PathBuf {
    let mut name = format!("{}-lambda{lambda}", code.name());
    if rule != CoarseGrainRule::Seed {
        name += &format!("-{}", rule_name(rule));
    }
    out.join("runs")
        .join(&scene.name)
        .join(format!("{name}-seed{seed}"))
}

fn run_case(
    scene: &Scene,
    case: &SuiteCase,
    options: &ValidateOptions,
) -> Result<Vec<RunRecord>, ValidateError> {
    let mut records = Vec::new();
    for &rule in &case.cg_rules {
        for &lambda in &case.lambdas {
            for &seed in &case.seeds {
                // Alternate the codes within each seed, so machine drift hits all alike.
                for &code in &case.codes {
                    let dir = run_dir(&options.out, scene, code, lambda, rule, seed);
                    let mut record = RunRecord {
                        case: scene.name.clone(),
                        code,
                        lambda,
                        cg_rule: rule,
                        seed,
                        status: "ok".into(),
                        reason: None,
                        dir: dir.clone(),
                        n_particles: None,
                        steps: None,
                        wall_s: None,
                        particle_steps_per_s: None,
                        repose_angle_deg: None,
                        repose_fit_r2: None,
                        runout_m: None,
                    };
                    let outcome = match code {
                        Code::Cgdem => run_cgdem(scene, lambda, rule, seed, &dir, options),
                        Code::Lammps => run_lammps(scene, lambda, rule, seed, &dir, options.reference_timeout_s),
                        Code::Liggghts => Err(RunOutcome::Skipped("LIGGGHTS cannot express the seed's WCA model; Hertz decks for LIGGGHTS are not written yet".into())),
                    };
                    match outcome {
                        Ok(()) => fill_from_summary(&mut record),
                        Err(RunOutcome::Skipped(reason)) => {
                            record.status = "skipped".into();
                            record.reason = Some(reason);
                        }
                        Err(RunOutcome::Failed(reason)) => {
                            record.status = "failed".into();
                            record.reason = Some(reason);
                        }
                    }
                    if !options.quiet {
                        eprintln!(
                            "{} {} lambda={lambda} rule={} seed={seed}: {}{}",
                            scene.name,
                            code.name(),
                            rule_name(rule),
                            record.status,
                            record
                                .reason
                                .as_deref()
                                .map_or(String::new(), |r| format!(" ({r})"))
                        );
                    }
                    records.push(record);
                }
            }
        }
    }
    Ok(records)
}

enum RunOutcome {
    Skipped(String),
    Failed(String),
}

fn run_cgdem(
    scene: &Scene,
    lambda: u32,
    rule: CoarseGrainRule,
    seed: u64,
    dir: &Path,
    validate: &ValidateOptions,
) -> Result<(), RunOutcome> {
    let coarse = coarse_grain_by(&scene.with_insertion_seed(seed), lambda, rule)
        .map_err(|e| RunOutcome::Failed(e.to_string()))?;
    let options = RunOptions {
        out_dir: dir.to_path_buf(),
        quiet: validate.quiet,
        force_dt: false,
        keep_going: validate.keep_going,
    };
    run(&coarse, &options)
        .map(|_| ())
        .map_err(|e| RunOutcome::Failed(e.to_string()))
}

fn run_lammps(
    scene: &Scene,
    lambda: u32,
    rule: CoarseGrainRule,
    seed: u64,
    dir: &Path,
    timeout_s: u64,
) -> Result<(), RunOutcome> {
    use super::lammps::{run_reference, RunStatus, RunnerOptions};
    let coarse = coarse_grain_by(&scene.with_insertion_seed(seed), lambda, rule)
        .map_err(|e| RunOutcome::Failed(e.to_string()))?;
    let options = RunnerOptions {
        np: None,
        timeout: std::time::Duration::from_secs(timeout_s),
    };
    match run_reference(&coarse, dir, &options).map_err(RunOutcome::Failed)? {
        (RunStatus::Completed { .. }, _) => Ok(()),
        (
            RunStatus::Skipped {
                reason,
                install_hint,
            },
            _,
        ) => Err(RunOutcome::Skipped(format!(
            "{reason}; install with `{install_hint}`"
        ))),
        (
            RunStatus::Failed {
                exit_code,
                log_tail,
            },
            _,
        ) => Err(RunOutcome::Failed(format!(
            "LAMMPS exit code {exit_code:?}; log tail: {log_tail}"
        ))),
        (RunStatus::TimedOut { after_s, log_tail }, _) => Err(RunOutcome::Failed(format!(
            "LAMMPS timed out after {after_s:.0} s (partial outputs kept); log tail: {log_tail}"
        ))),
    }
}

fn fill_from_summary(record: &mut RunRecord) {
    let path = record.dir.join("summary.json");
    let value: serde_json::Value = match std::fs::read_to_string(&path)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
    {
        Ok(v) => v,
        Err(e) => {
            record.status = "failed".into();
            record.reason = Some(format!("{}: {e}", path.display()));
            return;
        }
    };
    let f = |key: &str| value.get(key).and_then(|v| v.as_f64());
    record.n_particles = value.get("n_particles").and_then(|v| v.as_u64());
    record.steps = value.get("steps").and_then(|v| v.as_u64());
    record.wall_s = f("wall_s");
    record.particle_steps_per_s = f("particle_steps_per_s");
    record.repose_angle_deg = f("repose_angle_deg");
    record.repose_fit_r2 = f("repose_fit_r2");
    record.runout_m = f("runout_m");
}

/// Mean and sample standard deviation.
fn mean_spread(values: &[f64]) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let spread = if values.len() > 1 {
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    Some((mean, spread))
}

type Group = (CoarseGrainRule, u32, Code);

fn angles_by_group(runs: &[RunRecord]) -> BTreeMap<(u8, u32, Code), Vec<f64>> {
    let mut groups: BTreeMap<(u8, u32, Code), Vec<f64>> = BTreeMap::new();
    for r in runs {
        if let Some(a) = r.repose_angle_deg {
            groups
                .entry((r.cg_rule as u8, r.lambda, r.code))
                .or_default()
                .push(a);
        }
    }
    groups
}

fn rule_of(index: u8) -> CoarseGrainRule {
    if index == CoarseGrainRule::Seed as u8 {
        CoarseGrainRule::Seed
    } else {
        CoarseGrainRule::BulkViscosity
    }
}

fn compare(scene: &Scene, case: &SuiteCase, runs: &[RunRecord]) -> Vec<Comparison> {
    let groups = angles_by_group(runs);
    let stats: BTreeMap<(u8, u32, Code), (f64, f64)> = groups
        .iter()
        .filter_map(|(k, v)| mean_spread(v).map(|s| (*k, s)))
        .collect();
    let mut out = Vec::new();
    let judge = |kind: &str, what: String, a: (f64, f64), b: (f64, f64)| {
        let difference = (a.0 - b.0).abs();
        let combined_spread = (a.1 * a.1 + b.1 * b.1).sqrt();
        let within_spread = difference <= combined_spread;
        Comparison {
            case: scene.name.clone(),
            kind: kind.into(),
            what,
            difference,
            combined_spread,
            tolerance: case.angle_tolerance_deg,
            within_spread,
            pass: within_spread || difference <= case.angle_tolerance_deg,
        }
    };
    // Codes against each other at each level.
    for (&(rule, lambda, code_a), &a) in &stats {
        for (&(rule_b, lambda_b, code_b), &b) in &stats {
            if rule == rule_b && lambda == lambda_b && code_a < code_b {
                out.push(judge(
                    "codes",
                    format!(
                        "repose angle, {} vs {}, lambda = {lambda} ({})",
                        code_a.name(),
                        code_b.name(),
                        rule_name(rule_of(rule))
                    ),
                    a,
                    b,
                ));
            }
        }
    }
    // Each code's neighbouring levels (coarsening similarity of the final state).
    for (&(rule, lambda, code), &a) in &stats {
        let finer = stats
            .iter()
            .filter(|(&(r, l, c), _)| r == rule && c == code && l < lambda)
            .max_by_key(|(&(_, l, _), _)| l);
        if let Some((&(_, finer_lambda, _), &b)) = finer {
            out.push(judge(
                "levels",
                format!(
                    "repose angle, {} lambda = {finer_lambda} vs {lambda} ({})",
                    code.name(),
                    rule_name(rule_of(rule))
                ),
                b,
                a,
            ));
        }
    }
    out
}

fn read_csv(path: &Path) -> Vec<BTreeMap<String, String>> {
    let Ok(text) = std::fs::read_to_string(path) else {
        return Vec::new();
    };
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap_or("")
        .split(',')
        .map(String::from)
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect()
        })
        .collect()
}

fn number(row: &BTreeMap<String, String>, key: &str) -> Option<f64> {
    row.get(key).and_then(|v| v.parse().ok())
}

fn label(code: Code, lambda: u32, rule: CoarseGrainRule) -> String {
    match rule {
        CoarseGrainRule::Seed => format!("{} lambda={lambda}", code.name()),
        other => format!("{} lambda={lambda} {}", code.name(), rule_name(other)),
    }
}

fn write_case_section(
    report: &mut Report,
    scene: &Scene,
    case: &SuiteCase,
    runs: &[RunRecord],
    comparisons: &[Comparison],
    out: &Path,
) -> Result<(), ValidateError> {
    let dir = out.join("figures").join(&scene.name);
    let figure_error = |e: crate::report::PlotError| output_error(&dir, e);
    let section = report.section(format!("Case {}", scene.name));
    section.paragraph(format!(
        "{} Scene file: {}. Seeds: {:?}.",
        scene.description,
        case.file.display(),
        case.seeds
    ));
    let ok_runs: Vec<&RunRecord> = runs.iter().filter(|r| r.status == "ok").collect();

    // Heap profiles, averaged over seeds per code, level and rule.
    let mut profiles = Figure::new(
        format!("{}: heap profiles (mean over seeds)", scene.name),
        "distance from the remaining wall x [m]",
        "surface height h(x) [m]",
    );
    let mut front = Figure::new(
        format!(
            "{}: front position after the gate opens (first seed)",
            scene.name
        ),
        "time after the gate opens t [s]",
        "front position x_f [m]",
    );
    let mut keys: Vec<Group> = ok_runs
        .iter()
        .map(|r| (r.cg_rule, r.lambda, r.code))
        .collect();
    keys.sort_by_key(|k| (k.0 as u8, k.1, k.2));
    keys.dedup();
    for &(rule, lambda, code) in &keys {
        let members: Vec<&&RunRecord> = ok_runs
            .iter()
            .filter(|r| (r.cg_rule, r.lambda, r.code) == (rule, lambda, code))
            .collect();
        let mut sum: Vec<(f64, f64)> = Vec::new();
        for r in &members {
            for (k, row) in read_csv(&r.dir.join("profile.csv")).iter().enumerate() {
                if let (Some(x), Some(h)) = (number(row, "x_m"), number(row, "height_m")) {
                    if k < sum.len() {
                        sum[k].1 += h;
                    } else {
                        sum.push((x, h));
                    }
                }
            }
        }
        let n = members.len().max(1) as f64;
        profiles.series.push(
            Series::new(
                label(code, lambda, rule),
                sum.into_iter().map(|(x, h)| (x, h / n)).collect(),
            )
            .style(SeriesStyle::Line),
        );
        if let Some(first) = members.first() {
            let stage = scene
                .repose
                .as_ref()
                .map(|r| r.stage.clone())
                .unwrap_or_default();
            let rows: Vec<_> = read_csv(&first.dir.join("timeseries.csv"))
                .into_iter()
                .filter(|row| row.get("stage") == Some(&stage))
                .collect();
            let t0 = rows
                .first()
                .and_then(|r| number(r, "time_s"))
                .unwrap_or(0.0);
            let points = rows
                .iter()
                .filter_map(|row| Some((number(row, "time_s")? - t0, number(row, "front_m")?)))
                .collect();
            front
                .series
                .push(Series::new(label(code, lambda, rule), points).style(SeriesStyle::Line));
        }
    }
    let files = write_figure(&dir, "profiles", &profiles).map_err(figure_error)?;
    section.figure(&files, "heap profiles", "Free-surface height against distance from the remaining wall at the measurement time, averaged over seeds.").map_err(|e| output_error(&dir, e))?;

    // Repose angle per level with seed spread.
    let mut angles = Figure::new(
        format!("{}: repose angle per level", scene.name),
        "coarse-graining level lambda",
        "repose angle [deg]",
    )
    .log_x();
    let groups = angles_by_group(runs);
    // (rule, code) -> (lambda, mean angle) points and their seed spreads.
    type AngleSeries = (Vec<(f64, f64)>, Vec<f64>);
    let mut series: BTreeMap<(u8, Code), AngleSeries> = BTreeMap::new();
    for (&(rule, lambda, code), values) in &groups {
        if let Some((mean, spread)) = mean_spread(values) {
            let entry = series.entry((rule, code)).or_default();
            entry.0.push((lambda as f64, mean));
            entry.1.push(spread);
        }
    }
    for ((rule, code), (points, errors)) in series {
        let name = match rule_of(rule) {
            CoarseGrainRule::Seed => code.name().to_string(),
            other => format!("{} {}", code.name(), rule_name(other)),
        };
        angles.series.push(
            Series::new(name, points)
                .y_err(errors)
                .style(SeriesStyle::LineMarkers),
        );
    }
    let files = write_figure(&dir, "repose_angle", &angles).map_err(figure_error)?;
    section.figure(&files, "repose angle per level", "Mean repose angle over seeds; error bars are the sample standard deviation across seeds.").map_err(|e| output_error(&dir, e))?;

    let files = write_figure(&dir, "front_position", &front).map_err(figure_error)?;
    section.figure(&files, "front position against time", "Furthest point where the deposit is at least two diameters deep, against time after the gate opens.").map_err(|e| output_error(&dir, e))?;

    let bars: Vec<(String, String, f64, Option<f64>)> = keys
        .iter()
        .filter_map(|&(rule, lambda, code)| {
            let values: Vec<f64> = ok_runs
                .iter()
                .filter(|r| (r.cg_rule, r.lambda, r.code) == (rule, lambda, code))
                .filter_map(|r| r.particle_steps_per_s)
                .collect();
            let (mean, spread) = mean_spread(&values)?;
            let group = match rule {
                CoarseGrainRule::Seed => format!("lambda={lambda}"),
                other => format!("lambda={lambda} {}", rule_name(other)),
            };
            Some((group, code.name().to_string(), mean, Some(spread)))
        })
        .collect();
    let files = write_bar_chart(
        &dir,
        "throughput",
        &format!("{}: throughput", scene.name),
        "particle-steps per second",
        &bars,
    )
    .map_err(figure_error)?;
    section.figure(&files, "throughput per code and level", "Particle-steps per second (mean and spread over seeds); wall time includes insertion and output.").map_err(|e| output_error(&dir, e))?;

    let mut table = Table::new([
        "comparison",
        "what",
        "difference [deg]",
        "combined spread [deg]",
        "tolerance [deg]",
        "verdict",
    ]);
    for c in comparisons {
        table.row(comparison_cells(c));
    }
    section.table(table);
    let rule = scene.repose.as_ref().map(|_| {
        "The repose angle is measured by the rule stated in each run's summary.json (repose_rule)."
    });
    if let Some(rule) = rule {
        section.paragraph(rule);
    }
    Ok(())
}
