//! The discharge rate per coarse-graining level of an accuracy sweep (cgdem's runs), beside
//! Beverloo's law evaluated with the parcel's diameter and with the fine reference's: does
//! a rule keep the law's C when the grains become parcels?

use std::path::Path;

use super::{beverloo_rate, DischargeSettings, PUBLISHED_K, STANDARD_GRAVITY};
use crate::report::{Cell, Section, Table};
use crate::runs::{output_error, ValidateError};
use cgdem_core::io::{write_atomic, CsvBuffer};

/// One level of a sweep, its seeds' means.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelRate {
    /// "reference" (the fine level) or the setting in words.
    pub setting: String,
    pub lambda: u32,
    pub rule: &'static str,
    pub seeds: usize,
    /// The parcel's diameter, m.
    pub diameter: f64,
    /// Mean rate over seeds, kg/s, its standard error (None for one seed) and range.
    pub rate: f64,
    pub rate_se: Option<f64>,
    pub rate_range: (f64, f64),
    /// Mean over seeds of W / W of the reference run with the same seed, with its SE.
    pub ratio: Option<(f64, Option<f64>)>,
    pub bulk_density: Option<f64>,
    /// (seed, when its flow stopped) of the seeds that clogged.
    pub stopped: Vec<(u64, f64)>,
}

/// The discharge subsection of a sweep with a `discharge` table: each level's rate with its
/// seed spread, its ratio to the fine rate, and Beverloo's ratio and C with the parcel's
/// diameter (k lambda d) and with the fine one (k d); a table and `discharge_levels.csv`.
/// Nothing without the fine reference (`setting` "reference").
pub fn write_levels_table(
    sub: &mut Section,
    discharge: &DischargeSettings,
    levels: &[LevelRate],
    dir: &Path,
) -> Result<(), ValidateError> {
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
    for l in levels {
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
