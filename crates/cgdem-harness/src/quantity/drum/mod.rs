//! The rotating drum of the open-source DEM comparison (reference/DRUM.md), measured from a
//! run's frames: the grains of each species in MercuryDPM's two zones, the dynamic angle of
//! repose by a stated rule and Lacey's mixing index (`measurement`); the period and
//! amplitude of the zone counts' swing (`oscillation`); each frame of a run read and
//! measured, and the means over its steady part (`run`); cgdem's verdict against the
//! reference codes (`verdict`); the case's section with its figures and CSV (`report`); the
//! measures per coarse-graining level of an accuracy sweep (`levels`). How a run is measured
//! (`settings`) comes from a suite's `[case.drum]` table or an `[[accuracy]]` entry's `drum`.

mod levels;
mod measurement;
mod oscillation;
mod report;
mod run;
mod settings;
#[cfg(test)]
mod tests;
mod verdict;

pub use levels::{write_levels_table, LevelMeans};
pub use measurement::{
    lacey_index, surface_angle, zone_counts, Grain, Lacey, SurfaceLine, ZoneCounts,
};
pub use oscillation::{oscillation, Oscillation};
pub use report::write_drum_section;
pub(crate) use run::species_diameters;
pub use run::{measure_runs, DrumRun, FrameMeasure, SteadyMeans};
pub use settings::DrumSettings;
pub(crate) use settings::{parse_drum, RawDrum};
pub use verdict::{drum_criteria, COMPARISON, CRITERIA};
