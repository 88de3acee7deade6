//! Time integration: the half-steps of each scheme as kernels over slices of particles.

pub mod pcvv;
mod velocity_verlet;

pub use velocity_verlet::{closing_kick, kick, kick_then_drift};

/// The scheme a world steps with, chosen once per scene (`[time] integrator`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Integrator {
    /// Velocity Verlet: forces from the half-step velocity.
    #[default]
    VelocityVerlet,
    /// Predictor-corrector velocity Verlet, paper B Eq. (11)-(15).
    Pcvv,
}
