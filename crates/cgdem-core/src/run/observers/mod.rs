//! Output observers: what a run measures and writes while its stages run. The stage driver
//! (`super::driver`) calls each observer when it is due: dynamic dispatch once per output
//! interval (or once per step for the few that accumulate every step), never per contact.
//!
//! The driver calls them in list order, so an observer that ends a stage (the time series,
//! when the stage has settled) keeps the later ones from seeing that step.

mod conveying;
mod packing;
mod repose;
mod stage_data;
mod timeseries;
mod vtk;

pub(crate) use conveying::ConveyingMeter;
pub(crate) use packing::PackingMeter;
pub(crate) use repose::ReposeMeter;
pub use stage_data::stage_end_data_path;
pub(crate) use stage_data::StageEndData;
pub(crate) use timeseries::TimeSeries;
pub(crate) use vtk::VtkFrames;

use crate::contact::PairLaw;
use crate::math::Real;
use crate::scene::Stage;
use crate::simulation::World;
use crate::walls::WallLaw;

use super::{RunError, RunSummary};

/// When an observer wants to be called next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Due {
    Never,
    EveryStep,
    /// At the first step with `time + dt/2 >= t` (absolute simulated time).
    At(Real),
    /// At the first step with `(time - stage start) + dt/2 >= t`.
    AfterStageStart(Real),
}

impl Due {
    /// Whether a step that ended at `time` is due (the comparison each observer's interval
    /// was always made with, so the steps that write are the same).
    pub(crate) fn is_due(self, time: Real, stage_start: Real, dt: Real) -> bool {
        match self {
            Due::Never => false,
            Due::EveryStep => true,
            Due::At(t) => time + 0.5 * dt >= t,
            Due::AfterStageStart(t) => time - stage_start + 0.5 * dt >= t,
        }
    }
}

/// Where the driver is: the stage, when it began, the step.
pub(crate) struct StageClock<'a> {
    pub stage: &'a Stage,
    pub start: Real,
    pub dt: Real,
}

/// What an observer tells the driver after it ran.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Flow {
    Continue,
    /// The stage ends now (its settling condition holds), for this reason.
    EndStage(super::StageEnding),
}

/// Warnings a run collects for `summary.json` (also printed as they arise, unless the
/// second field says not to: MPI ranks other than 0 collect the same ones).
#[derive(Default)]
pub(crate) struct Warnings(pub Vec<String>, pub bool);

impl Warnings {
    pub(crate) fn push(&mut self, w: String) {
        if !self.1 {
            eprintln!("warning: {w}");
        }
        self.0.push(w);
    }
}

pub(crate) trait Observer<L: PairLaw, W: WallLaw> {
    /// A stage begins; the observer sets up what it measures in it.
    fn stage_begins(&mut self, _world: &World<L, W>, _clock: &StageClock) {}
    /// When this observer wants to be called next (asked after each call).
    fn due(&self) -> Due;
    fn observe(&mut self, world: &World<L, W>, clock: &StageClock) -> Result<Flow, RunError>;
    /// Whether `observe` reads the particles at this due step (while decomposed they are
    /// gathered, under MPI from every rank, only at the steps where one does); most do.
    fn reads_particles(&self, _world: &World<L, W>, _clock: &StageClock) -> bool {
        true
    }
    /// Whether what `observe` reads decides the run's course (ends the stage), so that under
    /// MPI every rank must read the same particles; otherwise only rank 0's outputs use them.
    fn decides(&self) -> bool {
        false
    }
    /// The stage ended by its own condition (not by a guard).
    fn stage_ends(
        &mut self,
        _world: &World<L, W>,
        _clock: &StageClock,
        _warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        Ok(())
    }
    /// The observer's changing state for a restart file (what it has written made durable
    /// first); the scene and the stage give the rest.
    fn save(&mut self) -> Result<Vec<u8>, RunError> {
        Ok(Vec::new())
    }
    /// Puts back a state from [`Observer::save`] (after `stage_begins` when resuming within
    /// a stage), cutting what it writes back to that moment.
    fn restore(&mut self, _state: &[u8]) -> Result<(), String> {
        Ok(())
    }
    /// The run ended (`stopped`: by a guard); the observer writes its last outputs and puts
    /// its results into the summary.
    fn finish(
        &mut self,
        _world: &World<L, W>,
        _stopped: bool,
        _summary: &mut RunSummary,
        _warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        Ok(())
    }
}

/// An observer with its cached due time, so the driver asks it only when it is due.
pub(crate) struct Scheduled<'s, L: PairLaw, W: WallLaw> {
    due: Due,
    observer: Box<dyn Observer<L, W> + 's>,
}

impl<'s, L: PairLaw, W: WallLaw> Scheduled<'s, L, W> {
    pub(crate) fn new(observer: Box<dyn Observer<L, W> + 's>) -> Self {
        Scheduled {
            due: observer.due(),
            observer,
        }
    }

    pub(crate) fn stage_begins(&mut self, world: &World<L, W>, clock: &StageClock) {
        self.observer.stage_begins(world, clock);
        self.due = self.observer.due();
    }

    /// Whether the observer is due after the step that ended at `world.time`.
    pub(crate) fn is_due(&self, world: &World<L, W>, clock: &StageClock) -> bool {
        self.due.is_due(world.time, clock.start, clock.dt)
    }

    /// Whether the observer is due and reads the particles after this step.
    pub(crate) fn reads_particles(&self, world: &World<L, W>, clock: &StageClock) -> bool {
        self.is_due(world, clock) && self.observer.reads_particles(world, clock)
    }

    pub(crate) fn decides(&self) -> bool {
        self.observer.decides()
    }

    /// Runs the observer if it is due after the step that ended at `world.time`.
    pub(crate) fn after_step(
        &mut self,
        world: &World<L, W>,
        clock: &StageClock,
    ) -> Result<Flow, RunError> {
        if !self.due.is_due(world.time, clock.start, clock.dt) {
            return Ok(Flow::Continue);
        }
        let flow = self.observer.observe(world, clock)?;
        self.due = self.observer.due();
        Ok(flow)
    }

    pub(crate) fn restore(&mut self, state: &[u8]) -> Result<(), String> {
        self.observer.restore(state)?;
        self.due = self.observer.due();
        Ok(())
    }

    pub(crate) fn observer(&mut self) -> &mut (dyn Observer<L, W> + 's) {
        &mut *self.observer
    }
}
