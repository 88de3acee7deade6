//! The rotating drum of the open-source DEM comparison (reference/DRUM.md), measured from a
//! run's frames: the grains of each species in MercuryDPM's two zones, the dynamic angle of
//! repose by a stated rule and Lacey's mixing index (`measurement`); each frame of a run
//! read and measured, and the means over its steady part (`run`); the case's section with
//! its figures and CSV (`report`). How a run is measured (`settings`) comes from a suite's
//! `[case.drum]` table.

mod measurement;
mod report;
mod run;
mod settings;
#[cfg(test)]
mod tests;

pub use measurement::{
    lacey_index, surface_angle, zone_counts, Grain, Lacey, SurfaceLine, ZoneCounts,
};
pub use report::write_drum_section;
pub use run::{measure_runs, DrumRun, FrameMeasure, SteadyMeans};
pub use settings::DrumSettings;
pub(crate) use settings::{parse_drum, RawDrum};
