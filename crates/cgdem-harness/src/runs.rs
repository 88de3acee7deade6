//! One run of a suite case by one code (cgdem, LAMMPS or LIGGGHTS) into its directory, or
//! with `--reuse` the run already there, and what it measured (`RunRecord`); shared by the
//! validation report (`validate`), the accuracy sweeps and the screw sections, which need
//! these types and this runner but not each other.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::code::Code;
use crate::ranks::{run_scene, Ranks};
use crate::suite_entry::SuiteError;
use cgdem_core::coarse_graining::{coarse_grain_by, CoarseGrainRule};
use cgdem_core::decomposition::placement::FROM_THE_SCENE;
use cgdem_core::decomposition::{BalanceSpec, GridSpec};
use cgdem_core::math::Real;
use cgdem_core::run::{restart, CheckpointOptions, Progress, RunOptions, StageEnding};
use cgdem_core::scene::{ContactSettings, Scene};

/// How a run ended; `summary.json` and the history files spell it `ok`, `failed`, `skipped`,
/// `unsupported`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// It ran and its summary was read (it may still have stopped early: `partial`).
    Ok,
    Failed,
    /// Not run: the code is not installed (or cgdem was interrupted before it).
    Skipped,
    /// Not run: the code cannot express the scene (a feature it lacks, named in the reason),
    /// so this code's comparison is not made.
    Unsupported,
}

impl Outcome {
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Ok => "ok",
            Outcome::Failed => "failed",
            Outcome::Skipped => "skipped",
            Outcome::Unsupported => "unsupported",
        }
    }
}

impl std::fmt::Display for Outcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One run of one code, as recorded in the suite's `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct RunRecord {
    pub case: String,
    pub code: Code,
    pub lambda: u32,
    pub cg_rule: CoarseGrainRule,
    pub seed: u64,
    pub status: Outcome,
    pub reason: Option<String>,
    pub dir: PathBuf,
    pub n_particles: Option<u64>,
    pub steps: Option<u64>,
    pub wall_s: Option<f64>,
    pub particle_steps_per_s: Option<f64>,
    pub repose_angle_deg: Option<f64>,
    pub repose_fit_r2: Option<f64>,
    /// Why the repose angle was not measured, when the scene asks for one and it was not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repose_not_measured: Option<String>,
    pub runout_m: Option<f64>,
    /// The Hertz scene's tangential law (`history`, `coulomb`, `yang`); None for WCA.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tangential: Option<String>,
    /// The run was not repeated: its directory already held it (`--reuse`).
    pub reused: bool,
    /// The run stopped before its last stage ended (time limit, killed, stopped by a
    /// guard): its fixed-time samples and histories count, its final state does not.
    pub partial: bool,
    /// Screw speed of a conveying case run at a suite's `rpms`, rev/min.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rpm: Option<f64>,
    /// The conveying measurement (`analysis::conveying`) of a screw case.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_flow_kg_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_flow_std_error_kg_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fill_ratio: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bulk_density_kg_m3: Option<f64>,
    /// Eq. (7) with the measured fill ratio.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eq7_mass_flow_kg_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ratio_to_eq7: Option<f64>,
    /// The run's own `summary.json` warnings: a reference deck's approximations of the scene
    /// (reference/MAPPING.md) and the post-processing's caveats, shown with the case.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

impl RunRecord {
    /// A run that has not failed, with nothing measured yet.
    pub fn ok(
        case: String,
        code: Code,
        lambda: u32,
        cg_rule: CoarseGrainRule,
        seed: u64,
        dir: PathBuf,
    ) -> RunRecord {
        RunRecord {
            case,
            code,
            lambda,
            cg_rule,
            seed,
            status: Outcome::Ok,
            reason: None,
            dir,
            n_particles: None,
            steps: None,
            wall_s: None,
            particle_steps_per_s: None,
            repose_angle_deg: None,
            repose_fit_r2: None,
            repose_not_measured: None,
            runout_m: None,
            tangential: None,
            reused: false,
            partial: false,
            rpm: None,
            mass_flow_kg_s: None,
            mass_flow_std_error_kg_s: None,
            fill_ratio: None,
            bulk_density_kg_m3: None,
            eq7_mass_flow_kg_s: None,
            ratio_to_eq7: None,
            notes: Vec::new(),
        }
    }
}

/// What one code's runs of a case say beside their figures: why runs were not made
/// (`Outcome::Unsupported`: what the code cannot express) and the runs' notes, each distinct
/// text once.
#[derive(Clone, Debug, PartialEq)]
pub struct CodeNotes {
    pub code: Code,
    pub unsupported: Vec<String>,
    pub notes: Vec<String>,
}

/// Per code, in the order the runs name them, the reasons and notes of its runs; codes with
/// neither are left out.
pub fn notes_by_code(runs: &[RunRecord]) -> Vec<CodeNotes> {
    let mut out: Vec<CodeNotes> = Vec::new();
    let push = |v: &mut Vec<String>, text: &str| {
        if !v.iter().any(|t| t == text) {
            v.push(text.to_string());
        }
    };
    for r in runs {
        let at = match out.iter().position(|c| c.code == r.code) {
            Some(at) => at,
            None => {
                out.push(CodeNotes {
                    code: r.code,
                    unsupported: Vec::new(),
                    notes: Vec::new(),
                });
                out.len() - 1
            }
        };
        let c = &mut out[at];
        if let (Outcome::Unsupported, Some(reason)) = (r.status, &r.reason) {
            push(&mut c.unsupported, reason);
        }
        for note in &r.notes {
            push(&mut c.notes, note);
        }
    }
    out.retain(|c| !c.unsupported.is_empty() || !c.notes.is_empty());
    out
}

#[derive(Debug, thiserror::Error)]
pub enum ValidateError {
    #[error(transparent)]
    Suite(#[from] SuiteError),
    #[error("{file}: {message}")]
    Case { file: PathBuf, message: String },
    #[error("cannot write {path}: {message}")]
    Output { path: PathBuf, message: String },
}

pub(super) fn output_error(path: &Path, e: impl std::fmt::Display) -> ValidateError {
    ValidateError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

#[derive(Clone)]
pub struct ValidateOptions {
    pub suite: PathBuf,
    pub out: PathBuf,
    pub quiet: bool,
    /// Where cgdem's runs report their progress.
    pub progress: Option<Progress>,
    /// Time limit of one reference-code run, seconds.
    pub reference_timeout_s: u64,
    /// Reuse a run directory that already holds this exact run (an interrupted suite resumes;
    /// a report is rebuilt without re-running): when its summary's scene digest matches, or
    /// for a reference run without one, when its deck is the one the case writes now (its
    /// dumps are then post-processed again by the current code).
    pub reuse: bool,
    /// cgdem's guards only warn instead of stopping a run (`--keep-going`).
    pub keep_going: bool,
    /// Runs of a case, or of an accuracy sweep, made at the same time (`--jobs`), sharing the
    /// threads.
    pub jobs: usize,
    /// Raised on SIGINT/SIGTERM: runs in progress stop (cgdem at the end of a step, reference
    /// codes with their process tree) and record why; no further run starts.
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Planted faults (`--fault KEY=VALUE`, `crate::faults`): scene overrides, or the
    /// screw's speed scaled, applied to cgdem's runs only, the scene keeping its name, so
    /// that its comparisons with the reference codes show whether the verdicts can fail
    /// (scripts/planted-faults.sh).
    pub cgdem_faults: Vec<String>,
    /// A nightly history directory (`history.json`, `cgdem history`): the report's first
    /// screen says what moved since the last night recorded there.
    pub history: Option<PathBuf>,
    /// `--grid`/`--balance`: cgdem's runs decomposed as `cgdem run --grid` decomposes them.
    pub decomposition: CgdemDecomposition,
    /// `--checkpoint-every`: cgdem's case and accuracy runs write restart files this many
    /// simulated seconds apart; with `reuse`, a run that was killed goes on from its last one.
    pub checkpoint_every: Option<Real>,
    /// Where the runs live; None: `OUT/runs`. `cgdem advise --run` keeps them in the
    /// matrix's directory (where `--reuse` finds those already made) while the report of the
    /// one case it ran is written beside, leaving the matrix's own report as it was.
    pub runs_dir: Option<PathBuf>,
}

impl Default for ValidateOptions {
    /// As `cgdem validate` with no options: the smoke suite into reports/latest, one run at
    /// a time, an hour per reference-code run.
    fn default() -> Self {
        ValidateOptions {
            suite: PathBuf::from("validation/suites/smoke.toml"),
            out: PathBuf::from("reports/latest"),
            quiet: false,
            progress: None,
            reference_timeout_s: 3600,
            reuse: false,
            keep_going: false,
            jobs: 1,
            stop: None,
            cgdem_faults: Vec::new(),
            history: None,
            decomposition: CgdemDecomposition::default(),
            checkpoint_every: None,
            runs_dir: None,
        }
    }
}

impl ValidateOptions {
    /// The directory that holds the runs: `runs_dir`, or `OUT/runs`.
    pub fn runs_dir(&self) -> PathBuf {
        self.runs_dir
            .clone()
            .unwrap_or_else(|| self.out.join("runs"))
    }
}

/// `validate --grid` and `--balance`: every cgdem run of the suite (cases, accuracy sweeps,
/// stability) on the given grid instead of the one each scene chooses, so that its verdicts
/// can be compared with the default suite's; with `--np`, as MPI ranks. The reference codes
/// run as without it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CgdemDecomposition {
    /// None: each scene's own grid (the default).
    pub grid: Option<GridSpec>,
    pub balance: BalanceSpec,
    /// `--np`: each run as this many MPI ranks (`mpirun`) instead of threads in this
    /// process; bitwise the same outputs, so `--reuse` takes either for the other.
    pub ranks: Option<Ranks>,
}

impl CgdemDecomposition {
    /// Whether the run that wrote `summary` (its summary.json) was decomposed this way, so
    /// that `--reuse` never takes a run on a given grid for one on its scene's grid or the
    /// reverse. A count (`--grid 4`) matches any grid of that many subdomains.
    pub fn made(&self, summary: &serde_json::Value) -> bool {
        let done = &summary["decomposition"];
        let Some(spec) = self.grid else {
            let reason = done["grid_reason"].as_str().unwrap_or("");
            return reason.starts_with(FROM_THE_SCENE)
                && done["balance_threshold"].as_f64() == self.balance.threshold();
        };
        let Some(grid) = done["grid"].as_array() else {
            return false;
        };
        let grid: Vec<u64> = grid.iter().map(|n| n.as_u64().unwrap_or(0)).collect();
        let same_grid = match spec {
            GridSpec::Given(counts) => grid.iter().zip(counts).all(|(&a, b)| a == b as u64),
            GridSpec::Auto(n) => grid.iter().product::<u64>() == n as u64,
        };
        same_grid && done["balance_threshold"].as_f64() == self.balance.threshold()
    }
}

/// `run` applied to every item, `jobs` at a time, results in the items' order. With more
/// than one job, the cores of the calling rayon pool are shared out: each job runs in a pool
/// of its own with `threads / jobs` threads (at least one), so cgdem runs do not oversubscribe
/// the machine; a reference code runs as one process per job.
pub(super) fn run_concurrently<T: Sync, R: Send>(
    items: &[T],
    jobs: usize,
    run: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    if jobs <= 1 || items.len() <= 1 {
        return items.iter().map(&run).collect();
    }
    let threads_per_job = (rayon::current_num_threads() / jobs).max(1);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<std::sync::Mutex<Option<R>>> =
        items.iter().map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|scope| {
        for _ in 0..jobs.min(items.len()) {
            scope.spawn(|| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads_per_job)
                    .build();
                loop {
                    let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(item) = items.get(k) else { break };
                    let result = match &pool {
                        Ok(pool) => pool.install(|| run(item)),
                        Err(_) => run(item), // no pool of its own: the global one
                    };
                    *results[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(result);
                }
            });
        }
    });
    results
        .into_iter()
        .map(|r| {
            r.into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .expect("every item is taken by exactly one job")
        })
        .collect()
}

/// Runs one code on one setting (or, with `--reuse`, takes the run already in `dir`) and
/// reads what it measured; a run that could not be made is recorded as skipped or failed.
pub(super) fn run_one(
    scene: &Scene,
    code: Code,
    lambda: u32,
    rule: CoarseGrainRule,
    seed: u64,
    dir: &Path,
    options: &ValidateOptions,
) -> RunRecord {
    let mut record = RunRecord::ok(
        scene.name.clone(),
        code,
        lambda,
        rule,
        seed,
        dir.to_path_buf(),
    );
    if let ContactSettings::Hertz(h) = &scene.contact {
        record.tangential = Some(h.tangential.name().into());
    }
    let outcome = match code {
        Code::Cgdem => run_cgdem(scene, lambda, rule, seed, dir, options),
        Code::Lammps | Code::Liggghts => {
            run_reference_code(code, scene, lambda, rule, seed, dir, options)
        }
    };
    match outcome {
        Ok(reused) => {
            record.reused = reused;
            fill_from_summary(&mut record);
        }
        Err(RunOutcome::Skipped(reason)) => {
            record.status = Outcome::Skipped;
            record.reason = Some(reason);
        }
        Err(RunOutcome::Unsupported(reason)) => {
            record.status = Outcome::Unsupported;
            record.reason = Some(reason);
        }
        Err(RunOutcome::Failed(reason)) => {
            record.status = Outcome::Failed;
            record.reason = Some(reason);
        }
    }
    record
}

enum RunOutcome {
    Skipped(String),
    Unsupported(String),
    Failed(String),
}

/// Runs cgdem, or with `--reuse` takes the run already in `dir`; true when reused.
fn run_cgdem(
    scene: &Scene,
    lambda: u32,
    rule: CoarseGrainRule,
    seed: u64,
    dir: &Path,
    options: &ValidateOptions,
) -> Result<bool, RunOutcome> {
    let coarse = coarse_grain_by(&scene.with_insertion_seed(seed), lambda, rule)
        .map_err(|e| RunOutcome::Failed(e.to_string()))?;
    if options.reuse
        && finished_summary(dir).is_some_and(|s| {
            s["scene_digest"].as_str() == Some(coarse.digest().as_str())
                && options.decomposition.made(&s)
        })
    {
        return Ok(true);
    }
    // A run killed in an earlier attempt goes on from its last restart file, if it holds
    // this very scene.
    let resume = options
        .reuse
        .then(|| restart::read_latest(dir).ok())
        .flatten()
        .filter(|r| r.restart.scene_digest == coarse.digest())
        .map(std::sync::Arc::new);
    if let Some(r) = &resume {
        eprintln!("resuming {}", r.path.display());
    }
    let run_options = RunOptions {
        out_dir: dir.to_path_buf(),
        progress: options.progress.clone(),
        force_dt: false,
        keep_going: options.keep_going,
        stop: options.stop.clone(),
        grid: options.decomposition.grid,
        balance: options.decomposition.balance,
        checkpoint: options.checkpoint_every.map(|every| CheckpointOptions {
            every,
            invocation: "cgdem validate".into(),
        }),
        resume,
        ..Default::default()
    };
    let ranks = options.decomposition.ranks.as_ref();
    run_scene(&coarse, &run_options, ranks)
        .map(|_| false)
        .map_err(RunOutcome::Failed)
}

/// `dir/summary.json`, if a finished run left one (an interrupted run leaves one too).
fn finished_summary(dir: &Path) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    serde_json::from_str(&text)
        .ok()
        .filter(|s| !StageEnding::interrupted_summary(s))
}

/// The scene digest in `dir/summary.json`, if a finished run left one.
fn finished_digest(dir: &Path) -> Option<String> {
    finished_summary(dir)?
        .get("scene_digest")?
        .as_str()
        .map(str::to_string)
}

/// Runs LAMMPS or LIGGGHTS, or with `--reuse` takes the run already in `dir`; true when
/// reused. LIGGGHTS cannot express the WCA model of Hirose: its runs of such a case are skipped.
fn run_reference_code(
    code: Code,
    scene: &Scene,
    lambda: u32,
    rule: CoarseGrainRule,
    seed: u64,
    dir: &Path,
    validate: &ValidateOptions,
) -> Result<bool, RunOutcome> {
    use super::decks::{
        run_reference, DeckError, ReferenceError, ReferenceOptions, RunStatus, RunnerOptions,
    };
    let reference = match code {
        Code::Liggghts => Code::Liggghts,
        _ => Code::Lammps,
    };
    if reference == Code::Liggghts
        && matches!(scene.contact, cgdem_core::scene::ContactSettings::Wca(_))
    {
        return Err(RunOutcome::Unsupported(
            "LIGGGHTS cannot express the WCA model of Hirose (model = \"wca\"); it runs Hertz cases"
                .into(),
        ));
    }
    let name = reference.label();
    let coarse = coarse_grain_by(&scene.with_insertion_seed(seed), lambda, rule)
        .map_err(|e| RunOutcome::Failed(e.to_string()))?;
    let mut options = ReferenceOptions {
        code: reference,
        runner: RunnerOptions {
            np: None,
            timeout: std::time::Duration::from_secs(validate.reference_timeout_s),
            stop: validate.stop.clone(),
        },
        ..ReferenceOptions::default()
    };
    // A finished run of this very scene is reused; one whose deck is the one this case
    // writes now (an older summary without a digest) is post-processed again; anything else
    // (no run, another deck, dumps gone) runs.
    if validate.reuse && finished_digest(dir).as_deref() == Some(coarse.digest().as_str()) {
        return Ok(true);
    }
    if validate.reuse && dir.join("summary.json").exists() {
        options.postprocess_only = true;
        if let Ok(run) = run_reference(&coarse, dir, &options) {
            if run.summary.is_some() {
                return Ok(true);
            }
        }
        options.postprocess_only = false;
    }
    let run = run_reference(&coarse, dir, &options).map_err(|e| match e {
        ReferenceError::CannotExpress(DeckError::Unsupported { file, reason }) => {
            RunOutcome::Unsupported(format!("{name} cannot express {file}: {reason}"))
        }
        ReferenceError::Failed(e) => RunOutcome::Failed(e),
    })?;
    match run.status {
        RunStatus::Completed { .. } => Ok(false),
        RunStatus::Skipped {
            reason,
            install_hint,
        } => Err(RunOutcome::Skipped(format!(
            "{reason}; install with `{install_hint}`"
        ))),
        RunStatus::Failed {
            exit_code,
            log_tail,
        } => Err(RunOutcome::Failed(format!(
            "{name} exit code {exit_code:?}; log tail: {log_tail}"
        ))),
        RunStatus::TimedOut {
            after_s,
            cpu_s,
            log_tail,
        } => Err(RunOutcome::Failed(format!(
            "{name} timed out after {cpu_s:.0} s of CPU per rank ({after_s:.0} s of wall clock; --reference-timeout) (partial outputs kept); log tail: {log_tail}"
        ))),
    }
}

fn fill_from_summary(record: &mut RunRecord) {
    let path = record.dir.join("summary.json");
    let value: serde_json::Value = match std::fs::read_to_string(&path)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
    {
        Ok(v) => v,
        Err(e) => {
            record.status = Outcome::Failed;
            record.reason = Some(format!("{}: {e}", path.display()));
            return;
        }
    };
    let f = |key: &str| value.get(key).and_then(|v| v.as_f64());
    record.notes = value["warnings"].as_array().map_or(Vec::new(), |w| {
        w.iter()
            .filter_map(|n| n.as_str().map(str::to_string))
            .collect()
    });
    record.n_particles = value.get("n_particles").and_then(|v| v.as_u64());
    record.steps = value.get("steps").and_then(|v| v.as_u64());
    record.wall_s = f("wall_s");
    record.particle_steps_per_s = f("particle_steps_per_s");
    record.repose_angle_deg = f("repose_angle_deg");
    record.repose_fit_r2 = f("repose_fit_r2");
    record.repose_not_measured = value["repose_not_measured"].as_str().map(str::to_string);
    record.runout_m = f("runout_m");
    let conveying = |key: &str| value["conveying"][key].as_f64();
    record.mass_flow_kg_s = conveying("mass_flow_kg_s");
    record.mass_flow_std_error_kg_s = conveying("mass_flow_std_error_kg_s");
    record.fill_ratio = conveying("fill_ratio");
    record.bulk_density_kg_m3 = conveying("bulk_density_kg_m3");
    record.eq7_mass_flow_kg_s = conveying("eq7_mass_flow_kg_s");
    record.ratio_to_eq7 = conveying("ratio_to_eq7");
    let unfinished = value["stages"].as_array().and_then(|stages| {
        stages.iter().find(|st| {
            let how = st["ended_by"].as_str().unwrap_or("");
            how == "did not finish" || how.starts_with("stopped")
        })
    });
    if let Some(stage) = unfinished {
        record.partial = true;
        record.reason = Some(format!(
            "partial: stage `{}` {} after {:.2} s",
            stage["name"].as_str().unwrap_or("?"),
            stage["ended_by"].as_str().unwrap_or("?"),
            stage["end_s"].as_f64().unwrap_or(0.0) - stage["start_s"].as_f64().unwrap_or(0.0),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outcomes_keep_the_words_of_summary_json_and_the_history_files() {
        for (outcome, word) in [
            (Outcome::Ok, "ok"),
            (Outcome::Failed, "failed"),
            (Outcome::Skipped, "skipped"),
            (Outcome::Unsupported, "unsupported"),
        ] {
            let json = format!("\"{word}\"");
            assert_eq!(serde_json::to_string(&outcome).unwrap(), json);
            assert_eq!(serde_json::from_str::<Outcome>(&json).unwrap(), outcome);
            assert_eq!(outcome.to_string(), word);
        }
        assert!(serde_json::from_str::<Outcome>("\"completed\"").is_err());
    }

    /// A scene a reference code cannot express is recorded as `unsupported` with the feature
    /// and why, before anything runs (no code needs to be installed), and the case's notes
    /// carry the reason for that code.
    #[test]
    fn a_feature_a_code_cannot_express_is_recorded_as_unsupported_with_the_reason() {
        crate::at_repo_root();
        let mut scene = Scene::load(Path::new("tests/data/tiny_drop.toml")).unwrap();
        let dir = std::env::temp_dir().join(format!("cgdem_unsupported_{}", std::process::id()));
        let options = ValidateOptions::default();
        let run = |scene: &Scene, code: Code| {
            run_one(
                scene,
                code,
                1,
                CoarseGrainRule::RelativeOverlap,
                1,
                &dir.join(code.name()),
                &options,
            )
        };
        // LIGGGHTS has no WCA model.
        let liggghts = run(&scene, Code::Liggghts);
        assert_eq!(liggghts.status, Outcome::Unsupported);
        assert!(
            liggghts.reason.as_deref().unwrap().contains("WCA"),
            "{liggghts:?}"
        );
        // The LAMMPS seed-model deck refuses a [[delete]] box (it would run another case).
        let lo = cgdem_core::math::Vec3::new(0.0, 0.0, 0.0);
        scene
            .deletions
            .push((lo, cgdem_core::math::Vec3::new(0.12, 0.05, 0.01)));
        let lammps = run(&scene, Code::Lammps);
        assert_eq!(lammps.status, Outcome::Unsupported, "{lammps:?}");
        let reason = lammps.reason.clone().unwrap();
        assert!(
            reason.starts_with("LAMMPS cannot express")
                && reason.contains("tiny_drop.toml")
                && reason.contains("no [[delete]]"),
            "{reason}"
        );
        assert!(!dir.join("lammps").join("deck.in").exists());
        let notes = notes_by_code(&[liggghts, lammps]);
        assert_eq!(notes.len(), 2);
        assert_eq!(
            (notes[1].code, &notes[1].unsupported),
            (Code::Lammps, &vec![reason])
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn notes_are_listed_per_code_each_once() {
        let record = |code: Code, seed: u64, notes: &[&str]| RunRecord {
            notes: notes.iter().map(|n| n.to_string()).collect(),
            ..RunRecord::ok(
                "c".into(),
                code,
                1,
                CoarseGrainRule::RelativeOverlap,
                seed,
                "d".into(),
            )
        };
        let runs = [
            record(Code::Cgdem, 1, &[]),
            record(Code::Liggghts, 1, &["sliver", "vanished"]),
            record(Code::Liggghts, 2, &["vanished"]),
        ];
        let notes = notes_by_code(&runs);
        assert_eq!(
            notes,
            vec![CodeNotes {
                code: Code::Liggghts,
                unsupported: vec![],
                notes: vec!["sliver".into(), "vanished".into()]
            }]
        );
    }

    #[test]
    fn reuse_takes_only_a_run_decomposed_as_asked() {
        let plain = serde_json::json!({ "decomposition": { "grid": [1, 1, 1], "balance_threshold": 1.1, "grid_reason": format!("{FROM_THE_SCENE}: 40 particles") } });
        let split = |grid: [u64; 3], threshold: Option<f64>| serde_json::json!({ "decomposition": { "grid": grid, "balance_threshold": threshold } });
        let asked = |grid: Option<GridSpec>, balance: BalanceSpec| CgdemDecomposition {
            grid,
            balance,
            ranks: None,
        };
        let none = CgdemDecomposition::default();
        assert!(none.made(&plain));
        assert!(!none.made(&split([2, 1, 1], Some(1.1))));
        // Written before every run was a grid: made again.
        assert!(!none.made(&serde_json::json!({ "scene_digest": "x" })));
        let given = asked(Some(GridSpec::Given([2, 1, 1])), BalanceSpec::Shift(1.1));
        assert!(given.made(&split([2, 1, 1], Some(1.1))));
        assert!(!given.made(&plain));
        assert!(!given.made(&split([1, 2, 1], Some(1.1))));
        assert!(!given.made(&split([2, 1, 1], None)));
        assert!(!given.made(&split([2, 1, 1], Some(1.2))));
        let off = asked(Some(GridSpec::Given([2, 1, 1])), BalanceSpec::Off);
        assert!(off.made(&split([2, 1, 1], None)));
        let count = asked(Some(GridSpec::Auto(4)), BalanceSpec::Shift(1.1));
        assert!(count.made(&split([1, 2, 2], Some(1.1))));
        assert!(!count.made(&split([2, 1, 1], Some(1.1))));
    }

    #[test]
    fn concurrent_runs_take_every_item_once_and_keep_the_order() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let items: Vec<u32> = (0..17).collect();
        for jobs in [1, 2, 3, 40] {
            let calls = AtomicUsize::new(0);
            let out = run_concurrently(&items, jobs, |&k| {
                calls.fetch_add(1, Ordering::Relaxed);
                (k * k, rayon::current_num_threads())
            });
            assert_eq!(calls.load(Ordering::Relaxed), items.len(), "jobs {jobs}");
            let squares: Vec<u32> = out.iter().map(|o| o.0).collect();
            assert_eq!(squares, items.iter().map(|k| k * k).collect::<Vec<_>>());
            if jobs > 1 {
                // Each job's pool holds its share of the threads, at least one.
                let share = (rayon::current_num_threads() / jobs).max(1);
                assert!(out.iter().all(|o| o.1 == share), "jobs {jobs}: {out:?}");
            }
        }
    }
}
