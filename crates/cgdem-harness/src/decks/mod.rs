//! The reference codes: a scene written as a LAMMPS or LIGGGHTS input deck, run, and its
//! dumps turned into cgdem's output format, so every code's run compares with cgdem's.
//!
//! Both codes share what LIGGGHTS kept of LAMMPS, here: the deck's common lines (`lines`:
//! units, the data file, the neighbour list, frozen species), the energy and trajectory
//! output and the scene's stages (`stages`: settle loops, wall removal, repose samples), the
//! Hertz settings both can express (`hertz`), the dump reader (`dump`), the process runner
//! (`runner`) and the post-processing into the output format (`postprocess`). What differs
//! between the two is a [`Dialect`] (the words for the same thing) and each code's own deck
//! writer: `lammps` (the seed's WCA model and the Hertz family through `pair_style
//! granular`, bodies as particles or regions) and `liggghts` (the Hertz family with
//! LIGGGHTS's own keywords, bodies as meshes). Neither builds on the other.
//!
//! `run` puts it together: [`run_reference`] writes the deck for a scene, runs the code and
//! post-processes its outputs. How each model maps onto the codes, and what they cannot
//! reproduce: `reference/MAPPING.md` and `reference/lammps/SEED_MODEL.md`.

pub mod dump;
pub mod hertz;
pub mod lammps;
pub mod liggghts;
mod lines;
pub mod postprocess;
pub mod run;
pub mod runner;
mod stages;
pub mod version;

pub use dump::{parse_dump, read_dump, DumpError, Frame};
pub use postprocess::{postprocess, write_summary, PostprocessError};
pub use run::{run_reference, ReferenceError, ReferenceOptions, ReferenceRun};
pub use runner::{RunStatus, RunnerOptions, INSTALL_HINT};

use std::path::{Path, PathBuf};

use crate::code::Code;
use cgdem_core::math::Real;
use cgdem_core::particles::Particles;
use cgdem_core::scene::Scene;

/// File names inside a reference run's directory (both codes; the log is the dialect's).
pub const DECK_FILE: &str = "deck.in";
pub const DATA_FILE: &str = "particles.data";
pub const TRAJECTORY_FILE: &str = "traj.dump";

/// What differs between LAMMPS and LIGGGHTS in the files and lines both take: the binary,
/// the log, and the words for spheres with a diameter, ghost velocities and the neighbour
/// list's checks.
#[derive(Debug, PartialEq)]
pub struct Dialect {
    pub code: Code,
    /// The binary looked for on `PATH`, and the variable that names another.
    pub program: &'static str,
    pub program_variable: &'static str,
    /// The code's log file in the run directory (`-log`).
    pub log_file: &'static str,
    /// `atom_style` of spheres with a diameter and a density.
    pub atom_style: &'static str,
    /// The line that sends ghost atoms' velocities (`newton off` needs them).
    pub ghost_velocities: &'static str,
    /// The `neigh_modify` line: rebuild when needed, no delay.
    pub neigh_modify: &'static str,
}

/// The dialect of a reference code; None for cgdem.
pub fn dialect(code: Code) -> Option<&'static Dialect> {
    match code {
        Code::Lammps => Some(&lammps::DIALECT),
        Code::Liggghts => Some(&liggghts::DIALECT),
        Code::Cgdem => None,
    }
}

/// The deck for a scene (already coarse-grained) in a reference code, starting from
/// `particles` and stepping `dt`; for LAMMPS, in the words of the release the harness finds.
pub fn write_deck(
    code: Code,
    scene: &Scene,
    particles: &Particles,
    dt: Real,
) -> Result<Deck, DeckError> {
    match code {
        Code::Lammps => lammps::write_deck(scene, particles, dt, lammps::WallModulus::installed()),
        Code::Liggghts => liggghts::write_deck(scene, particles, dt),
        Code::Cgdem => Err(DeckError::unsupported(
            scene,
            "cgdem is not a reference code".into(),
        )),
    }
}

/// The code's binary: `$CGDEM_LMP` / `$CGDEM_LIGGGHTS`, else `lmp` / `liggghts` on `PATH`.
pub fn find_program(dialect: &Dialect) -> Result<PathBuf, String> {
    runner::find_program(dialect.program, dialect.program_variable)
}

/// Runs the deck in `dir` (which must hold it) with the code of `dialect` and waits, ending
/// the run at the time limit; a code that is not installed is a skipped run.
pub fn run_deck(dialect: &Dialect, dir: &Path, options: &RunnerOptions) -> RunStatus {
    match find_program(dialect) {
        Ok(program) => runner::run_program(&program, dir, DECK_FILE, dialect.log_file, options),
        Err(reason) => RunStatus::Skipped {
            reason,
            install_hint: INSTALL_HINT.into(),
        },
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DeckError {
    #[error("{file}: cannot write a reference-code deck for this scene: {reason}")]
    Unsupported { file: String, reason: String },
}

impl DeckError {
    /// The scene asks for something the deck cannot express, and why.
    pub fn unsupported(scene: &Scene, reason: String) -> Self {
        DeckError::Unsupported {
            file: scene.source.display().to_string(),
            reason,
        }
    }
}

/// What the deck will do, for post-processing.
#[derive(Clone, Debug, PartialEq)]
pub struct DeckPlan {
    /// The code the deck is for (`lammps` or `liggghts`), as the summary names it.
    pub code: &'static str,
    /// The code's log file in the run directory.
    pub log_file: &'static str,
    /// Known differences of this deck's model from cgdem's, carried into the summary's warnings.
    pub notes: Vec<String>,
    pub dt: Real,
    /// Steps between trajectory frames (one time-series interval).
    pub dump_every: u64,
    /// (stage, time after the stage starts, dump file) of each repose sample.
    pub repose_dumps: Vec<(String, Real, String)>,
}

/// What every reference deck leaves to cgdem, whatever the code, as notes for the run's
/// summary (shown with the case in the report; reference/MAPPING.md, "Scene features").
pub(crate) fn scene_notes(scene: &Scene, code: &str) -> Vec<String> {
    let mut notes = Vec::new();
    if scene.integrator == cgdem_core::integrate::Integrator::Pcvv {
        notes.push(format!("{code} integrates with velocity Verlet (`nve/sphere`), cgdem with the predictor-corrector the scene asks for (integrator = \"pcvv\"): both second order, their step errors differ"));
    }
    if scene.packing.is_some() {
        notes.push(format!(
            "{code}: the porosity and pore sizes of [packing] are measured in cgdem's runs only"
        ));
    }
    notes
}

/// The deck text, the data file text and the plan.
#[derive(Clone, Debug)]
pub struct Deck {
    pub input: String,
    pub data: String,
    pub plan: DeckPlan,
    /// Further files the deck reads (name in the run directory, content): LIGGGHTS's meshes.
    pub files: Vec<(String, Vec<u8>)>,
}

impl Deck {
    /// Writes `deck.in`, `particles.data` and the further files into `dir`.
    pub fn write_to(&self, dir: &Path) -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join(DECK_FILE), &self.input)?;
        for (name, content) in &self.files {
            std::fs::write(dir.join(name), content)?;
        }
        std::fs::write(dir.join(DATA_FILE), &self.data)
    }
}
