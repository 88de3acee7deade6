//! A `[[chung_ooi]]` entry of a suite file: a contact law the benchmark is run under, as
//! scene overrides, and, for a law known to fail some criteria, the reason.

use std::path::Path;

use serde::Deserialize;

use crate::suite_entry::SuiteError;
use cgdem_core::scene::Override;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawChungOoiLaw {
    law: String,
    #[serde(default)]
    set: Vec<String>,
    known_difference: Option<String>,
}

/// A law the benchmark runs under: `set` applied to every test's scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ChungOoiLaw {
    pub name: String,
    pub set: Vec<String>,
    pub overrides: Vec<Override>,
    /// Why this law fails some criteria: its failing criteria are amber, not red.
    pub known_difference: Option<String>,
}

pub(crate) fn parse_laws(
    raw: Vec<RawChungOoiLaw>,
    path: &Path,
) -> Result<Vec<ChungOoiLaw>, SuiteError> {
    let invalid = |field: String, value: String, allowed: &str| SuiteError::Invalid {
        file: path.to_path_buf(),
        field,
        value,
        allowed: allowed.into(),
    };
    let mut out: Vec<ChungOoiLaw> = Vec::new();
    for (k, r) in raw.into_iter().enumerate() {
        let name_ok = !r.law.is_empty()
            && r.law
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
        if !name_ok || out.iter().any(|l| l.name == r.law) {
            return Err(invalid(
                format!("chung_ooi[{k}].law"),
                format!("\"{}\"", r.law),
                "a unique name of letters, digits, '-' and '_'",
            ));
        }
        if r.known_difference
            .as_deref()
            .is_some_and(|s| s.trim().is_empty())
        {
            return Err(invalid(
                format!("chung_ooi[{k}].known_difference"),
                "\"\"".into(),
                "why the law fails some criteria, in words",
            ));
        }
        let overrides = r
            .set
            .iter()
            .map(|s| {
                Override::parse(s, path).map_err(|_| {
                    invalid(
                        format!("chung_ooi[{k}].set"),
                        format!("\"{s}\""),
                        "KEY=VALUE scene overrides, e.g. contact.limit_force=true",
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        out.push(ChungOoiLaw {
            name: r.law,
            set: r.set,
            overrides,
            known_difference: r.known_difference,
        });
    }
    Ok(out)
}
