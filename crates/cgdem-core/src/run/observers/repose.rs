//! The repose angle (`[repose]`): the heap profile measured at fixed times after its stage
//! began and when that stage ends, written to `repose.csv` and `profile.csv` as soon as each
//! is taken, so a run stopped later keeps them.

use std::path::PathBuf;

use crate::analysis::heap::HeapProfile;
use crate::contact::PairLaw;
use crate::io::write_atomic;
use crate::math::Real;
use crate::particles::Particles;
use crate::scene::{ReposeSettings, Scene};
use crate::simulation::World;
use crate::walls::WallLaw;

use super::super::restart::{decode, encode};
use super::super::{
    headline_sample, output_error, profile_csv, repose_csv, ReposeSample, RunError, RunSummary,
    SampleTrigger,
};
use super::{Due, Flow, Observer, StageClock, Warnings};

/// The heap surface of the scene's `[repose]` section, if it has one.
pub(crate) fn heap_profile(scene: &Scene, particles: &Particles) -> Option<HeapProfile> {
    super::super::heap_profile(scene, &particles.position, &particles.radius)
}

pub(crate) struct ReposeMeter<'s> {
    scene: &'s Scene,
    rule: &'s ReposeSettings,
    out: PathBuf,
    /// The fixed times of the current stage (none outside the repose stage) and the next one.
    times: &'s [Real],
    next: usize,
    samples: Vec<ReposeSample>,
    measured: bool,
}

impl<'s> ReposeMeter<'s> {
    pub(crate) fn new(scene: &'s Scene, rule: &'s ReposeSettings, out: PathBuf) -> Self {
        ReposeMeter {
            scene,
            rule,
            out,
            times: &[],
            next: 0,
            samples: Vec::new(),
            measured: false,
        }
    }

    fn sample(
        &mut self,
        particles: &Particles,
        time_after_start_s: Real,
        trigger: SampleTrigger,
    ) -> Result<(), RunError> {
        let Some(profile) = heap_profile(self.scene, particles) else {
            return Ok(());
        };
        self.samples.push(ReposeSample::measure(
            &profile,
            self.rule,
            self.scene.max_diameter(),
            time_after_start_s,
            trigger,
        ));
        self.write(&profile)?;
        self.measured = true;
        Ok(())
    }

    /// Writes `repose.csv` (all samples so far) and `profile.csv` (the latest profile).
    fn write(&self, profile: &HeapProfile) -> Result<(), RunError> {
        let path = self.out.join("profile.csv");
        profile_csv(profile)
            .and_then(|csv| write_atomic(&path, &csv))
            .map_err(|e| output_error(&path, e))?;
        if !self.samples.is_empty() {
            let path = self.out.join("repose.csv");
            repose_csv(&self.samples)
                .and_then(|csv| write_atomic(&path, &csv))
                .map_err(|e| output_error(&path, e))?;
        }
        Ok(())
    }
}

impl<L: PairLaw, W: WallLaw> Observer<L, W> for ReposeMeter<'_> {
    fn stage_begins(&mut self, _world: &World<L, W>, clock: &StageClock) {
        self.times = if self.rule.stage == clock.stage.name {
            &self.rule.at_times
        } else {
            &[]
        };
        self.next = 0;
    }

    fn due(&self) -> Due {
        self.times
            .get(self.next)
            .map_or(Due::Never, |&t| Due::AfterStageStart(t))
    }

    fn observe(&mut self, world: &World<L, W>, _clock: &StageClock) -> Result<Flow, RunError> {
        let t = self.times[self.next];
        self.next += 1;
        self.sample(world.particles(), t, SampleTrigger::FixedTime)?;
        Ok(Flow::Continue)
    }

    fn stage_ends(
        &mut self,
        world: &World<L, W>,
        clock: &StageClock,
        _warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        if self.rule.stage == clock.stage.name && self.rule.at_stage_end {
            self.sample(
                world.particles(),
                world.time - clock.start,
                SampleTrigger::StageEnd,
            )?;
        }
        Ok(())
    }

    fn save(&mut self) -> Result<Vec<u8>, RunError> {
        Ok(encode(&(self.next, &self.samples, self.measured)))
    }

    fn restore(&mut self, state: &[u8]) -> Result<(), String> {
        (self.next, self.samples, self.measured) = decode(state)?;
        Ok(())
    }

    fn finish(
        &mut self,
        world: &World<L, W>,
        stopped: bool,
        summary: &mut RunSummary,
        _warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        // A run that never reached a measurement still leaves its final profile.
        if !self.measured && !stopped {
            if let Some(profile) = heap_profile(self.scene, world.particles()) {
                self.write(&profile)?;
            }
        }
        let headline = headline_sample(&self.samples);
        summary.repose_angle_deg = headline.and_then(|s| s.repose_angle_deg);
        summary.repose_fit_r2 = headline.and_then(|s| s.repose_fit_r2);
        summary.repose_not_measured = match headline {
            Some(s) => s.not_measured.clone(),
            None => Some("the run ended before the repose stage's first measurement".into()),
        };
        summary.runout_m = headline.map(|s| s.runout_m);
        summary.repose_samples = std::mem::take(&mut self.samples);
        Ok(())
    }
}
