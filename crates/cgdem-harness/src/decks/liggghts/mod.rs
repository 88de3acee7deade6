//! LIGGGHTS (3.8.0) as a reference for the Hertz family, in its own keywords (`pair_style
//! gran model hertz tangential history`, walls as primitives, bodies as meshes): the deck
//! writer (`deck`) and LIGGGHTS's dialect. The model mapping is in `reference/MAPPING.md`.

pub mod deck;

pub use deck::{write_deck, MIN_YOUNGS_MODULUS};

use std::path::{Path, PathBuf};

use super::{Dialect, RunStatus, RunnerOptions};
use crate::code::Code;

/// LIGGGHTS's words: `atom_style granular`, `communicate single vel yes`, the neighbour
/// list's default check; `liggghts`, `log.liggghts`.
pub const DIALECT: Dialect = Dialect {
    code: Code::Liggghts,
    program: "liggghts",
    program_variable: "CGDEM_LIGGGHTS",
    log_file: LOG_FILE,
    atom_style: "granular",
    ghost_velocities: "communicate     single vel yes",
    neigh_modify: "neigh_modify    delay 0",
};

/// LIGGGHTS's log in the run directory.
pub const LOG_FILE: &str = "log.liggghts";

/// The `liggghts` binary: `$CGDEM_LIGGGHTS`, else `liggghts` on `PATH`.
pub fn find_liggghts() -> Result<PathBuf, String> {
    super::find_program(&DIALECT)
}

/// Runs the deck in `dir` (which must hold it) and waits, killing LIGGGHTS at the time limit.
pub fn run_deck(dir: &Path, options: &RunnerOptions) -> RunStatus {
    super::run_deck(&DIALECT, dir, options)
}
