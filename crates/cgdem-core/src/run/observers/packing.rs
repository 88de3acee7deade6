//! The bed's porosity and pore sizes (`[packing]`), measured when its stage ends
//! (`pore_size.csv` and the summary's `packing`).

use std::path::PathBuf;

use crate::analysis::{measure_packing, PackingSummary};
use crate::contact::PairLaw;
use crate::io::write_atomic;
use crate::scene::{PackingSettings, Scene};
use crate::simulation::World;
use crate::walls::WallLaw;

use super::super::restart::{decode, encode};
use super::super::{output_error, RunError, RunSummary};
use super::{Due, Flow, Observer, StageClock, Warnings};

pub(crate) struct PackingMeter<'s> {
    scene: &'s Scene,
    settings: &'s PackingSettings,
    out: PathBuf,
    result: Option<PackingSummary>,
}

impl<'s> PackingMeter<'s> {
    pub(crate) fn new(scene: &'s Scene, settings: &'s PackingSettings, out: PathBuf) -> Self {
        PackingMeter {
            scene,
            settings,
            out,
            result: None,
        }
    }
}

impl<L: PairLaw, W: WallLaw> Observer<L, W> for PackingMeter<'_> {
    fn due(&self) -> Due {
        Due::Never
    }

    fn observe(&mut self, _world: &World<L, W>, _clock: &StageClock) -> Result<Flow, RunError> {
        Ok(Flow::Continue)
    }

    fn stage_ends(
        &mut self,
        world: &World<L, W>,
        clock: &StageClock,
        warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        if self.settings.stage != clock.stage.name {
            return Ok(());
        }
        let (lo, hi) = (self.scene.domain.lo, self.scene.domain.hi);
        let pk = self.settings;
        match measure_packing(
            &world.particles().position,
            &world.particles().radius,
            [lo.x, lo.y],
            [hi.x, hi.y],
            lo.z,
            &pk.rule,
            pk.voxels_per_diameter,
            pk.bin_width_diameters,
        ) {
            Ok(m) => {
                let path = self.out.join("pore_size.csv");
                let mut csv = Vec::new();
                m.pore_sizes
                    .write_csv(&mut csv)
                    .map_err(|e| output_error(&path, e))?;
                write_atomic(&path, &csv).map_err(|e| output_error(&path, e))?;
                self.result = Some(m.summary);
            }
            Err(e) => warnings.push(format!(
                "packing: not measured at the end of stage `{}`: {e}",
                clock.stage.name
            )),
        }
        Ok(())
    }

    fn save(&mut self) -> Result<Vec<u8>, RunError> {
        Ok(encode(&self.result))
    }

    fn restore(&mut self, state: &[u8]) -> Result<(), String> {
        self.result = decode(state)?;
        Ok(())
    }

    fn finish(
        &mut self,
        _world: &World<L, W>,
        _stopped: bool,
        summary: &mut RunSummary,
        _warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        summary.packing = self.result.take();
        Ok(())
    }
}
