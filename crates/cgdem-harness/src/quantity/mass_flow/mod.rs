//! A screw feeder's mass flow (a scene with `[conveying]`): every code's flow is measured
//! the same way (`analysis::conveying`: cgdem from its state, LIGGGHTS and LAMMPS from their
//! dumps, `decks::postprocess::conveying_samples`) into each run's `summary.json`, with its
//! block-average standard error and Eq. (7) at the run's measured fill ratio. Here: the
//! mean over seeds at each speed; cgdem's flow judged against each reference code's at each
//! speed (`verdict`); and the case's section: the verdicts, mass flow against screw speed
//! for every code beside Eq. (7) (Hirose, Fig. 8), and a table of the numbers.

mod verdict;

pub use verdict::{flow_verdicts, FlowSide, FlowVerdict, FlowVerdicts, CRITERION, PART};

use std::path::Path;

use super::seeds::mean_with_block_error;
use super::{show_figure, CaseOrigin};
use crate::code::Code;
use crate::report::{Cell, Figure, Report, Section, Series, SeriesStyle, Status, Table};
use crate::runs::{Outcome, RunRecord, ValidateError};
use crate::verdict::{Verdict, K_NOISE};
use cgdem_core::scene::Scene;

/// A run's conveying measurement `key` (`mass_flow_kg_s`, `eq7_mass_flow_kg_s`, ...) from
/// its `summary.json`, when finite.
pub fn conveying_value(summary: &serde_json::Value, key: &str) -> Option<f64> {
    summary["conveying"][key].as_f64().filter(|v| v.is_finite())
}

/// One code's points at one speed: the mean over seeds of the flow, its standard error
/// (the block errors combined, `sqrt(sum se^2) / n`) and Eq. (7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedPoint {
    pub rpm: f64,
    pub mass_flow_kg_s: f64,
    pub std_error_kg_s: f64,
    pub eq7_mass_flow_kg_s: f64,
}

/// Per code, its points in order of speed (runs without a measurement left out).
pub fn points_by_code(runs: &[RunRecord]) -> Vec<(Code, Vec<SpeedPoint>)> {
    let mut out: Vec<(Code, Vec<SpeedPoint>)> = Vec::new();
    for code in [Code::Cgdem, Code::Liggghts, Code::Lammps] {
        let mut speeds: Vec<f64> = runs
            .iter()
            .filter(|r| r.code == code)
            .filter_map(|r| r.rpm)
            .collect();
        speeds.sort_by(f64::total_cmp);
        speeds.dedup();
        let mut points = Vec::new();
        for rpm in speeds {
            let at: Vec<&RunRecord> = runs
                .iter()
                .filter(|r| r.code == code && r.rpm == Some(rpm) && r.status == Outcome::Ok)
                .filter(|r| r.mass_flow_kg_s.is_some())
                .collect();
            // A run without its block error adds none.
            let flows: Vec<(f64, f64)> = at
                .iter()
                .filter_map(|r| {
                    Some((r.mass_flow_kg_s?, r.mass_flow_std_error_kg_s.unwrap_or(0.0)))
                })
                .collect();
            let Some((mass_flow_kg_s, std_error_kg_s)) = mean_with_block_error(&flows) else {
                continue;
            };
            let n = at.len() as f64;
            let eq7 = at.iter().filter_map(|r| r.eq7_mass_flow_kg_s).sum::<f64>() / n;
            points.push(SpeedPoint {
                rpm,
                mass_flow_kg_s,
                std_error_kg_s,
                eq7_mass_flow_kg_s: eq7,
            });
        }
        if !points.is_empty() {
            out.push((code, points));
        }
    }
    out
}

/// Per code of `runs`, its mass flow against speed with error bars and its Eq. (7) line
/// (dashed), labelled `label(code)`.
fn with_speed_series(
    mut figure: Figure,
    runs: &[RunRecord],
    label: impl Fn(Code) -> String,
) -> Figure {
    for (code, points) in points_by_code(runs) {
        figure = figure
            .with_series(
                Series::new(
                    label(code),
                    points.iter().map(|p| (p.rpm, p.mass_flow_kg_s)).collect(),
                )
                .style(SeriesStyle::LineMarkers)
                .y_err(points.iter().map(|p| p.std_error_kg_s).collect()),
            )
            .with_series(
                Series::new(
                    format!("Eq. (7), {} fill", label(code)),
                    points
                        .iter()
                        .map(|p| (p.rpm, p.eq7_mass_flow_kg_s))
                        .collect(),
                )
                .style(SeriesStyle::Dashed),
            );
    }
    figure
}

/// One figure of every screw case of a suite together (e.g. the mesh screw in cgdem and
/// LIGGGHTS and the particle screw in cgdem and LAMMPS, which has no mesh walls): each code
/// and case its own series, with its Eq. (7) line; under `figures/screw_overview/`.
pub fn write_screw_overview(
    report: &mut Report,
    cases: &[(&Scene, &[RunRecord])],
    out: &Path,
) -> Result<(), ValidateError> {
    let mut figure = Figure::new(
        "Screw feeder: mass flow against speed, every code and screw (Hirose, Fig. 8)",
        "screw speed (rpm)",
        "mass flow (kg/s)",
    );
    for (scene, runs) in cases {
        figure = with_speed_series(figure, runs, |code| {
            format!("{}, {}", code.name(), scene.name)
        });
    }
    if figure.series.is_empty() {
        return Ok(());
    }
    let names: Vec<&str> = cases.iter().map(|(s, _)| s.name.as_str()).collect();
    let section = report.section("Screw feeder: every code in one figure");
    section.paragraph(format!(
        "The screw cases {names:?} together: each code with the screw it can run (LIGGGHTS takes mesh walls only, LAMMPS has no mesh walls and runs the screw built of particles), measured by the same rule; the numbers are in each case's section. Dashed: Eq. (7) with each run's measured fill ratio."
    ));
    let dir = out.join("figures").join("screw_overview");
    show_figure(
        section,
        &dir,
        "mass_flow_vs_rpm",
        &figure,
        (
            "mass flow against screw speed, one series per code and screw case, with Eq. (7)",
            "Mass flow against screw speed for every code and screw case (mean over seeds), with Eq. (7) for each one's measured fill ratio.",
        ),
    )
}

/// The section: the verdicts, the figure (PNG, SVG and CSV under `figures/<case>/`) and
/// the table.
pub fn write_screw_section(
    report: &mut Report,
    scene: &Scene,
    case: &CaseOrigin,
    runs: &[RunRecord],
    verdicts: &FlowVerdicts,
    out: &Path,
) -> Result<(), ValidateError> {
    let dir = out.join("figures").join(&scene.name);
    let section = report.section(format!(
        "Case {}: mass flow against screw speed",
        scene.name
    ));
    let flow_rule = scene
        .conveying
        .as_ref()
        .map(cgdem_core::analysis::conveying::flow_rule)
        .unwrap_or_default();
    section.paragraph(format!(
        "{} Scene file: {}. Speeds: {:?} rpm (the conveying stage and its discarded start-up scaled to the same number of turns at every speed). Seeds: {:?}. Mass flow {flow_rule}, the same rule for every code (LIGGGHTS and LAMMPS from their dumps: a grain that vanishes counts as deleted with its mass); error bars: block-average standard error. Dashed: Eq. (7) with the code's measured fill ratio, (pi/4)(Ds^2 - ds^2) ps ns rho_p times the solid fill ratio.",
        scene.description,
        case.file.display(),
        case.rpms,
        case.seeds
    ));
    write_verdicts(section, verdicts);
    if case.keep_going {
        section.paragraph("cgdem's guards only warn in this case (suite entry `keep_going = true`): grains wedge between the flight's tip and the casing, a clearance narrower than a grain, deeper than the overlap guard allows; the warnings and the deepest overlap are in each run's summary.json.");
    }
    let mut figure = Figure::new(
        "Screw feeder: mass flow against speed (Hirose, Fig. 8)",
        "screw speed (rpm)",
        "mass flow (kg/s)",
    );
    figure = with_speed_series(figure, runs, |code| code.name().to_string());
    if !figure.series.is_empty() {
        show_figure(
            section,
            &dir,
            "mass_flow_vs_rpm",
            &figure,
            (
                "mass flow against screw speed, one series per code, with Eq. (7)",
                "Mass flow against screw speed per code (mean over seeds), with Eq. (7) for each code's measured fill ratio.",
            ),
        )?;
    }
    let mut table = Table::new([
        "code",
        "rpm",
        "seed",
        "status",
        "mass flow (kg/s)",
        "std error (kg/s)",
        "fill ratio",
        "bulk density (kg/m3)",
        "Eq. (7) (kg/s)",
        "flow / Eq. (7)",
        "wall s",
    ])
    .caption("Screw runs: the conveying measurement of every code and speed");
    let num = |v: Option<f64>, digits: usize| {
        Cell::num(v.map_or("-".into(), |x| format!("{x:.digits$}")))
    };
    for r in runs {
        let status = match r.status {
            Outcome::Ok if r.partial => Cell::skipped(r.reason.clone().unwrap_or_default()),
            Outcome::Ok => Cell::pass("ok"),
            Outcome::Skipped | Outcome::Unsupported => {
                Cell::skipped(r.reason.clone().unwrap_or_default())
            }
            Outcome::Failed => Cell::fail(r.reason.clone().unwrap_or_default()),
        };
        table.row([
            Cell::text(r.code.name()),
            num(r.rpm, 0),
            Cell::num(r.seed.to_string()),
            status,
            num(r.mass_flow_kg_s, 3),
            num(r.mass_flow_std_error_kg_s, 3),
            num(r.fill_ratio, 3),
            num(r.bulk_density_kg_m3, 0),
            num(r.eq7_mass_flow_kg_s, 3),
            num(r.ratio_to_eq7, 3),
            num(r.wall_s, 0),
        ]);
    }
    section.table(table);
    Ok(())
}

/// The verdicts of a screw case: a banner with the worst, the rule, and a row per speed
/// (the speeds not compared too, with why).
fn write_verdicts(section: &mut Section, verdicts: &FlowVerdicts) {
    if verdicts.judged.is_empty() && verdicts.not_compared.is_empty() {
        return;
    }
    let (status, banner) = verdict_banner(verdicts);
    section.banner(status, banner);
    section.paragraph(verdict_rule(verdicts));
    section.table(verdict_table(verdicts));
}

/// The screw case's verdict in one line: the worst comparison's status and the counts.
fn verdict_banner(verdicts: &FlowVerdicts) -> (Status, String) {
    let worst = verdicts.judged.iter().map(|v| v.criterion.verdict).max();
    let counted = |verdict: Verdict| {
        verdicts
            .judged
            .iter()
            .filter(|v| v.criterion.verdict == verdict)
            .count()
    };
    let (status, word) = match worst {
        Some(Verdict::Fail) => (Status::Fail, "red"),
        Some(Verdict::KnownDifference) => (Status::Known, "amber"),
        Some(Verdict::Pass) => (Status::Pass, "green"),
        None => (Status::Skipped, ""),
    };
    let banner = if verdicts.judged.is_empty() {
        format!(
            "Mass flow, cgdem against the reference codes: not judged ({} comparisons not \
             made, listed below).",
            verdicts.not_compared.len()
        )
    } else {
        format!(
            "Mass flow, cgdem against the reference codes: {word} ({} speeds within the band, \
             {} known differences inside their bands, {} outside; {} not compared).",
            counted(Verdict::Pass),
            counted(Verdict::KnownDifference),
            counted(Verdict::Fail),
            verdicts.not_compared.len()
        )
    };
    (status, banner)
}

/// How the screw's verdict is made, in words (and what a one-seed band rests on).
fn verdict_rule(verdicts: &FlowVerdicts) -> String {
    let one_seed = verdicts
        .judged
        .iter()
        .any(|v| v.cgdem.seeds == 1 || v.reference.seeds == 1);
    let mut rule = format!(
        "Verdict, speed by speed: cgdem's mass flow against each reference code's that ran \
         the same screw, |cgdem - reference| over the reference code's flow. It passes when \
         the two flows, each widened by {K_NOISE} of its standard errors, meet (the silo's \
         discharge-rate rule): threshold = {K_NOISE} x (SE_cgdem + SE_reference) / reference. \
         No physical tolerance is added: the codes run the same grains, screw, feed and \
         window, so a difference beyond the noise is a finding, or a declared known \
         difference (amber inside its band). A side's standard error is its runs' \
         block-average errors combined, or, with several seeds, the standard error of the \
         seeds' spread when that is larger."
    );
    if one_seed {
        rule += &format!(
            " Where a code has one seed, the band rests on that one run: its standard error \
             is the block-average standard error of its own window ({} blocks, so the band \
             is itself uncertain); more seeds steady it.",
            verdicts.blocks
        );
    }
    rule
}

/// A row per judged speed, then a row per speed not compared, with why.
fn verdict_table(verdicts: &FlowVerdicts) -> Table {
    let mut table = Table::new([
        "comparison",
        "cgdem (kg/s)",
        "reference (kg/s)",
        "difference",
        "threshold",
        "seeds",
        "verdict",
    ])
    .caption("Mass flow verdicts: cgdem against each reference code, speed by speed");
    let side = |s: &FlowSide| format!("{:.3} +- {:.3}", s.mass_flow_kg_s, s.std_error_kg_s);
    for v in &verdicts.judged {
        let c = &v.criterion;
        let threshold = match &c.known_difference {
            Some(k) => format!(
                "band [{:.1}%, {:.1}%] +- {K_NOISE} x {:.1}%",
                100.0 * k.band[0],
                100.0 * k.band[1],
                100.0 * c.noise
            ),
            None => format!("{:.1}%", 100.0 * c.threshold),
        };
        let verdict = match (&c.known_difference, c.verdict) {
            (_, Verdict::Pass) => Cell::pass("pass"),
            (Some(k), Verdict::KnownDifference) => Cell::text(format!(
                "known difference: {} (evidence: {})",
                k.reason, k.evidence
            ))
            .status(Status::Known),
            (_, verdict) => Cell::fail(verdict.name()),
        };
        table.row([
            Cell::text(&v.what),
            Cell::num(side(&v.cgdem)),
            Cell::num(format!(
                "{} {}",
                v.reference.code.label(),
                side(&v.reference)
            )),
            Cell::num(format!(
                "{:+.1}%",
                100.0 * (v.cgdem.mass_flow_kg_s - v.reference.mass_flow_kg_s)
                    / v.reference.mass_flow_kg_s
            )),
            Cell::num(threshold),
            Cell::num(format!("{}+{}", v.cgdem.seeds, v.reference.seeds)),
            verdict,
        ]);
    }
    for (what, why) in &verdicts.not_compared {
        table.row([
            Cell::text(what),
            Cell::text("-"),
            Cell::text("-"),
            Cell::text("-"),
            Cell::text("-"),
            Cell::text("-"),
            Cell::skipped(format!("not compared: {why}")),
        ]);
    }
    table
}
