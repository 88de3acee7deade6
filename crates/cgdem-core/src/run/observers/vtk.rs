//! The VTK series (`vtk/particles.pvd`, `bodies.pvd`, `contacts.pvd` and their frames, see
//! `io::vtk`), one frame per `output.vtk_interval`.

use std::path::PathBuf;

use crate::contact::PairLaw;
use crate::io::vtk::VtkOutput;
use crate::math::Real;
use crate::scene::Scene;
use crate::simulation::World;
use crate::walls::WallLaw;

use super::super::restart::{decode, encode};
use super::super::{output_error, RunError};
use super::{Due, Flow, Observer, StageClock};

pub(crate) struct VtkFrames {
    dir: PathBuf,
    series: VtkOutput,
    interval: Real,
    next_frame: Real,
}

impl VtkFrames {
    pub(crate) fn new(scene: &Scene, dir: PathBuf, interval: Real) -> Result<Self, RunError> {
        let series = VtkOutput::for_scene(&dir, scene).map_err(|e| output_error(&dir, e))?;
        Ok(VtkFrames {
            dir,
            series,
            interval,
            next_frame: 0.0,
        })
    }
}

impl<L: PairLaw, W: WallLaw> Observer<L, W> for VtkFrames {
    fn due(&self) -> Due {
        Due::At(self.next_frame)
    }

    fn observe(&mut self, world: &World<L, W>, _clock: &StageClock) -> Result<Flow, RunError> {
        self.next_frame += self.interval;
        self.series
            .write_frame(world)
            .map_err(|e| output_error(&self.dir, e))?;
        Ok(Flow::Continue)
    }

    fn save(&mut self) -> Result<Vec<u8>, RunError> {
        Ok(encode(&(self.next_frame, self.series.state())))
    }

    fn restore(&mut self, state: &[u8]) -> Result<(), String> {
        let series;
        (self.next_frame, series) = decode(state)?;
        self.series.restore(series)
    }
}
