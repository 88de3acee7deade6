//! LAMMPS (29 Sep 2021) as a reference: the seed's WCA model (`wca`) and the Hertz family
//! (`hertz`, `pair_style granular hertz/material`), with a scene's bodies as frozen atoms
//! or analytic regions (`bodies`). How the models are expressed in LAMMPS and what it cannot
//! reproduce: `reference/lammps/SEED_MODEL.md` and `reference/MAPPING.md`.

mod bodies;
pub mod coefficients;
pub mod hertz;
pub mod tables;
pub mod wca;

pub use hertz::write_hertz_deck;
pub use wca::write_wca_deck;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::hertz::wall_axis;
use super::lines::g;
use super::{Deck, DeckError, Dialect, RunStatus, RunnerOptions};
use crate::code::Code;
use cgdem_core::math::Real;
use cgdem_core::particles::Particles;
use cgdem_core::scene::{ContactSettings, Scene, WallSettings};

/// LAMMPS's words: `atom_style sphere`, `comm_modify vel yes`, the neighbour list checked
/// every step; `lmp`, `log.lammps`.
pub const DIALECT: Dialect = Dialect {
    code: Code::Lammps,
    program: "lmp",
    program_variable: "CGDEM_LMP",
    log_file: LOG_FILE,
    atom_style: "sphere",
    ghost_velocities: "comm_modify     vel yes",
    neigh_modify: "neigh_modify    every 1 delay 0 check yes",
};

/// LAMMPS's log in the run directory.
pub const LOG_FILE: &str = "log.lammps";

/// The LAMMPS deck for a scene (already coarse-grained): the seed's WCA model (`wca`) or the
/// Hertz family (`hertz`, `pair_style granular hertz/material`, reference/MAPPING.md).
pub fn write_deck(scene: &Scene, particles: &Particles, dt: Real) -> Result<Deck, DeckError> {
    match scene.contact {
        ContactSettings::Wca(_) => write_wca_deck(scene, particles, dt),
        ContactSettings::Hertz(_) => write_hertz_deck(scene, particles, dt),
    }
}

/// The `lmp` binary: `$CGDEM_LMP`, else `lmp` on `PATH`.
pub fn find_lmp() -> Result<PathBuf, String> {
    super::find_program(&DIALECT)
}

/// Runs the deck in `dir` (which must hold it) and waits, killing LAMMPS at the time limit.
pub fn run_deck(dir: &Path, options: &RunnerOptions) -> RunStatus {
    super::run_deck(&DIALECT, dir, options)
}

/// `fix pad_k all addforce 0 0 0` lines, one per wall fix some stage removes, to follow the
/// wall fixes of a LAMMPS deck. LAMMPS builds its per-stage fix lists in the setup only;
/// `unfix` shifts the fix array down and a `run pre no` then walks the old list, so the last
/// fixes are applied twice (measured: the floor's restitution 0.366 instead of 0.49998 after
/// removing a wall defined before it). With zero-force pads at the end of the list, the pads
/// are the ones applied twice.
pub(crate) fn removal_pads(scene: &Scene, fixes_per_wall: usize) -> String {
    let removed: usize = scene.stages.iter().map(|s| s.remove_walls.len()).sum();
    let mut d = String::new();
    for k in 0..removed * fixes_per_wall {
        let _ = writeln!(d, "fix             pad_{k} all addforce 0.0 0.0 0.0");
    }
    d
}

/// The `Xplane lo hi` that ends a planar wall's `fix wall/gran`: the particles are on the
/// side the normal points to, so a wall facing +axis bounds them from below (`lo NULL`),
/// one facing -axis from above (`NULL hi`).
fn plane_args(scene: &Scene, wall: &WallSettings) -> Result<String, DeckError> {
    let (axis, up) = wall_axis(scene, wall)?;
    let at = g([wall.point.x, wall.point.y, wall.point.z][axis]);
    let (lo, hi) = if up {
        (at.as_str(), "NULL")
    } else {
        ("NULL", at.as_str())
    };
    Ok(format!("{}plane {lo} {hi}", ["x", "y", "z"][axis]))
}
