//! The discharge rate as an accuracy quantity: a sweep with a `discharge` table (the silo)
//! measures each run as `crate::silo` measures a suite case (mass discharged from the
//! particles counted out, a parcel carrying lambda^3 grains' mass; the rate's block standard
//! error; the fill's bulk density), and reports each level's rate beside Beverloo's law
//! evaluated with the parcel's diameter and with the fine reference's.

use std::path::Path;

use super::measurement::settings;
use super::AccuracyPoint;
use crate::code::Code;
use crate::report::{Cell, Section, Table};
use crate::runs::{output_error, RunRecord, ValidateError};
use crate::silo::{
    beverloo_rate, flow_stopped_at, measure_one, DischargeSettings, PUBLISHED_K, STANDARD_GRAVITY,
};
use cgdem_core::io::{write_atomic, CsvBuffer};
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
    let (Some(rate), Some(series)) = (&run.rate, &run.series) else {
        return Err("no discharge measured".into());
    };
    // Two blocks without a grain out: the flow stopped (a clog), not a gap between grains.
    let block = (rate.window_s[1] - rate.window_s[0]) / discharge.blocks as f64;
    point.discharge_rate_kg_s = Some(rate.rate_kg_s);
    point.discharge_rate_std_error_kg_s = Some(rate.std_error_kg_s);
    point.bulk_density_kg_m3 = run.bulk_density.map(|(rho, _)| rho);
    point.particle_diameter_m = Some(run.grain_diameter_m);
    point.flow_stopped_at_s = flow_stopped_at(series, 2.0 * block);
    Ok(())
}

/// One level of the sweep (cgdem's runs), its seeds' means.
struct Level {
    setting: String,
    lambda: u32,
    rule: &'static str,
    seeds: usize,
    diameter: f64,
    rate: f64,
    rate_se: Option<f64>,
    rate_range: (f64, f64),
    /// Mean over seeds of W / W of the reference run with the same seed, with its SE.
    ratio: Option<(f64, Option<f64>)>,
    bulk_density: Option<f64>,
    stopped: Vec<(u64, f64)>,
}

/// Mean and standard error of the mean (None for one value).
fn mean_se(v: &[f64]) -> (f64, Option<f64>) {
    let (mean, sd, n) = crate::verdict::mean_sd(v).unwrap_or((f64::NAN, 0.0, 0));
    (mean, (n > 1).then(|| sd / (n as f64).sqrt()))
}

fn levels(points: &[AccuracyPoint]) -> Vec<Level> {
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
            Some(Level {
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

/// The discharge subsection of a sweep with a `discharge` table: each level's rate with its
/// seed spread, its ratio to the fine rate, and Beverloo's ratio and C with the parcel's
/// diameter (k lambda d) and with the fine one (k d); a table and `discharge_levels.csv`.
pub(crate) fn write_discharge_table(
    sub: &mut Section,
    discharge: &DischargeSettings,
    points: &[AccuracyPoint],
    dir: &Path,
) -> Result<(), ValidateError> {
    let levels = levels(points);
    let Some(fine) = levels.iter().find(|l| l.setting == "reference") else {
        return Ok(());
    };
    let d0 = discharge.orifice_diameter_m;
    let unit = |rho: Option<f64>, d: f64| beverloo_rate(1.0, rho?, d0, d, PUBLISHED_K);
    let fine_unit = unit(fine.bulk_density, fine.diameter);
    let mut table = levels_table(discharge);
    let mut csv = CsvBuffer::new([
        "setting",
        "cg_rule",
        "lambda",
        "seeds",
        "particle_diameter_m",
        "orifice_over_diameter",
        "rate_kg_s",
        "rate_se_kg_s",
        "rate_min_kg_s",
        "rate_max_kg_s",
        "ratio_to_fine",
        "ratio_to_fine_se",
        "beverloo_ratio_parcel_d",
        "beverloo_ratio_fine_d",
        "c_parcel_d",
        "c_fine_d",
        "bulk_density_kg_m3",
        "seeds_stopped",
    ]);
    let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    let f = |v: Option<f64>, digits: usize| v.map_or("-".into(), |x| format!("{x:.digits$}"));
    for l in &levels {
        let parcel = unit(l.bulk_density, l.diameter);
        let with_fine = unit(l.bulk_density, fine.diameter);
        let ratio = |u: Option<f64>| Some(u? / fine_unit?);
        let c = |u: Option<f64>| Some(l.rate / u?);
        let stopped = l
            .stopped
            .iter()
            .map(|(seed, t)| format!("{seed}: {t:.2}"))
            .collect::<Vec<_>>()
            .join(", ");
        table.row([
            Cell::text(&l.setting),
            Cell::text(l.rule),
            Cell::num(l.lambda.to_string()),
            Cell::num(format!("{:.2}", d0 / l.diameter)),
            Cell::num(format!(
                "{:.4}{} ({}; {:.4} .. {:.4})",
                l.rate,
                l.rate_se.map_or(String::new(), |se| format!(" +- {se:.4}")),
                l.seeds,
                l.rate_range.0,
                l.rate_range.1
            )),
            Cell::num(l.ratio.map_or("-".into(), |(r, se)| {
                format!(
                    "{r:.3}{}",
                    se.map_or(String::new(), |se| format!(" +- {se:.3}"))
                )
            })),
            Cell::num(ratio(parcel).map_or("no flow predicted".into(), |r| format!("{r:.3}"))),
            Cell::num(f(ratio(with_fine), 3)),
            Cell::num(f(c(parcel), 3)),
            Cell::num(f(c(with_fine), 3)),
            Cell::num(f(l.bulk_density, 0)),
            Cell::text(if stopped.is_empty() {
                "-".into()
            } else {
                stopped
            }),
        ]);
        csv.row([
            l.setting.replace(',', ";"),
            l.rule.to_string(),
            l.lambda.to_string(),
            l.seeds.to_string(),
            o(Some(l.diameter)),
            o(Some(d0 / l.diameter)),
            o(Some(l.rate)),
            o(l.rate_se),
            o(Some(l.rate_range.0)),
            o(Some(l.rate_range.1)),
            o(l.ratio.map(|r| r.0)),
            o(l.ratio.and_then(|r| r.1)),
            o(ratio(parcel)),
            o(ratio(with_fine)),
            o(c(parcel)),
            o(c(with_fine)),
            o(l.bulk_density),
            l.stopped.len().to_string(),
        ]);
    }
    let path = dir.join("discharge_levels.csv");
    csv.bytes()
        .and_then(|bytes| write_atomic(&path, bytes))
        .map_err(|e| output_error(&path, e))?;
    sub.paragraph(format!(
        "Beverloo's law here takes g = {STANDARD_GRAVITY} m/s2; C = 0.58 is published for a flat-bottomed silo (the hopper raises it: reference/silo/PLAN.md 3)."
    ));
    sub.table(table);
    Ok(())
}

/// The per-level table's columns and caption.
fn levels_table(discharge: &DischargeSettings) -> Table {
    let d0 = discharge.orifice_diameter_m;
    Table::new([
        "setting",
        "rule",
        "lambda",
        "D0 / d",
        "rate, kg/s (mean +- SE over seeds; range)",
        "W / W_fine (same seed)",
        "Beverloo W / W_fine, k lambda d",
        "Beverloo W / W_fine, k d",
        "C, k lambda d",
        "C, k d",
        "bulk density kg/m3",
        "flow stopped (seed: s)",
    ])
    .caption(format!(
        "Discharge rate per level (cgdem): the mass discharged (a parcel counts lambda^3 grains), its slope from {} s after the gate opens, mean over seeds. Beverloo, W = C rho_b sqrt(g) (D0 - k d)^(5/2) with D0 = {d0} m, k = {PUBLISHED_K} and each level's measured rho_b, evaluated with the level's parcel diameter (k lambda d) and with the fine reference's diameter (k d): the ratio it predicts to the fine rate, and the C the measured rate gives. A rule that keeps Beverloo's law with the parcel diameter has the same C at every lambda in the column k lambda d. Flow stopped: no parcel out over the window's last two blocks (a clog, measured). CSV: discharge_levels.csv.",
        discharge.discard_s
    ))
}
