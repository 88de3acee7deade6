//! `timeseries.csv`: one row per `output.timeseries_interval` (energies, particle count, heap
//! front and wall height, deleted mass, body torques, conveying state); it also ends a
//! settling stage, whose condition is judged at these rows.

use std::fs::File;
use std::io::{Seek, SeekFrom};
use std::path::PathBuf;

use crate::contact::PairLaw;
use crate::math::Real;
use crate::scene::{ConveyingSettings, Scene, StageEnd};
use crate::simulation::World;
use crate::walls::WallLaw;

use super::super::restart::{decode, encode};
use super::super::{output_error, RunError, StageEnding, TIMESERIES_COLUMNS};
use super::conveying::conveying_sample;
use super::repose::heap_profile;
use super::{Due, Flow, Observer, StageClock};

pub(crate) struct TimeSeries<'s> {
    scene: &'s Scene,
    path: PathBuf,
    file: csv::Writer<File>,
    next_row: Real,
    /// The conveying body's settings and index, for the conveying columns.
    conveying: Option<(&'s ConveyingSettings, usize)>,
    /// The stage's settling condition: (kinetic energy per mass, minimum duration).
    settle: Option<(Real, Real)>,
    /// The file is the resumed run's (not a fresh one, as an MPI rank's scratch copy).
    resumed: bool,
}

impl<'s> TimeSeries<'s> {
    pub(crate) fn new(
        scene: &'s Scene,
        path: PathBuf,
        conveying: Option<(&'s ConveyingSettings, usize)>,
        resuming: bool,
    ) -> Result<Self, RunError> {
        if resuming {
            // The file of the run being resumed: `restore` cuts it back to the checkpoint.
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(&path)
                .map_err(|e| output_error(&path, e))?;
            return Ok(TimeSeries {
                scene,
                path,
                file: csv::Writer::from_writer(file),
                next_row: 0.0,
                conveying,
                settle: None,
                resumed: true,
            });
        }
        let file = File::create(&path).map_err(|e| output_error(&path, e))?;
        let mut series = TimeSeries {
            scene,
            path,
            file: csv::Writer::from_writer(file),
            next_row: 0.0,
            conveying,
            settle: None,
            resumed: false,
        };
        let mut header: Vec<String> = TIMESERIES_COLUMNS.map(String::from).into();
        header.push("deleted_mass_kg".into());
        header.extend(
            scene
                .bodies
                .iter()
                .map(|b| format!("axial_torque_{}_nm", b.name)),
        );
        if conveying.is_some() {
            header.extend(["fill_ratio", "bulk_density_kg_m3", "passed_mass_kg"].map(String::from));
        }
        header.push("mechanical_energy_j".into());
        series
            .file
            .write_record(&header)
            .map_err(|e| output_error(&series.path, e))?;
        Ok(series)
    }
}

impl<L: PairLaw, W: WallLaw> Observer<L, W> for TimeSeries<'_> {
    fn stage_begins(&mut self, _world: &World<L, W>, clock: &StageClock) {
        self.settle = match clock.stage.end {
            StageEnd::Duration(_) => None,
            StageEnd::Settled {
                kinetic_energy_per_mass,
                min_duration,
                ..
            } => Some((kinetic_energy_per_mass, min_duration)),
        };
    }

    fn due(&self) -> Due {
        Due::At(self.next_row)
    }

    /// A settling stage ends on the kinetic energy of the particles it reads.
    fn decides(&self) -> bool {
        self.settle.is_some()
    }

    fn observe(&mut self, world: &World<L, W>, clock: &StageClock) -> Result<Flow, RunError> {
        let elapsed = world.time - clock.start;
        self.next_row += self.scene.output.timeseries_interval;
        let ke = world.kinetic_energy();
        let mass = world.particles().mobile_mass();
        let profile = heap_profile(self.scene, world.particles());
        let max_diameter = self.scene.max_diameter();
        let front = profile.as_ref().map(|p| p.front(2.0 * max_diameter));
        let wall_height = profile.as_ref().map(|p| p.wall_height());
        let opt = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6e}"));
        let mut row = vec![
            format!("{:.9e}", world.time),
            clock.stage.name.clone(),
            format!("{ke:.9e}"),
            format!("{:.9e}", ke / mass.max(Real::MIN_POSITIVE)),
            world.particles().len().to_string(),
            opt(front),
            opt(wall_height),
            format!("{:.9e}", world.deleted_mass),
        ];
        for body in world.bodies() {
            row.push(format!("{:.6e}", body.axial_torque()));
        }
        if let Some((c, k)) = self.conveying {
            let sample = conveying_sample(c, &world.bodies()[k], world);
            row.push(format!("{:.6e}", sample.fill_ratio));
            row.push(format!("{:.6e}", sample.bulk_density));
            row.push(format!("{:.9e}", sample.passed_mass));
        }
        // Kinetic plus gravitational energy, for the stability suite's energy balance.
        row.push(format!("{:.9e}", world.mechanical_energy()));
        self.file
            .write_record(&row)
            .and_then(|()| Ok(self.file.flush()?))
            .map_err(|e| output_error(&self.path, e))?;
        if let Some((threshold, min_duration)) = self.settle {
            if elapsed >= min_duration && ke / mass < threshold {
                return Ok(Flow::EndStage(StageEnding::Settled {
                    kinetic_energy_per_mass: ke / mass,
                    threshold,
                }));
            }
        }
        Ok(Flow::Continue)
    }

    /// The next row's time and the file's length so far (every row is flushed as written).
    fn save(&mut self) -> Result<Vec<u8>, RunError> {
        let len = self
            .file
            .flush()
            .and_then(|()| self.file.get_ref().sync_data())
            .and_then(|()| self.file.get_ref().metadata())
            .map_err(|e| output_error(&self.path, e))?
            .len();
        Ok(encode(&(self.next_row, len)))
    }

    /// Cuts the file back to its length at the checkpoint: rows a killed run wrote after it
    /// are written again.
    fn restore(&mut self, state: &[u8]) -> Result<(), String> {
        let len: u64;
        (self.next_row, len) = decode(state)?;
        if !self.resumed {
            // A fresh file (an MPI rank's scratch copy): the rows from here on follow it.
            return Ok(());
        }
        // `&File` seeks and truncates; the writer's buffer is empty (flushed every row).
        let mut file: &File = self.file.get_ref();
        let actual = file
            .metadata()
            .map_err(|e| format!("{}: {e}", self.path.display()))?
            .len();
        if actual < len {
            return Err(format!(
                "{}: {actual} bytes, shorter than the {len} bytes at the checkpoint",
                self.path.display()
            ));
        }
        file.set_len(len)
            .and_then(|()| file.seek(SeekFrom::Start(len)).map(|_| ()))
            .map_err(|e| format!("{}: {e}", self.path.display()))
    }
}
