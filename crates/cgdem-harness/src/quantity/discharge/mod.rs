//! The discharge rate of a silo or hopper (reference/silo/PLAN.md), measured in every code
//! alike: the mass discharged against time from the grains counted out of the scene, its
//! rate over the steady window with a block-average standard error, the fill's bulk
//! density and Beverloo's law (`measurement`); cgdem's rate judged against the reference
//! codes' spread (`verdict`); the case's section and the overview across orifices
//! (`report`); the rate per coarse-graining level beside Beverloo's law for an accuracy
//! sweep (`levels`). How a run is measured (`settings`) comes from a suite's table, a
//! scene's `[discharge]` table or the scene's `[[delete]]` boxes.

mod levels;
mod measurement;
mod report;
mod run;
mod settings;
#[cfg(test)]
mod tests;
mod verdict;

pub use levels::{write_levels_table, LevelRate};
pub use measurement::{
    beverloo_c, beverloo_rate, bulk_density, combined_c, data_bulk_density, discharge_rate,
    discharge_series, dump_bulk_density, fit_c_and_k, flow_stopped_at, DischargeRate,
    DischargeSeries, PUBLISHED_C, PUBLISHED_K, STANDARD_GRAVITY,
};
pub use report::{write_silo_overview, write_silo_section};
pub(crate) use run::measure_one;
pub use run::{measure_runs, SiloRun};
pub use settings::{discharge_settings, opening, DischargeSettings, Opening};
pub(crate) use settings::{parse_discharge, RawDischarge};
pub use verdict::{cgdem_verdict, rate_criterion, RateVerdict, COMPARISON, CRITERION};
