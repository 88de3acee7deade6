//! The Chung & Ooi section of the report: per test, its inputs, a figure per curve (every
//! law, the closed form, the digitized reference; CSV beside it), a table of each point and
//! the criteria with their verdicts; and `chung_ooi.csv` with every verdict.

use std::path::Path;

use super::benchmark::{Curve, TestResult};
use super::{ChungOoiLaw, ChungOoiVerdict};
use crate::report::{write_figure, Cell, Figure, Report, Series, SeriesStyle, Status, Table};
use cgdem_core::io::CsvBuffer;

fn sig(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.5}")
    } else {
        "-".into()
    }
}

fn verdict_cell(verdict: &str) -> Cell {
    let status = match verdict {
        "pass" => Status::Pass,
        "known difference" => Status::Known,
        _ => Status::Fail,
    };
    Cell::text(verdict).status(status)
}

fn figure(curve: &Curve, number: u8, laws: &[(ChungOoiLaw, Vec<TestResult>)], k: usize) -> Figure {
    let mut fig = Figure::new(
        format!("Chung & Ooi test {number}: {}", curve.title),
        curve.x_label,
        curve.y_label,
    );
    for (law, tests) in laws {
        let c = &tests[number as usize - 1].curves[k];
        fig = fig.with_series(
            Series::new(
                format!("cgdem, {}", law.name),
                c.points.iter().map(|p| (p.x, p.y)).collect(),
            )
            .style(SeriesStyle::LineMarkers),
        );
    }
    let closed: Vec<(f64, f64)> = curve
        .points
        .iter()
        .filter_map(|p| p.closed_form.map(|c| (p.x, c)))
        .collect();
    if !closed.is_empty() {
        fig = fig.with_series(Series::new("closed form", closed).style(SeriesStyle::Dashed));
    }
    if let Some(r) = curve.reference {
        fig = fig.with_series(Series::new(r.label, r.points.to_vec()).style(SeriesStyle::Markers));
    }
    fig
}

pub(super) fn write(
    report: &mut Report,
    laws: &[(ChungOoiLaw, Vec<TestResult>)],
    verdicts: &[ChungOoiVerdict],
    dir: &Path,
) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    write_csv(verdicts, &dir.join("chung_ooi.csv"))?;
    let section = report.section("Chung & Ooi (2011) benchmark");
    section.paragraph(
        "The eight particle-impact tests of Y. C. Chung and J. Y. Ooi, \"Benchmark tests for verifying discrete element modelling codes at particle impact level\", Granular Matter 13 (2011) 643-656, with the paper's materials, speeds and spins, run by cgdem alone (the reference codes are not run). Verdicts: Kratos DEM's criteria (DEM_benchmarks_class.py: error = sum |measured - reference| / sum |reference| over the points it names, against the paper's curves as Kratos digitized them), the closed forms of tests 1-4, and rigid-body impact theory at every point of tests 5, 6 and 8 where the contact slides throughout (the slip exceeds 1.2 times 3.5 mu (1 + e) V_cn).",
    );
    let fails = verdicts.iter().filter(|v| v.failed()).count();
    let known = verdicts
        .iter()
        .filter(|v| v.verdict == "known difference")
        .count();
    let status = if fails > 0 {
        Status::Fail
    } else if known > 0 {
        Status::Known
    } else {
        Status::Pass
    };
    section.banner(
        status,
        format!(
            "{} criteria: {fails} fail, {known} known differences, {} pass",
            verdicts.len(),
            verdicts.len() - fails - known
        ),
    );
    for (law, _) in laws {
        let mut text = format!(
            "Law `{}`: scene overrides [{}].",
            law.name,
            law.set.join(", ")
        );
        if let Some(why) = &law.known_difference {
            text += &format!(" Declared known difference: {why}");
        }
        section.paragraph(text);
    }
    let Some((_, first)) = laws.first() else {
        return Ok(());
    };
    for t in first {
        let sub = section.subsection(format!("Test {}: {}", t.number, t.title));
        sub.paragraph(format!("Inputs: {}.", t.inputs));
        for (k, curve) in t.curves.iter().enumerate() {
            let files = write_figure(dir, curve.stem, &figure(curve, t.number, laws, k))
                .map_err(|e| e.to_string())?;
            sub.figure(
                &files,
                curve.title,
                format!("Test {}: {}.", t.number, curve.title),
            )
            .map_err(|e| e.to_string())?;
            let mut header = vec!["k".to_string(), curve.x_label.to_string()];
            header.extend(laws.iter().map(|(l, _)| format!("cgdem, {}", l.name)));
            header.push("closed form".into());
            header.push("slides throughout".into());
            let mut table = Table::new(header);
            for (i, p) in curve.points.iter().enumerate() {
                let mut row = vec![Cell::num(p.k.to_string()), Cell::num(sig(p.x))];
                for (_, tests) in laws {
                    let q = &tests[t.number as usize - 1].curves[k].points[i];
                    row.push(Cell::num(sig(q.y)));
                }
                row.push(Cell::num(p.closed_form.map_or("-".into(), sig)));
                row.push(Cell::text(if p.sliding { "yes" } else { "no" }));
                table.row(row);
            }
            sub.table(table.caption(format!("Test {}: {}, each point.", t.number, curve.title)));
        }
        let mut table = Table::new([
            "law",
            "criterion",
            "value",
            "tolerance",
            "points",
            "source",
            "verdict",
        ]);
        for v in verdicts.iter().filter(|v| v.test == t.number) {
            let c = &v.criterion;
            table.row([
                Cell::text(v.law.clone()),
                Cell::text(c.name.clone()),
                Cell::num(sig(c.value)),
                Cell::num(sig(c.tolerance)),
                Cell::text(c.points.clone()),
                Cell::text(c.source.clone()),
                verdict_cell(&v.verdict),
            ]);
        }
        sub.table(table.caption(format!("Test {}: criteria and verdicts.", t.number)));
    }
    Ok(())
}

fn write_csv(verdicts: &[ChungOoiVerdict], path: &Path) -> Result<(), String> {
    let mut csv = CsvBuffer::new([
        "law",
        "test",
        "criterion",
        "value",
        "tolerance",
        "points",
        "source",
        "verdict",
    ]);
    for v in verdicts {
        let c = &v.criterion;
        csv.row([
            v.law.clone(),
            v.test.to_string(),
            c.name.clone(),
            format!("{:.6e}", c.value),
            format!("{}", c.tolerance),
            c.points.clone(),
            c.source.clone(),
            v.verdict.clone(),
        ]);
    }
    csv.bytes()
        .and_then(|bytes| cgdem_core::io::write_atomic(path, bytes))
        .map_err(|e| format!("{}: {e}", path.display()))
}
