//! `[packing]`.

use super::super::raw::*;
use super::super::*;
use super::Checker;

/// `[packing]`: a poured bed in a box periodic in x and y with a floor below.
pub(super) fn packing(
    c: &Checker,
    pk: &RawPacking,
    stages: &[Stage],
    domain: &Domain,
    species: &[Species],
) -> Result<PackingSettings, SceneError> {
    c.one_of(
        "packing.stage",
        &pk.stage,
        "stages",
        stages.iter().map(|s| &s.name),
    )?;
    if !(domain.periodic[0] && domain.periodic[1]) || domain.periodic[2] {
        return Err(c.invalid(
            "domain.periodic",
            format!("{:?}", domain.periodic),
            "[true, true, false] with [packing] (a bed periodic in x and y on a floor)",
        ));
    }
    if species.len() != 1 {
        return Err(c.invalid(
            "species",
            format!("{} species", species.len()),
            "exactly one species with [packing] (monodisperse beds)",
        ));
    }
    let default = crate::scene::BedRegionRule::default();
    let margin = |field: &str, v: Option<f64>, default: f64| -> Result<f64, SceneError> {
        let v = v.unwrap_or(default);
        if v.is_finite() && (0.0..=50.0).contains(&v) {
            Ok(v)
        } else {
            Err(c.invalid(field, v, "0 <= margin <= 50 diameters"))
        }
    };
    let top_quantile = pk.top_quantile.unwrap_or(default.top_quantile);
    if !(top_quantile > 0.0 && top_quantile <= 1.0) {
        return Err(c.invalid(
            "packing.top_quantile",
            top_quantile,
            "0 < top_quantile <= 1",
        ));
    }
    let voxels_per_diameter = pk.voxels_per_diameter.unwrap_or(16);
    if !(2..=64).contains(&voxels_per_diameter) {
        return Err(c.invalid(
            "packing.voxels_per_diameter",
            voxels_per_diameter,
            "2 ..= 64 voxels per particle diameter",
        ));
    }
    let d = species[0].diameter;
    for axis in 0..2 {
        let cells = (domain.hi[axis] - domain.lo[axis]) / d * voxels_per_diameter as f64;
        if (cells - cells.round()).abs() > 1e-6 * cells {
            return Err(c.invalid(
                format!("domain.hi[{axis}]"),
                domain.hi[axis],
                format!("a lateral period that is a whole number of pore-size voxels (d / {voxels_per_diameter}); it is {cells:.4} voxels"),
            ));
        }
    }
    let bin_width_diameters = pk.bin_width_diameters.unwrap_or(0.1);
    if !(bin_width_diameters.is_finite()
        && bin_width_diameters * voxels_per_diameter as f64 >= 1.0 - 1e-9
        && bin_width_diameters <= 1.0)
    {
        return Err(c.invalid(
            "packing.bin_width_diameters",
            bin_width_diameters,
            format!(
                "1 / voxels_per_diameter = {:.4} ..= 1 (at least one voxel)",
                1.0 / voxels_per_diameter as f64
            ),
        ));
    }
    Ok(PackingSettings {
        stage: pk.stage.clone(),
        rule: crate::scene::BedRegionRule {
            floor_margin: margin(
                "packing.floor_margin",
                pk.floor_margin,
                default.floor_margin,
            )?,
            top_quantile,
            top_margin: margin("packing.top_margin", pk.top_margin, default.top_margin)?,
        },
        voxels_per_diameter,
        bin_width_diameters,
    })
}
