//! cgdem-harness: the validation harness around the cgdem solver. It writes LIGGGHTS and
//! LAMMPS inputs for a scene, runs them, turns their outputs into cgdem's summary format, runs
//! suites of cases into compared reports with plots, and runs parameter sweeps.
//! The solver core (`cgdem-core`) never depends on this crate.

pub mod accuracy;
pub mod advise;
pub mod bench;
pub mod code;
pub mod csv_table;
pub mod decks;
pub mod dynamics;
pub mod history;
pub mod ranks;
pub mod report;
pub mod runs;
pub mod screw;
pub mod stability;
pub mod suite;
pub mod suite_entry;
pub mod sweep;
pub mod validate;
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
