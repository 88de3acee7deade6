//! The screw's conveying measurement (`[conveying]`): the drive torque and power summed every
//! step after the discarded start-up, and the passed mass, fill ratio and bulk density at each
//! time-series row of the conveying stage; summarized as the mass flow against Eq. (7).

use crate::analysis::conveying::{self, ConveyingSample};
use crate::bodies::Body;
use crate::contact::PairLaw;
use crate::math::{Real, Vec3};
use crate::scene::{ConveyingSettings, Scene};
use crate::simulation::World;
use crate::walls::WallLaw;

use super::super::restart::{decode, encode};
use super::super::{RunError, RunSummary};
use super::{Due, Flow, Observer, StageClock, Warnings};

/// The conveying state of the grains now (a body's own frozen particles are not material).
pub(crate) fn conveying_sample<L: PairLaw, W: WallLaw>(
    c: &ConveyingSettings,
    body: &Body,
    world: &World<L, W>,
) -> ConveyingSample {
    let p = world.particles();
    let mobile: Vec<usize> = (0..p.len()).filter(|&k| !p.is_frozen(k)).collect();
    let position: Vec<Vec3> = mobile.iter().map(|&k| p.position[k]).collect();
    let radius: Vec<Real> = mobile.iter().map(|&k| p.radius[k]).collect();
    let mass: Vec<Real> = mobile.iter().map(|&k| p.mass[k]).collect();
    ConveyingSample {
        time: world.time,
        passed_mass: conveying::passed_mass(
            c,
            body.motion.axis,
            body.motion.point,
            &position,
            &mass,
            world.deleted_mass,
        ),
        fill_ratio: conveying::fill_ratio(
            c,
            body.motion.axis,
            body.motion.point,
            &position,
            &radius,
        ),
        bulk_density: conveying::bulk_density(c, &position, &mass),
    }
}

pub(crate) struct ConveyingMeter<'s> {
    scene: &'s Scene,
    settings: &'s ConveyingSettings,
    /// The conveying body's index.
    body: usize,
    /// Rows follow the time series' (`output.timeseries_interval`), in every stage.
    next_row: Real,
    measuring: bool,
    samples: Vec<ConveyingSample>,
    torque_sum: Real,
    power_sum: Real,
    torque_steps: u64,
    window: Option<(Real, Real)>,
}

impl<'s> ConveyingMeter<'s> {
    pub(crate) fn new(scene: &'s Scene, settings: &'s ConveyingSettings, body: usize) -> Self {
        ConveyingMeter {
            scene,
            settings,
            body,
            next_row: 0.0,
            measuring: false,
            samples: Vec::new(),
            torque_sum: 0.0,
            power_sum: 0.0,
            torque_steps: 0,
            window: None,
        }
    }
}

impl<L: PairLaw, W: WallLaw> Observer<L, W> for ConveyingMeter<'_> {
    fn stage_begins(&mut self, _world: &World<L, W>, clock: &StageClock) {
        self.measuring = self.settings.stage == clock.stage.name;
    }

    fn due(&self) -> Due {
        Due::EveryStep
    }

    /// Every step it reads only the body's load (summed over the subdomains already); the
    /// particles only for a sample.
    fn reads_particles(&self, world: &World<L, W>, clock: &StageClock) -> bool {
        self.measuring && world.time + 0.5 * clock.dt >= self.next_row
    }

    fn observe(&mut self, world: &World<L, W>, clock: &StageClock) -> Result<Flow, RunError> {
        let body = &world.bodies()[self.body];
        if self.measuring && world.time - clock.start >= self.settings.discard - 0.5 * clock.dt {
            self.torque_sum -= body.axial_torque();
            self.power_sum += body.drive_power();
            self.torque_steps += 1;
        }
        if world.time + 0.5 * clock.dt >= self.next_row {
            self.next_row += self.scene.output.timeseries_interval;
            if self.measuring {
                self.samples
                    .push(conveying_sample(self.settings, body, world));
            }
        }
        Ok(Flow::Continue)
    }

    fn stage_ends(
        &mut self,
        world: &World<L, W>,
        clock: &StageClock,
        _warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        if self.measuring {
            self.window = Some((clock.start + self.settings.discard, world.time));
        }
        Ok(())
    }

    fn save(&mut self) -> Result<Vec<u8>, RunError> {
        Ok(encode(&(
            self.next_row,
            &self.samples,
            self.torque_sum,
            self.power_sum,
            self.torque_steps,
            self.window,
        )))
    }

    fn restore(&mut self, state: &[u8]) -> Result<(), String> {
        (
            self.next_row,
            self.samples,
            self.torque_sum,
            self.power_sum,
            self.torque_steps,
            self.window,
        ) = decode(state)?;
        Ok(())
    }

    fn finish(
        &mut self,
        _world: &World<L, W>,
        _stopped: bool,
        summary: &mut RunSummary,
        warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        let Some((t0, t1)) = self.window else {
            return Ok(());
        };
        let c = self.settings;
        let n = self.torque_steps.max(1) as Real;
        summary.conveying = conveying::summarize(
            c,
            self.scene.bodies[self.body].rpm,
            self.scene.species[0].density,
            &self.samples,
            t0,
            t1,
            self.torque_sum / n,
            self.power_sum / n,
        );
        if summary.conveying.is_none() {
            warnings.push(format!("conveying: too few time-series samples after the discarded {} s for {} blocks; shorten output.timeseries_interval or run longer", c.discard, c.blocks));
        }
        Ok(())
    }
}
