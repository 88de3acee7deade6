//! LAMMPS (29 Sep 2021) as a reference for the seed model (and, `hertz`, the Hertz family); how
//! the model is expressed in LAMMPS and what it cannot reproduce is in
//! `reference/lammps/SEED_MODEL.md` and `reference/MAPPING.md`. LIGGGHTS (`harness::liggghts`)
//! shares the stage lines, runner and post-processing; `harness::reference` runs either.

mod bodies;
pub mod deck;
pub mod dump;
pub mod hertz;
pub mod postprocess;
pub mod runner;

pub use deck::{Deck, DeckError, DeckPlan};
pub use dump::{read_dump, DumpError, Frame};
pub use hertz::write_hertz_deck;
pub use postprocess::{postprocess, write_summary, PostprocessError};
pub use runner::{find_lmp, run_deck, RunStatus, RunnerOptions, INSTALL_HINT};

use cgdem_core::scene::{ContactSettings, Scene};

/// The LAMMPS deck for a scene (already coarse-grained): the seed's WCA model (`deck`) or the
/// Hertz family (`hertz`, `pair_style granular hertz/material`, reference/MAPPING.md).
pub fn write_deck(
    scene: &Scene,
    particles: &cgdem_core::particles::Particles,
    dt: cgdem_core::math::Real,
) -> Result<Deck, DeckError> {
    match scene.contact {
        ContactSettings::Wca(_) => deck::write_wca_deck(scene, particles, dt),
        ContactSettings::Hertz(_) => write_hertz_deck(scene, particles, dt),
    }
}
