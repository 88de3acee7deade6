//! Velocity Verlet, split around the force evaluation: `v += dt/2 F/m; x += dt v`
//! ([`kick_then_drift`]), forces at the new positions and half-step velocities, then
//! `v += dt/2 F/m` ([`closing_kick`]); spins the same with torque and inverse inertia
//! ([`kick`]). Kernels over slices (a subdomain's owned particles): every particle is
//! updated on its own, so the result does not depend on who steps which slice.

use crate::math::{Real, Vec3};

/// Half kick then drift of each particle; whether one moved farther than
/// `sqrt(limit_sq)` from its `reference` position (the pair list's rebuild test, at no
/// extra pass).
#[inline(always)]
pub fn kick_then_drift(
    position: &mut [Vec3],
    velocity: &mut [Vec3],
    force: &[Vec3],
    inv_mass: &[Real],
    reference: &[Vec3],
    limit_sq: Real,
    dt: Real,
) -> bool {
    let half = 0.5 * dt;
    let mut moved = false;
    let n = position.len();
    let (velocity, force, inv_mass, reference) = (
        &mut velocity[..n],
        &force[..n],
        &inv_mass[..n],
        &reference[..n],
    );
    for k in 0..n {
        velocity[k] += half * inv_mass[k] * force[k];
        position[k] += dt * velocity[k];
        moved |= (position[k] - reference[k]).length_squared() > limit_sq;
    }
    moved
}

/// `v += half F/m` (or `w += half T/I`): a half kick; whether every result is finite.
#[inline(always)]
pub fn kick(rate: &mut [Vec3], load: &[Vec3], inv_inertia: &[Real], half: Real) -> bool {
    let mut finite = true;
    for ((v, f), inv_m) in rate.iter_mut().zip(load).zip(inv_inertia) {
        *v += half * *inv_m * *f;
        finite &= v.is_finite();
    }
    finite
}

/// The closing half kick `v += dt/2 F/m`; whether every result is finite (the non-finite
/// guard, at no extra pass).
#[inline(always)]
pub fn closing_kick(velocity: &mut [Vec3], force: &[Vec3], inv_mass: &[Real], dt: Real) -> bool {
    kick(velocity, force, inv_mass, 0.5 * dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kick_then_drift_moves_and_reports_the_displacement_test() {
        let n = 7;
        let mut x: Vec<Vec3> = (0..n).map(|k| Vec3::new(k as Real, 0.0, 0.0)).collect();
        let reference = x.clone();
        let mut v = vec![Vec3::ZERO; n];
        let f = vec![Vec3::new(0.0, 0.0, -4.0); n];
        let inv_m = vec![0.5; n];
        v[n - 1] = Vec3::new(10.0, 0.0, 0.0);
        // dt = 0.1: the last particle moves 1 (beyond 0.5), the others 0.01.
        assert!(kick_then_drift(
            &mut x, &mut v, &f, &inv_m, &reference, 0.25, 0.1
        ));
        assert!((v[0].z - -0.1).abs() < 1e-15);
        assert!((x[0].z - -0.01).abs() < 1e-15);
        assert!((x[n - 1].x - (n as Real - 1.0 + 1.0)).abs() < 1e-9);
        let mut slow = reference.clone();
        let mut w = vec![Vec3::ZERO; n];
        assert!(!kick_then_drift(
            &mut slow, &mut w, &f, &inv_m, &reference, 0.25, 0.1
        ));
    }

    #[test]
    fn closing_kick_reports_a_non_finite_velocity() {
        let mut v = vec![Vec3::ZERO; 3];
        let mut f = vec![Vec3::new(0.0, 0.0, -4.0); 3];
        let inv_m = vec![0.5; 3];
        assert!(closing_kick(&mut v, &f, &inv_m, 0.1));
        assert!((v[2].z - -0.1).abs() < 1e-15);
        f[1] = Vec3::new(Real::NAN, 0.0, 0.0);
        assert!(!closing_kick(&mut v, &f, &inv_m, 0.1));
    }
}
