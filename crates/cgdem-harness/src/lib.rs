//! cgdem-harness: the validation harness around the cgdem solver. It writes LIGGGHTS and
//! LAMMPS inputs for a scene, runs them, turns their outputs into cgdem's summary format, runs
//! suites of cases into compared reports with plots, and runs parameter sweeps.
//! The solver core (`cgdem-core`) never depends on this crate; the command (`cgdem`) calls it.
//!
//! Every run, whatever the code, leaves the same files (`summary.json`, `timeseries.csv`,
//! `profile.csv`, ...): cgdem writes them itself, the reference codes' dumps go through the
//! core's analysis in [`decks::postprocess()`]. Comparisons, verdicts and figures read only
//! those files, so every code is measured the same way.
//!
//! The modules, in three groups:
//!
//! - **Commands**: [`validation`] (`cgdem validate`), [`mod@bench`] (`cgdem bench`),
//!   [`advise`] (`cgdem advise`), [`history`] (`cgdem history`), [`sweep`]
//!   (`cgdem run --sweep`), [`decks::run_reference`] (`cgdem reference`).
//! - **Suite kinds**, each a folder of its phases (`suite`, `runs`, `measurement`,
//!   `report`): the cases of [`validation`], the error-against-run-time sweeps of
//!   [`accuracy`], the stress cases of [`stability`], and [`mod@bench`]'s timed runs.
//! - **Measured quantities**, one file (or folder) each in [`quantity`]: the repose angle
//!   and profile, a collapse's flow, a screw's mass flow, a discharge rate, a packing's
//!   porosity; each with its measurement from a run, its noise over seeds, its criterion and
//!   its figures, which the suite kinds and [`advise`] combine.
//! - **Building blocks**: [`suite`] and [`suite_entry`] (suite files), [`runs`] (one run of
//!   any code, reuse, concurrency), [`decks`] (the reference codes: a LAMMPS and a LIGGGHTS
//!   dialect, runner, dump parser, post-processing), [`faults`] (`--fault`, planted in
//!   cgdem's runs only), [`ranks`] (cgdem as MPI ranks),
//!   [`verdict`], [`report`] (figures and HTML), [`csv_table`], [`code`].

// Commands.
pub mod advise;
pub mod history;
pub mod sweep;
// Suite kinds.
pub mod accuracy;
pub mod bench;
pub mod chung_ooi;
pub mod stability;
pub mod validation;
// Measured quantities.
pub mod quantity;
// Building blocks.
pub mod code;
pub mod csv_table;
pub mod decks;
pub mod faults;
pub mod ranks;
pub mod report;
pub mod runs;
pub mod suite;
pub mod suite_entry;
pub mod verdict;

/// Tests read the shipped cases and suites by their paths from the repository root, as the
/// command does; `cargo test` starts them in this crate's folder.
#[cfg(test)]
pub(crate) fn at_repo_root() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        std::env::set_current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .expect("the repository root exists")
    });
}
