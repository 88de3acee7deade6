//! Velocity Verlet, split around the force evaluation:
//! `v += dt/2 F/m; x += dt v` (drift_kick), forces at the new positions and half-step
//! velocities, then `v += dt/2 F/m` (complete_and_kick, which first adds what the force
//! pass left to add); spins the same with torque and inverse inertia.
//! Every particle is updated independently, so the result does not depend on how rayon
//! splits the work.
//!
//! Each half of the step is one parallel pass over all particles (translation, spin and,
//! in the drift, the pair list's displacement test together): every pass costs a fork and
//! a join, which is what limits the gain from a second thread.

use rayon::prelude::*;

use crate::math::{Real, Vec3};
use crate::neighbor::DisplacementCheck;
use crate::particles::{AngularState, Particles};

const CHUNK: usize = 1024;

/// Half kick then drift of every particle, half kick of the spins. Returns whether some
/// particle moved past the `check` (false without one).
pub fn drift_kick(p: &mut Particles, dt: Real, check: Option<DisplacementCheck>) -> bool {
    let half = 0.5 * dt;
    let Particles {
        position,
        velocity,
        force,
        inv_mass,
        angular,
        ..
    } = p;
    let (force, inv_mass) = (&*force, &*inv_mass);
    let translate = |start: usize, x: &mut [Vec3], v: &mut [Vec3]| -> bool {
        for (k, (x, v)) in x.iter_mut().zip(v.iter_mut()).enumerate() {
            *v += half * inv_mass[start + k] * force[start + k];
            *x += dt * *v;
        }
        check.is_some_and(|c| {
            x.iter()
                .zip(&c.reference[start..])
                .any(|(x, r)| (*x - *r).length_squared() > c.limit_sq)
        })
    };
    let chunks = position
        .par_chunks_mut(CHUNK)
        .zip(velocity.par_chunks_mut(CHUNK))
        .enumerate();
    match angular {
        Some(AngularState {
            omega,
            torque,
            inv_inertia,
        }) => chunks
            .zip(omega.par_chunks_mut(CHUNK))
            .map(|((c, (x, v)), w)| {
                let start = c * CHUNK;
                kick_slice(w, &torque[start..], &inv_inertia[start..], half);
                translate(start, x, v)
            })
            .reduce(|| false, |a, b| a || b),
        None => chunks
            .map(|(c, (x, v))| translate(c * CHUNK, x, v))
            .reduce(|| false, |a, b| a || b),
    }
}

/// Half kick of velocities and spins, completing each particle's force and torque first
/// with `complete(i, force, torque)` (what the force pass left to add, such as the
/// reactions of pairs owned by other particles): the pass that finishes the forces is the
/// pass that kicks, so the particles are read once. Returns whether every updated value is
/// finite (the non-finite guard, at no extra pass).
pub fn complete_and_kick(
    p: &mut Particles,
    dt: Real,
    complete: impl Fn(usize, &mut Vec3, &mut Vec3) + Sync,
) -> bool {
    let half = 0.5 * dt;
    let Particles {
        velocity,
        force,
        inv_mass,
        angular,
        ..
    } = p;
    let inv_mass = &*inv_mass;
    let chunks = velocity
        .par_chunks_mut(CHUNK)
        .zip(force.par_chunks_mut(CHUNK))
        .enumerate();
    match angular {
        Some(AngularState {
            omega,
            torque,
            inv_inertia,
        }) => chunks
            .zip(omega.par_chunks_mut(CHUNK))
            .zip(torque.par_chunks_mut(CHUNK))
            .map(|(((c, (v, f)), w), t)| {
                let start = c * CHUNK;
                let mut finite = true;
                for k in 0..v.len() {
                    let i = start + k;
                    complete(i, &mut f[k], &mut t[k]);
                    v[k] += half * inv_mass[i] * f[k];
                    w[k] += half * inv_inertia[i] * t[k];
                    finite &= v[k].is_finite() & w[k].is_finite();
                }
                finite
            })
            .reduce(|| true, |a, b| a && b),
        None => chunks
            .map(|(c, (v, f))| {
                let start = c * CHUNK;
                let mut finite = true;
                for k in 0..v.len() {
                    let i = start + k;
                    let mut unused_torque = Vec3::ZERO;
                    complete(i, &mut f[k], &mut unused_torque);
                    v[k] += half * inv_mass[i] * f[k];
                    finite &= v[k].is_finite();
                }
                finite
            })
            .reduce(|| true, |a, b| a && b),
    }
}

/// `v += half F/m` over one chunk; whether every result is finite.
#[inline(always)]
fn kick_slice(velocity: &mut [Vec3], force: &[Vec3], inv_mass: &[Real], half: Real) -> bool {
    let mut finite = true;
    for ((v, f), inv_m) in velocity.iter_mut().zip(force).zip(inv_mass) {
        *v += half * *inv_m * *f;
        finite &= v.is_finite();
    }
    finite
}

#[cfg(test)]
mod tests {
    use super::*;

    fn particles(n: usize, rotation: bool) -> Particles {
        let mut p = Particles::new(rotation);
        for k in 0..n {
            p.push(0, Vec3::new(k as Real, 0.0, 0.0), 0.5, 2.0);
            p.force[k] = Vec3::new(0.0, 0.0, -4.0);
        }
        p
    }

    #[test]
    fn drift_kick_moves_every_chunk_and_reports_the_displacement_test() {
        let n = 3 * CHUNK + 7;
        let mut p = particles(n, true);
        let reference = p.position.clone();
        p.velocity[n - 1] = Vec3::new(10.0, 0.0, 0.0);
        let check = DisplacementCheck {
            reference: &reference,
            limit_sq: 0.5 * 0.5,
        };
        // dt = 0.1: the last particle moves 1 (beyond 0.5), the others 0.01.
        assert!(drift_kick(&mut p, 0.1, Some(check)));
        assert!((p.velocity[0].z - -0.1).abs() < 1e-15);
        assert!((p.position[0].z - -0.01).abs() < 1e-15);
        assert!((p.position[n - 1].x - (n as Real - 1.0 + 1.0)).abs() < 1e-9);
        // Without the fast particle nothing moved past the limit.
        let mut q = particles(n, false);
        assert!(!drift_kick(&mut q, 0.1, Some(check)));
        assert!(!drift_kick(&mut q, 0.1, None));
    }

    #[test]
    fn kick_completes_the_forces_and_reports_a_non_finite_velocity_or_spin() {
        let n = CHUNK + 3;
        let nothing = |_: usize, _: &mut Vec3, _: &mut Vec3| {};
        let mut p = particles(n, true);
        assert!(complete_and_kick(&mut p, 0.1, nothing));
        assert!((p.velocity[n - 1].z - -0.1).abs() < 1e-15);
        // The completion runs before the kick, for every particle.
        let lift = |_: usize, f: &mut Vec3, _: &mut Vec3| f.z += 8.0;
        assert!(complete_and_kick(&mut p, 0.1, lift));
        assert!((p.velocity[n - 1].z - 0.0).abs() < 1e-15 && p.force[0].z == 4.0);
        p.angular.as_mut().unwrap().torque[n - 2] = Vec3::new(Real::NAN, 0.0, 0.0);
        assert!(!complete_and_kick(&mut p, 0.1, nothing));
    }
}
