//! Error against run time (`[[accuracy]]` in a suite): what each knob that buys speed costs in
//! accuracy.
//!
//! A sweep names a case, a reference setting (the finest affordable) and one series per knob:
//! the coarse-graining level `lambda`, or a scene key (`time.dt_fraction`,
//! `neighbor.skin_fraction`, `body[0].cell_size`). Each point changes one knob from the
//! reference and is judged against the same code's reference run: repose-angle difference and
//! heap-profile distance for a collapse, mass-flow difference (and the distance from Eq. 7) for
//! a screw feeder. Every setting (the reference and each point) is run with each of the
//! sweep's insertion seeds, and a point's error is taken against the reference run with the
//! same seed (the same packing), so the packing largely cancels; a setting's error is the mean
//! over seeds with its standard error (the error bars). The largest difference between two
//! reference runs with different seeds is the floor below which a difference is the packing,
//! not the knob. The report plots error against wall time on log axes with each code's Pareto
//! front, and tables the cheapest setting within each target.
//!
//! Its phases, one file each: `suite` (the `[[accuracy]]` entry), `runs` (every setting
//! with every seed and code), `measurement` (errors, means over seeds, the cheapest setting)
//! and `report` (the subsection, its figures, `points.csv` and the coarse-graining matrix);
//! `discharge` puts a silo's discharge rate into the points and the report (a sweep with a
//! `discharge` table), `drum` a rotating drum's angle, mixing period and segregation (a sweep
//! with a `drum` table). What each run measures, and how, is `crate::quantity`'s.

mod discharge;
#[cfg(test)]
mod discharge_tests;
mod drum;
#[cfg(test)]
mod drum_tests;
mod measurement;
mod report;
mod runs;
mod suite;
#[cfg(test)]
pub(crate) mod tests;

pub use crate::quantity::flow::front_history_gap;
pub use crate::quantity::repose::profile_distance;
pub(crate) use measurement::{
    cheapest_setting, measure, measure_named, settings, Cost, Setting, SettingMean,
};
pub use measurement::{
    cheapest_within, pareto_front, AccuracyPoint, AccuracySummary, CheapestSetting, Measure,
};
pub(crate) use suite::RawSweep;
pub use suite::{AccuracySweep, Knob, KnobSeries, Targets};

use std::path::Path;

use crate::report::Report;
use crate::runs::{ValidateError, ValidateOptions};
use report::write_sweep_section;
pub(crate) use runs::planned_runs;
use runs::{own_rule_sweeps, run_sweep};

/// Spread = this many standard errors of the mean over seeds (the matrix's columns and
/// `cgdem advise`).
pub const SPREAD_STANDARD_ERRORS: f64 = 2.0;

/// Runs every `[[accuracy]]` sweep of the suite, writes the "Error against run time" section
/// of the report and its figures; None when the suite has no sweep.
pub(crate) fn run_sweeps(
    sweeps: &[AccuracySweep],
    suite_file: &Path,
    options: &ValidateOptions,
    report: &mut Report,
) -> Result<Option<AccuracySummary>, ValidateError> {
    if sweeps.is_empty() {
        return Ok(None);
    }
    let section = report.section("Error against run time");
    section.paragraph(
        "For each case: a reference setting (the finest affordable) and one series per knob \
         that buys speed (coarse-graining level lambda, time-step fraction of the contact \
         period, neighbour skin, SDF cell size), each point changing one knob from the \
         reference. Every setting runs with each of the sweep's insertion seeds, and a run's \
         error is against the same code's reference run with the same seed (the same \
         packing); a setting's error is the mean over its seeds, the error bars one standard \
         error of that mean. The largest difference between two reference runs with \
         different seeds (\"floor\") shows how far a different random packing alone moves the \
         result. Wall time is the whole run (insertion and output included) on the \
         machine and thread count in the provenance; the machine is shared, so wall times \
         carry some percent of noise. Figures: error against wall time on log axes, one series \
         per knob and code, the Pareto front of each code dashed, the target dotted.",
    );
    let mut summary = AccuracySummary {
        points: Vec::new(),
        cheapest: Vec::new(),
    };
    for sweep in sweeps {
        let mut points = run_sweep(sweep, suite_file, options)?;
        measure(&mut points);
        let case = points.first().map(|p| p.case.clone()).unwrap_or_default();
        let dir = options.out.join("figures").join("accuracy").join(&case);
        let cheapest = write_sweep_section(section, sweep, &case, &points, &dir, None)?;
        let own = own_rule_sweeps(sweep, &case, &points);
        summary.points.extend(points);
        summary.cheapest.extend(cheapest);
        for (own_sweep, mut own_points) in own {
            measure(&mut own_points);
            let own_case = own_points[0].case.clone();
            let dir = options.out.join("figures").join("accuracy").join(&own_case);
            let note = format!(
                "The {} rule's own matrix: its levels against its own lambda = {}, from the runs of case {case} (none made again).",
                own_sweep.rule.name(),
                own_sweep.reference[&Knob::Lambda]
            );
            let cheapest = write_sweep_section(
                section,
                &own_sweep,
                &own_case,
                &own_points,
                &dir,
                Some(&note),
            )?;
            summary.points.extend(own_points);
            summary.cheapest.extend(cheapest);
        }
    }
    Ok(Some(summary))
}
