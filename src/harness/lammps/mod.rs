//! LAMMPS (29 Sep 2021) as a reference for the seed model; how the model is expressed in
//! LAMMPS and what it cannot reproduce is in `reference/lammps/SEED_MODEL.md`.

pub mod deck;
pub mod dump;
pub mod postprocess;
pub mod runner;

pub use deck::{write_deck, Deck, DeckError, DeckPlan};
pub use dump::{read_dump, DumpError, Frame};
pub use postprocess::{postprocess, write_summary, PostprocessError};
pub use runner::{find_lmp, run_deck, RunStatus, RunnerOptions, INSTALL_HINT};
