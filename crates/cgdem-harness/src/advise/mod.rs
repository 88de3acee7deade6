//! `cgdem advise`: from a stored coarse-graining matrix (the `accuracy` points of a
//! `cgdem validate` report whose sweeps vary lambda under each rule against a fine
//! reference), the coarsest level and rule that keeps a quantity within a target, and what it
//! saves.
//!
//! A setting meets the target when its mean error over seeds plus its spread (twice the
//! standard error of the mean, the `k = 2` of the verdicts) is within it, so a level that
//! meets it by the luck of one packing is not advised. Among those, the largest lambda wins
//! (ties: the fewest particle-steps). When none meets it, the answer is "none" with the
//! setting that came closest.
//!
//! The matrix comes from a suite's sweeps, or for a scene no suite names, from the scene
//! alone (`scene`: its levels, rules and seeds), with its cost counted before it runs
//! (`cost`).

mod cost;
mod scene;

pub use cost::{matrix_cost, probe, MatrixCost, Probe, RunCost, PROBE_STEPS};
pub use scene::{
    discharge_settings, measurable, opening, scene_matrix, LevelPlan, MatrixChoice, Opening,
    SceneMatrix, DEFAULT_SEEDS, MIN_ACROSS_OPENING, MIN_PARTICLES, VARIANT,
};

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::accuracy::{settings, AccuracyPoint, Cost, Measure, Setting, SPREAD_STANDARD_ERRORS};
use super::code::Code;
use super::runs::{ValidateError, ValidateOptions};
use super::suite::Suite;
use super::validation::validate_suite;

#[derive(Debug, thiserror::Error)]
pub enum AdviseError {
    #[error("{file}: cannot read the stored matrix: {reason}; make it with `cgdem validate --suite SUITE --out DIR` (its sweeps vary lambda) and pass --matrix DIR")]
    Matrix { file: PathBuf, reason: String },
    #[error("{file}: no coarse-graining points for case `{case}` (cases with points: {known})")]
    NoCase {
        file: PathBuf,
        case: String,
        known: String,
    },
    #[error("{file}: `{case}` names several cases, one per variant: {variants}; name one of them")]
    Ambiguous {
        file: PathBuf,
        case: String,
        variants: String,
    },
    #[error("{file}: case `{case}` has no successful fine reference run to compare with")]
    NoReference { file: PathBuf, case: String },
    #[error("{suite}: `{case}` is not one of its accuracy sweeps' cases, nor the one of them with a variant (its sweeps' cases: {known})")]
    NoSweep {
        suite: PathBuf,
        case: String,
        known: String,
    },
    #[error("{0}")]
    Run(#[from] ValidateError),
    #[error("{file}: the scene cannot measure {quantity}; it can measure: {measurable}")]
    NotMeasurable {
        file: PathBuf,
        quantity: String,
        measurable: String,
    },
    #[error("{file}: no coarse-graining matrix: {reason}")]
    NoMatrix { file: PathBuf, reason: String },
    #[error("{file}: {option} {value} is not allowed: {reason}")]
    Choice {
        file: PathBuf,
        option: String,
        value: String,
        reason: String,
    },
    #[error("case `{case}`: no coarse-grained run measured {quantity} (they measured: {measured}; a failed run measures nothing, the report says why)")]
    NotMeasured {
        case: String,
        quantity: String,
        measured: String,
    },
}

/// One coarse-graining setting as the answer reports it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Level {
    pub setting: String,
    pub lambda: u32,
    pub cg_rule: String,
    /// Mean error over seeds and its spread (`SPREAD_STANDARD_ERRORS` standard errors; None
    /// with one seed, when it is unknown and counted as zero).
    pub error: f64,
    pub spread: Option<f64>,
    pub seeds: usize,
    pub particle_steps: f64,
    pub wall_s: Option<f64>,
    /// The fine reference's particle-steps (and wall time) over this setting's.
    pub saving_particle_steps: f64,
    pub saving_wall: Option<f64>,
}

impl Level {
    /// The error a target must allow: the mean plus the spread.
    pub fn reach(&self) -> f64 {
        self.error + self.spread.unwrap_or(0.0)
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Advice {
    pub case: String,
    pub quantity: String,
    pub target: f64,
    /// The fine reference: its lambda and rule.
    pub reference: String,
    /// The coarsest setting within the target; None: nothing meets it.
    pub advised: Option<Level>,
    /// When nothing meets the target: the setting with the smallest error plus spread.
    pub best_reached: Option<Level>,
    /// Every coarse-grained setting considered, finest first.
    pub considered: Vec<Level>,
}

impl Advice {
    /// The answer in words, as the command prints it.
    pub fn text(&self, m: Measure) -> String {
        let level = |l: &Level| {
            format!(
                "lambda = {} under the {} rule: error {} {}, {:.1}x fewer particle-steps{}",
                l.lambda,
                l.cg_rule,
                m.format(l.error),
                match l.spread {
                    Some(s) => format!("+- {} ({} seeds)", m.format(s), l.seeds),
                    None => "(1 seed: spread unknown)".into(),
                },
                l.saving_particle_steps,
                l.saving_wall
                    .map_or(String::new(), |w| format!(", {w:.1}x less wall time"))
            )
        };
        match (&self.advised, &self.best_reached) {
            (Some(l), _) => format!(
                "{}: {} within {}: {} (against {})",
                self.case,
                self.quantity,
                m.format(self.target),
                level(l),
                self.reference
            ),
            (None, Some(l)) => format!(
                "{}: {} within {}: none; the closest is {} (against {})",
                self.case,
                self.quantity,
                m.format(self.target),
                level(l),
                self.reference
            ),
            (None, None) => format!(
                "{}: {} within {}: none; no coarse-grained setting measured it",
                self.case,
                self.quantity,
                m.format(self.target)
            ),
        }
    }
}

/// Reads the `accuracy` points of a report directory's (or file's) `summary.json`.
pub fn read_matrix(path: &Path) -> Result<(PathBuf, Vec<AccuracyPoint>), AdviseError> {
    let (_, file) = matrix_paths(path);
    let fail = |reason: String| AdviseError::Matrix {
        file: file.clone(),
        reason,
    };
    let text = std::fs::read_to_string(&file).map_err(|e| fail(e.to_string()))?;
    let summary: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| fail(format!("not JSON: {e}")))?;
    let points = summary
        .get("accuracy")
        .and_then(|a| a.get("points"))
        .ok_or_else(|| fail("no `accuracy.points` (a report without sweeps)".into()))?;
    let points: Vec<AccuracyPoint> = serde_json::from_value(points.clone())
        .map_err(|e| fail(format!("`accuracy.points`: {e}")))?;
    Ok((file, points))
}

/// The matrix's directory and its summary.json, from `--matrix` naming either (a
/// summary.json that `advise --run` has yet to write included).
pub fn matrix_paths(matrix: &Path) -> (PathBuf, PathBuf) {
    if matrix.is_file() || matrix.extension().is_some_and(|e| e == "json") {
        let dir = matrix.parent().unwrap_or(Path::new("."));
        (dir.to_path_buf(), matrix.to_path_buf())
    } else {
        (matrix.to_path_buf(), matrix.join("summary.json"))
    }
}

/// Which of `cases` the user's `case` names: itself, or the one case that is `case` with a
/// variant (`aor_hertz` for `aor_hertz-fidelity`). Otherwise the cases with a variant it
/// names (several: ambiguous; none: unknown).
pub fn resolve_case<'a>(cases: &[&'a str], case: &str) -> Result<&'a str, Vec<&'a str>> {
    if let Some(exact) = cases.iter().find(|&&c| c == case) {
        return Ok(exact);
    }
    let mut variants: Vec<&str> = cases
        .iter()
        .copied()
        .filter(|c| c.strip_prefix(case).is_some_and(|v| v.starts_with('-')))
        .collect();
    variants.sort();
    variants.dedup();
    match variants[..] {
        [one] => Ok(one),
        _ => Err(variants),
    }
}

/// The error for a `case` that names none of `known` (`NotFound`'s) or several (`Ambiguous`).
fn unresolved(
    source: &Path,
    case: &str,
    variants: Vec<&str>,
    known: &[&str],
    not_found: impl FnOnce(String) -> AdviseError,
) -> AdviseError {
    if variants.len() > 1 {
        return AdviseError::Ambiguous {
            file: source.to_path_buf(),
            case: case.to_string(),
            variants: variants.join(", "),
        };
    }
    let mut known = known.to_vec();
    known.sort();
    known.dedup();
    not_found(if known.is_empty() {
        "none".into()
    } else {
        known.join(", ")
    })
}

/// `cgdem advise --run`: makes the accuracy sweeps of `case` in `suite` as `cgdem validate
/// --reuse` would, with the runs in `MATRIX/runs` (those already there are taken, the
/// missing ones made) and the report of this case alone in `MATRIX/advise/<case>/`, so the
/// matrix's own report and its other cases are left as they were. `options` carries the
/// threads, jobs and interrupt flag; its output and runs directories are set here. Returns
/// the case's report directory, to read the matrix from.
pub fn run_case(
    suite: &Suite,
    case: &str,
    matrix: &Path,
    options: &ValidateOptions,
) -> Result<PathBuf, AdviseError> {
    let mut names = Vec::new();
    for sweep in &suite.accuracy {
        let name = sweep
            .case_name(&suite.source)
            .map_err(|message| ValidateError::Case {
                file: sweep.file.clone(),
                message,
            })?;
        names.push(name);
    }
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let name = match resolve_case(&refs, case) {
        Ok(name) => name.to_string(),
        Err(variants) => {
            return Err(unresolved(&suite.source, case, variants, &refs, |known| {
                AdviseError::NoSweep {
                    suite: suite.source.clone(),
                    case: case.to_string(),
                    known,
                }
            }))
        }
    };
    let mine = Suite {
        cases: Vec::new(),
        stability: Vec::new(),
        chung_ooi: Vec::new(),
        accuracy: suite
            .accuracy
            .iter()
            .zip(&names)
            .filter(|(_, n)| **n == name)
            .map(|(s, _)| s.clone())
            .collect(),
        ..suite.clone()
    };
    let (matrix_dir, _) = matrix_paths(matrix);
    let out = matrix_dir.join("advise").join(&name);
    let options = ValidateOptions {
        suite: suite.source.clone(),
        out: out.clone(),
        runs_dir: Some(matrix_dir.join("runs")),
        reuse: true,
        ..options.clone()
    };
    validate_suite(&mine, &options)?;
    Ok(out)
}

/// `cgdem advise CASE.toml --run` for a scene no suite names: makes the runs of its
/// matrix as `cgdem validate --reuse` would (those already in `options.out`/runs are taken)
/// and writes the matrix's report into `options.out`, which the answer then reads.
pub fn run_scene_matrix(
    matrix: &SceneMatrix,
    options: &ValidateOptions,
) -> Result<(), AdviseError> {
    let suite = Suite {
        name: format!("advise {}", matrix.scene.name),
        description: format!(
            "The coarse-graining matrix of {} (cgdem advise)",
            matrix.sweep.file.display()
        ),
        source: matrix.sweep.file.clone(),
        cases: Vec::new(),
        accuracy: vec![matrix.sweep.clone()],
        stability: Vec::new(),
        chung_ooi: Vec::new(),
    };
    let options = ValidateOptions {
        suite: suite.source.clone(),
        reuse: true,
        ..options.clone()
    };
    validate_suite(&suite, &options)?;
    Ok(())
}

/// The advice for `case` (a case name as in the report, e.g. `aor_hertz-fidelity`, or its
/// scene name without the variant when only one variant has points).
pub fn advise(
    file: &Path,
    points: &[AccuracyPoint],
    case: &str,
    m: Measure,
    target: f64,
) -> Result<Advice, AdviseError> {
    let mut cases: Vec<&str> = points.iter().map(|p| p.case.as_str()).collect();
    cases.sort();
    cases.dedup();
    let name = match resolve_case(&cases, case) {
        Ok(name) => name,
        Err(variants) => {
            return Err(unresolved(file, case, variants, &cases, |known| {
                AdviseError::NoCase {
                    file: file.to_path_buf(),
                    case: case.to_string(),
                    known,
                }
            }))
        }
    };
    let mine: Vec<AccuracyPoint> = points
        .iter()
        .filter(|p| p.case == name && p.code == Code::Cgdem)
        .cloned()
        .collect();
    let all = settings(Code::Cgdem, &mine);
    let Some(reference) = all.iter().find(|s| s.series == "reference") else {
        return Err(AdviseError::NoReference {
            file: file.to_path_buf(),
            case: name.to_string(),
        });
    };
    // What the coarse-grained runs measured, for the error when they did not measure `m`.
    let measured: Vec<&str> = Measure::ALL
        .into_iter()
        .filter(|q| {
            mine.iter()
                .any(|p| p.series.starts_with("lambda") && q.of(p).is_some())
        })
        .map(Measure::quantity)
        .collect();
    let first = reference.runs[0];
    let considered = levels(&all, reference, m);
    if considered.is_empty() {
        return Err(AdviseError::NotMeasured {
            case: name.to_string(),
            quantity: m.quantity().to_string(),
            measured: if measured.is_empty() {
                "nothing".into()
            } else {
                measured.join(", ")
            },
        });
    }
    let advised = considered
        .iter()
        .filter(|l| l.reach() <= target)
        .max_by(|a, b| {
            a.lambda
                .cmp(&b.lambda)
                .then(b.particle_steps.total_cmp(&a.particle_steps))
        })
        .cloned();
    let best_reached = match advised {
        Some(_) => None,
        None => considered
            .iter()
            .min_by(|a, b| a.reach().total_cmp(&b.reach()))
            .cloned(),
    };
    Ok(Advice {
        case: name.to_string(),
        quantity: m.quantity().to_string(),
        target,
        reference: format!(
            "the fine reference lambda = {} under the {} rule, {} seed{}",
            first.lambda,
            first.cg_rule.name(),
            reference.runs.len(),
            if reference.runs.len() == 1 { "" } else { "s" }
        ),
        advised,
        best_reached,
        considered,
    })
}

/// The coarse-grained settings that measured `m`, each with its error, spread and what it
/// saves against `reference`; in the order of lambda, rule and cost.
fn levels(all: &[Setting], reference: &Setting, m: Measure) -> Vec<Level> {
    let mean_wall = |runs: &[&AccuracyPoint]| {
        let w: Vec<f64> = runs.iter().filter_map(|p| p.wall_s).collect();
        (!w.is_empty()).then(|| w.iter().sum::<f64>() / w.len() as f64)
    };
    let reference_cost = {
        let c: Vec<f64> = reference
            .runs
            .iter()
            .filter_map(|p| p.particle_steps)
            .collect();
        c.iter().sum::<f64>() / c.len().max(1) as f64
    };
    let reference_wall = mean_wall(&reference.runs);
    let mut considered: Vec<Level> = all
        .iter()
        .filter(|s| s.series.starts_with("lambda"))
        .filter_map(|s| {
            let mean = s.mean(m, Cost::ParticleSteps)?;
            let wall = mean_wall(&s.runs);
            Some(Level {
                setting: s.setting.to_string(),
                lambda: s.runs[0].lambda,
                cg_rule: s.runs[0].cg_rule.name().to_string(),
                error: mean.error,
                spread: mean.se.map(|se| SPREAD_STANDARD_ERRORS * se),
                seeds: mean.n,
                particle_steps: mean.cost,
                wall_s: wall,
                saving_particle_steps: reference_cost / mean.cost,
                saving_wall: reference_wall.zip(wall).map(|(r, w)| r / w),
            })
        })
        .collect();
    considered.sort_by(|a, b| {
        a.lambda
            .cmp(&b.lambda)
            .then(a.cg_rule.cmp(&b.cg_rule))
            .then(a.particle_steps.total_cmp(&b.particle_steps))
    });
    considered
}

#[cfg(test)]
mod scene_tests;
#[cfg(test)]
mod tests;
