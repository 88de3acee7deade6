//! How a discharge is measured (`DischargeSettings`): from a suite's `[case.discharge]` or
//! `[accuracy.discharge]` table, from a scene's own `[discharge]` table, or, for a scene
//! whose grains leave through `[[delete]]` and that says nothing, by default; and the
//! narrowest opening the grains leave through (Beverloo's D0, and the coarsest level a
//! default matrix keeps).

use std::path::Path;

use serde::Deserialize;

use crate::suite_entry::SuiteError;
use cgdem_core::scene::{MeshSource, Scene, StageEnd};

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

/// The narrowest opening the grains leave through, and where its width comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct Opening {
    pub diameter_m: f64,
    pub source: String,
}

/// How a scene's discharge is measured: as its `[discharge]` table says, else grains of its one species deleted by `[[delete]]`
/// (no screw), counted from the first stage that removes a wall (the gate; else the last
/// stage), its first quarter discarded as start-up, the rest in 5 blocks; the fill's bulk
/// density over its first insertion's box.
pub fn discharge_settings(scene: &Scene, opening: Option<&Opening>) -> Option<DischargeSettings> {
    // The scene's own `[discharge]` table says how, when it has one.
    if let Some(own) = &scene.discharge {
        return Some(own.into());
    }
    if scene.deletions.is_empty() || scene.conveying.is_some() || scene.species.len() != 1 {
        return None;
    }
    let stage = scene
        .stages
        .iter()
        .find(|s| !s.remove_walls.is_empty())
        .or(scene.stages.last())?;
    let duration = match stage.end {
        StageEnd::Duration(d) => d,
        StageEnd::Settled { max_duration, .. } => max_duration,
    };
    let fill = scene.insertions.first()?;
    Some(DischargeSettings {
        stage: stage.name.clone(),
        // Only Beverloo's column of the report uses it; without an opening it says nothing.
        orifice_diameter_m: opening.map_or(f64::NAN, |o| o.diameter_m),
        discard_s: 0.25 * duration,
        blocks: 5,
        bulk_lo: fill.lo.to_array(),
        bulk_hi: fill.hi.to_array(),
    })
}

/// The narrowest opening of a scene whose grains leave through `[[delete]]`: its
/// `[discharge]` table's `orifice_diameter`, a built-in
/// silo's orifice, or for a mesh body that does not move, twice the smallest distance of its
/// vertices from its vertical axis (the line along gravity through the centre of its
/// bounding box): the rim of a hopper's orifice.
pub fn opening(scene: &Scene) -> Option<Opening> {
    if let Some(own) = &scene.discharge {
        return Some(Opening {
            diameter_m: own.orifice_diameter,
            source: "the scene's [discharge] orifice_diameter".into(),
        });
    }
    if scene.deletions.is_empty() || scene.conveying.is_some() {
        return None;
    }
    let down = scene.gravity.normalize_or_zero();
    for body in &scene.bodies {
        match &body.mesh {
            MeshSource::Silo(_, spec) => {
                return Some(Opening {
                    diameter_m: spec.orifice_diameter,
                    source: format!("body `{}`: the silo's orifice_diameter", body.name),
                })
            }
            MeshSource::Stl(path) if body.rpm == 0.0 && body.velocity.length() == 0.0 => {
                if down == cgdem_core::math::Vec3::ZERO {
                    continue;
                }
                let Ok(mesh) = body.load_mesh() else { continue };
                let b = mesh.bounding_box();
                let centre = 0.5 * (b.min + b.max);
                let radius = mesh
                    .vertices
                    .iter()
                    .map(|v| {
                        let r = *v - centre;
                        (r - r.dot(down) * down).length()
                    })
                    .fold(f64::INFINITY, f64::min);
                if radius.is_finite() && radius > 0.0 {
                    return Some(Opening {
                        diameter_m: 2.0 * radius,
                        source: format!(
                            "body `{}` ({}): twice its vertices' smallest distance from its vertical axis",
                            body.name,
                            path.display()
                        ),
                    });
                }
            }
            _ => {}
        }
    }
    None
}
