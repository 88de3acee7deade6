//! The discharge rate as an accuracy quantity: a sweep with a `discharge` table (the silo)
//! measures each run as a suite case's discharge is measured (`crate::quantity::discharge`:
//! mass discharged from the particles counted out, a parcel carrying lambda^3 grains' mass;
//! the rate's block standard error; the fill's bulk density), and reports each level's mean
//! over seeds beside Beverloo's law (`quantity::discharge::write_levels_table`).

use std::path::Path;

use super::measurement::settings;
use super::AccuracyPoint;
use crate::code::Code;
use crate::quantity::discharge::{measure_one, write_levels_table, DischargeSettings, LevelRate};
use crate::quantity::seeds::mean_se;
use crate::report::Section;
use crate::runs::{RunRecord, ValidateError};
use cgdem_core::scene::Scene;

/// Measures the finished run `record` of `scene` as a discharge and writes what it measured
/// into `point`; `Err` says why it cannot be measured.
pub(crate) fn measure_discharge(
    scene: &Scene,
    discharge: &DischargeSettings,
    record: &RunRecord,
    point: &mut AccuracyPoint,
) -> Result<(), String> {
    let (run, _) = measure_one(scene, discharge, record)?;
    let (Some(rate), Some(_)) = (&run.rate, &run.series) else {
        return Err("no discharge measured".into());
    };
    point.discharge_rate_kg_s = Some(rate.rate_kg_s);
    point.discharge_rate_std_error_kg_s = Some(rate.std_error_kg_s);
    point.bulk_density_kg_m3 = run.bulk_density.map(|(rho, _)| rho);
    point.particle_diameter_m = Some(run.grain_diameter_m);
    point.flow_stopped_at_s = run.clogged_at(discharge.blocks);
    Ok(())
}

/// Each level of the sweep (cgdem's runs) with its seeds' means.
fn levels(points: &[AccuracyPoint]) -> Vec<LevelRate> {
    let all = settings(Code::Cgdem, points);
    let reference = all.iter().find(|s| s.series == "reference");
    all.iter()
        .filter_map(|s| {
            let rates: Vec<f64> = s
                .runs
                .iter()
                .filter_map(|p| p.discharge_rate_kg_s)
                .collect();
            if rates.is_empty() {
                return None;
            }
            let ratios: Vec<f64> = s
                .runs
                .iter()
                .filter_map(|p| {
                    let r = reference?.runs.iter().find(|r| r.seed == p.seed)?;
                    Some(p.discharge_rate_kg_s? / r.discharge_rate_kg_s?)
                })
                .filter(|x| x.is_finite())
                .collect();
            let rhos: Vec<f64> = s.runs.iter().filter_map(|p| p.bulk_density_kg_m3).collect();
            let (rate, rate_se) = mean_se(&rates);
            let first = s.runs[0];
            Some(LevelRate {
                setting: s.setting.to_string(),
                lambda: first.lambda,
                rule: first.cg_rule.name(),
                seeds: rates.len(),
                diameter: first.particle_diameter_m.unwrap_or(f64::NAN),
                rate,
                rate_se,
                rate_range: rates
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &r| {
                        (lo.min(r), hi.max(r))
                    }),
                ratio: (!ratios.is_empty()).then(|| mean_se(&ratios)),
                bulk_density: (!rhos.is_empty()).then(|| mean_se(&rhos).0),
                stopped: s
                    .runs
                    .iter()
                    .filter_map(|p| Some((p.seed, p.flow_stopped_at_s?)))
                    .collect(),
            })
        })
        .collect()
}

/// The discharge subsection of a sweep with a `discharge` table, from its levels' means.
pub(crate) fn write_discharge_table(
    sub: &mut Section,
    discharge: &DischargeSettings,
    points: &[AccuracyPoint],
    dir: &Path,
) -> Result<(), ValidateError> {
    write_levels_table(sub, discharge, &levels(points), dir)
}
