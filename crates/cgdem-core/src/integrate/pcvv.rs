//! Predictor-corrector velocity Verlet, paper B Eq. (11)-(15), for forces that depend on
//! velocity: predictor `r1 = r0 + dt v0 + dt^2/(2m) F0`, `v1 = v0 + dt F0/m`,
//! `w1 = w0 + dt T0/I`; forces `F1, T1` from `(r1, v1, w1)`; corrector
//! `v2 = v1 + dt/(2m) (F1 - F0)`, `w2 = w1 + dt/(2I) (T1 - T0)`.
//!
//! Velocity Verlet evaluates the force with the half-step velocity `v0 + dt/(2m) F0`; PCVV
//! with the full-step prediction `v1`. For position-only forces both give the same positions
//! and velocities.

use crate::math::{Real, Vec3};

/// The predictor for positions and velocities.
#[inline(always)]
pub fn predict(
    position: &mut [Vec3],
    velocity: &mut [Vec3],
    force: &[Vec3],
    inv_mass: &[Real],
    dt: Real,
) {
    for ((x, v), (f, inv_m)) in position
        .iter_mut()
        .zip(velocity)
        .zip(force.iter().zip(inv_mass))
    {
        let a = *inv_m * *f;
        *x += dt * *v + 0.5 * dt * dt * a;
        *v += dt * a;
    }
}

/// The predictor for spins (or any rate): `w += dt T/I`.
#[inline(always)]
pub fn predict_rate(rate: &mut [Vec3], torque: &[Vec3], inv_inertia: &[Real], dt: Real) {
    for (w, (t, inv_i)) in rate.iter_mut().zip(torque.iter().zip(inv_inertia)) {
        *w += dt * *inv_i * *t;
    }
}

/// The corrector: `v += dt/(2m) (F1 - F0)`. Returns whether every updated value is finite.
#[inline(always)]
pub fn correct(
    velocity: &mut [Vec3],
    force: &[Vec3],
    old_force: &[Vec3],
    inv_mass: &[Real],
    dt: Real,
) -> bool {
    let half = 0.5 * dt;
    let mut finite = true;
    for ((v, (f1, f0)), inv_m) in velocity
        .iter_mut()
        .zip(force.iter().zip(old_force))
        .zip(inv_mass)
    {
        *v += half * *inv_m * (*f1 - *f0);
        finite &= v.is_finite();
    }
    finite
}
