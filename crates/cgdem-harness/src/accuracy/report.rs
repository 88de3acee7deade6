//! The report of a sweep: its subsection with the points table and `points.csv`, one figure
//! per error measure and cost, the cheapest settings, and the coarse-graining matrix of a
//! sweep over lambda.

use std::path::Path;

use super::discharge::write_discharge_table;
use super::drum::write_drum_table;
use super::measurement::candidates;
use super::{
    cheapest_setting, measure_named, pareto_front, settings, AccuracyPoint, AccuracySweep,
    CheapestSetting, Cost, Knob, Measure, Setting, SettingMean, Targets, SPREAD_STANDARD_ERRORS,
};
use crate::code::Code;
use crate::report::{write_figure, Cell, Figure, Section, Series, SeriesStyle, Table};
use crate::runs::{output_error, Outcome, ValidateError};
use cgdem_core::io::{write_atomic, CsvBuffer};

fn fmt_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |x| format!("{x:.digits$}"))
}

/// The sweep's subsection: runs table, one figure per error measure, the cheapest settings.
pub(crate) fn write_sweep_section(
    section: &mut Section,
    sweep: &AccuracySweep,
    case: &str,
    points: &[AccuracyPoint],
    dir: &Path,
    note: Option<&str>,
) -> Result<Vec<CheapestSetting>, ValidateError> {
    let sub = section.subsection(format!("Case {case}"));
    if let Some(note) = note {
        sub.paragraph(note);
    }
    sub.paragraph(sweep_setup(sweep));
    let measures: Vec<Measure> = Measure::ALL
        .into_iter()
        .filter(|m| points.iter().any(|p| m.of(p).is_some()))
        .collect();
    let table = points_table(points, &measures);
    std::fs::create_dir_all(dir).map_err(|e| output_error(dir, e))?;
    let csv_path = dir.join("points.csv");
    points_csv(points)
        .bytes()
        .and_then(|bytes| write_atomic(&csv_path, bytes))
        .map_err(|e| output_error(&csv_path, e))?;
    let cheapest = write_error_figures(sub, sweep, case, &measures, points, dir)?;
    sub.table(cheapest_table(&cheapest));
    if sweep.series.iter().any(|s| s.knob == Knob::Lambda) {
        write_matrix(sub, case, &measures, &sweep.targets, points, dir)?;
    }
    if let Some(discharge) = &sweep.discharge {
        write_discharge_table(sub, discharge, points, dir)?;
    }
    if sweep.drum.is_some() {
        write_drum_table(sub, points, dir)?;
    }
    sub.table(table);
    Ok(cheapest)
}

/// The sentence that opens a sweep's subsection: its scene, variant, seeds and reference.
fn sweep_setup(sweep: &AccuracySweep) -> String {
    let reference = sweep
        .reference
        .iter()
        .map(|(k, v)| format!("{} = {v}", k.name()))
        .collect::<Vec<_>>()
        .join(", ");
    let shared = sweep
        .overrides
        .iter()
        .map(|o| o.key.clone())
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "Scene file {} with the overrides of variant `{}` ({}); insertion seeds {}. \
         Reference setting: {reference}, {} rule.",
        sweep.file.display(),
        sweep.variant,
        if shared.is_empty() { "none" } else { &shared },
        sweep
            .seeds
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        sweep.rule.name(),
    )
}

/// Every point's cost and errors, one column per error measure the sweep has.
fn points_table(points: &[AccuracyPoint], measures: &[Measure]) -> Table {
    let mut table = Table::new(
        [
            "code",
            "series",
            "setting",
            "seed",
            "status",
            "particles",
            "particle-steps",
            "wall s",
            "result",
        ]
        .into_iter()
        .map(String::from)
        .chain(measures.iter().map(|m| m.name().to_string())),
    )
    .caption("Every point: its cost and its errors");
    for p in points {
        let status = match p.status {
            Outcome::Ok if p.reused => Cell::pass("ok (reused)"),
            Outcome::Ok => Cell::pass("ok"),
            Outcome::Skipped => {
                Cell::skipped(format!("skipped: {}", p.reason.clone().unwrap_or_default()))
            }
            Outcome::Unsupported => Cell::skipped(format!(
                "unsupported: {}",
                p.reason.clone().unwrap_or_default()
            )),
            Outcome::Failed => {
                Cell::fail(format!("failed: {}", p.reason.clone().unwrap_or_default()))
            }
        };
        let result = match (p.repose_angle_deg, p.mass_flow_kg_s, p.porosity) {
            (Some(a), _, _) => format!("{a:.2} deg"),
            (_, Some(q), _) => format!("{q:.3} kg/s"),
            (_, _, Some(e)) => format!("porosity {e:.4}"),
            _ => match (p.discharge_rate_kg_s, p.flow_stopped_at_s) {
                (Some(w), None) => format!("discharge {w:.4} kg/s"),
                (Some(w), Some(t)) => format!("discharge {w:.4} kg/s, stopped at {t:.2} s"),
                _ => drum_result(p),
            },
        };
        table.row(
            [
                Cell::text(p.code.name()),
                Cell::text(&p.series),
                Cell::text(&p.setting),
                Cell::num(p.seed.to_string()),
                status,
                Cell::num(p.n_particles.map_or("-".into(), |n| n.to_string())),
                Cell::num(p.particle_steps.map_or("-".into(), |n| format!("{n:.3e}"))),
                Cell::num(fmt_opt(p.wall_s, 1)),
                Cell::num(result),
            ]
            .into_iter()
            .chain(
                measures
                    .iter()
                    .map(|m| Cell::num(m.of(p).map_or("-".into(), |v| m.format(v)))),
            ),
        );
    }
    table
}

/// `points.csv`: every point with every figure, empty where a point has none.
fn points_csv(points: &[AccuracyPoint]) -> CsvBuffer {
    let mut csv = CsvBuffer::new([
        "case",
        "code",
        "series",
        "knob_value",
        "setting",
        "lambda",
        "cg_rule",
        "seed",
        "status",
        "n_particles",
        "steps",
        "particle_steps",
        "wall_s",
        "repose_angle_deg",
        "angle_error_deg",
        "profile_distance",
        "mass_flow_kg_s",
        "mass_flow_error",
        "eq7_mass_flow_kg_s",
        "eq7_error",
        "t_half_s",
        "t_half_error",
        "porosity",
        "porosity_error",
        "pore_diameter_d",
        "pore_size_error",
        "front_error",
        "discharge_rate_kg_s",
        "discharge_rate_std_error_kg_s",
        "discharge_rate_error",
        "bulk_density_kg_m3",
        "particle_diameter_m",
        "flow_stopped_at_s",
        "dynamic_angle_deg",
        "dynamic_angle_error_deg",
        "mixing_period_s",
        "mixing_period_error",
        "mixing_index",
        "mixing_index_error",
        "large_share_zone1",
        "large_share_zone2",
    ]);
    let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    for p in points {
        csv.row([
            p.case.clone(),
            p.code.name().to_string(),
            p.series.clone(),
            p.value.to_string(),
            // Kept free of commas (a spreadsheet's eye reads the file too).
            p.setting.replace(',', ";"),
            p.lambda.to_string(),
            p.cg_rule.name().to_string(),
            p.seed.to_string(),
            p.status.to_string(),
            p.n_particles.map_or(String::new(), |n| n.to_string()),
            p.steps.map_or(String::new(), |n| n.to_string()),
            o(p.particle_steps),
            o(p.wall_s),
            o(p.repose_angle_deg),
            o(p.angle_error_deg),
            o(p.profile_distance),
            o(p.mass_flow_kg_s),
            o(p.mass_flow_error),
            o(p.eq7_mass_flow_kg_s),
            o(p.eq7_error),
            o(p.t_half_s),
            o(p.t_half_error),
            o(p.porosity),
            o(p.porosity_error),
            o(p.pore_diameter_d),
            o(p.pore_size_error),
            o(p.front_error),
            o(p.discharge_rate_kg_s),
            o(p.discharge_rate_std_error_kg_s),
            o(p.discharge_rate_error),
            o(p.bulk_density_kg_m3),
            o(p.particle_diameter_m),
            o(p.flow_stopped_at_s),
            o(p.dynamic_angle_deg),
            o(p.dynamic_angle_error_deg),
            o(p.mixing_period_s),
            o(p.mixing_period_error),
            o(p.mixing_index),
            o(p.mixing_index_error),
            o(p.large_share_zones.map(|z| z[0])),
            o(p.large_share_zones.map(|z| z[1])),
        ]);
    }
    csv
}

/// A drum run's result in words, or "-".
fn drum_result(p: &AccuracyPoint) -> String {
    match (p.dynamic_angle_deg, p.mixing_period_s) {
        (Some(a), Some(t)) => format!("drum {a:.2} deg, swing {t:.2} s"),
        (Some(a), None) => format!("drum {a:.2} deg, swing not resolved"),
        _ => "-".into(),
    }
}

/// One figure per error measure and cost, with each code's cheapest setting per measure.
fn write_error_figures(
    sub: &mut Section,
    sweep: &AccuracySweep,
    case: &str,
    measures: &[Measure],
    points: &[AccuracyPoint],
    dir: &Path,
) -> Result<Vec<CheapestSetting>, ValidateError> {
    let mut cheapest = Vec::new();
    let codes = sweep.codes();
    for &m in measures {
        for cost in [Cost::WallTime, Cost::ParticleSteps] {
            let fig = error_figure(case, m, cost, &sweep.targets, &codes, points);
            let stem = match cost {
                Cost::WallTime => m.stem().to_string(),
                Cost::ParticleSteps => format!("{}_vs_particle_steps", m.stem()),
            };
            let files = write_figure(dir, &stem, &fig).map_err(|e| output_error(dir, e))?;
            sub.figure(
                &files,
                fig.title.clone(),
                format!(
                    "{} against {}, log axes; one series per knob and code (points in the \
                     knob's order), the Pareto front of each code dashed, the target ({}) as a \
                     line.{} All points: points.csv beside it.",
                    m.name(),
                    cost.name(),
                    m.format(m.target(&sweep.targets)),
                    match cost {
                        Cost::WallTime => "",
                        Cost::ParticleSteps =>
                            " Particle-steps do not depend on the load of a shared machine, nor \
                             on the code's speed.",
                    }
                ),
            )
            .map_err(|e| output_error(dir, e))?;
        }
        for &code in &codes {
            cheapest.push(cheapest_setting(case, code, m, &sweep.targets, points));
        }
    }
    Ok(cheapest)
}

/// The cheapest setting within each target, per code and error measure.
fn cheapest_table(cheapest: &[CheapestSetting]) -> Table {
    let mut choice = Table::new([
        "code",
        "error measure",
        "target",
        "cheapest setting within it",
        "wall s",
        "particle-steps",
        "its error (mean +- SE, seeds)",
        "reference wall s",
        "speed-up",
        "floor (other seeds)",
    ])
    .caption(format!("Cheapest setting within each target, per code: the fewest particle-steps (wall time beside it; on a shared machine the wall time of equal work varies too much to choose by) among the settings whose every seed ran to its end and whose mean error plus spread ({SPREAD_STANDARD_ERRORS} standard errors of the mean) meets the target. The reference is the yardstick: when no other point qualifies, none is named. A setting's error, cost and wall time are means over its seeds, the error with one standard error of the mean. Floor: the largest difference between two reference runs with different insertion seeds; a target below it is met by chance."));
    for c in cheapest {
        let m = measure_named(&c.measure);
        let speedup = match (c.reference_wall_s, c.wall_s) {
            (Some(r), Some(w)) if w > 0.0 => format!("{:.1}x", r / w),
            _ => "-".into(),
        };
        choice.row([
            Cell::text(c.code.name()),
            Cell::text(&c.measure),
            Cell::num(m.format(c.target)),
            match &c.setting {
                Some(s) => Cell::pass(s.clone()),
                None => Cell::skipped("none: only the reference"),
            },
            Cell::num(fmt_opt(c.wall_s, 1)),
            Cell::num(c.particle_steps.map_or("-".into(), |n| format!("{n:.3e}"))),
            Cell::num(c.error.map_or("-".into(), |v| {
                format!(
                    "{}{} ({})",
                    m.format(v),
                    c.error_se
                        .map_or(String::new(), |se| format!(" +- {}", m.format(se))),
                    c.seeds
                )
            })),
            Cell::num(fmt_opt(c.reference_wall_s, 1)),
            Cell::num(speedup),
            Cell::num(c.floor.map_or("-".into(), |v| m.format(v))),
        ]);
    }
    choice
}

/// The coarse-graining matrix of a sweep over lambda (cgdem's runs): for each error measure,
/// each lambda and rule with its mean error over seeds, its spread (as `cgdem advise` counts
/// it) and what it saves against the fine reference; a table and `matrix.csv`.
fn write_matrix(
    sub: &mut Section,
    case: &str,
    measures: &[Measure],
    targets: &Targets,
    points: &[AccuracyPoint],
    dir: &Path,
) -> Result<(), ValidateError> {
    let code = Code::Cgdem;
    let all = settings(code, points);
    let Some(reference) = all.iter().find(|s| s.series == "reference") else {
        return Ok(());
    };
    let mean_of = |s: &Setting, f: fn(&AccuracyPoint) -> Option<f64>| {
        let v: Vec<f64> = s.runs.iter().filter_map(|p| f(p)).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    let reference_steps = mean_of(reference, |p| p.particle_steps);
    let reference_wall = mean_of(reference, |p| p.wall_s);
    let mut table = Table::new([
        "quantity",
        "rule",
        "lambda",
        "particles",
        "error (mean +- spread, seeds)",
        "within target",
        "particle-steps saved",
        "wall time saved",
    ])
    .caption(format!(
        "Coarse-graining matrix: each level and rule against the fine reference ({}, rule {}), error = mean over seeds, spread = {SPREAD_STANDARD_ERRORS} standard errors of the mean (what `cgdem advise` adds to the mean); within target when mean + spread is. Savings: the reference's mean particle-steps (wall time) over the setting's. CSV: matrix.csv beside the figures.",
        reference.setting,
        reference.runs[0].cg_rule.name()
    ));
    let mut csv = CsvBuffer::new([
        "case",
        "quantity",
        "cg_rule",
        "lambda",
        "setting",
        "seeds",
        "n_particles",
        "error_mean",
        "error_se",
        "error_reach",
        "target",
        "within_target",
        "particle_steps",
        "wall_s",
        "saving_particle_steps",
        "saving_wall",
    ]);
    let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    for &m in measures {
        for s in all.iter().filter(|s| {
            s.series.starts_with("lambda") || (s.series == "reference" && !m.against_reference())
        }) {
            let Some(mean) = s.mean(m, Cost::ParticleSteps) else {
                continue;
            };
            let spread = mean.se.map(|se| SPREAD_STANDARD_ERRORS * se);
            let reach = mean.error + spread.unwrap_or(0.0);
            let target = m.target(targets);
            let wall = mean_of(s, |p| p.wall_s);
            let particles = mean_of(s, |p| p.n_particles.map(|n| n as f64));
            let saving_steps = reference_steps.map(|r| r / mean.cost);
            let saving_wall = reference_wall.zip(wall).map(|(r, w)| r / w);
            let first = s.runs[0];
            table.row([
                Cell::text(m.quantity()),
                Cell::text(first.cg_rule.name()),
                Cell::num(first.lambda.to_string()),
                Cell::num(particles.map_or("-".into(), |n| format!("{n:.0}"))),
                Cell::num(format!(
                    "{}{} ({})",
                    m.format(mean.error),
                    spread.map_or(" (spread unknown)".into(), |v| format!(
                        " +- {}",
                        m.format(v)
                    )),
                    mean.n
                )),
                if reach <= target {
                    Cell::pass(format!("yes ({})", m.format(target)))
                } else {
                    Cell::fail(format!("no ({})", m.format(target)))
                },
                Cell::num(saving_steps.map_or("-".into(), |v| format!("{v:.1}x"))),
                Cell::num(saving_wall.map_or("-".into(), |v| format!("{v:.1}x"))),
            ]);
            csv.row([
                case.to_string(),
                m.quantity().to_string(),
                first.cg_rule.name().to_string(),
                first.lambda.to_string(),
                s.setting.replace(',', ";"),
                mean.n.to_string(),
                o(particles),
                o(Some(mean.error)),
                o(mean.se),
                o(Some(reach)),
                o(Some(target)),
                (reach <= target).to_string(),
                o(Some(mean.cost)),
                o(wall),
                o(saving_steps),
                o(saving_wall),
            ]);
        }
    }
    let path = dir.join("matrix.csv");
    csv.bytes()
        .and_then(|bytes| write_atomic(&path, bytes))
        .map_err(|e| output_error(&path, e))?;
    sub.table(table);
    Ok(())
}

fn error_figure(
    case: &str,
    m: Measure,
    cost_axis: Cost,
    targets: &Targets,
    codes: &[Code],
    points: &[AccuracyPoint],
) -> Figure {
    let mut fig = Figure::new(
        format!("{case}: {} against {}", m.name(), cost_axis.name()),
        match cost_axis {
            Cost::WallTime => "wall time [s]",
            Cost::ParticleSteps => "particle-steps [-]",
        },
        m.axis(),
    )
    .log_x()
    .log_y();
    let mut walls: Vec<f64> = Vec::new();
    for &code in codes {
        let all = settings(code, points);
        let mut knobs: Vec<&str> = all.iter().map(|s| s.series).collect();
        knobs.sort();
        knobs.dedup();
        for knob in knobs {
            let mut series: Vec<(f64, SettingMean)> = all
                .iter()
                .filter(|s| s.series == knob)
                .filter_map(|s| Some((s.value, s.mean(m, cost_axis)?)))
                .collect();
            series.sort_by(|a, b| a.0.total_cmp(&b.0));
            walls.extend(series.iter().map(|p| p.1.cost));
            if series.is_empty() || (knob == "reference" && m.against_reference()) {
                continue;
            }
            let xy = series.iter().map(|p| (p.1.cost, p.1.error)).collect();
            let se = series.iter().map(|p| p.1.se.unwrap_or(0.0)).collect();
            let style = match knob {
                "reference" => SeriesStyle::Markers,
                _ => SeriesStyle::LineMarkers,
            };
            fig.series.push(
                Series::new(format!("{}: {knob}", code.name()), xy)
                    .style(style)
                    .y_err(se),
            );
        }
        let cost: Vec<(f64, f64)> = candidates(code, m, points)
            .iter()
            .filter_map(|s| s.mean(m, cost_axis))
            .map(|a| (a.cost, a.error))
            .collect();
        let front: Vec<(f64, f64)> = pareto_front(&cost)
            .into_iter()
            .map(|k| cost[k])
            .filter(|p| p.1 > 0.0)
            .collect();
        if !front.is_empty() {
            // One point (it beats every other) is a front too; a lone dash would not show.
            let style = if front.len() > 1 {
                SeriesStyle::Dashed
            } else {
                SeriesStyle::Markers
            };
            fig.series
                .push(Series::new(format!("{}: Pareto front", code.name()), front).style(style));
        }
    }
    let (lo, hi) = walls
        .iter()
        .filter(|w| **w > 0.0)
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &w| {
            (lo.min(w), hi.max(w))
        });
    if lo < hi {
        let t = m.target(targets);
        fig.series.push(
            Series::new(format!("target {}", m.format(t)), vec![(lo, t), (hi, t)])
                .style(SeriesStyle::Dashed),
        );
    }
    fig
}
