//! How a drum case is measured (`DrumSettings`), from a suite's `[case.drum]` table.

use std::path::Path;

use serde::Deserialize;

use crate::suite_entry::SuiteError;

/// How a suite case is measured as a rotating drum (`drum = { stage, steady_from,
/// count_tolerance, angle_tolerance }`) and cgdem judged against the reference codes.
#[derive(Clone, Debug, PartialEq)]
pub struct DrumSettings {
    /// The stage in which the drum turns; the frames before it (the settle) are shown, and
    /// times count from its start.
    pub stage: String,
    /// Start of the steady part, s after the stage starts: the frames from it on give each
    /// run's means.
    pub steady_from_s: f64,
    /// The physical part of the verdict's band on a zone count, as a share of the reference
    /// codes' mean count (the seeds' noise is added to it).
    pub count_tolerance: f64,
    /// The physical part of the verdict's band on the dynamic angle, deg.
    pub angle_tolerance_deg: f64,
}

/// The default tolerances. On the reduced drum (three seeds per code) the seeds' means of a
/// zone count are a few tenths of a percent apart, while the two reference codes differ from
/// each other by up to 5% (LAMMPS's smooth cylinder against LIGGGHTS's mesh: zone 2 M1, 1431
/// against 1363) and by 0.2 degrees on the angle; with one reference code the seeds' noise
/// alone would turn such a difference red (reports/drum/NOTE.md).
pub const DEFAULT_COUNT_TOLERANCE: f64 = 0.03;
pub const DEFAULT_ANGLE_TOLERANCE_DEG: f64 = 1.0;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDrum {
    stage: String,
    steady_from: f64,
    count_tolerance: Option<f64>,
    angle_tolerance: Option<f64>,
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
    let tolerance = |field: &str, value: Option<f64>, default: f64, allowed: &str| {
        let v = value.unwrap_or(default);
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(invalid(field, v.to_string(), allowed))
        }
    };
    Ok(DrumSettings {
        stage: raw.stage,
        steady_from_s: raw.steady_from,
        count_tolerance: tolerance(
            "count_tolerance",
            raw.count_tolerance,
            DEFAULT_COUNT_TOLERANCE,
            "a share of the reference count, finite and >= 0",
        )?,
        angle_tolerance_deg: tolerance(
            "angle_tolerance",
            raw.angle_tolerance,
            DEFAULT_ANGLE_TOLERANCE_DEG,
            "degrees, finite and >= 0",
        )?,
    })
}
