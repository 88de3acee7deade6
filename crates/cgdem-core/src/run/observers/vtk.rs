//! The VTK series (`vtk/particles.pvd` and its frames), one frame per `output.vtk_interval`.

use std::path::PathBuf;

use crate::contact::PairLaw;
use crate::io::vtk::VtkSeries;
use crate::math::Real;
use crate::simulation::World;
use crate::walls::WallLaw;

use super::super::{output_error, RunError};
use super::{Due, Flow, Observer, StageClock};

pub(crate) struct VtkFrames {
    dir: PathBuf,
    series: VtkSeries,
    interval: Real,
    next_frame: Real,
}

impl VtkFrames {
    pub(crate) fn new(dir: PathBuf, interval: Real) -> Result<Self, RunError> {
        let series = VtkSeries::new(&dir, "particles").map_err(|e| output_error(&dir, e))?;
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
            .write_frame(&world.particles, world.time)
            .map_err(|e| output_error(&self.dir, e))?;
        Ok(Flow::Continue)
    }
}
