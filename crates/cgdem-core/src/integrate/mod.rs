//! Time integration.

pub mod pcvv;
mod velocity_verlet;

pub use velocity_verlet::{complete_and_kick, drift_kick};

/// The scheme a world steps with, chosen once per scene (`[time] integrator`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Integrator {
    /// Velocity Verlet: forces from the half-step velocity.
    #[default]
    VelocityVerlet,
    /// Predictor-corrector velocity Verlet, paper B Eq. (11)-(15).
    Pcvv,
}
