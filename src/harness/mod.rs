//! The validation harness: writes reference-code inputs for a scene, runs them, turns their
//! outputs into cgdem's summary format, and runs suites of cases into compared reports.
//! The solver core never imports this module.

pub mod accuracy;
pub mod bench;
pub mod dynamics;
pub mod history;
pub mod lammps;
pub mod liggghts;
pub mod screw;
pub mod stability;
pub mod suite;
pub mod validate;
