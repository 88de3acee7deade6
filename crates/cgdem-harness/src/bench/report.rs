//! The bench's outputs: `bench.json`, `bench_runs.csv`, the throughput figure and the text
//! the command prints.

use std::path::Path;

use super::{BenchError, BenchReport};
use crate::report::plot::write_bar_chart;
use cgdem_core::io::CsvBuffer;
use cgdem_core::math::Real;

pub(super) fn write_report(report: &BenchReport, out: &Path) -> Result<(), BenchError> {
    let io = |path: &Path, e: &dyn std::fmt::Display| BenchError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(out).map_err(|e| io(out, &e))?;
    let json_path = out.join("bench.json");
    let json = serde_json::to_string_pretty(report).map_err(|e| io(&json_path, &e))?;
    cgdem_core::io::write_atomic(&json_path, json.as_bytes()).map_err(|e| io(&json_path, &e))?;
    let mut csv = CsvBuffer::new([
        "case",
        "code",
        "build",
        "threads",
        "ranks",
        "openmp_threads",
        "repetition",
        "status",
        "n_particles",
        "steps",
        "loop_s",
        "particle_steps_per_s",
        "memory_mb",
    ]);
    let opt = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    for r in &report.runs {
        csv.row([
            r.case.to_string(),
            r.code.name().to_string(),
            r.build.clone().unwrap_or_default(),
            r.threads.to_string(),
            r.ranks.map_or(String::new(), |n| n.to_string()),
            r.openmp_threads.map_or(String::new(), |n| n.to_string()),
            r.repetition.to_string(),
            r.status.to_string(),
            r.n_particles.to_string(),
            r.steps.to_string(),
            opt(r.loop_s),
            opt(r.particle_steps_per_s),
            opt(r.memory_mb),
        ]);
    }
    let csv_path = out.join("bench_runs.csv");
    csv.bytes()
        .and_then(|bytes| cgdem_core::io::write_atomic(&csv_path, bytes))
        .map_err(|e| io(&csv_path, &e))?;
    let bars: Vec<(String, String, f64, Option<f64>)> = report
        .medians
        .iter()
        .map(|m| {
            (
                format!("{}, {} worker(s)", m.case, m.threads),
                m.label(),
                m.median_particle_steps_per_s / 1e6,
                Some(0.5 * (m.max_particle_steps_per_s - m.min_particle_steps_per_s) / 1e6),
            )
        })
        .collect();
    if !bars.is_empty() {
        write_bar_chart(
            out,
            "throughput",
            &format!(
                "Throughput, median of {} alternating runs of {} steps (error bar: half the range)",
                report
                    .runs
                    .iter()
                    .map(|r| r.repetition + 1)
                    .max()
                    .unwrap_or(0),
                report.steps
            ),
            "million particle-steps per second",
            &bars,
        )
        .map_err(|e| io(&out.join("throughput.png"), &e))?;
    }
    Ok(())
}

/// The report as text: medians, ratios, outcomes and memory.
pub fn format_report(report: &BenchReport) -> String {
    let mut s = String::new();
    s += "case | code | workers | runs | median particle-steps/s | range | parallel efficiency\n";
    for m in &report.medians {
        s += &format!(
            "{} | {} | {} | {} | {:.3e} | {:.3e} .. {:.3e} | {}\n",
            m.case,
            m.label(),
            m.threads,
            m.runs,
            m.median_particle_steps_per_s,
            m.min_particle_steps_per_s,
            m.max_particle_steps_per_s,
            m.parallel_efficiency
                .map_or("-".into(), |e| format!("{:.0}%", 100.0 * e))
        );
    }
    s += "\nratio | workers | median | per repetition\n";
    for r in &report.ratios {
        s += &format!(
            "{} / {} | {} | {:.2} | {}\n",
            r.numerator,
            r.denominator,
            r.threads,
            r.median,
            r.per_repetition
                .iter()
                .map(|v| format!("{v:.2}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    if !report.fastest.is_empty() {
        s += "\nfastest build per worker count | workers | median particle-steps/s | cgdem / fastest\n";
    }
    for f in &report.fastest {
        s += &format!(
            "{}: {} | {} | {:.3e} | {}\n",
            f.case,
            f.row,
            f.threads,
            f.median_particle_steps_per_s,
            f.cgdem_over_fastest
                .map_or("-".into(), |r| format!("{r:.2}"))
        );
    }
    if !report.outcomes.is_empty() {
        s += "\noutcome | code | simulated s | heap height mm | edge radius mm | flank slope deg | status\n";
        for o in &report.outcomes {
            let (h, e, a) = o.heap.map_or(("-".into(), "-".into(), "-".into()), |h| {
                (
                    format!("{:.2}", 1e3 * h.height_m),
                    format!("{:.1}", 1e3 * h.edge_radius_m),
                    format!("{:.2}", h.slope_deg),
                )
            });
            s += &format!(
                "{} | {} | {:.3} | {h} | {e} | {a} | {}\n",
                o.case,
                super::label(o.code, o.build.as_deref(), None, None),
                o.simulated_s,
                o.status.lines().next().unwrap_or("")
            );
        }
    }
    for m in &report.memory {
        s += &format!(
            "\nmemory ({}): {:.0} bytes per particle, {:.0} bytes per listed pair ({} pairs, {} history entries)\n",
            m.case, m.bytes_per_particle, m.bytes_per_listed_pair, m.listed_pairs, m.history_entries
        );
    }
    s
}
