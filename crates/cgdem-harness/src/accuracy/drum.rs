//! A rotating drum as an accuracy quantity: a sweep with a `drum` table measures each run as a
//! suite case's drum is measured (`crate::quantity::drum`: the zone counts, the dynamic angle
//! and Lacey's index of every frame, the swing of the counts), and reports each level's means
//! over seeds (`quantity::drum::write_levels_table`): does coarse-graining keep the angle,
//! the mixing period and the segregation of the two sizes?

use std::path::Path;

use super::measurement::settings;
use super::AccuracyPoint;
use crate::code::Code;
use crate::quantity::drum::{
    measure_runs, species_diameters, write_levels_table, DrumSettings, LevelMeans,
};
use crate::report::Section;
use crate::runs::{RunRecord, ValidateError};
use cgdem_core::scene::Scene;

/// Measures the finished run `record` of `scene` as a drum and writes what it measured into
/// `point`; `Err` says why it cannot be measured.
pub(crate) fn measure_drum(
    scene: &Scene,
    drum: &DrumSettings,
    record: &RunRecord,
    point: &mut AccuracyPoint,
) -> Result<(), String> {
    let run = measure_runs(scene, drum, std::slice::from_ref(record)).remove(0);
    if let Some(problem) = run.problem {
        return Err(problem);
    }
    let means = run
        .steady_means(drum.steady_from_s)
        .ok_or_else(|| format!("no frame from {} s of rotation on", drum.steady_from_s))?;
    point.dynamic_angle_deg = means.angle_deg;
    point.mixing_index = means.lacey;
    point.mixing_period_s = run.oscillation(drum.steady_from_s).map(|o| o.period_s);
    point.large_share_zones = large_share_zones(scene, &means.counts);
    Ok(())
}

/// The large grains' share of the solid volume in zones 1 and 2 from the mean counts (a
/// parcel's volume is lambda^3 grains' for both species, so the share needs no lambda).
fn large_share_zones(scene: &Scene, counts: &[f64; 4]) -> Option<[f64; 2]> {
    let (small, large) = species_diameters(scene);
    let share = |m1: f64, m2: f64| {
        let (v1, v2) = (m1 * small.powi(3), m2 * large.powi(3));
        (v1 + v2 > 0.0).then(|| v2 / (v1 + v2))
    };
    Some([share(counts[0], counts[1])?, share(counts[2], counts[3])?])
}

/// Each level of the sweep (cgdem's runs) with its seeds' means.
fn levels(points: &[AccuracyPoint]) -> Vec<LevelMeans> {
    settings(Code::Cgdem, points)
        .iter()
        .filter(|s| s.runs.iter().any(|p| p.dynamic_angle_deg.is_some()))
        .map(|s| {
            let of = |f: &dyn Fn(&AccuracyPoint) -> Option<f64>| -> Vec<f64> {
                s.runs.iter().filter_map(|p| f(p)).collect()
            };
            let first = s.runs[0];
            LevelMeans {
                setting: s.setting.to_string(),
                lambda: first.lambda,
                rule: first.cg_rule.name(),
                seeds: s.runs.len(),
                angle_deg: of(&|p| p.dynamic_angle_deg),
                period_s: of(&|p| p.mixing_period_s),
                lacey: of(&|p| p.mixing_index),
                large_share_zone1: of(&|p| p.large_share_zones.map(|z| z[0])),
                large_share_zone2: of(&|p| p.large_share_zones.map(|z| z[1])),
                particle_steps: of(&|p| p.particle_steps),
            }
        })
        .collect()
}

/// The drum subsection of a sweep with a `drum` table, from its levels' means.
pub(crate) fn write_drum_table(
    sub: &mut Section,
    points: &[AccuracyPoint],
    dir: &Path,
) -> Result<(), ValidateError> {
    write_levels_table(sub, &levels(points), dir)
}
