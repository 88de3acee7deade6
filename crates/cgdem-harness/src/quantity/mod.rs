//! The measured quantities, one home each. A quantity's file holds how a run is measured
//! (from the files every code leaves alike: `summary.json`, `timeseries.csv`, `profile.csv`,
//! a trajectory), or why it was not; its noise over seeds; the criterion two groups of runs
//! are judged by; and the figures and tables that show it. The suite kinds (the cases of
//! `crate::validation`, the sweeps of `crate::accuracy`) and `crate::advise` combine these
//! parts, so a new case adds the quantities it measures here and no corner of its own.
//!
//! - [`repose`]: the repose angle and heap profile, a collapse's final state.
//! - [`flow`]: a collapse's dynamics: front, height at the wall, kinetic energy, t_half.
//! - [`mass_flow`]: a screw feeder's mass flow, beside Eq. (7).
//! - [`discharge`]: a silo's or hopper's discharge rate, beside Beverloo's law.
//! - [`drum`]: a rotating drum's zone counts, dynamic angle and mixing index.
//! - [`porosity`]: a packing's porosity and pore size.
//! - [`seeds`]: runs grouped by all but their seed, and the statistics over a group.
//!
//! A quantity reads no suite file: `crate::suite` holds the quantities' settings (a
//! `[case.discharge]` table), so the reverse would be an import circle. What a section says
//! about its case comes in a [`CaseOrigin`], its tolerances and known differences as
//! arguments.

pub mod discharge;
pub mod drum;
pub mod flow;
pub mod mass_flow;
pub mod porosity;
pub mod repose;
pub mod seeds;

use std::path::Path;

use crate::report::{write_figure, Figure, Section};
use crate::runs::{output_error, ValidateError};

/// What a quantity's section says of the suite case it reports.
#[derive(Clone, Copy, Debug)]
pub struct CaseOrigin<'a> {
    /// The scene file.
    pub file: &'a Path,
    pub seeds: &'a [u64],
    /// The screw speeds the case runs at, rev/min (empty: the scene's own).
    pub rpms: &'a [f64],
    /// cgdem's guards only warn in this case (the suite entry's `keep_going`).
    pub keep_going: bool,
}

/// Writes `figure` under `dir` as `stem` (PNG, SVG and CSV) and shows it in `section` with
/// its title and caption.
pub(crate) fn show_figure(
    section: &mut Section,
    dir: &Path,
    stem: &str,
    figure: &Figure,
    (title, caption): (&str, &str),
) -> Result<(), ValidateError> {
    let files = write_figure(dir, stem, figure).map_err(|e| output_error(dir, e))?;
    section
        .figure(&files, title, caption)
        .map_err(|e| output_error(&files.png, e))?;
    Ok(())
}
