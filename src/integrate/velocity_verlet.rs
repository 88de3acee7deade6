//! Velocity Verlet, split around the force evaluation:
//! `v += dt/2 F/m; x += dt v` (drift_kick), forces at the new positions and half-step
//! velocities, then `v += dt/2 F/m` (kick). Every particle is updated independently, so the
//! result does not depend on how rayon splits the work.

use rayon::prelude::*;

use crate::math::{Real, Vec3};

const CHUNK: usize = 1024;

/// Half kick then drift.
pub fn drift_kick(
    position: &mut [Vec3],
    velocity: &mut [Vec3],
    force: &[Vec3],
    inv_mass: &[Real],
    dt: Real,
) {
    let half = 0.5 * dt;
    position
        .par_iter_mut()
        .zip(velocity.par_iter_mut())
        .zip(force.par_iter().zip(inv_mass.par_iter()))
        .with_min_len(CHUNK)
        .for_each(|((x, v), (f, inv_m))| {
            *v += half * *inv_m * *f;
            *x += dt * *v;
        });
}

/// Half kick: `v += dt/2 F/m` (also used for spins with torque and inverse inertia).
/// Returns whether every updated value is finite (the non-finite guard, at no extra pass).
pub fn kick(velocity: &mut [Vec3], force: &[Vec3], inv_mass: &[Real], dt: Real) -> bool {
    let half = 0.5 * dt;
    velocity
        .par_iter_mut()
        .zip(force.par_iter().zip(inv_mass.par_iter()))
        .with_min_len(CHUNK)
        .map(|(v, (f, inv_m))| {
            *v += half * *inv_m * *f;
            v.is_finite()
        })
        .reduce(|| true, |a, b| a && b)
}
