//! The validation harness: suites of cases run by cgdem and the reference codes, compared
//! and reported. The solver core never depends on this module.

pub mod suite;
pub mod validate;
