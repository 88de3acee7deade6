//! Running `liggghts` on a deck in its own directory, under a time limit (the LAMMPS runner
//! with another binary: both take `-in deck -log log`).

use std::path::{Path, PathBuf};

use super::deck::{DECK_FILE, LOG_FILE};
use crate::lammps::runner::{find_program, run_program, RunStatus, RunnerOptions};
use crate::lammps::INSTALL_HINT;

/// The `liggghts` binary: `$CGDEM_LIGGGHTS`, else `liggghts` on `PATH`.
pub fn find_liggghts() -> Result<PathBuf, String> {
    find_program("liggghts", "CGDEM_LIGGGHTS")
}

/// Runs the deck in `dir` (which must hold it) and waits, killing LIGGGHTS at the time limit.
pub fn run_deck(dir: &Path, options: &RunnerOptions) -> RunStatus {
    match find_liggghts() {
        Ok(liggghts) => run_program(&liggghts, dir, DECK_FILE, LOG_FILE, options),
        Err(reason) => RunStatus::Skipped {
            reason,
            install_hint: INSTALL_HINT.into(),
        },
    }
}
