//! The report of a drum case: the rules, cgdem's verdict against the reference codes, a
//! table of each run's steady means and swing (`figures/<case>/drum_runs.csv`), the zone
//! counts, the surface angle and Lacey's index against time (each code's mean over its
//! seeds), and every frame's measures as CSV (`figures/<case>/drum_frames.csv`) beside the
//! figures.

use std::fmt::Write as _;
use std::path::Path;

use super::{DrumRun, DrumSettings};
use crate::quantity::{show_figure, CaseOrigin};
use crate::report::{Cell, Figure, Report, Series, SeriesStyle, Table};
use crate::runs::{output_error, ValidateError};
use crate::verdict::Verdict;
use cgdem_core::io::{write_atomic, CsvBuffer};
use cgdem_core::scene::Scene;

fn num(v: Option<f64>, digits: usize) -> Cell {
    Cell::num(v.map_or("-".into(), |x| format!("{x:.digits$}")))
}

fn label(r: &DrumRun) -> String {
    format!("{} l{} s{}", r.code.name(), r.lambda, r.seed)
}

/// The section of one drum case, with cgdem's verdict (and the means in words) when it has
/// one.
pub fn write_drum_section(
    report: &mut Report,
    scene: &Scene,
    case: &CaseOrigin,
    settings: &DrumSettings,
    runs: &[DrumRun],
    verdict: Option<(Verdict, &str)>,
    out: &Path,
) -> Result<(), ValidateError> {
    let dir = out.join("figures").join(&scene.name);
    let section = report.section(format!("Case {}: rotating drum", scene.name));
    section.paragraph(format!(
        "{} Scene file: {}. Seeds: {:?}. From each frame (every code's grains at the frame's time; times from the start of stage `{}`, when the drum starts turning; earlier frames are the settle): the grains of the small (M1) and the large (M2) species whose centre lies in zone 1 (x > 0, z > 0, the upper quadrant on the side where the wall rises) and zone 2 (x < 0, z < 0), as MercuryDPM counts them; the dynamic angle of repose: the highest grain top in bins of two small-grain diameters along x, a least-squares line through the bins between 20% and 80% of the occupied span, atan of its slope, positive when the surface rises towards +x; Lacey's index of the large grains' volume fraction in cubic cells of 2.5 large-grain diameters with at least 10 grains (0 segregated, 1 random). Steady means: the frames from {} s of rotation on. The swing of the zone counts over the same frames: for trial periods from two frame intervals to the window's length, 0.5% apart, each count fitted by least squares with a constant and a sinusoid of that period; the period is the one that leaves the least of the four counts' variance unexplained (each count weighed by its own variance), the amplitude each sinusoid's (half its swing); none when the best period is the window's length (less than one swing seen). reference/DRUM.md defines the measures. cgdem's verdict: each zone count's and the angle's mean over cgdem's seeds within the reference codes' spread, every code's mean widened by two standard errors of its seeds' mean (a count's gap as a share of the reference codes' mean, the angle's in degrees).",
        scene.description,
        case.file.display(),
        case.seeds,
        settings.stage,
        settings.steady_from_s,
    ));
    if let Some((verdict, text)) = verdict {
        let status = match verdict {
            Verdict::Pass => crate::report::Status::Pass,
            Verdict::KnownDifference => crate::report::Status::Known,
            Verdict::Fail => crate::report::Status::Fail,
        };
        section.banner(status, format!("Zone counts and dynamic angle: {text}."));
    }
    let mut table = Table::new([
        "run",
        "frames",
        "zone 1 M1",
        "zone 1 M2",
        "zone 2 M1",
        "zone 2 M2",
        "angle, deg",
        "Lacey",
        "swing period, s",
        "swing amplitudes (grains)",
        "problem",
    ])
    .caption(format!(
        "Means over the steady frames (from {} s of rotation)",
        settings.steady_from_s
    ));
    for r in runs {
        let m = r.steady_means(settings.steady_from_s);
        let swing = r.oscillation(settings.steady_from_s);
        let count = |k: usize| num(m.map(|m| m.counts[k]), 0);
        table.row([
            Cell::text(label(r)),
            Cell::num(m.map_or(0, |m| m.frames).to_string()),
            count(0),
            count(1),
            count(2),
            count(3),
            num(m.and_then(|m| m.angle_deg), 1),
            num(m.and_then(|m| m.lacey), 3),
            num(swing.map(|o| o.period_s), 2),
            Cell::num(swing.map_or("-".into(), |o| {
                (o.amplitudes.map(|a| format!("{a:.0}"))).join(" / ")
            })),
            Cell::text(r.problem.clone().unwrap_or_default()),
        ]);
    }
    section.table(table);
    std::fs::create_dir_all(&dir).map_err(|e| output_error(&dir, e))?;
    let runs_csv = dir.join("drum_runs.csv");
    runs_table(runs, settings.steady_from_s)
        .bytes()
        .and_then(|bytes| write_atomic(&runs_csv, bytes))
        .map_err(|e| output_error(&runs_csv, e))?;
    let frames_csv = dir.join("drum_frames.csv");
    write_atomic(&frames_csv, frames_table(runs).as_bytes())
        .map_err(|e| output_error(&frames_csv, e))?;
    for (stem, figure, caption) in figures(runs) {
        show_figure(
            section,
            &dir,
            stem,
            &figure,
            (&figure.title.clone(), caption),
        )?;
    }
    section.paragraph(format!(
        "Each run's steady means and swing: {}. Every frame's measures: {}.",
        runs_csv.display(),
        frames_csv.display()
    ));
    Ok(())
}

/// Each run's steady means and swing as CSV.
fn runs_table(runs: &[DrumRun], steady_from_s: f64) -> CsvBuffer {
    let mut csv = CsvBuffer::new([
        "code",
        "lambda",
        "seed",
        "steady_frames",
        "zone1_m1",
        "zone1_m2",
        "zone2_m1",
        "zone2_m2",
        "surface_angle_deg",
        "lacey_index",
        "swing_period_s",
        "swing_amplitude_zone1_m1",
        "swing_amplitude_zone1_m2",
        "swing_amplitude_zone2_m1",
        "swing_amplitude_zone2_m2",
        "swing_explained",
    ]);
    let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6}"));
    for r in runs {
        let m = r.steady_means(steady_from_s);
        let swing = r.oscillation(steady_from_s);
        let count = |k: usize| o(m.map(|m| m.counts[k]));
        let amplitude = |k: usize| o(swing.map(|s| s.amplitudes[k]));
        csv.row([
            r.code.name().to_string(),
            r.lambda.to_string(),
            r.seed.to_string(),
            m.map_or(0, |m| m.frames).to_string(),
            count(0),
            count(1),
            count(2),
            count(3),
            o(m.and_then(|m| m.angle_deg)),
            o(m.and_then(|m| m.lacey)),
            o(swing.map(|s| s.period_s)),
            amplitude(0),
            amplitude(1),
            amplitude(2),
            amplitude(3),
            o(swing.map(|s| s.explained)),
        ]);
    }
    csv
}

/// Every measured frame of every run as CSV.
fn frames_table(runs: &[DrumRun]) -> String {
    let mut csv = String::from(
        "code,lambda,seed,time_s,zone1_m1,zone1_m2,zone2_m1,zone2_m2,surface_angle_deg,surface_r2,lacey_index,lacey_cells\n",
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6}"));
    for r in runs {
        for f in &r.frames {
            let [a, b, c, d] = f.counts.as_array();
            let _ = writeln!(
                csv,
                "{},{},{},{:.6},{a},{b},{c},{d},{},{},{},{}",
                r.code.name(),
                r.lambda,
                r.seed,
                f.time_s,
                opt(f.surface.map(|s| s.angle_deg)),
                opt(f.surface.map(|s| s.r2)),
                opt(f.lacey.map(|l| l.index)),
                f.lacey.map_or(String::new(), |l| l.cells.to_string()),
            );
        }
    }
    csv
}

/// The runs of one code and level (their seeds): for each frame time, rounded to the
/// nearest frame interval (the seeds' rotations start up to a few steps apart), the mean and
/// standard deviation over the seeds of `value`.
fn seeds_mean(
    runs: &[&DrumRun],
    value: impl Fn(&super::FrameMeasure) -> Option<f64>,
) -> (Vec<(f64, f64)>, Vec<f64>) {
    let interval = (runs.iter())
        .flat_map(|r| r.frames.windows(2).map(|w| w[1].time_s - w[0].time_s))
        .fold(f64::INFINITY, f64::min);
    let interval = if interval.is_finite() && interval > 0.0 {
        interval
    } else {
        1.0
    };
    let mut at: std::collections::BTreeMap<i64, Vec<f64>> = Default::default();
    for f in runs.iter().flat_map(|r| &r.frames) {
        if let Some(v) = value(f) {
            at.entry((f.time_s / interval).round() as i64)
                .or_default()
                .push(v);
        }
    }
    at.into_iter()
        .map(|(k, v)| {
            let (mean, sd) = crate::quantity::seeds::mean_spread(&v).unwrap_or((f64::NAN, 0.0));
            ((k as f64 * interval, mean), sd)
        })
        .unzip()
}

/// The zone counts (zone 1 and zone 2 apart), the surface angle and Lacey's index against
/// time: each code's mean over its seeds, with their standard deviation as error bars (each
/// run's frames are in `drum_frames.csv`).
fn figures(runs: &[DrumRun]) -> Vec<(&'static str, Figure, &'static str)> {
    let axis = "time since the drum started, s";
    let mut zone1 = Figure::new("Zone 1 counts against time", axis, "grains in zone 1");
    let mut zone2 = Figure::new("Zone 2 counts against time", axis, "grains in zone 2");
    let mut angle = Figure::new("Dynamic angle of repose", axis, "surface angle, deg");
    let mut lacey = Figure::new("Lacey's mixing index", axis, "Lacey index");
    let mut groups: Vec<(crate::code::Code, u32)> = (runs.iter())
        .filter(|r| !r.frames.is_empty())
        .map(|r| (r.code, r.lambda))
        .collect();
    groups.sort();
    groups.dedup();
    for (code, lambda) in groups {
        let members: Vec<&DrumRun> = (runs.iter())
            .filter(|r| r.code == code && r.lambda == lambda && !r.frames.is_empty())
            .collect();
        let name = format!("{} l{lambda} ({} seeds)", code.name(), members.len());
        let series = |label: String, (points, sd): (Vec<(f64, f64)>, Vec<f64>)| {
            Series::new(label, points)
                .y_err(sd)
                .style(SeriesStyle::LineMarkers)
        };
        for (k, species) in ["M1", "M2"].iter().enumerate() {
            let count = |zone: usize| {
                seeds_mean(&members, move |f| {
                    Some(f.counts.as_array()[2 * zone + k] as f64)
                })
            };
            zone1 = zone1.with_series(series(format!("{name} {species}"), count(0)));
            zone2 = zone2.with_series(series(format!("{name} {species}"), count(1)));
        }
        angle = angle.with_series(series(
            name.clone(),
            seeds_mean(&members, |f| f.surface.map(|s| s.angle_deg)),
        ));
        lacey = lacey.with_series(series(
            name,
            seeds_mean(&members, |f| f.lacey.map(|l| l.index)),
        ));
    }
    vec![
        ("drum_zone1_counts", zone1, "Grains of each species in MercuryDPM's zone 1 (x > 0, z > 0): each code's mean over its seeds at each frame, error bars one standard deviation over the seeds; negative times are the settle."),
        ("drum_zone2_counts", zone2, "Grains of each species in MercuryDPM's zone 2 (x < 0, z < 0), as zone 1's figure."),
        ("drum_surface_angle", angle, "The free surface's angle by the rule above, each code's mean over its seeds per frame."),
        ("drum_lacey", lacey, "Lacey's index of the large grains' volume fraction, each code's mean over its seeds per frame."),
    ]
}
