//! A reference run: the deck for a scene written, run by LAMMPS or LIGGGHTS, and its dumps
//! post-processed into cgdem's output files.

use std::path::Path;

use super::{dialect, postprocess, run_deck, write_deck, write_summary, DECK_FILE};
use super::{DeckError, RunStatus, RunnerOptions};
use crate::code::Code;
use cgdem_core::output_format::RunSummary;
use cgdem_core::scene::Scene;

/// How `run_reference` runs: the code, the runner's settings and the two choices a user makes.
#[derive(Clone, Debug)]
pub struct ReferenceOptions {
    /// `Code::Lammps` or `Code::Liggghts`.
    pub code: Code,
    pub runner: RunnerOptions,
    /// Write the deck even if the time step exceeds the stable limit.
    pub force_dt: bool,
    /// Do not run: post-process the outputs already in `out` (of a stopped run, say). The
    /// deck there must be the one this scene writes, so the outputs belong to it.
    pub postprocess_only: bool,
}

impl Default for ReferenceOptions {
    fn default() -> Self {
        ReferenceOptions {
            code: Code::Lammps,
            runner: RunnerOptions::default(),
            force_dt: false,
            postprocess_only: false,
        }
    }
}

/// What `run_reference` did.
#[derive(Debug)]
pub struct ReferenceRun {
    pub status: RunStatus,
    /// Present when LAMMPS completed or timed out (a partial run) and post-processing worked.
    pub summary: Option<RunSummary>,
    pub n_particles: usize,
    pub dt: cgdem_core::math::Real,
    /// The time-step warning when `force_dt` let an unstable step through.
    pub dt_warning: Option<String>,
    /// Why a timed-out run has no summary (its partial outputs could not be post-processed).
    pub partial_error: Option<String>,
}

/// Why `run_reference` made no run: the code cannot express the scene (its comparison is not
/// made, for that reason), or anything else went wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ReferenceError {
    #[error(transparent)]
    CannotExpress(#[from] DeckError),
    #[error("{0}")]
    Failed(String),
}

impl From<String> for ReferenceError {
    fn from(message: String) -> Self {
        ReferenceError::Failed(message)
    }
}

/// Writes the deck for `scene` (already coarse-grained) into `out`, runs the reference code
/// (`options.code`) there and post-processes its dumps into cgdem's output files. Returns how
/// the run ended, with the summary when there is one (also for a timed-out, partial run); a
/// scene the code cannot express is [`ReferenceError::CannotExpress`], before anything runs.
pub fn run_reference(
    scene: &Scene,
    out: &Path,
    options: &ReferenceOptions,
) -> Result<ReferenceRun, ReferenceError> {
    let (dt, scales, dt_warning) =
        cgdem_core::run::time_step(scene, options.force_dt).map_err(|e| e.to_string())?;
    let particles =
        cgdem_core::run::initial_particles_clear_of_bodies(scene).map_err(|e| e.to_string())?;
    let Some(dialect) = dialect(options.code) else {
        return Err("cgdem is not a reference code".to_string().into());
    };
    let deck = write_deck(options.code, scene, &particles, dt)?;
    let status = if options.postprocess_only {
        let path = out.join(DECK_FILE);
        let previous = std::fs::read_to_string(&path)
            .map_err(|e| format!("--postprocess-only: cannot read {}: {e}", path.display()))?;
        if previous != deck.input {
            return Err(format!(
                "--postprocess-only: {} was not written for this case, lambda and seed",
                path.display()
            )
            .into());
        }
        RunStatus::Completed { wall_s: f64::NAN }
    } else {
        deck.write_to(out)
            .map_err(|e| format!("cannot write the deck into {}: {e}", out.display()))?;
        run_deck(dialect, out, &options.runner)
    };
    let mut run = ReferenceRun {
        status,
        summary: None,
        n_particles: particles.len(),
        dt,
        dt_warning,
        partial_error: None,
    };
    let wall_s = match &run.status {
        RunStatus::Completed { wall_s } => *wall_s,
        RunStatus::TimedOut { after_s, .. } => *after_s,
        _ => return Ok(run),
    };
    let ranks = options.runner.np.unwrap_or(1) as usize;
    let mut summary = match postprocess(scene, out, &deck.plan, &scales, wall_s, ranks) {
        Ok(summary) => summary,
        // A partial run keeps its status; why it has no summary goes with it.
        Err(e) if matches!(run.status, RunStatus::TimedOut { .. }) => {
            run.partial_error = Some(e.to_string());
            return Ok(run);
        }
        Err(e) => return Err(e.to_string().into()),
    };
    if let RunStatus::TimedOut { after_s, cpu_s, .. } = &run.status {
        summary.warnings.push(format!(
            "{} killed after {cpu_s:.0} s of CPU per rank ({after_s:.0} s of wall clock; the time limit): partial run",
            options.code.label()
        ));
    }
    write_summary(&summary, out).map_err(|e| e.to_string())?;
    run.summary = Some(summary);
    Ok(run)
}
