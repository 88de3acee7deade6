//! `tangential = "coulomb"`: `Mindlin`'s spring and dashpot (LIGGGHTS `tangential history`'s
//! `k_t`, `gamma_t`, shear displacement and its update) with Coulomb's bound on the force they
//! exert together:
//!
//! `F_t = -k_t u_t - gamma_t v_t`, and if `|F_t| > mu max(F_n, 0)` it is scaled down to that
//! bound (its direction kept) and the spring is reset to carry it alone, `u_t = -F_t / k_t`.
//!
//! `F_n` is the normal force of the same law: elastic plus dashpot, the contact's load. With
//! van der Waals cohesion the pull is not taken off: it acts across the gap around the
//! contact and presses the surfaces together (the elastic force rises to balance it, DMT), so
//! the load of the contact is still the elastic plus dashpot force.
//!
//! Two differences from `history` (LIGGGHTS), where a sliding contact can exceed the bound:
//! - LIGGGHTS caps the spring alone at `mu |F_n|` and adds the dashpot uncapped below the cap
//!   (`tangential_model_history.h`). Here the sum is capped.
//! - LIGGGHTS's cap is `mu |F_n|`: at the end of a damped contact `F_n` turns attractive (the
//!   dashpot pulls while the surfaces separate) and friction still acts. Here it is
//!   `mu max(F_n, 0)`: no load, no friction. The rolling torque's cap (epsd2) follows
//!   (`cap_load`).
//!
//! Why the spring alone carries the capped force: when the slip stops or reverses, the force
//! then falls from the bound continuously. Storing spring plus dashpot share (LAMMPS
//! `mindlin`: `u_t = -(F_t + gamma_t v_t)/k_t`) leaves a spring that, at high slip speed,
//! points the other way and flips the friction force when the slip slows.

use super::super::{exceeds, Contact, TangentialModel};
use super::Mindlin;
use crate::math::{Real, Vec3};

/// `Mindlin`'s coefficients (per species pair: `G_eff`, `2 sqrt(5/6) |beta(e)|`, `mu`).
#[derive(Clone, Debug)]
pub struct CoulombMindlin(pub Mindlin);

impl TangentialModel for CoulombMindlin {
    type History = Vec3;
    const NEEDS_ROTATION: bool = true;

    #[inline(always)]
    fn cap_load(normal_force: Real) -> Real {
        normal_force.max(0.0)
    }

    #[inline(always)]
    fn force(&self, contact: &Contact, normal_force: Real, history: &mut Vec3, dt: Real) -> Vec3 {
        let m = &self.0;
        let sp = contact.species_pair;
        let (u, k_t) = m.loaded_spring(contact, *history, dt);
        let gamma_t = m.damping_factor[sp] * (k_t * contact.m_eff).sqrt();
        let force = -k_t * u - gamma_t * contact.tangential_velocity;
        let cap = m.friction[sp] * Self::cap_load(normal_force);
        // `|force| > cap` on squares: no square root below the cap (`exceeds`).
        let size_squared = force.length_squared();
        if exceeds(size_squared, cap) {
            // size > cap >= 0: the direction is defined.
            let capped = force * (cap / size_squared.sqrt());
            *history = if k_t > 0.0 { -capped / k_t } else { Vec3::ZERO };
            capped
        } else {
            *history = u;
            force
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tests::contact_at;

    fn model(damping_factor: Real) -> CoulombMindlin {
        CoulombMindlin(Mindlin {
            g_eff: vec![1e6],
            damping_factor: vec![damping_factor],
            friction: vec![0.5],
        })
    }

    #[test]
    fn below_the_bound_it_is_the_history_law() {
        let mut c = contact_at(1e-5, 5e-4);
        c.tangential_velocity = Vec3::new(0.0, 1e-3, 0.0);
        let (mut u, mut v) = (Vec3::ZERO, Vec3::ZERO);
        let f = model(0.5).force(&c, 100.0, &mut u, 1e-3);
        let g = model(0.5).0.force(&c, 100.0, &mut v, 1e-3);
        assert_eq!((f, u), (g, v));
    }

    #[test]
    fn spring_plus_dashpot_is_capped_at_mu_max_fn_0_and_the_spring_carries_the_cap() {
        let mut c = contact_at(1e-5, 5e-4);
        // A slip the spring alone holds below the bound, but not with the dashpot.
        c.tangential_velocity = Vec3::new(0.0, 0.3, 0.0);
        let k_t = 8.0 * 1e6 * (5e-4_f64 * 1e-5).sqrt();
        let (n, dt) = (1e-3, 1e-7);
        assert!(k_t * 0.3 * dt < 0.5 * n);
        let mut u = Vec3::ZERO;
        let f = model(0.5).force(&c, n, &mut u, dt);
        assert!((f.length() - 0.5 * n).abs() < 1e-15 * n && f.y < 0.0);
        assert!((-k_t * u - f).length() < 1e-15 * n);
        // LIGGGHTS's law exceeds the bound here: the dashpot is added uncapped.
        let mut v = Vec3::ZERO;
        assert!(model(0.5).0.force(&c, n, &mut v, dt).length() > 0.5 * n);
        // No load, no friction: an attractive normal force leaves the slip free.
        let mut u = Vec3::new(0.0, 1e-7, 0.0);
        assert_eq!(model(0.5).force(&c, -n, &mut u, dt), Vec3::ZERO);
        assert_eq!(u, Vec3::ZERO);
    }
}
