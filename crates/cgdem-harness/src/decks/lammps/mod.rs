//! LAMMPS (29 Sep 2021) as a reference: the seed's WCA model (`wca`) and the Hertz family
//! (`hertz`, `pair_style granular hertz/material`), with a scene's bodies as frozen atoms
//! or analytic regions (`bodies`). How the models are expressed in LAMMPS and what it cannot
//! reproduce: `reference/lammps/SEED_MODEL.md` and `reference/MAPPING.md`.

mod bodies;
pub mod coefficients;
mod cylinder;
pub mod hertz;
pub mod tables;
pub mod wca;

pub use hertz::{write_hertz_deck, write_hertz_deck_for};
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
/// Hertz family (`hertz`, `pair_style granular hertz/material`, reference/MAPPING.md), for
/// a LAMMPS that reads the walls' modulus as `modulus` says.
pub fn write_deck(
    scene: &Scene,
    particles: &Particles,
    dt: Real,
    modulus: WallModulus,
) -> Result<Deck, DeckError> {
    match scene.contact {
        ContactSettings::Wca(_) => write_wca_deck(scene, particles, dt),
        ContactSettings::Hertz(_) => write_hertz_deck_for(scene, particles, dt, modulus),
    }
}

/// How a LAMMPS release turns the `E` of `fix wall/gran granular hertz/material E q nu`
/// into the wall's normal stiffness. Releases before 28 Mar 2023 take k_n = (4/3) E/(2(1 -
/// nu)) sqrt(R delta) (measured: contact 10% short with E itself, (1 + nu)^(-2/5)); the
/// reworked GRANULAR package, from 28 Mar 2023 on, treats the wall as a particle of the
/// same material, k_n = (4/3) E/(2(1 - nu^2)) sqrt(R delta) (`mix_stiffnessE_wall`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WallModulus {
    BeforeRework,
    Reworked,
}

impl WallModulus {
    /// The first release with the reworked GRANULAR package.
    pub const REWORK: (i32, u32, u32) = (2023, 3, 28);

    /// The convention of a LAMMPS release (`29 Sep 2021`); one that cannot be read is taken
    /// as the verified release's.
    pub fn of_release(release: Option<&str>) -> WallModulus {
        match release.and_then(super::version::lammps_date) {
            Some(date) if date >= Self::REWORK => WallModulus::Reworked,
            _ => WallModulus::BeforeRework,
        }
    }

    /// The `E` to give for a wall stiffness of (4/3) `y_eff` sqrt(R delta), with the
    /// particle's Poisson ratio `nu`.
    pub fn modulus(self, y_eff: Real, nu: Real) -> Real {
        match self {
            WallModulus::BeforeRework => 2.0 * (1.0 - nu) * y_eff,
            WallModulus::Reworked => 2.0 * (1.0 - nu * nu) * y_eff,
        }
    }

    /// The convention of the LAMMPS the harness finds (`$CGDEM_LMP` or `lmp` on `PATH`);
    /// the verified release's when none is found.
    pub fn installed() -> WallModulus {
        let version = super::version::find_version(&DIALECT).ok();
        WallModulus::of_release(version.as_ref().and_then(|v| v.release.as_deref()))
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

#[cfg(test)]
mod tests {
    use super::WallModulus;

    /// The wall stiffness (4/3) Y* sqrt(R delta) in either convention: before the rework
    /// LAMMPS divides E by 2 (1 - nu), since by 2 (1 - nu^2).
    #[test]
    fn the_walls_modulus_follows_the_release() {
        let before = WallModulus::of_release(Some("29 Sep 2021"));
        let since = WallModulus::of_release(Some("22 Jul 2025"));
        assert_eq!(before, WallModulus::BeforeRework);
        assert_eq!(since, WallModulus::Reworked);
        assert_eq!(WallModulus::of_release(Some("8 Feb 2023")), before);
        assert_eq!(WallModulus::of_release(Some("28 Mar 2023")), since);
        assert_eq!(WallModulus::of_release(None), before);
        let (y, nu) = (2.0e6, 0.3);
        assert!((before.modulus(y, nu) / (2.0 * (1.0 - nu)) - y).abs() < 1e-9);
        assert!((since.modulus(y, nu) / (2.0 * (1.0 - nu * nu)) - y).abs() < 1e-9);
    }
}
