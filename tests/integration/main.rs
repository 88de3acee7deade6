//! Integration tests, one binary: physics of the seed's model, coarse-graining invariants,
//! determinism across thread counts, scene validation, the solver guards, the command line and
//! the multi-stage Hertz decks in LIGGGHTS and LAMMPS.

mod advise_scene;
#[path = "../support/bead_scene.rs"]
mod bead_scene;
mod bodies;
mod cli;
mod cli_reference;
mod common;
mod decomposition;
#[path = "../support/golden.rs"]
mod golden;
mod guards;
mod interrupt;
mod physics;
mod reference_screw;
mod reference_stages;
mod restart;
mod scene_reference;
mod scenes;
mod scripts;
mod stability;
mod validate_status;
