//! The validation report: the first screen (status, criteria table, runs, provenance) and
//! one section per case (heap profiles, angles, similarity of every compared pair with the
//! flow histories behind it).

use std::collections::BTreeMap;
use std::path::Path;

use super::{Comparison, ValidationSummary};
use crate::quantity::flow::flow_figures;
use crate::quantity::repose::{angle_at_times_figure, angles_figure, profiles_figure};
use crate::quantity::seeds::{mean_spread, Group};
use crate::report::{write_bar_chart, write_figure, Cell, Report, Table};
use crate::runs::{output_error, Outcome, RunRecord, ValidateError, ValidateOptions};
use crate::suite::{Suite, SuiteCase};
use crate::verdict::Verdict;
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::Scene;

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
         error of the two sides from their seeds (0 where a side has one seed; a screw's \
         mass flow: the two sides' standard errors added, each from its runs' blocks or its \
         seeds' spread; a silo's discharge rate and a drum's counts and angle: inside the \
         value); a declared known difference is judged by its band instead (amber inside, \
         red outside). The comparison's verdict is its worst criterion's.",
        crate::verdict::K_NOISE
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
                    crate::verdict::fmt(kd.band[0]),
                    crate::verdict::fmt(kd.band[1])
                ),
                None => crate::verdict::fmt(crit.threshold),
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
                Cell::num(crate::verdict::fmt(crit.value)),
                Cell::num(crate::verdict::fmt(crit.noise)),
                Cell::num(format!("{}+{}", crit.seeds[0], crit.seeds[1])),
                Cell::num(crate::verdict::fmt(crit.tolerance)),
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
    let counts = super::StatusCounts::of(summary);
    let status = match summary.status {
        super::Status::Green => Status::Pass,
        super::Status::Amber => Status::Known,
        super::Status::Incomplete => Status::Skipped,
        super::Status::Red => Status::Fail,
    };
    let failed_runs: Vec<&RunRecord> = summary
        .runs
        .iter()
        .filter(|r| r.status == Outcome::Failed)
        .collect();
    let mut line = format!(
        "Status: {}. {} comparisons fail, {} are known differences inside their bands, {} \
         pass; {} of {} runs failed",
        summary.status.word(),
        counts.failed_comparisons,
        counts.known_differences,
        counts.passed_comparisons,
        counts.failed_runs,
        summary.runs.len()
    );
    if !summary.stability.is_empty() {
        line += &format!(
            "; {} cgdem stability verdicts failed",
            counts.failed_stability
        );
    }
    if counts.skipped_runs + counts.skipped_stability > 0 {
        line += &format!(
            "; {} runs not made, so their comparisons are missing (listed below)",
            counts.skipped_runs + counts.skipped_stability
        );
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
    let not_made = super::status::not_made(summary);
    if !not_made.is_empty() {
        intro.paragraph("Runs not made (their comparisons are missing; the status is incomplete):");
        intro.list(not_made.into_iter().map(Cell::text).collect());
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
            let (text, items) = crate::history::since_previous(dir, &options.out, &value);
            intro.paragraph(text);
            if !items.is_empty() {
                intro.list(items.into_iter().map(Cell::text).collect());
            }
        }
    }
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or(String::from("-"), |x| format!("{x:.digits$}"))
}

pub(super) fn provenance(suite: &Suite, options: &ValidateOptions) -> BTreeMap<String, String> {
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

pub(super) fn write_case_section(
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
    let mut keys: Vec<Group> = ok_runs
        .iter()
        .map(|r| (r.cg_rule, r.lambda, r.code))
        .collect();
    keys.sort_by_key(|k| (k.0 as u8, k.1, k.2));
    keys.dedup();
    let profiles = profiles_figure(scene, &case.file, &ok_runs, &keys)?;
    let files = write_figure(&dir, "profiles", &profiles).map_err(figure_error)?;
    section.figure(&files, "heap profiles", "Free-surface height against distance from the remaining wall at the measurement time, averaged over seeds.").map_err(|e| output_error(&dir, e))?;

    // Repose angle per level with seed spread.
    let angles = angles_figure(scene, runs);
    let files = write_figure(&dir, "repose_angle", &angles).map_err(figure_error)?;
    section.figure(&files, "repose angle per level", "Mean repose angle over seeds; error bars are the sample standard deviation across seeds.").map_err(|e| output_error(&dir, e))?;

    let bars = throughput_bars(&ok_runs, &keys);
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

/// At the end of the case's section (written last): per code, what it could not express (its
/// comparisons not made) and what its runs noted (a deck's approximations of the scene).
pub(super) fn write_code_notes(report: &mut Report, runs: &[RunRecord]) {
    let Some(section) = report.last_section() else {
        return;
    };
    for c in crate::runs::notes_by_code(runs) {
        section.paragraph(format!("{} runs:", c.code.label()));
        let unsupported = (c.unsupported.iter())
            .map(|r| Cell::skipped(format!("not compared, cannot express the case: {r}")));
        let notes = c.notes.iter().map(Cell::text);
        section.list(unsupported.chain(notes).collect());
    }
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
    sub.paragraph(similarity_rule(case));
    let table = similarity_table(comparisons);
    sub.table(table);

    let [front, height, energy] = flow_figures(scene, runs);
    let angle = angle_at_times_figure(scene, runs);
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

/// Throughput per code, level and rule (`keys`): mean and spread over seeds.
fn throughput_bars(
    ok_runs: &[&RunRecord],
    keys: &[Group],
) -> Vec<(String, String, f64, Option<f64>)> {
    keys.iter()
        .filter_map(|&(rule, lambda, code)| {
            let values: Vec<f64> = ok_runs
                .iter()
                .filter(|r| (r.cg_rule, r.lambda, r.code) == (rule, lambda, code))
                .filter_map(|r| r.particle_steps_per_s)
                .collect();
            let (mean, spread) = mean_spread(&values)?;
            let group = match rule {
                CoarseGrainRule::RelativeOverlap => format!("lambda={lambda}"),
                other => format!("lambda={lambda} {}", other.name()),
            };
            Some((group, code.name().to_string(), mean, Some(spread)))
        })
        .collect()
}

/// What makes a pair similar, with the case's tolerances.
fn similarity_rule(case: &SuiteCase) -> String {
    format!(
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
        crate::verdict::K_NOISE
    )
}

/// One row per compared pair: its final state and dynamics verdicts and their numbers.
fn similarity_table(comparisons: &[Comparison]) -> Table {
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
    table
}

/// The first screen: the status, what the suite is, the criteria and runs tables and the
/// provenance.
pub(super) fn write_intro(
    report: &mut Report,
    summary: &ValidationSummary,
    suite: &Suite,
    options: &ValidateOptions,
    warnings: &[String],
) {
    let intro = report.intro();
    write_status(intro, summary, options);
    for w in warnings {
        intro.banner(crate::report::Status::Known, format!("Warning: {w}"));
    }
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
            Outcome::Unsupported => Cell::skipped(format!(
                "unsupported: {}",
                r.reason.clone().unwrap_or_default()
            )),
            Outcome::Failed => {
                Cell::fail(format!("failed: {}", r.reason.clone().unwrap_or_default()))
            }
        };
        run_table.row([
            Cell::text(&r.case),
            Cell::text(r.code.name()),
            Cell::num(r.lambda.to_string()),
            Cell::text(r.cg_rule.name()),
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
}
