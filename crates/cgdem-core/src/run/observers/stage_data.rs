//! The particles at the end of chosen stages as LAMMPS data files (`[output]
//! data_at_stage_ends`): `stage_<name>_end.data`, from which a scene can start (`read_data`)
//! and on which a measurement at that moment can be made (the silo's bulk density when its
//! gate opens, issue 42).

use std::path::{Path, PathBuf};

use crate::contact::PairLaw;
use crate::io::write_atomic;
use crate::lammps_data::data_text;
use crate::scene::Scene;
use crate::simulation::World;
use crate::walls::WallLaw;

use super::super::{output_error, RunError};
use super::{Due, Flow, Observer, StageClock, Warnings};

/// The file the particles at the end of stage `stage` are written to, in the run's directory.
pub fn stage_end_data_path(out: &Path, stage: &str) -> PathBuf {
    out.join(format!("stage_{stage}_end.data"))
}

pub(crate) struct StageEndData<'s> {
    scene: &'s Scene,
    out: PathBuf,
}

impl<'s> StageEndData<'s> {
    pub(crate) fn new(scene: &'s Scene, out: PathBuf) -> Self {
        StageEndData { scene, out }
    }
}

impl<L: PairLaw, W: WallLaw> Observer<L, W> for StageEndData<'_> {
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
        _warnings: &mut Warnings,
    ) -> Result<(), RunError> {
        let name = &clock.stage.name;
        if !self.scene.output.data_at_stage_ends.contains(name) {
            return Ok(());
        }
        let s = self.scene;
        let title = format!(
            "LAMMPS data file written by cgdem {}: scene {} at the end of stage {name}, t = {:.17e} s",
            env!("CARGO_PKG_VERSION"),
            s.name,
            world.time
        );
        let diameters: Vec<_> = s.species.iter().map(|p| p.diameter).collect();
        let densities: Vec<_> = s.species.iter().map(|p| p.density).collect();
        let text = data_text(
            &title,
            s.domain.lo,
            s.domain.hi,
            world.particles(),
            &diameters,
            &densities,
            diameters.len(),
        );
        let path = stage_end_data_path(&self.out, name);
        write_atomic(&path, text.as_bytes()).map_err(|e| output_error(&path, e))
    }
}
