//! A `[[stability]]` entry of a suite file: the scene, the codes that try it, and what it
//! is judged by.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::code::Code;
use crate::suite_entry::{load_variant, parse_codes, parse_variant, SuiteError};
use cgdem_core::scene::{Override, Scene, SceneError};

/// One `[[stability]]` entry of a suite file, as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawStabilityCase {
    file: PathBuf,
    #[serde(default)]
    codes: Vec<String>,
    lambda: Option<u32>,
    #[serde(default)]
    force_dt: bool,
    energy_tolerance: Option<f64>,
    #[serde(default)]
    conserves_energy: bool,
    energy_not_judged: Option<String>,
    max_overlap: Option<f64>,
    #[serde(default)]
    set: Vec<String>,
    variant: Option<String>,
}

/// A stability case: a scene, the codes that try it, and what it is judged by.
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityCase {
    pub file: PathBuf,
    /// The codes that try it (default all three; a code whose deck cannot express the scene
    /// is recorded "not applicable" with the reason).
    pub codes: Vec<Code>,
    pub lambda: u32,
    /// Run above the stable time-step limit (`--force-dt`), in every code.
    pub force_dt: bool,
    /// Largest rise of kinetic + gravitational energy over what the start held, as a fraction
    /// of `max(E0 + U0, total mass * 1e-3 J/kg)`.
    pub energy_tolerance: f64,
    /// No dissipation at all (restitution 1, no friction): the end energy must also be
    /// within the tolerance of the start (drift), not only below it.
    pub conserves_energy: bool,
    /// Why the energy is not judged (work done by a body, binding energy of attraction).
    pub energy_not_judged: Option<String>,
    /// Largest overlap, as a fraction of the smaller radius (pairs) or the radius (walls).
    pub max_overlap: f64,
    pub overrides: Vec<Override>,
    /// The overrides as written (`KEY = VALUE`), for the report.
    pub set: Vec<String>,
    pub variant: Option<String>,
}

impl StabilityCase {
    pub fn load_scene(&self) -> Result<Scene, SceneError> {
        load_variant(&self.file, &self.overrides, self.variant.as_deref())
    }
}

pub(crate) fn parse_cases(
    raw: Vec<RawStabilityCase>,
    path: &Path,
) -> Result<Vec<StabilityCase>, SuiteError> {
    let invalid = |field: String, value: String, allowed: &str| SuiteError::Invalid {
        file: path.to_path_buf(),
        field,
        value,
        allowed: allowed.into(),
    };
    let mut out = Vec::new();
    for (k, c) in raw.into_iter().enumerate() {
        let codes = if c.codes.is_empty() {
            vec![Code::Cgdem, Code::Lammps, Code::Liggghts]
        } else {
            parse_codes(&c.codes, &format!("stability[{k}].codes"), path)?
        };
        let lambda = c.lambda.unwrap_or(1);
        if !lambda.is_power_of_two() {
            return Err(invalid(
                format!("stability[{k}].lambda"),
                lambda.to_string(),
                "a power of two",
            ));
        }
        let fraction = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(invalid(
                    format!("stability[{k}].{field}"),
                    v.to_string(),
                    "a fraction > 0",
                ))
            }
        };
        let energy_tolerance = fraction("energy_tolerance", c.energy_tolerance.unwrap_or(0.05))?;
        let max_overlap = fraction("max_overlap", c.max_overlap.unwrap_or(0.25))?;
        let overrides = parse_variant(
            &c.set,
            c.variant.as_deref(),
            &format!("stability[{k}]"),
            path,
        )?;
        out.push(StabilityCase {
            file: crate::suite_entry::beside_suite(path, &c.file),
            codes,
            lambda,
            force_dt: c.force_dt,
            energy_tolerance,
            conserves_energy: c.conserves_energy,
            energy_not_judged: c.energy_not_judged,
            max_overlap,
            overrides,
            set: c.set,
            variant: c.variant,
        });
    }
    Ok(out)
}
