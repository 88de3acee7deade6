//! LIGGGHTS `tangential history` with `model hertz` (Mindlin no-slip stiffness):
//! a spring on the accumulated tangential displacement `u_t`,
//! `k_t = 8 G_eff sqrt(R_eff delta)`, a dashpot
//! `gamma_t = 2 sqrt(5/6) |beta| sqrt(S_t m_eff)` with `S_t = k_t`, and the Coulomb cap: when
//! the spring force exceeds `mu |F_n|` it is truncated to the cap, `u_t` is reset so the spring
//! gives exactly the cap, and (as in LIGGGHTS) the dashpot is left out in that step.
//!
//! Each step `v_t dt` is added to `u_t` (the history, seen from `i`) and the sum is projected
//! onto the current tangent plane, without rescaling: LIGGGHTS's order
//! (`tangential_model_history.h`; LAMMPS instead rotates keeping the length, then adds). It is
//! zero when a contact starts; seen from `j` it is `-u_t`.

use super::super::{exceeds, Contact, TangentialModel};
use crate::math::{Real, Vec3};

/// Per species pair: `G_eff` (Pa), `2 sqrt(5/6) |beta(e)|`, and `mu`.
#[derive(Clone, Debug)]
pub struct Mindlin {
    pub g_eff: Vec<Real>,
    pub damping_factor: Vec<Real>,
    pub friction: Vec<Real>,
}

impl Mindlin {
    /// The shear displacement after this step's slip, `u_t + v_t dt` projected onto the
    /// tangent plane (LIGGGHTS's order), and the stiffness `k_t = 8 G_eff sqrt(R_eff delta)`.
    #[inline(always)]
    pub(super) fn loaded_spring(&self, contact: &Contact, history: Vec3, dt: Real) -> (Vec3, Real) {
        let n = contact.normal;
        let mut u = history + contact.tangential_velocity * dt;
        u -= u.dot(n) * n;
        let k_t = 8.0
            * self.g_eff[contact.species_pair]
            * (contact.r_eff * contact.overlap.max(0.0)).sqrt();
        (u, k_t)
    }
}

impl TangentialModel for Mindlin {
    type History = Vec3;
    const NEEDS_ROTATION: bool = true;

    #[inline(always)]
    fn force(&self, contact: &Contact, normal_force: Real, history: &mut Vec3, dt: Real) -> Vec3 {
        let sp = contact.species_pair;
        let (u, k_t) = self.loaded_spring(contact, *history, dt);
        let spring = -k_t * u;
        let cap = self.friction[sp] * normal_force.abs();
        // `|spring| > cap` on squares: no square root below the cap (`exceeds`).
        let spring_squared = spring.length_squared();
        if exceeds(spring_squared, cap) {
            let capped = spring * (cap / spring_squared.sqrt());
            *history = if k_t > 0.0 { -capped / k_t } else { Vec3::ZERO };
            capped
        } else {
            *history = u;
            let gamma_t = self.damping_factor[sp] * (k_t * contact.m_eff).sqrt();
            spring - gamma_t * contact.tangential_velocity
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tests::contact_at;

    fn model() -> Mindlin {
        Mindlin {
            g_eff: vec![1e6],
            damping_factor: vec![0.0],
            friction: vec![0.5],
        }
    }

    #[test]
    fn spring_force_is_k_t_times_displacement_below_the_cap() {
        let mut c = contact_at(1e-5, 5e-4);
        c.tangential_velocity = Vec3::new(0.0, 1e-3, 0.0);
        let mut u = Vec3::ZERO;
        let f = model().force(&c, 100.0, &mut u, 1e-3);
        let k_t = 8.0 * 1e6 * (5e-4_f64 * 1e-5).sqrt();
        assert!((f.y + k_t * 1e-6).abs() < 1e-12 * k_t);
        assert!((u.y - 1e-6).abs() < 1e-18);
    }

    #[test]
    fn friction_is_capped_at_mu_normal_force_and_the_spring_truncated() {
        let mut c = contact_at(1e-5, 5e-4);
        c.tangential_velocity = Vec3::new(0.0, 10.0, 0.0);
        let mut u = Vec3::ZERO;
        let f = model().force(&c, 1e-3, &mut u, 1e-3);
        assert!((f.length() - 0.5e-3).abs() < 1e-15);
        let k_t = 8.0 * 1e6 * (5e-4_f64 * 1e-5).sqrt();
        assert!((k_t * u.length() - 0.5e-3).abs() < 1e-15);
    }

    #[test]
    fn history_is_projected_onto_the_new_tangent_plane_as_in_liggghts() {
        let mut c = contact_at(1e-5, 5e-4);
        c.tangential_velocity = Vec3::ZERO;
        let tilt = 0.1_f64;
        c.normal = Vec3::new(tilt.cos(), tilt.sin(), 0.0);
        let mut u = Vec3::new(0.0, 1e-7, 0.0);
        model().force(&c, 100.0, &mut u, 1e-3);
        assert!(u.dot(c.normal).abs() < 1e-20);
        // Projection, no rescaling: the length shrinks by cos(tilt).
        assert!((u.length() - 1e-7 * tilt.cos()).abs() < 1e-20);
    }
}
