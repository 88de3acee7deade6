//! `[[stage]]`, `[output]`, `[repose]` and `[discharge]`.

use super::super::raw::*;
use super::super::*;
use super::{names, Checker};

/// `[[stage]]`: at least one, names unique; each ends after a duration or once the bed has
/// settled.
pub(super) fn stages(
    c: &Checker,
    raw: &[RawStage],
    walls: &[WallSettings],
) -> Result<Vec<Stage>, SceneError> {
    if raw.is_empty() {
        return Err(c.invalid("stage", "none", "at least one [[stage]]"));
    }
    let mut stages = Vec::new();
    for (k, s) in raw.iter().enumerate() {
        // Measurements and outputs name a stage: two of one name would be measured twice.
        if stages.iter().any(|x: &Stage| x.name == s.name) {
            return Err(c.invalid(
                format!("stage[{k}].name"),
                &s.name,
                "a name not used by another stage",
            ));
        }
        for name in &s.remove_walls {
            c.one_of(
                format!("stage[{k}].remove_walls"),
                name,
                "walls",
                walls.iter().map(|w| &w.name),
            )?;
        }
        stages.push(Stage {
            name: s.name.clone(),
            remove_walls: s.remove_walls.clone(),
            end: stage_end(c, k, s)?,
        });
    }
    Ok(stages)
}

fn stage_end(c: &Checker, k: usize, s: &RawStage) -> Result<StageEnd, SceneError> {
    match (s.duration, s.until_kinetic_energy_per_mass_below, s.max_duration) {
        (Some(d), None, None) if s.min_duration.is_none() => Ok(StageEnd::Duration(c.positive(&format!("stage[{k}].duration"), d)?)),
        (None, Some(threshold), Some(max)) => {
            let min = c.non_negative(&format!("stage[{k}].min_duration"), s.min_duration.unwrap_or(0.0))?;
            let max = c.positive(&format!("stage[{k}].max_duration"), max)?;
            if min > max {
                return Err(c.invalid(format!("stage[{k}].min_duration"), min, format!("at most max_duration = {max} s")));
            }
            Ok(StageEnd::Settled {
                kinetic_energy_per_mass: c.positive(&format!("stage[{k}].until_kinetic_energy_per_mass_below"), threshold)?,
                min_duration: min,
                max_duration: max,
            })
        }
        _ => Err(c.invalid(format!("stage[{k}]"), &s.name, "either duration alone, or until_kinetic_energy_per_mass_below (J/kg) with max_duration (and optionally min_duration)")),
    }
}

/// `[output]`: VTK (0 = none) and time-series intervals, s.
pub(super) fn output(
    c: &Checker,
    output: Option<&RawOutput>,
    stages: &[Stage],
) -> Result<OutputSettings, SceneError> {
    let vtk_interval = c.non_negative(
        "output.vtk_interval",
        output.and_then(|o| o.vtk_interval).unwrap_or(0.0),
    )?;
    let timeseries_interval = c.positive(
        "output.timeseries_interval",
        output.and_then(|o| o.timeseries_interval).unwrap_or(0.01),
    )?;
    let data_at_stage_ends = output.map_or(Vec::new(), |o| o.data_at_stage_ends.clone());
    for (k, name) in data_at_stage_ends.iter().enumerate() {
        c.one_of(
            format!("output.data_at_stage_ends[{k}]"),
            name,
            "stages",
            stages.iter().map(|s| &s.name),
        )?;
    }
    Ok(OutputSettings {
        vtk_interval,
        vtk_contact_network: output.and_then(|o| o.vtk_contact_network).unwrap_or(false),
        write_data: output.and_then(|o| o.write_data).unwrap_or(false),
        data_at_stage_ends,
        timeseries_interval,
    })
}

/// `[repose]`: when, during which stage, the angle of repose is measured.
pub(super) fn repose(
    c: &Checker,
    r: &RawRepose,
    stages: &[Stage],
) -> Result<ReposeSettings, SceneError> {
    let stage = stages.iter().find(|s| s.name == r.stage).ok_or_else(|| {
        c.invalid(
            "repose.stage",
            &r.stage,
            format!(
                "one of the stages: {}",
                names(stages.iter().map(|s| &s.name))
            ),
        )
    })?;
    if r.at_times.windows(2).any(|w| w[1] <= w[0]) || r.at_times.first().is_some_and(|&t| t <= 0.0)
    {
        return Err(c.invalid(
            "repose.at_times",
            format!("{:?}", r.at_times),
            "increasing times > 0 s after the stage starts",
        ));
    }
    if r.at_times.is_empty() && !r.at_stage_end {
        return Err(c.invalid(
            "repose",
            "no measurement time",
            "at_times, or at_stage_end = true, or both",
        ));
    }
    if let StageEnd::Duration(d) = stage.end {
        let last = *r.at_times.last().unwrap_or(&0.0);
        if last > d {
            return Err(c.invalid(
                "repose.at_times",
                last,
                format!("times within the stage `{}`, which lasts {d} s", stage.name),
            ));
        }
    }
    let fraction = |field: &str, v: Option<f64>, default: f64| -> Result<f64, SceneError> {
        let v = v.unwrap_or(default);
        if (0.0..0.5).contains(&v) {
            Ok(v)
        } else {
            Err(c.invalid(field, v, "0 <= fraction < 0.5 of the run-out"))
        }
    };
    Ok(ReposeSettings {
        stage: r.stage.clone(),
        wall_x: r.wall_x,
        at_times: r.at_times.clone(),
        at_stage_end: r.at_stage_end,
        bin_width_diameters: c.positive(
            "repose.bin_width_diameters",
            r.bin_width_diameters.unwrap_or(1.0),
        )?,
        exclude_wall_fraction: fraction(
            "repose.exclude_wall_fraction",
            r.exclude_wall_fraction,
            0.15,
        )?,
        exclude_toe_fraction: fraction(
            "repose.exclude_toe_fraction",
            r.exclude_toe_fraction,
            0.15,
        )?,
    })
}

/// `[discharge]`: its stage, orifice, window and bulk-density box; the discharged mass is
/// what the `[[delete]]` boxes remove, so there must be one.
pub(super) fn discharge(
    c: &Checker,
    d: &RawDischarge,
    stages: &[Stage],
    deletions: &[(Vec3, Vec3)],
) -> Result<DischargeSettings, SceneError> {
    c.one_of(
        "discharge.stage",
        &d.stage,
        "stages",
        stages.iter().map(|s| &s.name),
    )?;
    if deletions.is_empty() {
        return Err(c.invalid(
            "delete",
            "(none)",
            "at least one [[delete]] box with [discharge]: the discharged mass is what they remove",
        ));
    }
    if !(d.orifice_diameter.is_finite() && d.orifice_diameter > 0.0) {
        return Err(c.invalid(
            "discharge.orifice_diameter",
            d.orifice_diameter,
            "a diameter in m, > 0",
        ));
    }
    let stage = stages.iter().find(|s| s.name == d.stage).expect("checked");
    let longest = match stage.end {
        StageEnd::Duration(t) => t,
        StageEnd::Settled { max_duration, .. } => max_duration,
    };
    if !(d.discard.is_finite() && d.discard >= 0.0 && d.discard < longest) {
        return Err(c.invalid(
            "discharge.discard",
            d.discard,
            format!("seconds >= 0 and shorter than the stage ({longest} s)"),
        ));
    }
    let blocks = d.blocks.unwrap_or(5);
    if blocks < 2 {
        return Err(c.invalid("discharge.blocks", blocks, "an integer, at least 2"));
    }
    if (0..3).any(|i| {
        !(d.bulk_lo[i].is_finite() && d.bulk_hi[i].is_finite() && d.bulk_hi[i] > d.bulk_lo[i])
    }) {
        return Err(c.invalid(
            "discharge.bulk_hi",
            format!("{:?} (bulk_lo {:?})", d.bulk_hi, d.bulk_lo),
            "a box corner above bulk_lo along x, y and z, in m",
        ));
    }
    Ok(DischargeSettings {
        stage: d.stage.clone(),
        orifice_diameter: d.orifice_diameter,
        discard: d.discard,
        blocks,
        bulk_lo: d.bulk_lo,
        bulk_hi: d.bulk_hi,
    })
}
