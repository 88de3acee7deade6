//! The silo discharge (issue 42, reference/silo/PLAN.md): a suite case with a `[case.discharge]`
//! table is measured as a discharge in every code alike (`measurement`: mass discharged
//! against time, its rate over the steady window with a block-average standard error, the
//! fill's bulk density, Beverloo's law) and reported per case and across orifices
//! (`report`), as the screw's cases are by `crate::screw`.

mod measurement;
mod report;
#[cfg(test)]
mod tests;
mod verdict;

pub use measurement::{
    beverloo_c, beverloo_rate, bulk_density, combined_c, data_bulk_density, discharge_rate,
    discharge_series, dump_bulk_density, fit_c_and_k, flow_stopped_at, DischargeRate,
    DischargeSeries, PUBLISHED_C, PUBLISHED_K, STANDARD_GRAVITY,
};
pub(crate) use report::measure_one;
pub use report::{measure_runs, write_silo_overview, write_silo_section, SiloRun};
pub use verdict::{cgdem_verdict, rate_criterion, RateVerdict, COMPARISON, CRITERION};

use std::path::Path;

use serde::Deserialize;

use crate::suite_entry::SuiteError;

/// How a suite case is measured as a discharge (`[case.discharge]`).
#[derive(Clone, Debug, PartialEq)]
pub struct DischargeSettings {
    /// The stage that opens the orifice; times count from its start.
    pub stage: String,
    /// The orifice's diameter D0, m (Beverloo's law).
    pub orifice_diameter_m: f64,
    /// Start-up discarded after the gate opens, s.
    pub discard_s: f64,
    /// Blocks of the window for the standard error.
    pub blocks: usize,
    /// The box whose grains give the fill's bulk density at the gate's opening, m.
    pub bulk_lo: [f64; 3],
    pub bulk_hi: [f64; 3],
}

impl From<&cgdem_core::scene::DischargeSettings> for DischargeSettings {
    /// A scene's own `[discharge]` table, checked when the scene was read.
    fn from(d: &cgdem_core::scene::DischargeSettings) -> Self {
        DischargeSettings {
            stage: d.stage.clone(),
            orifice_diameter_m: d.orifice_diameter,
            discard_s: d.discard,
            blocks: d.blocks as usize,
            bulk_lo: d.bulk_lo,
            bulk_hi: d.bulk_hi,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDischarge {
    stage: String,
    orifice_diameter: f64,
    discard: f64,
    blocks: usize,
    bulk_lo: [f64; 3],
    bulk_hi: [f64; 3],
}

/// The `discharge` table of the suite entry `entry` (`case[0]`, `accuracy[2]`), checked.
pub(crate) fn parse_discharge(
    raw: RawDischarge,
    entry: &str,
    path: &Path,
) -> Result<DischargeSettings, SuiteError> {
    let invalid = |field: &str, value: String, allowed: &str| SuiteError::Invalid {
        file: path.to_path_buf(),
        field: format!("{entry}.discharge.{field}"),
        value,
        allowed: allowed.into(),
    };
    if raw.stage.is_empty() {
        return Err(invalid(
            "stage",
            "\"\"".into(),
            "the name of the stage that opens the orifice",
        ));
    }
    if !(raw.orifice_diameter.is_finite() && raw.orifice_diameter > 0.0) {
        return Err(invalid(
            "orifice_diameter",
            raw.orifice_diameter.to_string(),
            "a diameter in m, finite and > 0",
        ));
    }
    if !(raw.discard.is_finite() && raw.discard >= 0.0) {
        return Err(invalid(
            "discard",
            raw.discard.to_string(),
            "seconds after the gate opens, finite and >= 0",
        ));
    }
    if raw.blocks < 2 {
        return Err(invalid(
            "blocks",
            raw.blocks.to_string(),
            "at least 2 (their spread gives the standard error)",
        ));
    }
    if (0..3).any(|i| !(raw.bulk_lo[i].is_finite() && raw.bulk_hi[i] > raw.bulk_lo[i])) {
        return Err(invalid(
            "bulk_hi",
            format!("{:?} (bulk_lo {:?})", raw.bulk_hi, raw.bulk_lo),
            "a box corner above bulk_lo along x, y and z",
        ));
    }
    Ok(DischargeSettings {
        stage: raw.stage,
        orifice_diameter_m: raw.orifice_diameter,
        discard_s: raw.discard,
        blocks: raw.blocks,
        bulk_lo: raw.bulk_lo,
        bulk_hi: raw.bulk_hi,
    })
}
