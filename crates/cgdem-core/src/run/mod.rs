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
    hertz_coulomb_wall, hertz_history_wall, hertz_law, hertz_wall, FromScene, SUPPORTED,
};
pub use laws::{seed_laws, with_laws, LawVisitor};
pub use progress::{Progress, ProgressReporter, RunProgress};
pub use setup::{
    build_bodies, initial_particles, initial_particles_clear_of_bodies,
    initial_particles_with_bodies, linear_contacts, scene_walls,
};

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::analysis::conveying::ConveyingSummary;
use crate::analysis::heap::{self, HeapProfile};
use crate::analysis::PackingSummary;
use crate::contact::PairLaw;
use crate::guard::{GuardKind, GuardPeaks, GuardTrip};
use crate::insertion::InsertionFailed;
use crate::io::CsvBuffer;
use crate::math::{Real, Vec3};
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

/// What took a repose sample: a fixed time after the stage began, or the stage's own end.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SampleTrigger {
    #[serde(rename = "fixed time")]
    FixedTime,
    #[serde(rename = "stage end")]
    StageEnd,
}

impl std::fmt::Display for SampleTrigger {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SampleTrigger::FixedTime => "fixed time",
            SampleTrigger::StageEnd => "stage end",
        })
    }
}

/// Why a stage ended; in `summary.json` as its sentence (`StageRecord::ended_by`).
#[derive(Clone, Debug, PartialEq)]
pub enum StageEnding {
    /// It ran its whole duration (a settling stage: its `max_duration`, unsettled).
    Duration(Real),
    /// Its kinetic energy per mass fell below the threshold.
    Settled {
        kinetic_energy_per_mass: Real,
        threshold: Real,
    },
    /// A guard stopped the run.
    Guard(GuardKind),
    /// The stop flag (SIGINT/SIGTERM) was raised: the run stopped at the end of a step.
    Interrupted,
}

impl std::fmt::Display for StageEnding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StageEnding::Duration(d) => write!(f, "duration {d} s"),
            StageEnding::Settled {
                kinetic_energy_per_mass,
                threshold,
            } => write!(
                f,
                "kinetic energy per mass {kinetic_energy_per_mass:.3e} J/kg < {threshold:.3e} J/kg"
            ),
            StageEnding::Guard(kind) => write!(f, "stopped by the {} guard", kind.name()),
            StageEnding::Interrupted => write!(f, "interrupted (SIGINT/SIGTERM)"),
        }
    }
}

impl StageEnding {
    /// Whether `summary` (a summary.json) is that of a run SIGINT/SIGTERM ended: its last
    /// stage ended so, and its outputs stop there. Such a run is not finished; `validate
    /// --reuse` runs it again (or resumes it from its restart file).
    pub fn interrupted_summary(summary: &serde_json::Value) -> bool {
        summary["stages"]
            .as_array()
            .and_then(|stages| stages.last())
            .and_then(|stage| stage["ended_by"].as_str())
            == Some(StageEnding::Interrupted.to_string().as_str())
    }
}

/// The angle measured at one time after the repose stage began.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct ReposeSample {
    pub time_after_start_s: Real,
    pub trigger: SampleTrigger,
    pub repose_angle_deg: Option<Real>,
    pub repose_fit_r2: Option<Real>,
    pub runout_m: Real,
    pub wall_height_m: Real,
}

impl ReposeSample {
    /// Measures a heap profile by the scene's repose rule (the same for every code).
    pub fn measure(
        profile: &HeapProfile,
        rule: &ReposeSettings,
        max_diameter: Real,
        time_after_start_s: Real,
        trigger: SampleTrigger,
    ) -> ReposeSample {
        let fit = heap::repose_angle(
            profile,
            2.0 * max_diameter,
            rule.exclude_wall_fraction,
            rule.exclude_toe_fraction,
        );
        ReposeSample {
            time_after_start_s,
            trigger,
            repose_angle_deg: fit.as_ref().map(|f| f.angle_deg),
            repose_fit_r2: fit.as_ref().map(|f| f.r_squared),
            runout_m: profile.front(2.0 * max_diameter) - profile.wall_x,
            wall_height_m: profile.wall_height(),
        }
    }
}

#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct StageRecord {
    pub name: String,
    pub start_s: Real,
    pub end_s: Real,
    pub steps: u64,
    pub ended_by: String,
}

/// Everything `summary.json` holds.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct RunSummary {
    pub case: String,
    pub code: String,
    pub lambda: u32,
    pub cg_rule: crate::coarse_graining::CoarseGrainRule,
    pub n_particles: usize,
    pub n_particles_inserted: usize,
    /// Particles added by top-ups (`[[insert]] refill`).
    pub n_particles_refilled: u64,
    /// Particles that make up bodies built of particles (frozen, counted in `n_particles`).
    pub n_body_particles: usize,
    pub lost_particles: u64,
    pub steps: u64,
    pub dt_s: Real,
    pub contact_period_s: Real,
    pub stable_dt_s: Real,
    pub simulated_s: Real,
    pub wall_s: Real,
    pub particle_steps: u64,
    pub particle_steps_per_s: Real,
    pub threads: usize,
    pub repose_angle_deg: Option<Real>,
    pub repose_fit_r2: Option<Real>,
    pub repose_rule: Option<String>,
    pub runout_m: Option<Real>,
    pub repose_samples: Vec<ReposeSample>,
    pub stages: Vec<StageRecord>,
    /// Particles deleted in `[[delete]]` regions, and their mass.
    pub deleted_particles: u64,
    pub deleted_mass_kg: Real,
    pub conveying: Option<ConveyingSummary>,
    /// Porosity and pore sizes of the bed (`[packing]`), measured when its stage ends.
    pub packing: Option<PackingSummary>,
    pub warnings: Vec<String>,
    /// The guard that stopped the run early, if one did.
    pub stopped_by: Option<GuardTrip>,
    /// How close the run came to the guards' thresholds (none for reference codes).
    pub guard_peaks: Option<GuardPeaks>,
    pub scene_file: String,
    /// `Scene::digest` of the (coarse-grained) scene this run simulated.
    pub scene_digest: String,
    pub cgdem_version: String,
    /// The particles at the end (with `RunOptions::keep_final_state`).
    #[serde(skip)]
    pub final_state: Option<Particles>,
    /// The solver's arrays at the end (none for reference codes).
    pub memory: Option<crate::memory_use::MemoryUse>,
    /// The subdomains of a `--grid` run (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decomposition: Option<crate::decomposition::DecompositionSummary>,
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

/// The first columns of `timeseries.csv`, as cgdem and the reference post-processing write
/// them.
pub const TIMESERIES_COLUMNS: [&str; 7] = [
    "time_s",
    "stage",
    "kinetic_energy_j",
    "kinetic_energy_per_mass_j_kg",
    "n_particles",
    "front_m",
    "wall_height_m",
];

/// The heap surface of `scene`'s `[repose]` section for particles at `position` of `radius`
/// (None without one).
pub fn heap_profile(scene: &Scene, position: &[Vec3], radius: &[Real]) -> Option<HeapProfile> {
    scene.repose.as_ref().map(|r| {
        heap::profile(
            position,
            radius,
            r.wall_x,
            scene.domain.hi.x,
            scene.domain.lo.z,
            r.bin_width_diameters * scene.max_diameter(),
        )
    })
}

/// `profile.csv`: the heap surface height per bin.
pub fn profile_csv(profile: &HeapProfile) -> std::io::Result<Vec<u8>> {
    let mut csv = CsvBuffer::new(["x_m", "height_m"]);
    for (k, h) in profile.heights.iter().enumerate() {
        csv.row([format!("{:.6e}", profile.bin_centre(k)), format!("{h:.6e}")]);
    }
    csv.bytes().map(<[u8]>::to_vec)
}

/// `repose.csv`: the angle at each measurement.
pub fn repose_csv(samples: &[ReposeSample]) -> std::io::Result<Vec<u8>> {
    let mut csv = CsvBuffer::new([
        "time_after_start_s",
        "trigger",
        "repose_angle_deg",
        "repose_fit_r2",
        "runout_m",
        "wall_height_m",
    ]);
    let opt = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6}"));
    for s in samples {
        csv.row([
            s.time_after_start_s.to_string(),
            s.trigger.to_string(),
            opt(s.repose_angle_deg),
            opt(s.repose_fit_r2),
            format!("{:.6e}", s.runout_m),
            format!("{:.6e}", s.wall_height_m),
        ]);
    }
    csv.bytes().map(<[u8]>::to_vec)
}

/// The headline measurement: the stage-end sample when the scene asks for one, else the last
/// fixed time.
pub fn headline_sample(samples: &[ReposeSample]) -> Option<&ReposeSample> {
    samples
        .iter()
        .rev()
        .find(|s| s.trigger == SampleTrigger::StageEnd)
        .or(samples.last())
}
