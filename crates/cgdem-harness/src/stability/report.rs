//! The stability section of the report and `stability.csv`: one row per case and code with
//! its verdict, the evidence and the message.

use std::path::Path;

use super::{StabilityCase, StabilityRecord, Verdict};
use crate::code::Code;
use crate::report::{Cell, Report, Table};
use cgdem_core::io::CsvBuffer;
use cgdem_core::math::Real;

fn fmt(v: Option<Real>, f: impl Fn(Real) -> String) -> String {
    v.map_or(String::new(), f)
}

pub(crate) fn write_csv(records: &[StabilityRecord], path: &Path) -> Result<(), String> {
    let mut csv = CsvBuffer::new([
        "case",
        "code",
        "verdict",
        "particles",
        "particles_lost",
        "steps",
        "dt_s",
        "dt_over_stable",
        "energy_start_j",
        "elastic_start_j",
        "energy_max_j",
        "energy_end_j",
        "energy_rise",
        "energy_drift",
        "dissipated_j",
        "largest_overlap",
        "overlap_measured",
        "message",
    ]);
    for r in records {
        let e = r.evidence.clone().unwrap_or_default();
        let sci = |v: Real| format!("{v:.6e}");
        let dt_ratio = (e.dt_s / e.stable_dt_s)
            .is_finite()
            .then(|| e.dt_s / e.stable_dt_s);
        csv.row([
            r.case.clone(),
            r.code.name().to_string(),
            r.verdict.name().to_string(),
            e.particles.to_string(),
            e.particles_lost.to_string(),
            e.steps.to_string(),
            if e.dt_s.is_finite() {
                sci(e.dt_s)
            } else {
                String::new()
            },
            fmt(dt_ratio, |v| format!("{v:.3}")),
            fmt(e.energy_start_j, sci),
            fmt(e.elastic_start_j, sci),
            fmt(e.energy_max_j, sci),
            fmt(e.energy_end_j, sci),
            fmt(e.energy_rise, sci),
            fmt(e.energy_drift, sci),
            fmt(e.dissipated_j, sci),
            fmt(e.largest_overlap, |v| format!("{v:.4}")),
            e.overlap_measured.to_string(),
            // One row per line.
            r.message.replace('\n', " "),
        ]);
    }
    csv.bytes()
        .and_then(|bytes| cgdem_core::io::write_atomic(path, bytes))
        .map_err(|e| format!("{}: {e}", path.display()))
}

fn verdict_cell(r: &StabilityRecord) -> Cell {
    match r.verdict {
        Verdict::Stable | Verdict::Detected => Cell::pass(r.verdict.name()),
        Verdict::Failed => Cell::fail(r.verdict.name()),
        Verdict::NotApplicable | Verdict::Skipped => Cell::skipped(r.verdict.name()),
    }
}

pub(crate) fn write_section(
    report: &mut Report,
    cases: &[(String, String, StabilityCase)],
    records: &[StabilityRecord],
) {
    let section = report.section("Stability");
    section.paragraph(
        "Each case run by cgdem (with its guards) and, where their decks can express the physics, \
         LAMMPS and LIGGGHTS (same particles, same time step, `thermo_modify lost error`). \
         stable: ran to the end, no particle lost, no non-finite value, kinetic + gravitational \
         energy never above the start's (kinetic + gravitational + elastic energy of overlaps \
         placed at the start) by more than the case's tolerance, largest overlap below its limit. \
         detected: stopped with a clear message (cgdem guard or refusal, a reference code's ERROR) \
         before any non-finite value or lost particle. failed: anything else. cgdem's overlap is its \
         guard's per-step peak; the reference codes' is measured on their dump frames. Every record, \
         with its numbers, is in summary.json (`stability`) and stability.csv.",
    );
    let codes = [Code::Cgdem, Code::Lammps, Code::Liggghts];
    let mut table = Table::new(["case", "what", "cgdem", "lammps", "liggghts"])
        .caption("Stability: verdict per code and case (details below)");
    for (name, description, _) in cases {
        let mut row = vec![Cell::text(name), Cell::text(description)];
        for code in codes {
            row.push(
                records
                    .iter()
                    .find(|r| &r.case == name && r.code == code)
                    .map_or(Cell::text("-"), verdict_cell),
            );
        }
        table.row(row);
    }
    section.table(table);
    let mut detail = Table::new([
        "case",
        "code",
        "verdict",
        "dt / stable",
        "energy rise",
        "energy at end",
        "largest overlap",
        "lost",
        "message (and log tail)",
    ])
    .caption("Stability: evidence per run (energies as fractions of the start's kinetic + gravitational + elastic energy)");
    for r in records {
        let e = r.evidence.clone().unwrap_or_default();
        let ratio = e.dt_s / e.stable_dt_s;
        let mut message = r.message.clone();
        if let Some(tail) = &r.log_tail {
            message += &format!(" | log tail: {}", tail.replace('\n', " / "));
        }
        detail.row([
            Cell::text(&r.case),
            Cell::text(r.code.name()),
            verdict_cell(r),
            Cell::num(if ratio.is_finite() {
                format!("{ratio:.2}")
            } else {
                "-".into()
            }),
            Cell::num(fmt(e.energy_rise, |v| format!("{v:.2e}"))),
            Cell::num(fmt(e.energy_drift, |v| format!("{v:+.2e}"))),
            Cell::num(fmt(e.largest_overlap, |v| format!("{:.2}%", 100.0 * v))),
            Cell::num(if r.evidence.is_some() {
                e.particles_lost.to_string()
            } else {
                String::new()
            }),
            Cell::text(message),
        ]);
    }
    section.table(detail);
}
