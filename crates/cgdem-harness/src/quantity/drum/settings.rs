//! How a drum case is measured (`DrumSettings`), from a suite's `[case.drum]` table.

use std::path::Path;

use serde::Deserialize;

use crate::suite_entry::SuiteError;

/// How a suite case is measured as a rotating drum (`drum = { stage, steady_from }`).
#[derive(Clone, Debug, PartialEq)]
pub struct DrumSettings {
    /// The stage in which the drum turns; the frames before it (the settle) are shown, and
    /// times count from its start.
    pub stage: String,
    /// Start of the steady part, s after the stage starts: the frames from it on give each
    /// run's means.
    pub steady_from_s: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDrum {
    stage: String,
    steady_from: f64,
}

/// The `drum` table of the suite entry `entry` (`case[0]`), checked.
pub(crate) fn parse_drum(
    raw: RawDrum,
    entry: &str,
    path: &Path,
) -> Result<DrumSettings, SuiteError> {
    let invalid = |field: &str, value: String, allowed: &str| SuiteError::Invalid {
        file: path.to_path_buf(),
        field: format!("{entry}.drum.{field}"),
        value,
        allowed: allowed.into(),
    };
    if raw.stage.is_empty() {
        return Err(invalid(
            "stage",
            "\"\"".into(),
            "the name of the stage in which the drum turns",
        ));
    }
    if !(raw.steady_from.is_finite() && raw.steady_from >= 0.0) {
        return Err(invalid(
            "steady_from",
            raw.steady_from.to_string(),
            "seconds after the stage starts, finite and >= 0",
        ));
    }
    Ok(DrumSettings {
        stage: raw.stage,
        steady_from_s: raw.steady_from,
    })
}
