//! Scene overrides, `KEY=VALUE` with a dotted key (`wall_contact.friction=0.0`,
//! `wall[2].point=[0.1, 0.0, 0.0]`): a variant of a case without a second copy of its
//! parameters, as LAMMPS's `-var` or LIGGGHTS's `-var` do for their inputs. The value is TOML
//! (strings quoted); the overridden text goes through the same validation as the file.

use std::path::Path;

use super::SceneError;

/// One `KEY=VALUE` override.
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// The key as written, for messages and provenance.
    pub key: String,
    path: Vec<KeyPart>,
    value: toml::Value,
}

#[derive(Clone, Debug, PartialEq)]
enum KeyPart {
    Field(String),
    /// `name[k]`: the k-th (0-based) entry of an array of tables or values.
    Element(String, usize),
}

impl Override {
    /// Parses `KEY=VALUE`; `origin` names where it came from (for messages).
    pub fn parse(text: &str, origin: &Path) -> Result<Override, SceneError> {
        let invalid = |value: &str, allowed: &str| SceneError::Invalid {
            file: origin.to_path_buf(),
            field: "set".into(),
            value: format!("\"{value}\""),
            allowed: allowed.into(),
        };
        let (key, value) = text
            .split_once('=')
            .ok_or_else(|| invalid(text, "KEY=VALUE, e.g. wall_contact.friction=0.0"))?;
        let key = key.trim();
        let path = key
            .split('.')
            .map(|part| {
                parse_key_part(part).ok_or_else(|| {
                    invalid(
                        text,
                        "a dotted key of names, each optionally indexed, e.g. wall[2].point",
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let value: toml::Value = toml::from_str::<toml::Table>(&format!("v = {}", value.trim()))
            .ok()
            .and_then(|mut t| t.remove("v"))
            .ok_or_else(|| {
                invalid(
                    text,
                    "a TOML value after `=` (numbers, [arrays], \"quoted strings\", true/false)",
                )
            })?;
        Ok(Override {
            key: key.to_string(),
            path,
            value,
        })
    }

    /// Sets the value in `doc`; the tables and array entries on the way must exist (so a
    /// misspelt section is an error here, and a misspelt leaf is one in validation).
    fn apply(&self, doc: &mut toml::Table, file: &Path) -> Result<(), SceneError> {
        let missing = |what: String| SceneError::Invalid {
            file: file.to_path_buf(),
            field: self.key.clone(),
            value: self.value.to_string(),
            allowed: format!("an override of a field the scene has: {what}"),
        };
        let (last, parents) = self
            .path
            .split_last()
            .expect("parse makes one part at least");
        let mut table = doc;
        for part in parents {
            let next = match part {
                KeyPart::Field(name) => table.get_mut(name),
                KeyPart::Element(name, k) => table
                    .get_mut(name)
                    .and_then(|v| v.as_array_mut())
                    .and_then(|a| a.get_mut(*k)),
            };
            table = next
                .and_then(|v| v.as_table_mut())
                .ok_or_else(|| missing(format!("no table `{}`", part.text())))?;
        }
        match last {
            KeyPart::Field(name) => {
                table.insert(name.clone(), self.value.clone());
            }
            KeyPart::Element(name, k) => {
                let slot = table
                    .get_mut(name)
                    .and_then(|v| v.as_array_mut())
                    .and_then(|a| a.get_mut(*k))
                    .ok_or_else(|| missing(format!("no entry `{}`", last.text())))?;
                *slot = self.value.clone();
            }
        }
        Ok(())
    }
}

impl KeyPart {
    fn text(&self) -> String {
        match self {
            KeyPart::Field(name) => name.clone(),
            KeyPart::Element(name, k) => format!("{name}[{k}]"),
        }
    }
}

fn parse_key_part(part: &str) -> Option<KeyPart> {
    let is_name =
        |s: &str| !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    match part.split_once('[') {
        None => is_name(part).then(|| KeyPart::Field(part.to_string())),
        Some((name, rest)) => {
            let index = rest.strip_suffix(']')?.parse().ok()?;
            is_name(name).then(|| KeyPart::Element(name.to_string(), index))
        }
    }
}

/// Applies `overrides` in order to the scene text read from `file`.
pub fn apply_overrides(
    text: &str,
    file: &Path,
    overrides: &[Override],
) -> Result<String, SceneError> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc: toml::Table = toml::from_str(text).map_err(|e| SceneError::Syntax {
        file: file.to_path_buf(),
        message: e.to_string().trim_end().replace('\n', "\n  "),
    })?;
    for o in overrides {
        o.apply(&mut doc, file)?;
    }
    Ok(toml::to_string(&doc).expect("a parsed TOML table serializes"))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "[wall_contact]\nfriction = 0.4\n[[wall]]\nname = \"a\"\n[[wall]]\nname = \"b\"\npoint = [0.0, 0.0, 0.0]\n";

    fn set(text: &str) -> Result<toml::Table, SceneError> {
        let o = Override::parse(text, Path::new("cli"))?;
        let out = apply_overrides(SCENE, Path::new("s.toml"), &[o])?;
        Ok(toml::from_str(&out).unwrap())
    }

    #[test]
    fn sets_a_field_and_an_array_entry() {
        let t = set("wall_contact.friction = 0.0").unwrap();
        assert_eq!(t["wall_contact"]["friction"].as_float(), Some(0.0));
        let t = set("wall[1].point=[0.1, 0.0, 0.0]").unwrap();
        assert_eq!(t["wall"][1]["point"][0].as_float(), Some(0.1));
        assert_eq!(t["wall"][0]["name"].as_str(), Some("a"));
    }

    #[test]
    fn refuses_missing_tables_and_bad_syntax_with_the_key() {
        let e = set("wall_contakt.friction=0.0").unwrap_err().to_string();
        assert!(
            e.contains("wall_contakt.friction") && e.contains("no table `wall_contakt`"),
            "{e}"
        );
        let e = set("wall[5].point=[0.0, 0.0, 0.0]")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no table `wall[5]`"), "{e}");
        for bad in [
            "friction",
            "wall_contact.friction=",
            "a..b=1",
            "x=unquoted words",
        ] {
            let e = set(bad).unwrap_err().to_string();
            assert!(e.contains("`set`"), "{bad}: {e}");
        }
    }
}
