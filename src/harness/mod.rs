//! The validation harness: writes reference-code inputs for a scene, runs them and turns
//! their outputs into cgdem's summary format. The solver core never imports this module.

pub mod lammps;
