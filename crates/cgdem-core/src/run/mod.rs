//! Running a scene: build the world with the scene's laws, run its stages, measure and
//! write the outputs (summary.json, timeseries.csv, profile.csv, repose.csv, VTK series).
//!
//! `laws` chooses the concrete laws once; `setup` inserts particles and builds bodies and
//! walls; `driver` runs the stages and calls the `observers` that measure and write.

mod driver;
mod laws;
pub mod memory;
mod observers;
mod progress;
mod refill;
pub mod restart;
mod setup;
pub mod state_file;

pub use laws::hertz::{
    hertz_coulomb_wall, hertz_coulomb_wall_limited, hertz_history_wall, hertz_history_wall_limited,
    hertz_law, hertz_wall, FromScene, SUPPORTED,
};
pub use laws::{seed_laws, with_laws, LawVisitor};
pub use observers::stage_end_data_path;
pub use progress::{Progress, ProgressReporter, RunProgress};
// The output format, where cgdem's runs (and the driver) have always found it.
pub use crate::output_format::{
    headline_sample, heap_profile, profile_csv, repose_csv, ReposeSample, RunSummary,
    SampleTrigger, StageEnding, StageRecord, TIMESERIES_COLUMNS,
};
pub use setup::{
    build_bodies, initial_particles, initial_particles_clear_of_bodies,
    initial_particles_with_bodies, linear_contacts, scene_walls,
};

use std::path::{Path, PathBuf};

use crate::contact::PairLaw;
use crate::guard::GuardTrip;
use crate::insertion::InsertionFailed;
use crate::math::Real;
use crate::particles::Particles;
use crate::scene::{ReposeSettings, Scene, StageEnd};
use crate::timestep::{self, Timescales, UnstableTimeStep};
use crate::walls::WallLaw;

#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub out_dir: PathBuf,
    /// Where to report progress; `None` reports nothing.
    pub progress: Option<Progress>,
    pub force_dt: bool,
    /// A guard that fires only warns (once per guard) instead of stopping the run.
    pub keep_going: bool,
    /// Start from these particles instead of the scene's insertions (as LAMMPS `read_data`
    /// after `write_data`): the benchmark starts every code from one prepared state.
    pub initial_state: Option<Particles>,
    /// Keep the particles at the end of the run in [`RunSummary::final_state`].
    pub keep_final_state: bool,
    /// Raised from outside (the command's SIGINT/SIGTERM handler): the run stops at the end of
    /// the current step, writes its outputs and returns [`RunError::Interrupted`].
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Split the box into these subdomains with ghost layers (`--grid`); None: one world.
    pub grid: Option<crate::decomposition::GridSpec>,
    /// With `grid`: move the cut planes by count when the imbalance passes a threshold
    /// (`--balance`; on at 1.1 by default).
    pub balance: crate::decomposition::BalanceSpec,
    /// The MPI ranks a `--grid` run is spread over (`mpirun`); one process by default.
    pub comm: crate::decomposition::Comm,
    /// Write restart files (`--checkpoint-every`), see [`restart`].
    pub checkpoint: Option<CheckpointOptions>,
    /// Continue the run this restart file was written by, in `out_dir` (`--resume`); the
    /// scene must be the one it ran (same digest). It keeps checkpointing as it did.
    pub resume: Option<std::sync::Arc<restart::RestartLoaded>>,
}

/// When to write restart files and what to store for the caller.
#[derive(Clone, Debug)]
pub struct CheckpointOptions {
    /// Simulated seconds between restart files (also one at the start, at every stage end
    /// and when the stop flag ends the run).
    pub every: Real,
    /// Stored as is: what the caller needs to rebuild the scene on resume.
    pub invocation: String,
}

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    NotAvailable(String),
    #[error("{file}: time step: {source}")]
    TimeStep {
        file: String,
        source: UnstableTimeStep,
    },
    #[error("{file}: insert[{index}]: {source}")]
    Insertion {
        file: String,
        index: usize,
        source: InsertionFailed,
    },
    #[error("{file}: insert[{index}]: the lattice site {site:?} overlaps particle {id} of an earlier insertion; move the lattice's box or the other insertion")]
    LatticeOverlap {
        file: String,
        index: usize,
        site: [Real; 3],
        id: u32,
    },
    #[error("{file}: contact: the combination damping/tangential/rolling/cohesion = {combination} is not compiled; supported: {supported}")]
    Unsupported {
        file: String,
        combination: String,
        supported: String,
    },
    #[error("{file}: {field}: {message}")]
    Geometry {
        file: String,
        field: String,
        message: String,
    },
    #[error("cannot write {path}: {message}")]
    Output { path: PathBuf, message: String },
    #[error("{file}: run stopped: {trip}; the outputs written so far are kept in {}; pass --keep-going to only warn", out_dir.display())]
    Stopped {
        file: String,
        trip: Box<GuardTrip>,
        out_dir: PathBuf,
    },
    #[error("{file}: the run needs about {estimate}, more than the {available} this machine has available (MemAvailable in /proc/meminfo); reduce the particle count (insert amounts, lambda) or the SDF resolution (body cell_size)")]
    NotEnoughMemory {
        file: String,
        estimate: String,
        available: String,
    },
    #[error("{0}")]
    Restart(String),
    #[error("{file}: run interrupted at t = {time_s:.6e} s (step {step}); the outputs written so far are kept in {}", out_dir.display())]
    Interrupted {
        file: String,
        time_s: Real,
        step: u64,
        out_dir: PathBuf,
    },
}

pub(crate) fn output_error(path: &Path, e: impl std::fmt::Display) -> RunError {
    RunError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Runs a (possibly coarse-grained) scene and writes its outputs into `options.out_dir`.
pub fn run(scene: &Scene, options: &RunOptions) -> Result<RunSummary, RunError> {
    check_memory(scene, options)?;
    struct Run<'a>(&'a Scene, &'a RunOptions);
    impl LawVisitor for Run<'_> {
        type Output = Result<RunSummary, RunError>;
        fn visit<L: PairLaw, W: WallLaw>(self, law: L, wall_law: W) -> Self::Output {
            driver::execute(self.0, law, wall_law, self.1)
        }
    }
    with_laws(scene, Run(scene, options))?
}

/// Refuses a scene whose estimated memory exceeds what the machine has available, before
/// anything is allocated.
fn check_memory(scene: &Scene, options: &RunOptions) -> Result<(), RunError> {
    let estimate = memory::estimate(scene, options.initial_state.as_ref().map(|p| p.len()));
    let Some(available) = memory::mem_available() else {
        return Ok(());
    };
    if estimate.total() > available {
        return Err(RunError::NotEnoughMemory {
            file: scene.source.display().to_string(),
            estimate: estimate.describe(),
            available: memory::bytes(available),
        });
    }
    Ok(())
}

/// The time step cgdem uses for a scene, with the contact time scales behind it (the
/// reference decks run at the same step).
pub fn time_step(
    scene: &Scene,
    force_dt: bool,
) -> Result<(Real, Timescales, Option<String>), RunError> {
    struct TimeStep<'a>(&'a Scene, bool);
    impl LawVisitor for TimeStep<'_> {
        type Output = Result<(Real, Timescales, Option<String>), RunError>;
        fn visit<L: PairLaw, W: WallLaw>(self, law: L, wall_law: W) -> Self::Output {
            time_step_for(self.0, &law, &wall_law, self.1)
        }
    }
    with_laws(scene, TimeStep(scene, force_dt))?
}

/// The time step for given laws: the scene's `time_step` against their linearized contacts.
pub fn time_step_for<L: PairLaw, W: WallLaw>(
    scene: &Scene,
    law: &L,
    wall_law: &W,
    force_dt: bool,
) -> Result<(Real, Timescales, Option<String>), RunError> {
    let scales = Timescales::of(&setup::linear_contacts(scene, law, wall_law));
    let (dt, warning) = timestep::choose(scene.time_step, &scales, force_dt).map_err(|source| {
        RunError::TimeStep {
            file: scene.source.display().to_string(),
            source,
        }
    })?;
    Ok((dt, scales, warning))
}

/// The repose rule in words, for the summary.
fn describe_repose_rule(scene: &Scene) -> Option<String> {
    let r: &ReposeSettings = scene.repose.as_ref()?;
    let when = if r.at_stage_end {
        let end = scene
            .stages
            .iter()
            .find(|s| s.name == r.stage)
            .map(|s| describe_end(&s.end))
            .unwrap_or_default();
        format!("at the end of stage `{}` ({end})", r.stage)
    } else {
        format!(
            "{} s after stage `{}` began",
            r.at_times.last().copied().unwrap_or(0.0),
            r.stage
        )
    };
    Some(format!(
        "least-squares line through the surface profile (bins of {} diameters) between {}% of the run-out from the wall and {}% before the front (deposit >= 2 diameters deep), measured {when}",
        r.bin_width_diameters,
        r.exclude_wall_fraction * 100.0,
        r.exclude_toe_fraction * 100.0,
    ))
}

/// How a stage ends, in words for the summary.
fn describe_end(end: &StageEnd) -> String {
    match end {
        StageEnd::Duration(d) => format!("after {d} s"),
        StageEnd::Settled {
            kinetic_energy_per_mass,
            min_duration,
            max_duration,
        } => format!("kinetic energy per mass below {kinetic_energy_per_mass:e} J/kg, after at least {min_duration} s and at most {max_duration} s"),
    }
}
