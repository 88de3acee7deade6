//! Time integration.

mod velocity_verlet;

pub use velocity_verlet::{drift_kick, kick};
