//! The nightly history: one record per night (its metrics, each with the tolerance it is
//! judged by), appended to `history.json` atomically, and `index.html` with the history
//! table, trend plots and the metrics that moved beyond their tolerance since the previous
//! night. An interrupted night loses nothing earlier: the history file is replaced whole,
//! by rename, only after the new night's record is complete.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::report::{write_figure, Cell, Figure, Report, Series, SeriesStyle, Table};
use crate::verdict::renamed_rule;
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::io::write_atomic;

/// One metric of one night.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metric {
    /// What is measured and its unit, e.g. "repose angle \[deg\]"; the trend plots group by it.
    pub quantity: String,
    pub value: f64,
    /// A change from the previous night larger than this is flagged.
    pub tolerance: f64,
    /// The tolerance is a fraction of the previous value (throughput), not an absolute one.
    pub relative: bool,
}

/// One night: where its report is and what it measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Night {
    pub date: String,
    pub commit: String,
    /// The night's report directory, relative to the history directory.
    pub report: String,
    pub runs: usize,
    pub runs_failed: usize,
    pub comparisons_failed: usize,
    pub metrics: BTreeMap<String, Metric>,
    /// This night's build against the previous night's, when the nightly ran the guard.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_guard: Option<SpeedGuard>,
}

/// Alternating pairs of the previous night's build and this one (`scripts/speed-guard.sh`,
/// its `speed_guard.json`): the median ratios new / base on the heap bench (throughput) and
/// the shortened main job (inverse wall time). Judged against a fixed threshold, not
/// against the previous night: a slow build must not become the next night's baseline
/// unnoticed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpeedGuard {
    /// The builds compared, as the nightly names them (their commits).
    pub base: String,
    pub new: String,
    pub pairs: usize,
    /// A median ratio below this is a flag.
    pub threshold: f64,
    pub heap_ratio_median: f64,
    pub mainjob_ratio_median: f64,
}

impl SpeedGuard {
    /// One flag per comparison whose median ratio is below the threshold, with the base
    /// build as 1.
    pub fn flags(&self) -> Vec<Flag> {
        [
            ("heap bench", self.heap_ratio_median),
            ("main job", self.mainjob_ratio_median),
        ]
        .into_iter()
        .filter(|&(_, ratio)| ratio < self.threshold)
        .map(|(what, ratio)| Flag {
            metric: format!(
                "speed guard: {what}, build {} against {} ({} alternating pairs)",
                self.new, self.base, self.pairs
            ),
            previous: 1.0,
            current: ratio,
            tolerance: 1.0 - self.threshold,
            relative: true,
        })
        .collect()
    }
}

/// A metric that moved beyond its tolerance since the previous night.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Flag {
    pub metric: String,
    pub previous: f64,
    pub current: f64,
    pub tolerance: f64,
    pub relative: bool,
}

#[derive(Debug, thiserror::Error)]
pub enum HistoryError {
    #[error("{file}: cannot read: {message}")]
    Unreadable { file: PathBuf, message: String },
    #[error("{file}: not a valid {what}: {message}")]
    Invalid {
        file: PathBuf,
        what: &'static str,
        message: String,
    },
    #[error("cannot write {file}: {message}")]
    Output { file: PathBuf, message: String },
}

/// Relative tolerance of throughput between nights: the machine is shared and noisy.
const THROUGHPUT_TOLERANCE: f64 = 0.25;

/// The night's metrics from its `summary.json` (as `cgdem validate` writes it): per case,
/// code, level and rule, the mean repose angle (tolerance: the suite's, recorded in the
/// comparisons) and the median throughput.
pub fn night_metrics(summary: &serde_json::Value) -> BTreeMap<String, Metric> {
    let empty = Vec::new();
    let runs = summary["runs"].as_array().unwrap_or(&empty);
    let comparisons = summary["comparisons"].as_array().unwrap_or(&empty);
    let mut groups: BTreeMap<String, (Vec<f64>, Vec<f64>, String)> = BTreeMap::new();
    for r in runs.iter().filter(|r| r["status"] == "ok") {
        let key = format!(
            "{} {} lambda={} {}",
            r["case"].as_str().unwrap_or("?"),
            r["code"].as_str().unwrap_or("?"),
            r["lambda"].as_u64().unwrap_or(0),
            r["cg_rule"]
                .as_str()
                .map_or("?", |n| CoarseGrainRule::from_name(n)
                    .map_or(n, |r| r.name())),
        );
        let entry = groups.entry(key).or_insert_with(|| {
            (
                Vec::new(),
                Vec::new(),
                r["case"].as_str().unwrap_or("?").into(),
            )
        });
        entry.0.extend(r["repose_angle_deg"].as_f64());
        entry.1.extend(r["particle_steps_per_s"].as_f64());
    }
    let mut out = BTreeMap::new();
    for (key, (angles, rates, case)) in groups {
        let angle_tolerance = comparisons
            .iter()
            .find(|c| c["case"] == case.as_str() && c["part"] == "final state")
            .and_then(|c| c["tolerance"].as_f64())
            .unwrap_or(2.0);
        if !angles.is_empty() {
            out.insert(
                format!("{key}: repose angle"),
                Metric {
                    quantity: "repose angle [deg]".into(),
                    value: angles.iter().sum::<f64>() / angles.len() as f64,
                    tolerance: angle_tolerance,
                    relative: false,
                },
            );
        }
        if let Some(median) = median(rates) {
            out.insert(
                format!("{key}: throughput"),
                Metric {
                    quantity: "throughput [particle-steps/s]".into(),
                    value: median,
                    tolerance: THROUGHPUT_TOLERANCE,
                    relative: true,
                },
            );
        }
    }
    out
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// The metrics of `current` that moved beyond their tolerance since `previous`.
pub fn flags(previous: &Night, current: &Night) -> Vec<Flag> {
    let moved = current.metrics.iter().filter_map(|(name, m)| {
        let p = previous.metrics.get(name)?;
        let allowed = if m.relative {
            m.tolerance * p.value.abs()
        } else {
            m.tolerance
        };
        ((m.value - p.value).abs() > allowed).then(|| Flag {
            metric: name.clone(),
            previous: p.value,
            current: m.value,
            tolerance: m.tolerance,
            relative: m.relative,
        })
    });
    moved.chain(guard_flags(current)).collect()
}

/// The flags of a night's speed guard (none when it did not run).
pub fn guard_flags(night: &Night) -> Vec<Flag> {
    night
        .speed_guard
        .as_ref()
        .map_or(Vec::new(), SpeedGuard::flags)
}

/// Adds the night in `night_dir` (a `cgdem validate` output) to the history in
/// `history_dir` (replacing an earlier record of the same report), rewrites the history
/// page, and returns the flags against the previous night.
/// The night's metrics from `cgdem bench` (`bench/bench.json` beside the suite's report):
/// the median throughput of each case, code and thread count, and the median speed ratio
/// cgdem / other code, both with the throughput tolerance (relative).
pub fn bench_metrics(bench: &serde_json::Value) -> BTreeMap<String, Metric> {
    let empty = Vec::new();
    let mut out = BTreeMap::new();
    for m in bench["medians"].as_array().unwrap_or(&empty) {
        if let Some(value) = m["median_particle_steps_per_s"].as_f64() {
            out.insert(
                format!(
                    "bench {} {} threads={}: throughput",
                    m["case"].as_str().unwrap_or("?"),
                    m["code"].as_str().unwrap_or("?"),
                    m["threads"].as_u64().unwrap_or(0)
                ),
                Metric {
                    quantity: "throughput [particle-steps/s]".into(),
                    value,
                    tolerance: THROUGHPUT_TOLERANCE,
                    relative: true,
                },
            );
        }
    }
    for r in bench["ratios"].as_array().unwrap_or(&empty) {
        if let Some(value) = r["median"].as_f64() {
            out.insert(
                format!(
                    "bench {} / {} threads={}: speed ratio",
                    r["numerator"].as_str().unwrap_or("?"),
                    r["denominator"].as_str().unwrap_or("?"),
                    r["threads"].as_u64().unwrap_or(0)
                ),
                Metric {
                    quantity: "speed ratio cgdem / other".into(),
                    value,
                    tolerance: THROUGHPUT_TOLERANCE,
                    relative: true,
                },
            );
        }
    }
    out
}

pub fn add_night(
    history_dir: &Path,
    night_dir: &Path,
    date: &str,
    commit: &str,
) -> Result<Vec<Flag>, HistoryError> {
    let summary_path = night_dir.join("summary.json");
    let text = std::fs::read_to_string(&summary_path).map_err(|e| HistoryError::Unreadable {
        file: summary_path.clone(),
        message: e.to_string(),
    })?;
    let summary: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| HistoryError::Invalid {
            file: summary_path.clone(),
            what: "validation summary",
            message: e.to_string(),
        })?;
    let runs = summary["runs"].as_array().map_or(0, Vec::len);
    let runs_failed = summary["runs"]
        .as_array()
        .map_or(0, |r| r.iter().filter(|r| r["status"] == "failed").count());
    // A known difference inside its band is not a failure (its `pass` is true).
    let comparisons_failed = summary["comparisons"]
        .as_array()
        .map_or(0, |c| c.iter().filter(|c| c["pass"] == false).count());
    let report = relative_to(night_dir, history_dir);
    let night = Night {
        date: date.into(),
        commit: commit.into(),
        report: report.clone(),
        runs,
        runs_failed,
        comparisons_failed,
        metrics: night_metrics(&summary),
        speed_guard: None,
    };
    let mut night = night;
    // The night's speed guard, when it ran (scripts/nightly.sh writes it before the suite).
    let guard_path = night_dir.join("speed_guard.json");
    if let Ok(text) = std::fs::read_to_string(&guard_path) {
        night.speed_guard =
            Some(
                serde_json::from_str(&text).map_err(|e| HistoryError::Invalid {
                    file: guard_path.clone(),
                    what: "speed guard result",
                    message: e.to_string(),
                })?,
            );
    }
    // The night's `cgdem bench`, when it ran (scripts/nightly.sh runs it into bench/).
    let bench_path = night_dir.join("bench").join("bench.json");
    if let Ok(text) = std::fs::read_to_string(&bench_path) {
        let bench: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| HistoryError::Invalid {
                file: bench_path.clone(),
                what: "bench report",
                message: e.to_string(),
            })?;
        night.metrics.extend(bench_metrics(&bench));
    }
    let history_path = history_dir.join("history.json");
    let mut nights = read_history(&history_path)?;
    nights.retain(|n| n.report != report);
    nights.push(night);
    let json = serde_json::to_string_pretty(&nights).expect("the history serializes");
    std::fs::create_dir_all(history_dir).map_err(|e| HistoryError::Output {
        file: history_dir.to_path_buf(),
        message: e.to_string(),
    })?;
    write_atomic(&history_path, json.as_bytes()).map_err(|e| HistoryError::Output {
        file: history_path.clone(),
        message: e.to_string(),
    })?;
    let latest = nights.len() - 1;
    let flagged = match latest {
        0 => guard_flags(&nights[0]),
        k => flags(&nights[k - 1], &nights[k]),
    };
    write_page(history_dir, &nights)?;
    Ok(flagged)
}

/// What moved since the last night recorded in `history_dir` before the night in
/// `night_dir` (whose `cgdem validate` summary is `summary`): a sentence, then one line per
/// metric beyond its tolerance and per comparison whose verdict changed.
pub fn since_previous(
    history_dir: &Path,
    night_dir: &Path,
    summary: &serde_json::Value,
) -> (String, Vec<String>) {
    let nights = match read_history(&history_dir.join("history.json")) {
        Ok(n) => n,
        Err(e) => {
            return (
                format!("Since the previous night: no history ({e})."),
                Vec::new(),
            )
        }
    };
    let report = relative_to(night_dir, history_dir);
    let Some(previous) = nights.iter().rev().find(|n| n.report != report) else {
        return (
            format!(
                "Since the previous night: this is the first night in {}.",
                history_dir.display()
            ),
            Vec::new(),
        );
    };
    // The night's own speed guard (scripts/nightly.sh runs it before the suite), not the
    // previous night's.
    let speed_guard = std::fs::read_to_string(night_dir.join("speed_guard.json"))
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok());
    let current = Night {
        metrics: night_metrics(summary),
        speed_guard,
        ..previous.clone()
    };
    let mut items: Vec<String> = flags(previous, &current)
        .iter()
        .map(|f| {
            format!(
                "{}: {} -> {} (tolerance {}{})",
                f.metric,
                crate::verdict::fmt(f.previous),
                crate::verdict::fmt(f.current),
                f.tolerance,
                if f.relative { " relative" } else { "" }
            )
        })
        .collect();
    // Verdicts then and now, by case, comparison and part (an older summary has only `pass`).
    let verdicts = |s: &serde_json::Value| -> BTreeMap<String, String> {
        s["comparisons"]
            .as_array()
            .map(|cs| {
                cs.iter()
                    .map(|c| {
                        let key = format!(
                            "{} {}, {}",
                            c["case"].as_str().unwrap_or("?"),
                            renamed_rule(c["what"].as_str().unwrap_or("?")),
                            c["part"].as_str().unwrap_or("?")
                        );
                        let verdict = match c["verdict"].as_str() {
                            Some(v) => v.to_string(),
                            None if c["pass"] == true => "pass".into(),
                            None => "fail".into(),
                        };
                        (key, verdict)
                    })
                    .collect()
            })
            .unwrap_or_default()
    };
    let before = std::fs::read_to_string(history_dir.join(&previous.report).join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .map(|v| verdicts(&v))
        .unwrap_or_default();
    for (key, now) in verdicts(summary) {
        match before.get(&key) {
            Some(then) if *then != now => items.push(format!("{key}: {then} -> {now}")),
            None if !before.is_empty() => items.push(format!("{key}: new ({now})")),
            _ => {}
        }
    }
    let text = format!(
        "Since the previous night ({} {}, {}): {}",
        previous.date,
        previous.commit,
        previous.report,
        if items.is_empty() {
            "no metric moved beyond its tolerance and no verdict changed."
        } else {
            "moved beyond tolerance or changed verdict:"
        }
    );
    (text, items)
}

/// The nights recorded so far (none if the file does not exist yet).
pub fn read_history(path: &Path) -> Result<Vec<Night>, HistoryError> {
    match std::fs::read_to_string(path) {
        Ok(text) => parse_history(&text, path),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
        Err(e) => Err(HistoryError::Unreadable {
            file: path.to_path_buf(),
            message: e.to_string(),
        }),
    }
}

/// The nights in the text of the history file `path` (named in errors, with serde's line and
/// column).
/// column). Metrics recorded under the rule's first name `seed` are read under
/// `relative-overlap`, so their trends continue.
pub fn parse_history(text: &str, path: &Path) -> Result<Vec<Night>, HistoryError> {
    let mut nights: Vec<Night> = serde_json::from_str(text).map_err(|e| HistoryError::Invalid {
        file: path.to_path_buf(),
        what: "history file (a JSON list of nights)",
        message: e.to_string(),
    })?;
    for night in &mut nights {
        night.metrics = std::mem::take(&mut night.metrics)
            .into_iter()
            .map(|(name, metric)| (renamed_rule(&name), metric))
            .collect();
    }
    Ok(nights)
}

fn relative_to(path: &Path, base: &Path) -> String {
    let abs = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let (p, b) = (abs(path), abs(base));
    p.strip_prefix(&b)
        .map(|r| r.display().to_string())
        .unwrap_or_else(|_| p.display().to_string())
}

/// One row per night: its report, runs, failures and flags.
fn nights_table(nights: &[Night]) -> Table {
    let mut table = Table::new([
        "night",
        "date",
        "commit",
        "report",
        "runs",
        "failed runs",
        "failed comparisons",
        "flags",
    ])
    .caption("Nights");
    for (k, n) in nights.iter().enumerate() {
        let flagged = if k == 0 {
            guard_flags(n).len()
        } else {
            flags(&nights[k - 1], n).len()
        };
        let count = |v: usize| {
            if v == 0 {
                Cell::pass("0")
            } else {
                Cell::fail(v.to_string())
            }
        };
        table.row([
            Cell::num((k + 1).to_string()),
            Cell::text(&n.date),
            Cell::text(&n.commit),
            Cell::text(format!("{}/index.html", n.report)),
            Cell::num(n.runs.to_string()),
            count(n.runs_failed),
            count(n.comparisons_failed),
            count(flagged),
        ]);
    }
    table
}

fn write_page(dir: &Path, nights: &[Night]) -> Result<(), HistoryError> {
    let output = |file: &Path, e: &dyn std::fmt::Display| HistoryError::Output {
        file: file.to_path_buf(),
        message: e.to_string(),
    };
    let mut report = Report::new("cgdem nightly validation: history");
    let intro = report.intro();
    intro.paragraph(
        "One row per night (newest last), with a link to its report; then the metrics that \
         moved beyond their tolerance since the previous night, and the trends. Repose angles \
         are judged by the suite's angle tolerance; throughput by 25% (the machine is shared).",
    );
    intro.table(nights_table(nights));
    if let Some(guard) = nights.last().and_then(|n| n.speed_guard.as_ref()) {
        intro.paragraph(format!(
            "Speed of build {} against the previous night's {} ({} alternating pairs, \
             new / base, a median below {} is a flag): heap bench {:.3}, main job {:.3}.",
            guard.new,
            guard.base,
            guard.pairs,
            guard.threshold,
            guard.heap_ratio_median,
            guard.mainjob_ratio_median
        ));
    }
    let flagged = match nights.len() {
        0 => Vec::new(),
        1 => guard_flags(&nights[0]),
        n => flags(&nights[n - 2], &nights[n - 1]),
    };
    if nights.len() >= 2 || !flagged.is_empty() {
        let mut moved = Table::new(["metric", "previous", "latest", "tolerance"])
            .caption("Moved beyond tolerance since the previous night (or the previous build)");
        for f in flagged {
            let tol = if f.relative {
                format!("{:.0}%", 100.0 * f.tolerance)
            } else {
                format!("{}", f.tolerance)
            };
            moved.row([
                Cell::fail(f.metric),
                Cell::num(format!("{:.4e}", f.previous)),
                Cell::num(format!("{:.4e}", f.current)),
                Cell::num(tol),
            ]);
        }
        intro.table(moved);
    }
    // One trend plot per quantity, one line per metric, x = night number.
    let mut quantities: BTreeMap<String, Figure> = BTreeMap::new();
    let names: std::collections::BTreeSet<&String> =
        nights.iter().flat_map(|n| n.metrics.keys()).collect();
    for name in names {
        let mut quantity = None;
        let points: Vec<(f64, f64)> = nights
            .iter()
            .enumerate()
            .filter_map(|(k, n)| {
                let m = n.metrics.get(name)?;
                quantity = Some(m.quantity.clone());
                Some(((k + 1) as f64, m.value))
            })
            .collect();
        let Some(quantity) = quantity else { continue };
        let label = name.rsplit_once(": ").map_or(name.as_str(), |(l, _)| l);
        quantities
            .entry(quantity.clone())
            .or_insert_with(|| Figure::new(format!("trend: {quantity}"), "night", quantity.clone()))
            .series
            .push(Series::new(label, points).style(SeriesStyle::LineMarkers));
    }
    let figures_dir = dir.join("trends");
    let section = report.section("Trends");
    for (k, (quantity, figure)) in quantities.iter().enumerate() {
        let files = write_figure(&figures_dir, &format!("trend{k}"), figure)
            .map_err(|e| output(&figures_dir, &e))?;
        section
            .figure(
                &files,
                format!("trend of {quantity}"),
                "One point per night; the night numbers are those of the table above.",
            )
            .map_err(|e| output(&figures_dir, &e))?;
    }
    let page = dir.join("index.html");
    report.write(&page).map_err(|e| output(&page, &e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary(angle: f64, rate: f64) -> serde_json::Value {
        serde_json::json!({
            "runs": [
                {"case": "c", "code": "cgdem", "lambda": 8, "cg_rule": "seed", "status": "ok", "repose_angle_deg": angle - 1.0, "particle_steps_per_s": rate},
                {"case": "c", "code": "cgdem", "lambda": 8, "cg_rule": "seed", "status": "ok", "repose_angle_deg": angle + 1.0, "particle_steps_per_s": rate * 3.0},
                {"case": "c", "code": "cgdem", "lambda": 8, "cg_rule": "seed", "status": "failed", "repose_angle_deg": null, "particle_steps_per_s": null}
            ],
            "comparisons": [{"case": "c", "part": "final state", "tolerance": 1.5, "pass": true}]
        })
    }

    #[test]
    fn metrics_are_seed_means_and_median_throughput_with_the_suite_tolerance() {
        let m = night_metrics(&summary(30.0, 1e6));
        let angle = &m["c cgdem lambda=8 relative-overlap: repose angle"];
        assert_eq!(
            (angle.value, angle.tolerance, angle.relative),
            (30.0, 1.5, false)
        );
        let rate = &m["c cgdem lambda=8 relative-overlap: throughput"];
        assert_eq!((rate.value, rate.relative), (2e6, true));
    }

    #[test]
    fn bench_medians_and_ratios_become_relative_metrics() {
        let bench = serde_json::json!({
            "medians": [{"case": "bench_heap", "code": "cgdem", "threads": 2, "median_particle_steps_per_s": 1.5e7}],
            "ratios": [{"numerator": "bench_heap cgdem", "denominator": "bench_heap lammps", "threads": 2, "median": 2.4}]
        });
        let m = bench_metrics(&bench);
        let ratio = &m["bench bench_heap cgdem / bench_heap lammps threads=2: speed ratio"];
        assert_eq!((ratio.value, ratio.relative), (2.4, true));
        assert_eq!(
            m["bench bench_heap cgdem threads=2: throughput"].value,
            1.5e7
        );
    }

    #[test]
    fn a_move_beyond_tolerance_is_flagged_and_a_small_one_is_not() {
        let night = |angle, rate| Night {
            date: "d".into(),
            commit: "c".into(),
            report: "r".into(),
            runs: 2,
            runs_failed: 0,
            comparisons_failed: 0,
            metrics: night_metrics(&summary(angle, rate)),
            speed_guard: None,
        };
        assert!(flags(&night(30.0, 1e6), &night(31.0, 1.2e6)).is_empty());
        let f = flags(&night(30.0, 1e6), &night(32.0, 0.5e6));
        let names: Vec<&str> = f.iter().map(|f| f.metric.as_str()).collect();
        assert_eq!(
            names,
            [
                "c cgdem lambda=8 relative-overlap: repose angle",
                "c cgdem lambda=8 relative-overlap: throughput"
            ]
        );
    }

    #[test]
    fn nights_accumulate_and_a_broken_history_is_refused_not_overwritten() {
        let base = std::env::temp_dir().join(format!("cgdem-history-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        for (k, angle) in [(1, 30.0), (2, 35.0)] {
            let night = base.join(format!("night{k}"));
            std::fs::create_dir_all(&night).unwrap();
            std::fs::write(night.join("summary.json"), summary(angle, 1e6).to_string()).unwrap();
            let f = add_night(&base, &night, &format!("2026-11-0{k}"), "abc").unwrap();
            assert_eq!(f.len(), k - 1, "night {k}: {f:?}");
        }
        // Re-adding a night replaces its record instead of duplicating it.
        add_night(&base, &base.join("night2"), "2026-11-02", "abc").unwrap();
        let nights = read_history(&base.join("history.json")).unwrap();
        assert_eq!(nights.len(), 2);
        assert!(std::fs::read_to_string(base.join("index.html"))
            .unwrap()
            .contains("night2/index.html"));
        std::fs::write(base.join("history.json"), "[{\"truncated").unwrap();
        let e = add_night(&base, &base.join("night2"), "x", "y")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("history.json") && e.contains("not a valid history file"),
            "{e}"
        );
        assert_eq!(
            std::fs::read_to_string(base.join("history.json")).unwrap(),
            "[{\"truncated"
        );
        let _ = std::fs::remove_dir_all(&base);
    }

    #[test]
    fn the_first_screen_lists_what_moved_since_the_previous_night() {
        let base = std::env::temp_dir().join(format!("cgdem-since-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        let night1 = base.join("night1");
        std::fs::create_dir_all(&night1).unwrap();
        std::fs::write(night1.join("summary.json"), summary(30.0, 1e6).to_string()).unwrap();
        let (text, items) = since_previous(&base, &base.join("night2"), &summary(30.0, 1e6));
        assert!(
            text.contains("no history") || text.contains("first night"),
            "{text}"
        );
        assert!(items.is_empty());
        add_night(&base, &night1, "2026-11-01", "abc").unwrap();
        // Same numbers: nothing moved.
        let (text, items) = since_previous(&base, &base.join("night2"), &summary(30.4, 1e6));
        assert!(text.contains("no metric moved"), "{text}");
        assert!(items.is_empty(), "{items:?}");
        // The angle moves by 3 deg (tolerance 1.5) and the comparison turns red.
        let mut now = summary(33.0, 1e6);
        now["comparisons"][0]["pass"] = serde_json::json!(false);
        now["comparisons"][0]["verdict"] = serde_json::json!("fail");
        let (_, items) = since_previous(&base, &base.join("night2"), &now);
        assert_eq!(items.len(), 2, "{items:?}");
        assert!(items[0].contains("repose angle: 30.0 -> 33.0"), "{items:?}");
        assert!(items[1].ends_with("pass -> fail"), "{items:?}");
        let _ = std::fs::remove_dir_all(&base);
    }

    #[test]
    fn a_slower_build_is_a_flag_on_the_first_screen_and_an_unchanged_one_is_not() {
        let base = std::env::temp_dir().join(format!("cgdem-guard-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        let guard = |heap: f64, mainjob: f64| {
            serde_json::json!({
                "base": "aaa1111", "new": "bbb2222", "pairs": 5, "threshold": 0.95,
                "heap_ratio_median": heap, "mainjob_ratio_median": mainjob,
                "heap_ratios": [heap], "flagged": heap < 0.95 || mainjob < 0.95
            })
        };
        for (k, (heap, mainjob)) in [(1, (0.99, 1.02)), (2, (0.80, 1.0))] {
            let night = base.join(format!("night{k}"));
            std::fs::create_dir_all(&night).unwrap();
            std::fs::write(night.join("summary.json"), summary(30.0, 1e6).to_string()).unwrap();
            std::fs::write(
                night.join("speed_guard.json"),
                guard(heap, mainjob).to_string(),
            )
            .unwrap();
            let f = add_night(&base, &night, &format!("2026-11-0{k}"), "bbb2222").unwrap();
            let page = std::fs::read_to_string(base.join("index.html")).unwrap();
            assert!(page.contains("against the previous night"), "night {k}");
            if k == 1 {
                assert!(f.is_empty(), "{f:?}");
            } else {
                assert_eq!(f.len(), 1, "{f:?}");
                assert!(f[0]
                    .metric
                    .contains("heap bench, build bbb2222 against aaa1111"));
                assert_eq!(f[0].current, 0.80);
                assert!(page.contains("speed guard: heap bench"));
                // The night's report says it too, before the history is written.
                let (_, items) = since_previous(&base, &base.join("night2"), &summary(30.0, 1e6));
                assert!(items.iter().any(|i| i.contains("speed guard")), "{items:?}");
            }
        }
        let _ = std::fs::remove_dir_all(&base);
    }
}
