//! A drum's measures per coarse-graining level of an accuracy sweep (cgdem's runs): the
//! dynamic angle, the period of the zone counts' swing, Lacey's index and the large grains'
//! share of each zone, each a mean over seeds with its standard error, beside the fine
//! reference's; does coarse-graining keep the angle, the mixing period and the segregation
//! of the two sizes, and what does it save?

use std::path::Path;

use crate::quantity::seeds::mean_se;
use crate::report::{Cell, Section, Table};
use crate::runs::{output_error, ValidateError};
use cgdem_core::io::{write_atomic, CsvBuffer};

/// One level of a sweep: each measure's values over its seeds.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelMeans {
    /// "reference" (the fine level) or the setting in words.
    pub setting: String,
    pub lambda: u32,
    pub rule: &'static str,
    /// Seeds the level ran with (a measure may have fewer values: a swing not resolved).
    pub seeds: usize,
    pub angle_deg: Vec<f64>,
    pub period_s: Vec<f64>,
    pub lacey: Vec<f64>,
    pub large_share_zone1: Vec<f64>,
    pub large_share_zone2: Vec<f64>,
    pub particle_steps: Vec<f64>,
}

/// "mean +- SE (n)" of `values`, or "-".
fn shown(values: &[f64], digits: usize) -> String {
    match mean_se(values) {
        (_, _) if values.is_empty() => "-".into(),
        (m, Some(se)) => format!("{m:.digits$} +- {se:.digits$} ({})", values.len()),
        (m, None) => format!("{m:.digits$} (1)"),
    }
}

/// The drum subsection of a sweep with a `drum` table: a table and `drum_levels.csv`.
/// Nothing without the fine reference (`setting` "reference").
pub fn write_levels_table(
    sub: &mut Section,
    levels: &[LevelMeans],
    dir: &Path,
) -> Result<(), ValidateError> {
    let Some(fine) = levels.iter().find(|l| l.setting == "reference") else {
        return Ok(());
    };
    let fine_cost = mean_se(&fine.particle_steps).0;
    let mut table = Table::new([
        "setting",
        "rule",
        "lambda",
        "seeds",
        "dynamic angle, deg",
        "swing period, s",
        "Lacey index",
        "large grains' share of zone 1",
        "large grains' share of zone 2",
        "particle-steps saved",
    ])
    .caption("A rotating drum per level (cgdem): each measure's mean over the seeds that measured it, +- its standard error (seeds in brackets; a swing is not resolved when the steady window holds less than one), and the fine reference's particle-steps over the level's. The large grains' share of a zone is of its solid volume, the same measure at every lambda (a parcel is lambda^3 grains of either size): the segregation of the two sizes as the zones see it. CSV: drum_levels.csv.");
    let mut csv = CsvBuffer::new([
        "setting",
        "cg_rule",
        "lambda",
        "seeds",
        "dynamic_angle_deg",
        "dynamic_angle_se_deg",
        "swing_period_s",
        "swing_period_se_s",
        "swings_resolved",
        "lacey_index",
        "lacey_index_se",
        "large_share_zone1",
        "large_share_zone1_se",
        "large_share_zone2",
        "large_share_zone2_se",
        "particle_steps",
        "saving_particle_steps",
    ]);
    let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    let mean = |v: &[f64]| (!v.is_empty()).then(|| mean_se(v).0);
    let se = |v: &[f64]| mean_se(v).1;
    for l in levels {
        let saving = mean(&l.particle_steps).map(|c| fine_cost / c);
        table.row([
            Cell::text(&l.setting),
            Cell::text(l.rule),
            Cell::num(l.lambda.to_string()),
            Cell::num(l.seeds.to_string()),
            Cell::num(shown(&l.angle_deg, 2)),
            Cell::num(shown(&l.period_s, 3)),
            Cell::num(shown(&l.lacey, 3)),
            Cell::num(shown(&l.large_share_zone1, 3)),
            Cell::num(shown(&l.large_share_zone2, 3)),
            Cell::num(saving.map_or("-".into(), |s| format!("{s:.1}x"))),
        ]);
        csv.row([
            l.setting.replace(',', ";"),
            l.rule.to_string(),
            l.lambda.to_string(),
            l.seeds.to_string(),
            o(mean(&l.angle_deg)),
            o(se(&l.angle_deg)),
            o(mean(&l.period_s)),
            o(se(&l.period_s)),
            l.period_s.len().to_string(),
            o(mean(&l.lacey)),
            o(se(&l.lacey)),
            o(mean(&l.large_share_zone1)),
            o(se(&l.large_share_zone1)),
            o(mean(&l.large_share_zone2)),
            o(se(&l.large_share_zone2)),
            o(mean(&l.particle_steps)),
            o(saving),
        ]);
    }
    let path = dir.join("drum_levels.csv");
    std::fs::create_dir_all(dir).map_err(|e| output_error(dir, e))?;
    csv.bytes()
        .and_then(|bytes| write_atomic(&path, bytes))
        .map_err(|e| output_error(&path, e))?;
    sub.table(table);
    Ok(())
}
