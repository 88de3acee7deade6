//! What every kind of suite entry (`[[case]]`, `[[accuracy]]`, `[[stability]]`) is read
//! with: its `codes`, its `set` overrides with their `variant` name, its scene, and the
//! suite file's errors. A leaf module, so that the entries' own modules need not import the
//! suite that lists them.

use std::path::{Path, PathBuf};

use crate::code::Code;
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::{Override, Scene, SceneError};

/// The scene of a suite entry: its file with the overrides applied, named after the
/// variant (`aor_collapse-smooth-walls`) when there is one.
pub(crate) fn load_variant(
    file: &Path,
    overrides: &[Override],
    variant: Option<&str>,
) -> Result<Scene, SceneError> {
    let mut scene = Scene::load_with_overrides(file, overrides)?;
    if let Some(v) = variant {
        scene.name = format!("{}-{v}", scene.name);
    }
    Ok(scene)
}

/// A path a suite file names (a case's scene, a known difference's evidence), taken relative
/// to the suite file's own directory, as LAMMPS users expect of files named in an input, so a
/// suite runs from any working directory. `.` and `..` are folded away without touching the
/// disk, so the repository's suites name their scenes as `validation/cases/...` in reports.
pub(crate) fn beside_suite(suite: &Path, named: &Path) -> PathBuf {
    use std::path::Component;
    let joined = suite.parent().unwrap_or(Path::new("")).join(named);
    let mut out = PathBuf::new();
    for part in joined.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir
                if matches!(out.components().next_back(), Some(Component::Normal(_))) =>
            {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// A suite entry's `set` overrides, checked with its `variant` name: a name of letters,
/// digits, `-` and `_`, required when `set` changes the scene. `entry` names the entry in
/// messages (`case[2]`).
pub(crate) fn parse_variant(
    set: &[String],
    variant: Option<&str>,
    entry: &str,
    path: &Path,
) -> Result<Vec<Override>, SuiteError> {
    let invalid = |field: &str, value: String, allowed: String| SuiteError::Invalid {
        file: path.to_path_buf(),
        field: format!("{entry}.{field}"),
        value,
        allowed,
    };
    let overrides = set
        .iter()
        .map(|o| Override::parse(o, path))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| invalid("set", format!("{set:?}"), e.to_string()))?;
    let name_ok = |v: &str| {
        !v.is_empty()
            && v.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    };
    match variant {
        Some(v) if !name_ok(v) => Err(invalid(
            "variant",
            format!("\"{v}\""),
            "a name of letters, digits, `-` and `_`".into(),
        )),
        None if !overrides.is_empty() => Err(invalid(
            "variant",
            "(missing)".into(),
            "a name for the variant that `set` makes, e.g. variant = \"smooth-walls\"".into(),
        )),
        _ => Ok(overrides),
    }
}

/// A suite entry's `codes`, by name; `field` names the list in messages.
pub(crate) fn parse_codes(
    names: &[String],
    field: &str,
    path: &Path,
) -> Result<Vec<Code>, SuiteError> {
    names
        .iter()
        .map(|name| {
            Code::from_name(name).ok_or_else(|| SuiteError::Invalid {
                file: path.to_path_buf(),
                field: field.into(),
                value: format!("\"{name}\""),
                allowed: "\"cgdem\", \"lammps\" or \"liggghts\"".into(),
            })
        })
        .collect()
}

#[derive(Debug, thiserror::Error)]
pub enum SuiteError {
    #[error("{file}: cannot read the suite file: {source}")]
    Unreadable {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{file}: not a valid suite file: {message}")]
    Syntax { file: PathBuf, message: String },
    #[error("{file}: field `{field}` = {value} is not allowed: {allowed}")]
    Invalid {
        file: PathBuf,
        field: String,
        value: String,
        allowed: String,
    },
}

/// The coarse-graining rules' names, as an error's "allowed" text.
pub(crate) fn rule_names() -> String {
    CoarseGrainRule::ALL
        .iter()
        .map(|r| format!("\"{}\"", r.name()))
        .collect::<Vec<_>>()
        .join(" or ")
}
