//! The output format every code's run goes through: what cgdem writes from its own state,
//! and what the harness writes from a LAMMPS or LIGGGHTS dump, in the same files and by the
//! same rules, so that the runs compare column by column.
//!
//! - `summary.json`: [`RunSummary`], its stages ([`StageRecord`], how each ended in words,
//!   [`StageEnding`]) and its repose samples;
//! - `timeseries.csv`: [`TIMESERIES_COLUMNS`] first; gravitational energy is counted from
//!   [`potential_origin`];
//! - `profile.csv` and `repose.csv`: the heap surface of a `[repose]` scene
//!   ([`heap_profile`]) and the angle measured on it by the scene's rule
//!   ([`ReposeSample::measure`]).
//!
//! Below `run` (which writes cgdem's outputs) and above `analysis` (the measurements).

mod repose;
mod summary;

pub use crate::domain::potential_origin;
pub use repose::{
    headline_sample, heap_profile, profile_csv, repose_csv, ReposeSample, SampleTrigger,
};
pub use summary::{RunSummary, StageEnding, StageRecord};

/// The first columns of `timeseries.csv`, as cgdem and the reference post-processing write
/// them.
pub const TIMESERIES_COLUMNS: [&str; 7] = [
    "time_s",
    "stage",
    "kinetic_energy_j",
    "kinetic_energy_per_mass_j_kg",
    "n_particles",
    "front_m",
    "wall_height_m",
];
