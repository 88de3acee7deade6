//! Coarse-graining as a transform of the scene, paper A Eq. (3)-(6).
//!
//! With `lambda = 2^n`: diameters `lambda d` (same density, so `m' = lambda^3 m`),
//! `phi'(r) = lambda^3 phi(r / lambda)` (so `sigma' = lambda sigma`, `eps' = lambda^3 eps`),
//! `gamma' = lambda^2 gamma`, an explicit `dt' = lambda dt`, the same box, and
//! `N' ~ N / lambda^3`. Positions and velocities are not scaled. Applied once, before the
//! world is built; the force loop never sees lambda.
//!
//! Consequences (tested below): contact stiffness `k = 72 eps / r_c^2` becomes `lambda k`;
//! the period `2 pi sqrt(m_eff / k)` becomes `lambda` times longer; the damping ratio
//! `gamma / (2 sqrt(k m_eff))` and hence the restitution are unchanged. Wall damping is set
//! from the restitution, so it follows the same rule by construction.

use crate::scene::{ContactSettings, InsertAmount, Scene};
use crate::timestep::TimeStepRequest;

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CoarseGrainError {
    #[error("lambda = {0} is not allowed: lambda must be a power of two (1, 2, 4, 8, ...)")]
    NotPowerOfTwo(u32),
    #[error(
        "{file}: at lambda = {lambda} the particles ({diameter:.4e} m) no longer fit: {reason}"
    )]
    TooCoarse {
        file: String,
        lambda: u32,
        diameter: f64,
        reason: String,
    },
}

/// Returns the scene coarse-grained by `lambda` relative to its current level.
pub fn coarse_grain(scene: &Scene, lambda: u32) -> Result<Scene, CoarseGrainError> {
    if lambda == 0 || !lambda.is_power_of_two() {
        return Err(CoarseGrainError::NotPowerOfTwo(lambda));
    }
    let l = lambda as f64;
    let mut out = scene.clone();
    out.lambda = scene.lambda * lambda;
    for s in &mut out.species {
        s.diameter *= l;
    }
    out.contact = match scene.contact {
        ContactSettings::Wca {
            epsilon,
            sigma,
            gamma_n,
            gamma_t,
        } => ContactSettings::Wca {
            epsilon: epsilon * l.powi(3),
            sigma: sigma * l,
            gamma_n: gamma_n * l * l,
            gamma_t: gamma_t * l * l,
        },
    };
    if let TimeStepRequest::Explicit(dt) = scene.time_step {
        out.time_step = TimeStepRequest::Explicit(dt * l);
    }
    for ins in &mut out.insertions {
        if let InsertAmount::Count(n) = ins.amount {
            ins.amount = InsertAmount::Count(((n as f64 / l.powi(3)).round() as u64).max(1));
        }
    }
    let diameter = out.max_diameter();
    let length = out.domain.length();
    let too_coarse = |reason: String| CoarseGrainError::TooCoarse {
        file: scene.source.display().to_string(),
        lambda: out.lambda,
        diameter,
        reason,
    };
    for axis in 0..3 {
        if diameter >= length[axis] {
            return Err(too_coarse(format!(
                "the box is only {:.4e} m along axis {axis}",
                length[axis]
            )));
        }
        let needed = (2.0 + out.skin_fraction) * diameter;
        if out.domain.periodic[axis] && length[axis] < needed {
            return Err(too_coarse(format!("the periodic side along axis {axis} ({:.4e} m) must be at least (2 + skin) diameters = {needed:.4e} m", length[axis])));
        }
    }
    Ok(out)
}
