//! LAMMPS (29 Sep 2021) as a reference for the seed model (and, `hertz`, the Hertz family); how the model is expressed in
//! LAMMPS and what it cannot reproduce is in `reference/lammps/SEED_MODEL.md`.

pub mod deck;
pub mod dump;
pub mod hertz;
pub mod postprocess;
pub mod runner;

pub use deck::{write_deck, Deck, DeckError, DeckPlan};
pub use dump::{read_dump, DumpError, Frame};
pub use hertz::write_hertz_deck;
pub use postprocess::{postprocess, write_summary, PostprocessError};
pub use runner::{find_lmp, run_deck, RunStatus, RunnerOptions, INSTALL_HINT};

use std::path::Path;

use crate::run::RunSummary;
use crate::scene::Scene;

/// Writes the deck for `scene` (already coarse-grained) into `out`, runs LAMMPS there and
/// post-processes its dumps into cgdem's output files. Returns how the run ended, with the
/// summary when there is one (also for a timed-out, partial run).
pub fn run_reference(
    scene: &Scene,
    out: &Path,
    options: &RunnerOptions,
) -> Result<(RunStatus, Option<RunSummary>), String> {
    let (dt, scales, _) = crate::run::time_step(scene, false).map_err(|e| e.to_string())?;
    let particles = crate::run::initial_particles(scene, false, &[]).map_err(|e| e.to_string())?;
    let deck = write_deck(scene, &particles, dt).map_err(|e| e.to_string())?;
    deck.write_to(out)
        .map_err(|e| format!("cannot write the deck into {}: {e}", out.display()))?;
    let status = run_deck(out, options);
    let wall_s = match &status {
        RunStatus::Completed { wall_s } => *wall_s,
        RunStatus::TimedOut { after_s, .. } => *after_s,
        _ => return Ok((status, None)),
    };
    let ranks = options.np.unwrap_or(1) as usize;
    let mut summary =
        postprocess(scene, out, &deck.plan, &scales, wall_s, ranks).map_err(|e| e.to_string())?;
    if let RunStatus::TimedOut { after_s, .. } = &status {
        summary.warnings.push(format!(
            "LAMMPS killed after {after_s:.0} s (time limit): partial run"
        ));
    }
    write_summary(&summary, out).map_err(|e| e.to_string())?;
    Ok((status, Some(summary)))
}
