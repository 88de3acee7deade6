//! LIGGGHTS (3.8.0) as a reference for the Hertz family: deck writer, runner and dump reader,
//! mirroring `harness::lammps`. The model mapping is in `reference/MAPPING.md`.

pub mod deck;
pub mod dump;
pub mod runner;

pub use deck::{write_deck, DECK_FILE, LOG_FILE};
pub use dump::read_dump;
pub use runner::{find_liggghts, run_deck};
