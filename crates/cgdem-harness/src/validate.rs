//! `cgdem validate`: run a suite, compare the runs, write `summary.json` and `index.html`.
//!
//! Every run, whatever the code, leaves the same files in its own directory (`summary.json`,
//! `profile.csv`, `timeseries.csv`); the comparisons and plots read only those, so the
//! reference codes go through exactly the same post-processing as cgdem.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::dynamics::{flow_difference, flow_noise, FlowSeries, FLOW_GRID_S};
use super::suite::{Code, Suite, SuiteCase};
use super::verdict::{combined_standard_error, mean_sd, Criterion, Verdict};
use crate::csv_table::CsvTable;
use crate::report::{
    write_bar_chart, write_figure, Cell, Figure, Report, Series, SeriesStyle, Table,
};
use crate::runs::{output_error, run_concurrently, run_one};
pub use crate::runs::{Outcome, RunRecord, ValidateError, ValidateOptions};
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::io::write_atomic;
use cgdem_core::scene::Scene;

/// One judged comparison: a pair of codes or levels, one part (final state or dynamics),
/// judged by its criteria (`verdict::Criterion`), each with its value, noise, threshold
/// and verdict; the comparison's verdict is its worst criterion's, named in `decided_by`.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub case: String,
    /// "codes" (two codes at one level) or "levels" (one code at two levels).
    pub kind: String,
    /// "final state" (repose angle) or "dynamics" (t_half ratio, front, wall-height and
    /// kinetic-energy gaps): a pair is similar only if both pass.
    pub part: String,
    pub what: String,
    /// The numbers behind the verdict, in words.
    pub detail: String,
    /// The deciding criterion's value, physical tolerance and threshold (tolerance + k noise).
    pub difference: f64,
    pub tolerance: f64,
    pub threshold: f64,
    /// "pass", "known difference" or "fail".
    pub verdict: super::verdict::Verdict,
    /// The criterion that decided the verdict.
    pub decided_by: String,
    pub criteria: Vec<super::verdict::Criterion>,
    /// Not a fail (a known difference inside its band passes).
    pub pass: bool,
}

impl Comparison {
    /// A comparison judged by `criteria`.
    fn judged(
        case: &str,
        kind: &str,
        part: &str,
        what: &str,
        detail: String,
        criteria: Vec<super::verdict::Criterion>,
    ) -> Comparison {
        let (verdict, decided_by) = super::verdict::decide(&criteria);
        let deciding = criteria.iter().find(|c| c.name == decided_by);
        Comparison {
            case: case.into(),
            kind: kind.into(),
            part: part.into(),
            what: what.into(),
            detail,
            difference: deciding.map_or(0.0, |c| c.value),
            tolerance: deciding.map_or(0.0, |c| c.tolerance),
            threshold: deciding.map_or(0.0, |c| c.threshold),
            verdict,
            decided_by,
            criteria,
            pass: verdict != super::verdict::Verdict::Fail,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct ValidationSummary {
    pub suite: String,
    pub provenance: BTreeMap<String, String>,
    pub runs: Vec<RunRecord>,
    pub comparisons: Vec<Comparison>,
    /// Error against run time (the suite's `[[accuracy]]` sweeps).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<super::accuracy::AccuracySummary>,
    /// The `[[stability]]` cases' verdicts, one per case and code.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stability: Vec<super::stability::StabilityRecord>,
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
    std::fs::create_dir_all(&options.out).map_err(|e| output_error(&options.out, e))?;
    let mut runs = Vec::new();
    let mut comparisons = Vec::new();
    let mut report = Report::new(format!("cgdem validation: suite `{}`", suite.name));
    let provenance = provenance(suite, options);
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
            None => scenes.push((scene, case.clone(), case_runs)),
        }
    }
    let screws: Vec<(&Scene, &[RunRecord])> = scenes
        .iter()
        .filter(|(s, _, _)| s.conveying.is_some())
        .map(|(s, _, r)| (s, r.as_slice()))
        .collect();
    if screws.len() > 1 {
        super::screw::write_screw_overview(&mut report, &screws, &options.out)?;
    }
    for (scene, case, case_runs) in scenes {
        if scene.conveying.is_some() {
            // A screw case is judged by its mass flow against Eq. (7), code by code.
            super::screw::write_screw_section(
                &mut report,
                &scene,
                &case,
                &case_runs,
                &options.out,
            )?;
            runs.extend(case_runs);
            continue;
        }
        let case_comparisons = compare(&scene, &case, &case_runs);
        write_case_section(
            &mut report,
            &scene,
            &case,
            &case_runs,
            &case_comparisons,
            &options.out,
        )?;
        runs.extend(case_runs);
        comparisons.extend(case_comparisons);
    }
    let accuracy =
        super::accuracy::run_sweeps(&suite.accuracy, &suite.source, options, &mut report)?;
    let stability = super::stability::run_stability(&suite.stability, options, &mut report)
        .map_err(|message| ValidateError::Case {
            file: suite.source.clone(),
            message,
        })?;
    let summary = ValidationSummary {
        suite: suite.name.clone(),
        provenance,
        runs,
        comparisons,
        accuracy,
        stability,
    };
    let intro = report.intro();
    write_status(intro, &summary, options);
    let runs_at = match &options.runs_dir {
        None => "runs/".to_string(),
        Some(dir) => dir.display().to_string(),
    };
    intro.paragraph(format!(
        "{} Each run's files are under {runs_at}; figures have their data as CSV beside them.",
        suite.description
    ));
    let table = criteria_table(&summary.comparisons);
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
        let status = match r.status {
            Outcome::Ok if r.partial => Cell::skipped(r.reason.clone().unwrap_or_default()),
            Outcome::Ok if r.reused => Cell::pass("ok (reused)"),
            Outcome::Ok => Cell::pass("ok"),
            Outcome::Skipped => {
                Cell::skipped(format!("skipped: {}", r.reason.clone().unwrap_or_default()))
            }
            Outcome::Failed => {
                Cell::fail(format!("failed: {}", r.reason.clone().unwrap_or_default()))
            }
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
    // A suite of only accuracy sweeps or stability cases has neither: its sections say it all.
    if !summary.comparisons.is_empty() {
        intro.table(table);
    }
    if !summary.runs.is_empty() {
        intro.table(run_table);
    }
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

/// The row anchor of the `k`-th comparison (links from the first screen).
fn comparison_id(k: usize) -> String {
    format!("comparison-{}", k + 1)
}

fn verdict_cell(v: Verdict, text: String) -> Cell {
    match v {
        Verdict::Pass => Cell::pass(text),
        Verdict::KnownDifference => Cell::text(text).status(crate::report::Status::Known),
        Verdict::Fail => Cell::fail(text),
    }
}

/// The summary table: one row per criterion of every comparison (its value, noise, seeds,
/// physical tolerance, threshold and own verdict) and the comparison's verdict with the
/// criterion that decided it; the first row of each comparison carries its anchor.
fn criteria_table(comparisons: &[Comparison]) -> Table {
    let mut table = Table::new([
        "case",
        "comparison",
        "part",
        "criterion",
        "value",
        "noise (SE)",
        "seeds",
        "tolerance",
        "threshold",
        "criterion verdict",
        "row verdict",
    ])
    .caption(format!(
        "Summary: every comparison by its criteria. A criterion passes when its value <= \
         threshold = physical tolerance + {} x noise, the noise being the combined standard \
         error of the two sides from their seeds (0 where a side has one seed); a declared \
         known difference is judged by its band instead (amber inside, red outside). The \
         comparison's verdict is its worst criterion's.",
        super::verdict::K_NOISE
    ));
    for (k, c) in comparisons.iter().enumerate() {
        for (j, crit) in c.criteria.iter().enumerate() {
            let row_verdict = if crit.name == c.decided_by {
                verdict_cell(
                    c.verdict,
                    format!("{} (decided by {})", c.verdict.name(), c.decided_by),
                )
            } else {
                Cell::text("")
            };
            let threshold = match &crit.known_difference {
                Some(kd) => format!(
                    "band [{}, {}]",
                    super::verdict::fmt(kd.band[0]),
                    super::verdict::fmt(kd.band[1])
                ),
                None => super::verdict::fmt(crit.threshold),
            };
            // The reason is on the first screen and in the case's similarity table.
            let verdict_text = match &crit.known_difference {
                Some(kd) => format!("{} (evidence: {})", crit.verdict.name(), kd.evidence),
                None => crit.verdict.name().to_string(),
            };
            let cells = [
                Cell::text(&c.case),
                Cell::text(&c.what),
                Cell::text(&c.part),
                Cell::text(format!("{} [{}]", crit.name, crit.unit)),
                Cell::num(super::verdict::fmt(crit.value)),
                Cell::num(super::verdict::fmt(crit.noise)),
                Cell::num(format!("{}+{}", crit.seeds[0], crit.seeds[1])),
                Cell::num(super::verdict::fmt(crit.tolerance)),
                Cell::num(threshold),
                verdict_cell(crit.verdict, verdict_text),
                row_verdict,
            ];
            if j == 0 {
                table.row_with_id(comparison_id(k), cells);
            } else {
                table.row(cells);
            }
        }
    }
    table
}

/// The night's status: its overall verdict, the red and amber rows (linked), failed runs,
/// and what moved since the previous night of the history, if one is given.
fn write_status(
    intro: &mut crate::report::Section,
    summary: &ValidationSummary,
    options: &ValidateOptions,
) {
    use crate::report::Status;
    let count = |v: Verdict| {
        summary
            .comparisons
            .iter()
            .filter(|c| c.verdict == v)
            .count()
    };
    let (red, amber, green) = (
        count(Verdict::Fail),
        count(Verdict::KnownDifference),
        count(Verdict::Pass),
    );
    let failed_runs: Vec<&RunRecord> = summary
        .runs
        .iter()
        .filter(|r| r.status == Outcome::Failed)
        .collect();
    let stability_failed = summary
        .stability
        .iter()
        .filter(|r| r.code == Code::Cgdem && r.verdict == super::stability::Verdict::Failed)
        .count();
    let (status, word) = if red > 0 || !failed_runs.is_empty() || stability_failed > 0 {
        (Status::Fail, "red")
    } else if amber > 0 {
        (Status::Known, "amber")
    } else {
        (Status::Pass, "green")
    };
    let mut line = format!(
        "Status: {word}. {red} comparisons fail, {amber} are known differences inside their \
         bands, {green} pass; {} of {} runs failed",
        failed_runs.len(),
        summary.runs.len()
    );
    if !summary.stability.is_empty() {
        line += &format!("; {stability_failed} cgdem stability verdicts failed");
    }
    line.push('.');
    intro.banner(status, line);
    if !options.cgdem_faults.is_empty() {
        intro.banner(
            Status::Fail,
            format!(
                "Planted faults in cgdem's runs only (--fault): {}. This report checks that \
                 the verdicts can fail; it is not a validation of cgdem.",
                options.cgdem_faults.join(", ")
            ),
        );
    }
    let flagged: Vec<Cell> = summary
        .comparisons
        .iter()
        .enumerate()
        .filter(|(_, c)| c.verdict != Verdict::Pass)
        .map(|(k, c)| {
            let decided = c.criteria.iter().find(|x| x.name == c.decided_by);
            Cell::link(
                format!(
                    "{} ({}): {}, {}: {}",
                    c.case,
                    c.what,
                    c.part,
                    c.verdict.name(),
                    decided.map_or(String::new(), |d| d.describe())
                ),
                format!("#{}", comparison_id(k)),
            )
        })
        .chain(failed_runs.iter().map(|r| {
            Cell::text(format!(
                "run failed: {} {} lambda={} seed={}: {}",
                r.case,
                r.code.name(),
                r.lambda,
                r.seed,
                r.reason.clone().unwrap_or_default()
            ))
        }))
        .collect();
    if !flagged.is_empty() {
        intro.paragraph("Red and amber rows:");
        intro.list(flagged);
    }
    match &options.history {
        None => {
            intro.paragraph(
                "Since the previous night: no history given (`cgdem validate --history DIR`, \
                 as scripts/nightly.sh does).",
            );
        }
        Some(dir) => {
            let value = serde_json::to_value(summary).unwrap_or_default();
            let (text, items) = super::history::since_previous(dir, &options.out, &value);
            intro.paragraph(text);
            if !items.is_empty() {
                intro.list(items.into_iter().map(Cell::text).collect());
            }
        }
    }
}

fn rule_name(rule: CoarseGrainRule) -> &'static str {
    rule.name()
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or(String::from("-"), |x| format!("{x:.digits$}"))
}

fn provenance(suite: &Suite, options: &ValidateOptions) -> BTreeMap<String, String> {
    let mut p = machine_provenance();
    p.insert("suite file".into(), suite.source.display().to_string());
    p.insert("output".into(), options.out.display().to_string());
    p.insert("concurrent runs (jobs)".into(), options.jobs.to_string());
    if let Some(grid) = options.decomposition.grid {
        p.insert(
            "cgdem decomposed (--grid, --balance)".into(),
            format!("{grid}, balance {}", options.decomposition.balance),
        );
    }
    if let Some(ranks) = &options.decomposition.ranks {
        p.insert(
            "cgdem as MPI ranks (--np)".into(),
            format!("{} ranks of {}", ranks.np, ranks.bin.display()),
        );
    }
    p
}

/// cgdem's version and commit, the machine, the date, the command line and the threads.
pub(crate) fn machine_provenance() -> BTreeMap<String, String> {
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
    p.insert("threads".into(), rayon::current_num_threads().to_string());
    p
}

fn run_dir(
    runs: &Path,
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
    runs.join(&scene.name).join(format!("{name}-seed{seed}"))
}

fn run_case(
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
    let faulted = if options.cgdem_faults.is_empty() {
        None
    } else {
        let case_error = |message: String| ValidateError::Case {
            file: case.file.clone(),
            message,
        };
        let mut overrides = case.overrides.clone();
        for f in &options.cgdem_faults {
            overrides.push(
                cgdem_core::scene::Override::parse(f, Path::new("--fault"))
                    .map_err(|e| case_error(e.to_string()))?,
            );
        }
        let mut s = super::suite::load_variant(&case.file, &overrides, case.variant.as_deref())
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
                    rule_name(rule),
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
/// A group of runs: (coarse-graining rule as u8, lambda, code).
type GroupKey = (u8, u32, Code);

fn angles_by_group(runs: &[RunRecord]) -> BTreeMap<GroupKey, Vec<f64>> {
    let mut groups: BTreeMap<GroupKey, Vec<f64>> = BTreeMap::new();
    for r in runs.iter().filter(|r| !r.partial) {
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
    CoarseGrainRule::ALL
        .into_iter()
        .find(|r| *r as u8 == index)
        .unwrap_or_default()
}

/// The pairs a case compares: codes against each other at each level and rule ("codes"),
/// and each code's neighbouring levels under each rule ("levels"), finer first.
fn comparison_pairs(keys: &[GroupKey]) -> Vec<(&'static str, GroupKey, GroupKey)> {
    let mut out = Vec::new();
    for &(rule, lambda, code_a) in keys {
        for &(rule_b, lambda_b, code_b) in keys {
            if rule == rule_b && lambda == lambda_b && code_a < code_b {
                out.push(("codes", (rule, lambda, code_a), (rule, lambda, code_b)));
            }
        }
    }
    for &(rule, lambda, code) in keys {
        let finer = keys
            .iter()
            .filter(|&&(r, l, c)| r == rule && c == code && l < lambda)
            .max_by_key(|&&(_, l, _)| l);
        if let Some(&f) = finer {
            out.push(("levels", f, (rule, lambda, code)));
        }
    }
    out
}

fn pair_name(kind: &str, a: GroupKey, b: GroupKey) -> String {
    let rule = rule_name(rule_of(a.0));
    if kind == "codes" {
        format!(
            "{} vs {}, lambda = {} ({rule})",
            a.2.name(),
            b.2.name(),
            a.1
        )
    } else {
        format!("{} lambda = {} vs {} ({rule})", a.2.name(), a.1, b.1)
    }
}

/// The ratio of characteristic times the derivation in reference/COARSE_GRAINING.md
/// predicts between two groups: 1 between codes and under the bulk-viscosity rule; under the
/// seed rule between 1 (inertial collapse) and the lambda ratio (viscous collapse).
fn predicted_time_ratio(kind: &str, a: GroupKey, b: GroupKey) -> String {
    match (kind, rule_of(a.0)) {
        ("levels", CoarseGrainRule::Seed) => format!(
            "1 (inertial) to {} (viscous): bulk viscosity ~ lambda gamma/d",
            b.1 as f64 / a.1 as f64
        ),
        _ => "1".into(),
    }
}

fn compare(scene: &Scene, case: &SuiteCase, runs: &[RunRecord]) -> Vec<Comparison> {
    let groups = angles_by_group(runs);
    let flows = flows_by_group(scene, runs);
    let mut keys: Vec<GroupKey> = groups.keys().chain(flows.keys()).copied().collect();
    keys.sort();
    keys.dedup();
    let box_length = scene.domain.hi.x - scene.domain.lo.x;
    let known = |what: &str, criterion: &str| {
        case.known_differences
            .iter()
            .find(|k| k.applies_to(what, criterion))
    };
    let mut out = Vec::new();
    for (kind, a, b) in comparison_pairs(&keys) {
        let what = pair_name(kind, a, b);
        let stats = |k| groups.get(&k).and_then(|v| mean_sd(v));
        if let (Some((ma, sa, na)), Some((mb, sb, nb))) = (stats(a), stats(b)) {
            let angle = Criterion::judge(
                "repose angle",
                "deg",
                (ma - mb).abs(),
                combined_standard_error((sa, na), (sb, nb)),
                [na, nb],
                case.angle_tolerance_deg,
                known(&what, "repose angle"),
            );
            out.push(Comparison::judged(
                &scene.name,
                kind,
                "final state",
                &what,
                format!(
                    "repose angle {ma:.1} +- {sa:.1} ({na} seeds) vs {mb:.1} +- {sb:.1} ({nb} seeds) deg"
                ),
                vec![angle],
            ));
        }
        if let (Some(fa), Some(fb)) = (flows.get(&a), flows.get(&b)) {
            if let Some(c) = compare_flows(scene, case, kind, &what, (a, fa), (b, fb), box_length) {
                out.push(c);
            }
        }
    }
    out
}

/// The dynamics part of a comparison, four criteria: the ratio of the seeds' mean `t_half`
/// (judged as |ratio - 1|), and the largest gaps between the seed-mean histories of the
/// front (of the box length), the height at the remaining wall (of its initial height) and
/// the kinetic energy (of its peak); each against its tolerance plus `K_NOISE` times the
/// noise the seeds show.
fn compare_flows(
    scene: &Scene,
    case: &SuiteCase,
    kind: &str,
    what: &str,
    (a, fa): (GroupKey, &Vec<FlowSeries>),
    (b, fb): (GroupKey, &Vec<FlowSeries>),
    box_length: f64,
) -> Option<Comparison> {
    let ta: Vec<f64> = fa.iter().filter_map(FlowSeries::t_half).collect();
    let tb: Vec<f64> = fb.iter().filter_map(FlowSeries::t_half).collect();
    let step = FLOW_GRID_S;
    let mean_a = FlowSeries::mean(fa, step)?;
    let mean_b = FlowSeries::mean(fb, step)?;
    let gap = flow_difference(&mean_a, &mean_b, box_length, step)?;
    let noise = flow_noise(fa, fb, box_length, step)?;
    let seeds = [fa.len(), fb.len()];
    let known = |criterion: &str| {
        case.known_differences
            .iter()
            .find(|k| k.applies_to(what, criterion))
    };
    let mut criteria = Vec::new();
    // t_half exists only where the front moved; without it on a side, the gaps still judge.
    let t_half_text = match (mean_sd(&ta), mean_sd(&tb)) {
        (Some((ma, sa, na)), Some((mb, sb, nb))) => {
            let ratio = mb / ma;
            // Standard error of the ratio from the relative standard errors of the means.
            let ratio_noise = ratio * combined_standard_error((sa / ma, na), (sb / mb, nb));
            criteria.push(Criterion::judge(
                "t_half ratio",
                "|ratio - 1|",
                (ratio - 1.0).abs(),
                ratio_noise,
                [na, nb],
                case.time_ratio_tolerance,
                known("t_half ratio"),
            ));
            format!(
                "t_half {ma:.3} +- {sa:.3} s vs {mb:.3} +- {sb:.3} s: ratio {ratio:.2} (predicted {})",
                predicted_time_ratio(kind, a, b)
            )
        }
        _ => format!(
            "t_half not measured (the front did not move in {} of {} and {} of {} runs)",
            fa.len() - ta.len(),
            fa.len(),
            fb.len() - tb.len(),
            fb.len()
        ),
    };
    criteria.extend([
        Criterion::judge(
            "front gap",
            "of the box length",
            gap.front_max,
            noise.front,
            seeds,
            case.front_tolerance,
            known("front gap"),
        ),
        Criterion::judge(
            "wall height gap",
            "of the initial height",
            gap.wall_height_max,
            noise.wall_height,
            seeds,
            case.wall_height_tolerance,
            known("wall height gap"),
        ),
        Criterion::judge(
            "kinetic energy gap",
            "of the peak",
            gap.kinetic_energy_max,
            noise.kinetic_energy,
            seeds,
            case.kinetic_energy_tolerance,
            known("kinetic energy gap"),
        ),
    ]);
    Some(Comparison::judged(
        &scene.name,
        kind,
        "dynamics",
        what,
        format!(
            "{t_half_text}; gaps, largest over time (mean): front {:.3} ({:.3}) of the box \
             length, wall height {:.3} ({:.3}) of the initial height, kinetic energy {:.3} \
             ({:.3}) of the peak",
            gap.front_max,
            gap.front_mean,
            gap.wall_height_max,
            gap.wall_height_mean,
            gap.kinetic_energy_max,
            gap.kinetic_energy_mean,
        ),
        criteria,
    ))
}

/// Every successful run's flow during the measured stage, per group.
fn flows_by_group(scene: &Scene, runs: &[RunRecord]) -> BTreeMap<GroupKey, Vec<FlowSeries>> {
    let mut groups: BTreeMap<GroupKey, Vec<FlowSeries>> = BTreeMap::new();
    let Some(stage) = scene.repose.as_ref().map(|r| r.stage.as_str()) else {
        return groups;
    };
    for r in runs.iter().filter(|r| r.status == Outcome::Ok) {
        if let Some(flow) = FlowSeries::read(&r.dir, stage) {
            groups
                .entry((r.cg_rule as u8, r.lambda, r.code))
                .or_default()
                .push(flow);
        }
    }
    groups
}

/// The `(x_m, height_m)` rows of a run's `profile.csv`; none when the run wrote no profile.
fn read_profile(path: &Path, case: &SuiteCase) -> Result<Vec<Vec<f64>>, ValidateError> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    CsvTable::read(path)
        .and_then(|t| t.numbers(&["x_m", "height_m"]))
        .map_err(|e| ValidateError::Case {
            file: case.file.clone(),
            message: e.to_string(),
        })
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
    let ok_runs: Vec<&RunRecord> = runs.iter().filter(|r| r.status == Outcome::Ok).collect();

    // Heap profiles, averaged over seeds per code, level and rule.
    let mut profiles = Figure::new(
        format!("{}: heap profiles (mean over seeds)", scene.name),
        "distance from the remaining wall x [m]",
        "surface height h(x) [m]",
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
            for (k, row) in read_profile(&r.dir.join("profile.csv"), case)?
                .iter()
                .enumerate()
            {
                let (x, h) = (row[0], row[1]);
                if k < sum.len() {
                    sum[k].1 += h;
                } else {
                    sum.push((x, h));
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

    write_similarity(section, scene, case, runs, comparisons, &dir)?;
    let rule = scene.repose.as_ref().map(|_| {
        "The repose angle is measured by the rule stated in each run's summary.json (repose_rule)."
    });
    if let Some(rule) = rule {
        section.paragraph(rule);
    }
    Ok(())
}

/// The case's similarity section: for every compared pair, the final state and the dynamics
/// judged separately (a pair is similar only if both pass), and the flow histories behind the
/// dynamics, mean over seeds, one line per code, level and rule.
fn write_similarity(
    section: &mut crate::report::Section,
    scene: &Scene,
    case: &SuiteCase,
    runs: &[RunRecord],
    comparisons: &[Comparison],
    dir: &Path,
) -> Result<(), ValidateError> {
    let figure_error = |e: crate::report::PlotError| output_error(dir, e);
    let sub = section.subsection("Similarity: final state and dynamics");
    sub.paragraph(format!(
        "A pair of codes or levels is similar only if both its final state and its dynamics \
         agree. Final state: the repose angles of the seed means within {} deg. Dynamics: the \
         characteristic time t_half (time for the front to cover half its largest advance \
         after the gate opens, mean over seeds) in a ratio within 1 +- {}; the seed-mean \
         histories of the front within {} of the box length, of the height at the wall within \
         {} of its initial height and of the kinetic energy within {} of its peak, at all \
         times. Each tolerance is widened by {} combined standard errors of the seeds (the \
         noise); declared known differences are judged by their bands. The predicted time \
         ratios are derived in reference/COARSE_GRAINING.md.",
        case.angle_tolerance_deg,
        case.time_ratio_tolerance,
        case.front_tolerance,
        case.wall_height_tolerance,
        case.kinetic_energy_tolerance,
        super::verdict::K_NOISE
    ));
    let mut table = Table::new(["pair", "final state", "dynamics", "similar", "numbers"])
        .caption("Final-state and dynamic similarity, judged separately");
    let mut pairs: Vec<&str> = comparisons.iter().map(|c| c.what.as_str()).collect();
    pairs.dedup();
    for what in pairs {
        let part = |name: &str| {
            comparisons
                .iter()
                .find(|c| c.what == what && c.part == name)
        };
        let verdict = |c: Option<&Comparison>| match c {
            Some(c) => verdict_cell(
                c.verdict,
                match c.verdict {
                    Verdict::Pass => "agrees".to_string(),
                    Verdict::KnownDifference => {
                        format!("known difference ({})", c.decided_by)
                    }
                    Verdict::Fail => format!("differs ({})", c.decided_by),
                },
            ),
            None => Cell::skipped("not measured"),
        };
        let (fs, dy) = (part("final state"), part("dynamics"));
        let similar = match (fs.map(|c| c.pass), dy.map(|c| c.pass)) {
            (Some(true), Some(true)) => Cell::pass("yes"),
            (Some(false), Some(false)) => Cell::fail("no: final state and dynamics"),
            (Some(false), _) => Cell::fail("no: final state"),
            (_, Some(false)) => Cell::fail("no: dynamics"),
            _ => Cell::skipped("incomplete"),
        };
        let numbers = [fs, dy]
            .iter()
            .flatten()
            .map(|c| {
                let parts: Vec<String> = c.criteria.iter().map(|x| x.describe()).collect();
                format!("{}; {}", c.detail, parts.join("; "))
            })
            .collect::<Vec<_>>()
            .join(". ");
        table.row([
            Cell::text(what),
            verdict(fs),
            verdict(dy),
            similar,
            Cell::text(numbers),
        ]);
    }
    sub.table(table);

    let flows = flows_by_group(scene, runs);
    let time_axis = "time after the gate opens t [s]";
    let mut front = Figure::new(
        format!("{}: front position (mean over seeds)", scene.name),
        time_axis,
        "front position x_f [m]",
    );
    let mut height = Figure::new(
        format!(
            "{}: height at the remaining wall (mean over seeds)",
            scene.name
        ),
        time_axis,
        "wall height h_w [m]",
    );
    let mut energy = Figure::new(
        format!("{}: kinetic energy (mean over seeds)", scene.name),
        time_axis,
        "kinetic energy per mass [J/kg]",
    )
    .log_y();
    for (&(rule, lambda, code), series) in &flows {
        let Some(mean) = FlowSeries::mean(series, FLOW_GRID_S) else {
            continue;
        };
        let name = label(code, lambda, rule_of(rule));
        let points = |v: &[f64]| {
            mean.time_s
                .iter()
                .copied()
                .zip(v.iter().copied())
                .collect::<Vec<_>>()
        };
        front
            .series
            .push(Series::new(name.clone(), points(&mean.front_m)).style(SeriesStyle::Line));
        height
            .series
            .push(Series::new(name.clone(), points(&mean.wall_height_m)).style(SeriesStyle::Line));
        let positive = points(&mean.kinetic_energy_per_mass)
            .into_iter()
            .filter(|p| p.1 > 0.0)
            .collect();
        energy
            .series
            .push(Series::new(name, positive).style(SeriesStyle::Line));
    }
    // The repose angle at the fixed times after the gate opens, mean and spread over seeds.
    let mut angle = Figure::new(
        format!(
            "{}: repose angle at fixed times (mean over seeds)",
            scene.name
        ),
        time_axis,
        "repose angle [deg]",
    );
    let mut keys: Vec<GroupKey> = runs
        .iter()
        .filter(|r| r.status == Outcome::Ok)
        .map(|r| (r.cg_rule as u8, r.lambda, r.code))
        .collect();
    keys.sort();
    keys.dedup();
    for key in keys {
        let mut by_time: BTreeMap<u64, Vec<f64>> = BTreeMap::new();
        for r in runs
            .iter()
            .filter(|r| r.status == Outcome::Ok && (r.cg_rule as u8, r.lambda, r.code) == key)
        {
            for (t, a) in fixed_time_angles(&r.dir) {
                by_time.entry(t.to_bits()).or_default().push(a);
            }
        }
        let (points, errors): (Vec<(f64, f64)>, Vec<f64>) = by_time
            .iter()
            .filter_map(|(t, v)| mean_spread(v).map(|(m, s)| ((f64::from_bits(*t), m), s)))
            .unzip();
        if !points.is_empty() {
            angle.series.push(
                Series::new(label(key.2, key.1, rule_of(key.0)), points)
                    .y_err(errors)
                    .style(SeriesStyle::LineMarkers),
            );
        }
    }
    for (stem, fig, title, caption) in [
        ("front_position", &front, "front position against time", "Furthest point where the deposit is at least two diameters deep, against time after the gate opens; mean over seeds (a run that came to rest holds its last value)."),
        ("wall_height", &height, "height at the remaining wall against time", "Surface height next to the remaining wall; mean over seeds."),
        ("kinetic_energy", &energy, "kinetic energy against time", "Kinetic energy per unit mass; mean over seeds."),
        ("angle_vs_time", &angle, "repose angle at fixed times", "Repose angle by the case's rule at fixed times after the gate opens (the heap is still flowing at the early ones); error bars are the spread over seeds."),
    ] {
        let files = write_figure(dir, stem, fig).map_err(figure_error)?;
        sub.figure(&files, title, caption).map_err(|e| output_error(dir, e))?;
    }
    Ok(())
}

/// (time after the stage start, angle) of a run's fixed-time repose samples.
fn fixed_time_angles(dir: &Path) -> Vec<(f64, f64)> {
    let Ok(text) = std::fs::read_to_string(dir.join("summary.json")) else {
        return Vec::new();
    };
    let Ok(value) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Vec::new();
    };
    value
        .get("repose_samples")
        .and_then(|v| v.as_array())
        .map(|samples| {
            samples
                .iter()
                .filter(|s| s.get("trigger").and_then(|v| v.as_str()) == Some("fixed time"))
                .filter_map(|s| {
                    Some((
                        s.get("time_after_start_s")?.as_f64()?,
                        s.get("repose_angle_deg")?.as_f64()?,
                    ))
                })
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A finished run of `code` and `seed` whose collapse front moves as `front(t)` and whose
    /// final repose angle is `angle`, written to a temporary directory.
    fn fake_run(
        root: &Path,
        code: Code,
        seed: u64,
        angle: f64,
        front: impl Fn(f64) -> f64,
    ) -> RunRecord {
        let dir = root.join(format!("{}-{seed}", code.name()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut csv = cgdem_core::io::CsvBuffer::new([
            "time_s",
            "stage",
            "front_m",
            "wall_height_m",
            "kinetic_energy_per_mass_j_kg",
        ]);
        for i in 0..=50 {
            let t = i as f64 * 0.01;
            let ke = (t * (0.6 - t)).max(1e-6);
            csv.row([
                (1.0 + t).to_string(),
                "collapse".into(),
                front(t).to_string(),
                (0.135 - 0.2 * (front(t) - 0.1)).to_string(),
                ke.to_string(),
            ]);
        }
        std::fs::write(dir.join("timeseries.csv"), csv.bytes().unwrap()).unwrap();
        let mut r = RunRecord::ok(
            "aor_hertz_smoke".into(),
            code,
            1,
            CoarseGrainRule::Seed,
            seed,
            dir,
        );
        r.repose_angle_deg = Some(angle);
        r.reused = true;
        r
    }

    fn judge(extra: &str, lammps_front: f64, lammps_angle: f64) -> Vec<Comparison> {
        crate::at_repo_root();
        let root = std::env::temp_dir().join(format!(
            "cgdem-verdicts-{}-{}",
            std::process::id(),
            lammps_front.to_bits() ^ lammps_angle.to_bits()
        ));
        let text = format!(
            "name = \"t\"\n[[case]]\nfile = \"validation/cases/aor_hertz_smoke.toml\"\ncodes = [\"cgdem\", \"lammps\"]\nlambdas = [1]\nseeds = [1, 2]\nangle_tolerance_deg = 2.0\n{extra}"
        );
        let suite = Suite::parse(&text, Path::new("t.toml")).unwrap();
        let case = &suite.cases[0];
        let scene = case.load_scene().unwrap();
        // Fronts advancing 0.2 m in 0.5 s; seeds 0.005 m apart; the box is 0.5 m long.
        let runs = vec![
            fake_run(&root, Code::Cgdem, 1, 14.0, |t| 0.1 + 0.4 * t),
            fake_run(&root, Code::Cgdem, 2, 14.4, |t| 0.105 + 0.4 * t),
            fake_run(&root, Code::Lammps, 1, lammps_angle, move |t| {
                0.1 + 0.4 * t + lammps_front * t
            }),
            fake_run(&root, Code::Lammps, 2, lammps_angle + 0.4, move |t| {
                0.105 + 0.4 * t + lammps_front * t
            }),
        ];
        let out = compare(&scene, case, &runs);
        let _ = std::fs::remove_dir_all(&root);
        out
    }

    #[test]
    fn the_same_runs_pass_and_a_shifted_front_fails_by_its_own_criterion() {
        let same = judge("", 0.0, 14.0);
        assert_eq!(same.len(), 2, "{same:?}");
        assert!(same.iter().all(|c| c.verdict == Verdict::Pass), "{same:?}");
        // The front runs 0.1 m further by the end: 0.2 of the box length.
        let moved = judge("", 0.2, 14.0);
        let dynamics = moved.iter().find(|c| c.part == "dynamics").unwrap();
        assert_eq!(dynamics.verdict, Verdict::Fail);
        let front = dynamics
            .criteria
            .iter()
            .find(|c| c.name == "front gap")
            .unwrap();
        assert!((front.value - 0.2).abs() < 1e-9, "{front:?}");
        // Seeds 0.005 m apart on both sides: noise sqrt(2 * 0.0025^2) / 0.5 of the box.
        assert!(
            (front.noise - 2f64.sqrt() * 0.0025 / 0.5).abs() < 1e-9,
            "{front:?}"
        );
        assert!(dynamics.decided_by == "front gap" || dynamics.decided_by == "wall height gap");
        let angle = moved.iter().find(|c| c.part == "final state").unwrap();
        assert_eq!(angle.verdict, Verdict::Pass);
    }

    #[test]
    fn a_declared_difference_is_amber_in_its_band_and_red_outside() {
        let declared = "[[case.known_difference]]\ncomparison = \"cgdem vs lammps\"\ncriterion = \"repose angle\"\nreason = \"r\"\nevidence = \"reference/lammps/SEED_MODEL.md\"\nband = [5.0, 30.0]\n";
        let inside = judge(declared, 0.0, 29.0);
        let angle = inside.iter().find(|c| c.part == "final state").unwrap();
        assert_eq!(angle.verdict, Verdict::KnownDifference, "{angle:?}");
        assert!(angle.pass);
        let outside = judge(declared, 0.0, 50.0);
        let angle = outside.iter().find(|c| c.part == "final state").unwrap();
        assert_eq!(angle.verdict, Verdict::Fail, "{angle:?}");
        // Undeclared, 15 deg is a plain failure.
        let plain = judge("", 0.0, 29.0);
        assert_eq!(
            plain
                .iter()
                .find(|c| c.part == "final state")
                .unwrap()
                .verdict,
            Verdict::Fail
        );
    }

    #[test]
    fn concurrent_runs_take_every_item_once_and_keep_the_order() {
        let items: Vec<u32> = (0..17).collect();
        for jobs in [1, 2, 3, 40] {
            let calls = AtomicUsize::new(0);
            let out = run_concurrently(&items, jobs, |&k| {
                calls.fetch_add(1, Ordering::Relaxed);
                (k * k, rayon::current_num_threads())
            });
            assert_eq!(calls.load(Ordering::Relaxed), items.len(), "jobs {jobs}");
            let squares: Vec<u32> = out.iter().map(|o| o.0).collect();
            assert_eq!(squares, items.iter().map(|k| k * k).collect::<Vec<_>>());
            if jobs > 1 {
                // Each job's pool holds its share of the threads, at least one.
                let share = (rayon::current_num_threads() / jobs).max(1);
                assert!(out.iter().all(|o| o.1 == share), "jobs {jobs}: {out:?}");
            }
        }
    }
}
