//! The report of the silo cases: per case (one orifice) the mass discharged against time of
//! every run, a table of the rates with their standard errors, the bulk density and Beverloo's
//! C, and cgdem's verdict against the reference codes; across the cases (orifices), each
//! code's C with k fixed, one C from all orifices and C and k both free. Tables go to CSV
//! beside the figures (`figures/<case>/discharge.csv`, `figures/silo_overview/beverloo.csv`).

use std::fmt::Write as _;
use std::path::Path;

use super::measurement::{
    beverloo_c, beverloo_rate, combined_c, fit_c_and_k, PUBLISHED_C, PUBLISHED_K,
};
use super::{DischargeSettings, SiloRun};
use crate::code::Code;
use crate::quantity::seeds::mean_with_block_error;
use crate::quantity::{show_figure, CaseOrigin};
use crate::report::{Cell, Figure, Report, Series, SeriesStyle, Table};
use crate::runs::{output_error, ValidateError};
use crate::verdict::Verdict;
use cgdem_core::io::write_atomic;
use cgdem_core::scene::Scene;

fn num(v: Option<f64>, digits: usize) -> Cell {
    Cell::num(v.map_or("-".into(), |x| format!("{x:.digits$}")))
}

/// The section of one discharge case: its scene, its suite file and seeds, its settings.
pub fn write_silo_section(
    report: &mut Report,
    scene: &Scene,
    case: &CaseOrigin,
    settings: &DischargeSettings,
    runs: &[SiloRun],
    verdict: Option<(Verdict, &str)>,
    out: &Path,
) -> Result<(), ValidateError> {
    let dir = out.join("figures").join(&scene.name);
    let section = report.section(format!("Case {}: silo discharge", scene.name));
    section.paragraph(format!(
        "{} Scene file: {}. Seeds: {:?}. Discharged mass: the grains gone from the scene since the gate opened (stage `{}`) times the grain's mass, from every code's timeseries.csv (LIGGGHTS and LAMMPS: the atoms of each dump frame); grains leave 0.02 m below the orifice, a constant lag. Rate: least-squares slope from {} s after the gate opens to the stage's end; standard error: {} equal blocks (their standard deviation over sqrt({})); drift: the block rates' fitted change across the window, flagged beyond two of its standard errors. Beverloo: W = C rho_b sqrt(g) (D0 - k d)^(5/2), D0 = {} m, k = {PUBLISHED_K} fixed, rho_b from the grains whose centres lie in {:?} .. {:?} m at the gate's opening; published C = {PUBLISHED_C} for a flat-bottomed silo (the hopper raises the rate: reference/silo/PLAN.md 3).",
        scene.description,
        case.file.display(),
        case.seeds,
        settings.stage,
        settings.discard_s,
        settings.blocks,
        settings.blocks,
        settings.orifice_diameter_m,
        settings.bulk_lo,
        settings.bulk_hi,
    ));
    if let Some((verdict, text)) = verdict {
        let status = match verdict {
            Verdict::Pass => crate::report::Status::Pass,
            Verdict::KnownDifference => crate::report::Status::Known,
            Verdict::Fail => crate::report::Status::Fail,
        };
        section.banner(status, format!("Discharge rate: {text}."));
    }
    let mut figure = Figure::new(
        format!("{}: mass discharged against time", scene.name),
        "time since the gate opened (s)",
        "discharged mass (kg)",
    );
    for s in runs {
        if let Some(series) = &s.series {
            figure = figure.with_series(
                Series::new(
                    format!("{}, lambda {}, seed {}", s.code.name(), s.lambda, s.seed),
                    series
                        .time_s
                        .iter()
                        .copied()
                        .zip(series.mass_kg.iter().copied())
                        .collect(),
                )
                .style(SeriesStyle::Line),
            );
        }
    }
    if !figure.series.is_empty() {
        show_figure(
            section,
            &dir,
            "discharged_mass",
            &figure,
            (
                "discharged mass against time, one line per run",
                "Mass discharged against time since the gate opened, every code and seed.",
            ),
        )?;
    }
    let (table, csv) = runs_table(settings, runs);
    section.table(table);
    std::fs::create_dir_all(&dir).map_err(|e| output_error(&dir, e))?;
    let path = dir.join("discharge.csv");
    write_atomic(&path, csv.as_bytes()).map_err(|e| output_error(&path, e))?;
    Ok(())
}

/// The table of a case's runs and the same as CSV.
fn runs_table(settings: &DischargeSettings, runs: &[SiloRun]) -> (Table, String) {
    let mut table = Table::new([
        "code",
        "lambda",
        "seed",
        "rate (kg/s)",
        "std error (kg/s)",
        "window (s)",
        "block rates (kg/s)",
        "drift (kg/s)",
        "bulk density (kg/m3)",
        "C (k = 1.5)",
        "Beverloo C = 0.58 (kg/s)",
    ])
    .caption("Discharge rate per run, its block-average standard error and Beverloo's C");
    let mut csv = String::from("code,lambda,seed,orifice_diameter_m,rate_kg_s,std_error_kg_s,window_start_s,window_end_s,block_rates_kg_s,drift_kg_s,drifts,bulk_density_kg_m3,bulk_density_from,c_k1_5,c_k1_5_std_error,beverloo_published_kg_s,problem\n");
    for s in runs {
        let rho = s.bulk_density.map(|(r, _)| r);
        let published = rho.and_then(|rho| {
            beverloo_rate(
                PUBLISHED_C,
                rho,
                settings.orifice_diameter_m,
                s.grain_diameter_m,
                PUBLISHED_K,
            )
        });
        let blocks = s.rate.as_ref().map_or(String::new(), |r| {
            r.block_rates_kg_s
                .iter()
                .map(|b| format!("{b:.4}"))
                .collect::<Vec<_>>()
                .join(" ")
        });
        let rho_text = s.bulk_density_text();
        let drift = s.rate.as_ref().map_or(Cell::num("-"), |r| {
            let text = format!("{:+.4}", r.drift_kg_s);
            if r.drifts {
                Cell::fail(format!("{text} (drifts)"))
            } else {
                Cell::num(text)
            }
        });
        match &s.problem {
            Some(p) => {
                table.row([
                    Cell::text(s.code.name()),
                    Cell::num(s.lambda.to_string()),
                    Cell::num(s.seed.to_string()),
                    Cell::skipped(p.clone()),
                    Cell::num("-"),
                    Cell::num("-"),
                    Cell::num("-"),
                    Cell::num("-"),
                    Cell::num("-"),
                    Cell::num("-"),
                    Cell::num("-"),
                ]);
            }
            None => {
                table.row([
                    Cell::text(s.code.name()),
                    Cell::num(s.lambda.to_string()),
                    Cell::num(s.seed.to_string()),
                    num(s.rate.as_ref().map(|r| r.rate_kg_s), 4),
                    num(s.rate.as_ref().map(|r| r.std_error_kg_s), 4),
                    Cell::num(s.rate.as_ref().map_or("-".into(), |r| {
                        format!("{:.2} .. {:.2}", r.window_s[0], r.window_s[1])
                    })),
                    Cell::num(blocks.clone()),
                    drift,
                    Cell::num(rho_text),
                    Cell::num(
                        s.c_fixed_k
                            .map_or("-".into(), |(c, se)| format!("{c:.3} +- {se:.3}")),
                    ),
                    num(published, 4),
                ]);
            }
        }
        let f = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6e}"));
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
            s.code.name(),
            s.lambda,
            s.seed,
            settings.orifice_diameter_m,
            f(s.rate.as_ref().map(|r| r.rate_kg_s)),
            f(s.rate.as_ref().map(|r| r.std_error_kg_s)),
            f(s.rate.as_ref().map(|r| r.window_s[0])),
            f(s.rate.as_ref().map(|r| r.window_s[1])),
            blocks,
            f(s.rate.as_ref().map(|r| r.drift_kg_s)),
            s.rate
                .as_ref()
                .map_or(String::new(), |r| r.drifts.to_string()),
            f(rho),
            s.bulk_density
                .map_or(String::new(), |(_, c)| c.name().to_string()),
            f(s.c_fixed_k.map(|c| c.0)),
            f(s.c_fixed_k.map(|c| c.1)),
            f(published),
            s.csv_problem(),
        );
    }
    (table, csv)
}

/// Across the discharge cases (orifices): per code and level, C at k = 1.5 from each
/// orifice, one C from all (weighted by 1/se^2, with chi^2 per degree of freedom), and, from
/// the first two orifices, C and k both free; a figure of the rate against the orifice.
pub fn write_silo_overview(
    report: &mut Report,
    cases: &[(&Scene, &DischargeSettings, Vec<SiloRun>)],
    out: &Path,
) -> Result<(), ValidateError> {
    let dir = out.join("figures").join("silo_overview");
    let section = report.section("Silo discharge: every code against Beverloo");
    section.paragraph(format!(
        "Each code's discharge rate (mean over seeds) against the orifice diameter, with Beverloo's law at the published C = {PUBLISHED_C}, k = {PUBLISHED_K} (dashed, each code's bulk density). The table fits C with k = {PUBLISHED_K} fixed per orifice and over all orifices (chi^2 per degree of freedom: do the orifices agree with k = {PUBLISHED_K}?), and C and k both free from two orifices (exactly determined)."
    ));
    let mut figure = Figure::new(
        "Silo discharge: rate against orifice diameter",
        "orifice diameter D0 (m)",
        "discharge rate (kg/s)",
    );
    let mut table = Table::new([
        "code",
        "lambda",
        "orifices (m)",
        "rates (kg/s)",
        "C per orifice (k = 1.5)",
        "C, all orifices",
        "chi^2 / dof",
        "C, k free",
    ])
    .caption("Beverloo's constants fitted to each code's rates");
    let mut csv = String::from(
        "code,lambda,orifice_diameter_m,rate_kg_s,std_error_kg_s,bulk_density_kg_m3,c_k1_5,c_k1_5_std_error,c_all_orifices,c_all_std_error,chi2_per_dof,c_free,k_free\n",
    );
    let mut levels: Vec<(Code, u32)> = cases
        .iter()
        .flat_map(|(_, _, runs)| runs.iter().map(|s| (s.code, s.lambda)))
        .collect();
    levels.sort();
    levels.dedup();
    for (code, lambda) in levels {
        let points = level_points(cases, code, lambda);
        if points.is_empty() {
            continue;
        }
        let cs: Vec<Option<(f64, f64)>> = points
            .iter()
            .map(|&(d0, w, se, rho, d)| beverloo_c(w, se, rho, d0, d, PUBLISHED_K))
            .collect();
        let all = combined_c(&cs.iter().flatten().copied().collect::<Vec<_>>());
        let free = (points.len() >= 2)
            .then(|| {
                let (a, b) = (points[0], points[1]);
                fit_c_and_k((a.0, a.1), (b.0, b.1), a.4, 0.5 * (a.3 + b.3))
            })
            .flatten();
        let label = format!("{} lambda {lambda}", code.name());
        figure = figure
            .with_series(
                Series::new(label.clone(), points.iter().map(|p| (p.0, p.1)).collect())
                    .style(SeriesStyle::LineMarkers)
                    .y_err(points.iter().map(|p| p.2).collect()),
            )
            .with_series(
                Series::new(
                    format!("Beverloo C = {PUBLISHED_C}, {label}'s bulk density"),
                    points
                        .iter()
                        .filter_map(|&(d0, _, _, rho, d)| {
                            beverloo_rate(PUBLISHED_C, rho, d0, d, PUBLISHED_K).map(|w| (d0, w))
                        })
                        .collect(),
                )
                .style(SeriesStyle::Dashed),
            );
        let list =
            |f: &dyn Fn(&Point) -> String| points.iter().map(f).collect::<Vec<_>>().join(", ");
        table.row([
            Cell::text(code.name()),
            Cell::num(lambda.to_string()),
            Cell::num(list(&|p| format!("{}", p.0))),
            Cell::num(list(&|p| format!("{:.4} +- {:.4}", p.1, p.2))),
            Cell::num(
                cs.iter()
                    .map(|c| c.map_or("-".into(), |(c, se)| format!("{c:.3} +- {se:.3}")))
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
            Cell::num(all.map_or("-".into(), |(c, se, _)| format!("{c:.3} +- {se:.3}"))),
            Cell::num(
                all.filter(|_| points.len() > 1)
                    .map_or("-".into(), |a| format!("{:.1}", a.2)),
            ),
            Cell::num(free.map_or("-".into(), |(c, k)| format!("C = {c:.3}, k = {k:.2}"))),
        ]);
        beverloo_rows(&mut csv, (code, lambda), &points, &cs, all, free);
    }
    if !figure.series.is_empty() {
        show_figure(
            section,
            &dir,
            "rate_vs_orifice",
            &figure,
            (
                "discharge rate against orifice diameter per code, with Beverloo's law",
                "Discharge rate against orifice diameter per code (mean over seeds, 1 SE bars), with Beverloo's law at the published constants.",
            ),
        )?;
    }
    section.table(table);
    std::fs::create_dir_all(&dir).map_err(|e| output_error(&dir, e))?;
    let path = dir.join("beverloo.csv");
    write_atomic(&path, csv.as_bytes()).map_err(|e| output_error(&path, e))?;
    Ok(())
}

/// One orifice's point: (D0, rate, its error, bulk density, grain diameter).
type Point = (f64, f64, f64, f64, f64);

/// `beverloo.csv`'s rows of one code and level: per orifice its point and C at k = 1.5,
/// then the level's C over all orifices (`all`: C, its error, chi^2 per degree of freedom)
/// and C, k free (`free`).
fn beverloo_rows(
    csv: &mut String,
    (code, lambda): (Code, u32),
    points: &[Point],
    cs: &[Option<(f64, f64)>],
    all: Option<(f64, f64, f64)>,
    free: Option<(f64, f64)>,
) {
    let f = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    for (p, c) in points.iter().zip(cs) {
        let _ = writeln!(
            csv,
            "{},{lambda},{},{},{},{},{},{},{},{},{},{},{}",
            code.name(),
            p.0,
            f(Some(p.1)),
            f(Some(p.2)),
            f(Some(p.3)),
            f(c.map(|c| c.0)),
            f(c.map(|c| c.1)),
            f(all.map(|a| a.0)),
            f(all.map(|a| a.1)),
            f(all.filter(|_| points.len() > 1).map(|a| a.2)),
            f(free.map(|x| x.0)),
            f(free.map(|x| x.1)),
        );
    }
}

/// Per orifice of `cases`, one code and level's (D0, mean rate over seeds, its combined
/// standard error, mean bulk density, grain diameter), in order of D0.
fn level_points(
    cases: &[(&Scene, &DischargeSettings, Vec<SiloRun>)],
    code: Code,
    lambda: u32,
) -> Vec<(f64, f64, f64, f64, f64)> {
    // Per orifice: the mean rate over seeds, its combined error, the mean bulk density.
    let mut points: Vec<(f64, f64, f64, f64, f64)> = Vec::new(); // (D0, W, se, rho, d)
    for (_, settings, runs) in cases {
        let at: Vec<&SiloRun> = runs
            .iter()
            .filter(|s| (s.code, s.lambda) == (code, lambda) && s.rate.is_some())
            .filter(|s| s.bulk_density.is_some())
            .collect();
        let rates: Vec<(f64, f64)> = at.iter().filter_map(|s| s.rate_with_error()).collect();
        let Some((w, se)) = mean_with_block_error(&rates) else {
            continue;
        };
        let n = at.len() as f64;
        let rho = at
            .iter()
            .map(|s| s.bulk_density.map_or(0.0, |b| b.0))
            .sum::<f64>()
            / n;
        points.push((
            settings.orifice_diameter_m,
            w,
            se,
            rho,
            at[0].grain_diameter_m,
        ));
    }
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    points
}
