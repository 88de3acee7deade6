//! The stage driver: builds the world for a scene's laws, runs its stages step by step (wall
//! removals, body starts, top-ups, guards, progress) and calls the output observers when
//! they are due; the summary is assembled from what they measured.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::bodies::KinematicParticles;
use crate::contact::PairLaw;
use crate::decomposition::placement::MAX_SUBDOMAINS;
use crate::decomposition::GridSpec;
use crate::geometry::Aabb;
use crate::guard::{GuardKind, GuardSettings, GuardTrip};
use crate::io::write_atomic;
use crate::math::Real;
use crate::particles::Particles;
use crate::scene::{Scene, Stage, StageEnd};
use crate::simulation::{Decompose, NeighborSettings, World, WorldSetup, WorldState};
use crate::timestep::Timescales;
use crate::walls::WallLaw;

use super::observers::{
    ConveyingMeter, Flow, Observer, PackingMeter, ReposeMeter, Scheduled, StageClock, StageEndData,
    TimeSeries, VtkFrames, Warnings,
};
use super::refill::RefillRegion;
use super::restart::{self, decode, encode, DriverState, Position, Restart};
use super::setup::{build_bodies, initial_particles_with_bodies, scene_walls};
use super::{
    describe_repose_rule, output_error, progress, time_step_for, CheckpointOptions, Progress,
    RunError, RunOptions, RunProgress, RunSummary, StageEnding, StageRecord,
};

/// Runs a scene with its concrete laws and writes its outputs into `options.out_dir`.
pub(crate) fn execute<L: PairLaw, W: WallLaw>(
    scene: &Scene,
    law: L,
    wall_law: W,
    options: &RunOptions,
) -> Result<RunSummary, RunError> {
    let out = &options.out_dir;
    let resume = options.resume.as_deref();
    let laws = format!(
        "{} {}",
        std::any::type_name::<L>(),
        std::any::type_name::<W>()
    );
    if let Some(r) = resume {
        check_resumable(scene, &r.restart, &r.path, &laws)?;
    }
    std::fs::create_dir_all(out).map_err(|e| output_error(out, e))?;
    let (dt, scales, warning) = time_step_for(scene, &law, &wall_law, options.force_dt)?;
    let mut warnings = Warnings(Vec::new(), !options.comm.is_root());
    if let Some(w) = warning {
        warnings.push(w);
    }
    // A resumed run's state, decoded before the world is built: the world starts on its
    // grid (unless another is given), so that its ranks fit.
    let stored: Option<WorldState<L::History, W::History>> = match resume {
        Some(r) => Some(
            decode(&r.restart.world)
                .map_err(|e| RunError::Restart(format!("{}: {e}", r.path.display())))?,
        ),
        None => None,
    };
    let grid = options
        .grid
        .or(stored.as_ref().map(|s| GridSpec::Given(s.grid())));
    let (mut world, n_inserted, n_body_particles) =
        build_world(scene, law, wall_law, dt, &scales, options, grid)?;
    if grid.is_none() {
        warn_of_idle_workers(&world, options, &mut warnings);
    }
    // Under MPI only rank 0 writes into the run's directory: the others' outputs (in a
    // scratch directory) start afresh.
    let root = options.comm.is_root();
    let mut observers = observers(scene, out, resume.is_some() && root)?;
    let checkpoint = checkpoint_options(options, resume);
    if checkpoint.is_some() && resume.is_none() {
        restart::remove(out).map_err(|e| output_error(&out.join(restart::RESTART_FILE), e))?;
    }
    let checkpointer = checkpoint.map(|c| Checkpointer {
        next: c.every,
        options: c,
        digest: scene.digest(),
        laws,
        out: out.clone(),
        n_inserted,
        n_body_particles,
    });
    let mut driver = Driver::new(scene, dt, options, checkpointer)?;
    let counts = Counts {
        inserted: n_inserted,
        body_particles: n_body_particles,
    };
    let stored = resume.zip(stored);
    let (resume_at, counts) = driver.start(
        &mut world,
        &mut observers,
        &mut warnings,
        stored,
        options,
        counts,
    )?;
    driver.started = Instant::now();
    let stopped_by = driver.run_stages(&mut world, &mut observers, &mut warnings, resume_at)?;
    driver.progress.finish();
    // Under MPI rank 0 gathers the final state and writes it.
    world.sync_particles_for_output();
    let ran = Ran {
        counts,
        steps: (dt, &scales),
        stopped_by,
    };
    conclude(
        scene,
        &world,
        &mut driver,
        &mut observers,
        warnings,
        ran,
        options,
    )
}

/// A scene large enough for more subdomains than the default grid gives, on more threads
/// than it has: say how to use them.
fn warn_of_idle_workers<L: PairLaw, W: WallLaw>(
    world: &World<L, W>,
    options: &RunOptions,
    warnings: &mut Warnings,
) {
    let subdomains: usize = world.grid().iter().product();
    let workers = rayon::current_num_threads() * options.comm.size();
    if subdomains == MAX_SUBDOMAINS && workers > subdomains {
        warnings.push(format!(
            "the grid chosen from the scene has {subdomains} subdomains (the most it chooses), fewer than the {workers} threads, which take whole subdomains: give --grid {workers} (or more) to keep them all busy"
        ));
    }
}

/// The restart files' settings: as given, or as the resumed run had them.
fn checkpoint_options(
    options: &RunOptions,
    resume: Option<&restart::RestartLoaded>,
) -> Option<CheckpointOptions> {
    match (&options.checkpoint, resume) {
        (Some(c), _) => Some(c.clone()),
        (None, Some(r)) => Some(CheckpointOptions {
            every: r.restart.checkpoint_every,
            invocation: r.restart.invocation.clone(),
        }),
        (None, None) => None,
    }
}

/// How a run's stepping ended: its particle counts, time step and time scales, and the
/// guard trip that stopped it, if one did.
struct Ran<'a> {
    counts: Counts,
    steps: (Real, &'a Timescales),
    stopped_by: Option<GuardTrip>,
}

/// After the last step: the run's warnings, its summary with what the observers measured
/// (written to summary.json), and the result: the summary, or why the run stopped early.
fn conclude<L: PairLaw, W: WallLaw>(
    scene: &Scene,
    world: &World<L, W>,
    driver: &mut Driver,
    observers: &mut [Scheduled<'_, L, W>],
    mut warnings: Warnings,
    ran: Ran<'_>,
    options: &RunOptions,
) -> Result<RunSummary, RunError> {
    let out = &options.out_dir;
    // A resumed run counts the wall time its earlier processes spent up to its checkpoint.
    let wall_s = driver.wall_s();
    for (kind, count) in driver.guard_counts.iter().filter(|(_, count)| *count > 1) {
        warnings.push(format!(
            "--keep-going: the {} guard fired in {count} steps",
            kind.name()
        ));
    }
    if world.lost > 0 {
        warnings.push(format!(
            "{} particles left the box through a bounded face and were removed",
            world.lost
        ));
    }
    let stopped_by = ran.stopped_by;
    let mut summary = base_summary(
        scene,
        world,
        driver,
        ran.counts,
        ran.steps,
        wall_s,
        stopped_by.clone(),
        options,
    );
    for o in observers.iter_mut() {
        o.observer()
            .finish(world, stopped_by.is_some(), &mut summary, &mut warnings)?;
    }
    summary.warnings = warnings.0;
    write_summary(out, &summary)?;
    if driver.interrupted {
        return Err(RunError::Interrupted {
            file: summary.scene_file,
            time_s: summary.simulated_s,
            step: summary.steps,
            out_dir: out.clone(),
        });
    }
    match stopped_by {
        Some(trip) => Err(RunError::Stopped {
            file: summary.scene_file,
            trip: Box::new(trip),
            out_dir: out.clone(),
        }),
        None => Ok(summary),
    }
}

/// The inserted and body particle counts of a run.
struct Counts {
    inserted: usize,
    body_particles: usize,
}

/// The summary of a finished (or stopped) run before its observers add their results.
#[allow(clippy::too_many_arguments)]
fn base_summary<L: PairLaw, W: WallLaw>(
    scene: &Scene,
    world: &World<L, W>,
    driver: &mut Driver,
    counts: Counts,
    (dt, scales): (Real, &crate::timestep::Timescales),
    wall_s: Real,
    stopped_by: Option<GuardTrip>,
    options: &RunOptions,
) -> RunSummary {
    RunSummary {
        case: scene.name.clone(),
        code: "cgdem".into(),
        lambda: scene.lambda,
        cg_rule: scene.cg_rule,
        n_particles: world.particles().len(),
        n_particles_inserted: counts.inserted,
        n_particles_refilled: driver.refilled,
        n_body_particles: counts.body_particles,
        lost_particles: world.lost,
        steps: world.steps,
        dt_s: dt,
        contact_period_s: scales.shortest_period,
        stable_dt_s: scales.stable_limit,
        simulated_s: world.time,
        wall_s,
        particle_steps: driver.particle_steps,
        particle_steps_per_s: driver.particle_steps as Real / wall_s.max(1e-9),
        threads: rayon::current_num_threads(),
        repose_angle_deg: None,
        repose_fit_r2: None,
        repose_rule: describe_repose_rule(scene),
        repose_not_measured: None,
        runout_m: None,
        repose_samples: Vec::new(),
        stages: std::mem::take(&mut driver.stages),
        deleted_particles: world.deleted,
        deleted_mass_kg: world.deleted_mass,
        conveying: None,
        packing: None,
        warnings: Vec::new(),
        stopped_by,
        guard_peaks: Some(world.guard_peaks()),
        scene_file: scene.source.display().to_string(),
        scene_digest: scene.digest(),
        cgdem_version: env!("CARGO_PKG_VERSION").into(),
        final_state: options.keep_final_state.then(|| world.particles().clone()),
        memory: Some(world.memory_use()),
        decomposition: Some(world.decomposition_summary()),
    }
}

/// The world at the start of the run, with the particles inserted (or given), bodies,
/// walls, deletion regions and guards, on `grid` (or the scene's); with the inserted and
/// body particle counts.
fn build_world<L: PairLaw, W: WallLaw>(
    scene: &Scene,
    law: L,
    wall_law: W,
    dt: Real,
    scales: &Timescales,
    options: &RunOptions,
    grid: Option<GridSpec>,
) -> Result<(World<L, W>, usize, usize), RunError> {
    let (bodies, body_sites) = build_bodies(scene, &wall_law)?;
    let (particles, kinematic): (Particles, Vec<KinematicParticles>) = match &options.initial_state
    {
        // A given state carries no particle-built bodies (the bench's heap has none).
        Some(_) if !body_sites.is_empty() => {
            return Err(RunError::NotAvailable(format!(
                "{}: starting from a given state is not supported with particle-built bodies",
                scene.source.display()
            )))
        }
        Some(state) => (state.clone(), Vec::new()),
        None => initial_particles_with_bodies(scene, L::NEEDS_ROTATION, &bodies, &body_sites)?,
    };
    let n_inserted = particles.len();
    let n_body_particles = kinematic.iter().map(|k| k.reference.len()).sum();
    let neighbor = NeighborSettings {
        skin: scene.skin_fraction * scene.max_diameter(),
        resort_every: scene.resort_every,
    };
    let mut setup = WorldSetup::new(
        particles,
        scene.domain.clone(),
        law,
        wall_law,
        scene.species.len(),
        scene.gravity,
        dt,
        neighbor,
    );
    setup.walls = scene_walls(scene);
    setup.integrator = scene.integrator;
    setup.bodies = bodies;
    setup.kinematic = kinematic;
    setup.delete_regions = scene
        .deletions
        .iter()
        .map(|&(min, max)| Aabb { min, max })
        .collect();
    setup.guard = GuardSettings {
        stable_dt: scales.stable_limit,
        // With --keep-going guards only warn: lost particles are removed, as with "warn".
        stop_on_lost: scene.stop_on_lost && !options.keep_going,
        ..GuardSettings::default()
    };
    let decompose = Decompose {
        grid,
        balance: options.balance,
        comm: options.comm.clone(),
    };
    let world = World::new(setup, &decompose).map_err(|e| {
        let given = grid.map_or(String::new(), |g| format!(" --grid {g}:"));
        RunError::NotAvailable(format!("{}:{given} {e}", scene.source.display()))
    })?;
    Ok((world, n_inserted, n_body_particles))
}

/// The observers the scene's outputs need, in the order they see each step.
fn observers<'s, L: PairLaw, W: WallLaw>(
    scene: &'s Scene,
    out: &Path,
    resuming: bool,
) -> Result<Vec<Scheduled<'s, L, W>>, RunError> {
    let conveying = scene.conveying.as_ref().and_then(|c| {
        scene
            .bodies
            .iter()
            .position(|b| b.name == c.body)
            .map(|k| (c, k))
    });
    let mut list: Vec<Box<dyn Observer<L, W> + 's>> = Vec::new();
    if let Some((c, k)) = conveying {
        list.push(Box::new(ConveyingMeter::new(scene, c, k)));
    }
    list.push(Box::new(TimeSeries::new(
        scene,
        out.join("timeseries.csv"),
        conveying,
        resuming,
    )?));
    if scene.output.vtk_interval > 0.0 {
        list.push(Box::new(VtkFrames::new(
            scene,
            out.join("vtk"),
            scene.output.vtk_interval,
        )?));
    }
    if let Some(rule) = &scene.repose {
        list.push(Box::new(ReposeMeter::new(scene, rule, out.to_path_buf())));
    }
    if let Some(settings) = &scene.packing {
        list.push(Box::new(PackingMeter::new(
            scene,
            settings,
            out.to_path_buf(),
        )));
    }
    if !scene.output.data_at_stage_ends.is_empty() {
        list.push(Box::new(StageEndData::new(scene, out.to_path_buf())));
    }
    Ok(list.into_iter().map(Scheduled::new).collect())
}

/// Steps for the progress display: every stage at its longest.
fn total_steps(scene: &Scene, dt: Real) -> u64 {
    let total: Real = scene
        .stages
        .iter()
        .map(|s| match s.end {
            StageEnd::Duration(d) => d,
            StageEnd::Settled { max_duration, .. } => max_duration,
        })
        .sum();
    (total / dt).ceil() as u64
}

fn write_summary(out: &Path, summary: &RunSummary) -> Result<(), RunError> {
    let path = out.join("summary.json");
    let json = serde_json::to_string_pretty(summary).map_err(|e| output_error(&path, e))?;
    write_atomic(&path, json.as_bytes()).map_err(|e| output_error(&path, e))
}

struct Driver<'s> {
    scene: &'s Scene,
    dt: Real,
    progress: Box<dyn RunProgress>,
    keep_going: bool,
    refill_regions: Vec<(usize, RefillRegion)>,
    refilled: u64,
    particle_steps: u64,
    stages: Vec<StageRecord>,
    /// Guards that fired under --keep-going, and how often.
    guard_counts: Vec<(GuardKind, u64)>,
    /// `RunOptions::stop`, polled at the end of every step.
    stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    interrupted: bool,
    checkpoint: Option<Checkpointer>,
    /// Wall seconds the run spent in the processes before this one (from the restart file
    /// it resumed), up to their last checkpoint.
    wall_before: Real,
    /// When this process began stepping.
    started: Instant,
}

/// Writes the restart files (`--checkpoint-every`).
struct Checkpointer {
    options: CheckpointOptions,
    /// The simulated time of the next periodic restart file.
    next: Real,
    digest: String,
    laws: String,
    out: PathBuf,
    n_inserted: usize,
    n_body_particles: usize,
}

/// A stored run to take over: its restart file and its world's state.
type Stored<'r, H, WH> = (&'r restart::RestartLoaded, WorldState<H, WH>);

/// Where a resumed run starts: the position, and the observers' and top-ups' states to
/// put back once the stage has begun again (when resuming within a stage).
struct Resume<'r> {
    at: Position,
    observers: Option<(&'r [Vec<u8>], &'r Path)>,
    refills: Vec<(usize, usize, u64)>,
}

fn restore_observers<L: PairLaw, W: WallLaw>(
    observers: &mut [Scheduled<'_, L, W>],
    states: &[Vec<u8>],
) -> Result<(), String> {
    for (o, state) in observers.iter_mut().zip(states) {
        o.restore(state)?;
    }
    Ok(())
}

/// Refuses a restart file written for another scene or law combination.
fn check_resumable(
    scene: &Scene,
    restart: &Restart,
    path: &Path,
    laws: &str,
) -> Result<(), RunError> {
    let digest = scene.digest();
    if restart.scene_digest != digest {
        return Err(RunError::Restart(format!(
            "{}: written for a scene with digest {}, but {} (with the stored options) now has digest {digest}: the case file or a file it reads changed since the run began",
            path.display(),
            restart.scene_digest,
            scene.source.display()
        )));
    }
    if restart.laws != laws {
        return Err(RunError::Restart(format!(
            "{}: written for the laws {}, this scene runs {laws}",
            path.display(),
            restart.laws
        )));
    }
    Ok(())
}

/// A top-up of the current stage: (insertion, region, particles it held at the stage start,
/// top-ups so far).
type Refill<'r> = (usize, &'r RefillRegion, usize, u64);

impl<'s> Driver<'s> {
    /// The driver of `scene`'s stages, at its start.
    fn new(
        scene: &'s Scene,
        dt: Real,
        options: &RunOptions,
        checkpoint: Option<Checkpointer>,
    ) -> Result<Self, RunError> {
        Ok(Driver {
            scene,
            dt,
            progress: match &options.progress {
                Some(Progress(reporter)) => reporter.start(total_steps(scene, dt)),
                None => Box::new(progress::Silent),
            },
            keep_going: options.keep_going,
            refill_regions: scene
                .insertions
                .iter()
                .enumerate()
                .filter(|(_, ins)| ins.refill.is_some())
                .map(|(k, ins)| RefillRegion::new(scene, k, ins).map(|r| (k, r)))
                .collect::<Result<_, _>>()?,
            refilled: 0,
            particle_steps: 0,
            stages: Vec::new(),
            guard_counts: Vec::new(),
            stop: options.stop.clone(),
            interrupted: false,
            checkpoint,
            wall_before: 0.0,
            started: Instant::now(),
        })
    }

    /// Where the stage loop starts: a stored run taken over (`stored`: the restart file and
    /// its world's state; the particle counts become the stored run's), or the first stage,
    /// whose start is saved as a checkpoint.
    fn start<'r, L: PairLaw, W: WallLaw>(
        &mut self,
        world: &mut World<L, W>,
        observers: &mut [Scheduled<'_, L, W>],
        warnings: &mut Warnings,
        stored: Option<Stored<'r, L::History, W::History>>,
        options: &RunOptions,
        counts: Counts,
    ) -> Result<(Resume<'r>, Counts), RunError> {
        if let Some((loaded, state)) = stored {
            let (at, (inserted, body_particles)) =
                self.resume_from(world, observers, warnings, loaded, state, options.grid)?;
            let counts = Counts {
                inserted,
                body_particles,
            };
            return Ok((at, counts));
        }
        let start = Position {
            stage: 0,
            within: None,
        };
        self.save_checkpoint(world, observers, warnings, start, &[])?;
        let at = Resume {
            at: start,
            observers: None,
            refills: Vec::new(),
        };
        Ok((at, counts))
    }

    /// Wall seconds of stepping so far, over every process of the run.
    fn wall_s(&self) -> Real {
        self.wall_before + self.started.elapsed().as_secs_f64()
    }

    /// Takes over a stored run: the world's state, the driver's counters and warnings, and
    /// where the stage loop goes on (observers restored now, or at their stage's start when
    /// the run stopped within a stage); with the inserted and body particle counts.
    fn resume_from<'r, L: PairLaw, W: WallLaw>(
        &mut self,
        world: &mut World<L, W>,
        observers: &mut [Scheduled<'_, L, W>],
        warnings: &mut Warnings,
        loaded: &'r restart::RestartLoaded,
        state: WorldState<L::History, W::History>,
        grid: Option<GridSpec>,
    ) -> Result<(Resume<'r>, (usize, usize)), RunError> {
        let r = &loaded.restart;
        let bad = |e: String| RunError::Restart(format!("{}: {e}", loaded.path.display()));
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
        world.set_state(state, grid).map_err(bad)?;
        let d = &r.driver;
        self.refilled = d.refilled;
        self.particle_steps = d.particle_steps;
        self.wall_before = d.wall_s;
        self.stages = d.stages.clone();
        self.guard_counts = d.guard_counts.clone();
        // Already printed by the run that met them.
        warnings.0 = d.warnings.clone();
        if let Some(c) = &mut self.checkpoint {
            c.next = d.next_checkpoint;
            (c.n_inserted, c.n_body_particles) = (d.n_inserted, d.n_body_particles);
        }
        if r.observers.len() != observers.len() {
            return Err(bad(format!(
                "{} observer states stored, the scene has {} observers",
                r.observers.len(),
                observers.len()
            )));
        }
        let mut pending = None;
        if r.position.within.is_none() {
            restore_observers(observers, &r.observers).map_err(bad)?;
        } else {
            pending = Some((r.observers.as_slice(), loaded.path.as_path()));
        }
        let resume = Resume {
            at: r.position,
            observers: pending,
            refills: d.refills.clone(),
        };
        Ok((resume, (d.n_inserted, d.n_body_particles)))
    }

    /// Runs every stage from `resume.at` on; returns the guard trip that stopped the run, if
    /// one did.
    fn run_stages<L: PairLaw, W: WallLaw>(
        &mut self,
        world: &mut World<L, W>,
        observers: &mut [Scheduled<'_, L, W>],
        warnings: &mut Warnings,
        resume: Resume<'_>,
    ) -> Result<Option<GuardTrip>, RunError> {
        let mut within = resume.at.within;
        let mut saved_refills = Some(resume.refills);
        for (index, stage) in self.scene.stages.iter().enumerate().skip(resume.at.stage) {
            world.sync_particles();
            // Resuming within this stage: its start (walls, bodies, energy reference) is in
            // the restored state already.
            let resumed = within.take();
            if resumed.is_none() {
                world.reset_energy_reference();
                for name in &stage.remove_walls {
                    world.walls.remove(name);
                }
                for b in &self.scene.bodies {
                    if b.start_stage.as_deref() == Some(stage.name.as_str()) {
                        world.start_body(&b.name);
                    }
                }
            }
            self.progress.stage(&stage.name);
            let clock = StageClock {
                stage,
                start: resumed.map_or(world.time, |(_, start)| start),
                dt: self.dt,
            };
            for o in observers.iter_mut() {
                o.stage_begins(world, &clock);
            }
            if let (Some(_), Some((states, path))) = (resumed, resume.observers) {
                restore_observers(observers, states)
                    .map_err(|e| RunError::Restart(format!("{}: {e}", path.display())))?;
            }
            let done = resumed.map_or(0, |(steps, _)| steps);
            let start_steps = world.steps - done;
            let refills = if resumed.is_some() {
                saved_refills.take()
            } else {
                None
            };
            let ending =
                match self.run_stage(world, observers, &clock, warnings, index, done, refills)? {
                    Ok(ending) => ending,
                    Err(trip) => {
                        self.record(
                            stage,
                            &clock,
                            world,
                            start_steps,
                            StageEnding::Guard(trip.kind),
                        );
                        return Ok(Some(trip));
                    }
                };
            if matches!(ending, StageEnding::Interrupted) {
                // Not a stage end: the stage-end samples are not taken.
                self.record(stage, &clock, world, start_steps, ending);
                return Ok(None);
            }
            if let (StageEnd::Settled { max_duration, .. }, StageEnding::Duration(_)) =
                (&stage.end, &ending)
            {
                warnings.push(format!(
                    "stage `{}` did not settle within max_duration {max_duration} s",
                    stage.name
                ));
            }
            // The stage-end measurements go into rank 0's outputs only.
            world.sync_particles_for_output();
            for o in observers.iter_mut() {
                o.observer().stage_ends(world, &clock, warnings)?;
            }
            self.record(stage, &clock, world, start_steps, ending);
            let next = Position {
                stage: index + 1,
                within: None,
            };
            self.save_checkpoint(world, observers, warnings, next, &[])?;
        }
        Ok(None)
    }

    /// Steps one stage (stage `index`, `done` steps of it already taken) until its end;
    /// `Err(trip)` when a guard stops the run. `saved_refills`: the top-ups' counters of a
    /// resumed stage.
    #[allow(clippy::type_complexity, clippy::too_many_arguments)]
    fn run_stage<L: PairLaw, W: WallLaw>(
        &mut self,
        world: &mut World<L, W>,
        observers: &mut [Scheduled<'_, L, W>],
        clock: &StageClock,
        warnings: &mut Warnings,
        index: usize,
        done: u64,
        saved_refills: Option<Vec<(usize, usize, u64)>>,
    ) -> Result<Result<StageEnding, GuardTrip>, RunError> {
        let duration = match clock.stage.end {
            StageEnd::Duration(d) => d,
            StageEnd::Settled { max_duration, .. } => max_duration,
        };
        let refill_regions = std::mem::take(&mut self.refill_regions);
        let mut refills: Vec<Refill> = refill_regions
            .iter()
            .filter(|(k, _)| {
                self.scene.insertions[*k]
                    .refill
                    .as_ref()
                    .is_some_and(|r| r.stage == clock.stage.name)
            })
            .map(|(k, region)| {
                let saved = saved_refills
                    .as_ref()
                    .and_then(|s| s.iter().find(|(i, _, _)| i == k));
                match saved {
                    Some(&(_, target, count)) => (*k, region, target, count),
                    None => (*k, region, region.count(world.particles()), 0),
                }
            })
            .collect();
        let stage_steps = (duration / self.dt).round() as u64;
        let mut ending = Ok(StageEnding::Duration(duration));
        'steps: for k in done + 1..=stage_steps {
            world.step();
            self.particle_steps += world.particle_count() as u64;
            if let Some(trip) = world.take_guard_trip() {
                if !self.keep_going {
                    ending = Err(trip);
                    break;
                }
                self.count_guard(world, trip, warnings);
            }
            self.top_up(world, &mut refills, clock);
            if k % 256 == 0 {
                self.progress.advance(256);
            }
            // While decomposed the observers read the particles gathered at the steps where
            // one that is due reads them; under MPI to rank 0 only, which writes, unless
            // what one reads decides the run's course on every rank.
            let reading = observers.iter().filter(|o| o.reads_particles(world, clock));
            match reading.map(|o| o.decides()).reduce(|a, b| a || b) {
                Some(true) => world.sync_particles(),
                Some(false) => world.sync_particles_for_output(),
                None => {}
            }
            for o in observers.iter_mut() {
                if let Flow::EndStage(reason) = o.after_step(world, clock)? {
                    ending = Ok(reason);
                    break 'steps;
                }
            }
            // At the end of a whole step, its outputs written: a consistent state to keep.
            let stop = self
                .stop
                .as_ref()
                .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed));
            // Under MPI all ranks stop at the same step when a signal reached any of them
            // (asked every 64 steps: a collective costs a wait on a loaded machine).
            let comm = world.comm();
            let stop = if comm.is_distributed() {
                k % 64 == 0 && comm.any(stop)
            } else {
                stop
            };
            let due = self
                .checkpoint
                .as_ref()
                .is_some_and(|c| world.time + 0.5 * self.dt >= c.next);
            if stop || due {
                if let Some(c) = &mut self.checkpoint {
                    while world.time + 0.5 * self.dt >= c.next {
                        c.next += c.options.every;
                    }
                }
                let counters: Vec<_> = refills.iter().map(|&(i, _, t, n)| (i, t, n)).collect();
                let here = Position {
                    stage: index,
                    within: Some((k, clock.start)),
                };
                self.save_checkpoint(world, observers, warnings, here, &counters)?;
            }
            if stop {
                self.interrupted = true;
                ending = Ok(StageEnding::Interrupted);
                break;
            }
        }
        drop(refills);
        self.refill_regions = refill_regions;
        Ok(ending)
    }

    /// Writes a restart file for `position` (nothing without `--checkpoint-every`).
    fn save_checkpoint<L: PairLaw, W: WallLaw>(
        &mut self,
        world: &World<L, W>,
        observers: &mut [Scheduled<'_, L, W>],
        warnings: &Warnings,
        position: Position,
        refills: &[(usize, usize, u64)],
    ) -> Result<(), RunError> {
        let Some(c) = &self.checkpoint else {
            return Ok(());
        };
        let path = c.out.join(restart::RESTART_FILE);
        // Collective under MPI: every rank gathers, rank 0 writes.
        let state = world.state();
        let observers = observers
            .iter_mut()
            .map(|o| o.observer().save())
            .collect::<Result<Vec<_>, _>>()?;
        let file = Restart {
            invocation: c.options.invocation.clone(),
            scene_digest: c.digest.clone(),
            laws: c.laws.clone(),
            checkpoint_every: c.options.every,
            position,
            world: encode(&state),
            driver: DriverState {
                refilled: self.refilled,
                particle_steps: self.particle_steps,
                stages: self.stages.clone(),
                guard_counts: self.guard_counts.clone(),
                refills: refills.to_vec(),
                next_checkpoint: c.next,
                warnings: warnings.0.clone(),
                n_inserted: c.n_inserted,
                n_body_particles: c.n_body_particles,
                wall_s: self.wall_s(),
            },
            observers,
        };
        if world.comm().is_root() {
            restart::write(&c.out, &file).map_err(|e| output_error(&path, e))?;
        }
        Ok(())
    }

    /// Under --keep-going: warn once per guard and count the rest; a new energy reference,
    /// so the energy guard judges what follows.
    fn count_guard<L: PairLaw, W: WallLaw>(
        &mut self,
        world: &mut World<L, W>,
        trip: GuardTrip,
        warnings: &mut Warnings,
    ) {
        world.reset_energy_reference();
        match self
            .guard_counts
            .iter_mut()
            .find(|(kind, _)| *kind == trip.kind)
        {
            Some((_, count)) => *count += 1,
            None => {
                warnings.push(format!("--keep-going: {trip}"));
                self.guard_counts.push((trip.kind, 1));
            }
        }
    }

    /// Tops up the stage's refill regions that are due.
    fn top_up<L: PairLaw, W: WallLaw>(
        &mut self,
        world: &mut World<L, W>,
        refills: &mut [Refill],
        clock: &StageClock,
    ) {
        for (index, region, target, done) in refills.iter_mut() {
            let ins = &self.scene.insertions[*index];
            let interval = ins.refill.as_ref().map_or(Real::INFINITY, |r| r.interval);
            if world.time - clock.start + 0.5 * self.dt >= (*done + 1) as Real * interval {
                *done += 1;
                world.sync_particles();
                let seed = ins.seed.wrapping_add(1_000_003 * *done);
                let added = region.top_up(world.particles(), world.bodies(), *target, seed);
                let species = &self.scene.species[ins.species];
                world.add_particles(ins.species as u16, &added, species.radius(), species.mass());
                self.refilled += added.len() as u64;
            }
        }
    }

    fn record<L: PairLaw, W: WallLaw>(
        &mut self,
        stage: &Stage,
        clock: &StageClock,
        world: &World<L, W>,
        start_steps: u64,
        ending: StageEnding,
    ) {
        self.stages.push(StageRecord {
            name: stage.name.clone(),
            start_s: clock.start,
            end_s: world.time,
            steps: world.steps - start_steps,
            ended_by: ending.to_string(),
        });
    }
}
