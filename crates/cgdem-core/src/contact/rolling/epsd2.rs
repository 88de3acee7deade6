//! LIGGGHTS `rolling_friction epsd2` (Iwashita & Oda; Ai et al. 2011, doc
//! `gran_rolling_friction_epsd2`): an elastic-plastic rolling spring. Each step the relative
//! rotation `d theta = (omega_i - omega_j) dt`, less its normal (torsion) part, loads the
//! stored torque, `M += -k_r d theta`, with `k_r = k_t R_eff^2`, `k_t = 8 G_eff sqrt(R_eff delta)`
//! the current Hertz tangential stiffness; then `|M| <= mu_r R_eff |F_n|` (truncated to the
//! cap). No viscous rolling torque. The stored `M` (the torque on `i`; `j` gets `-M`) is the
//! per-pair history and is zeroed when the contact ends. As in LIGGGHTS the stored torque is
//! not rotated with the contact.

use super::super::{exceeds, Contact, RollingModel};
use crate::math::{Real, Vec3};

/// Per species pair: `mu_r` and `G_eff` (Pa).
#[derive(Clone, Debug)]
pub struct Epsd2 {
    pub rolling_friction: Vec<Real>,
    pub g_eff: Vec<Real>,
}

impl RollingModel for Epsd2 {
    type History = Vec3;
    const NEEDS_ROTATION: bool = true;

    #[inline(always)]
    fn torque(
        &self,
        contact: &Contact,
        normal_force: Real,
        omega_i: Vec3,
        omega_j: Vec3,
        stored: &mut Vec3,
        dt: Real,
    ) -> Vec3 {
        let sp = contact.species_pair;
        let n = contact.normal;
        let relative = omega_i - omega_j;
        let rotation = (relative - relative.dot(n) * n) * dt;
        let k_t = 8.0 * self.g_eff[sp] * (contact.r_eff * contact.overlap.max(0.0)).sqrt();
        let k_r = k_t * contact.r_eff * contact.r_eff;
        let mut torque = *stored - k_r * rotation;
        let cap = self.rolling_friction[sp] * contact.r_eff * normal_force.abs();
        // `|torque| > cap` on squares: no square root below the cap (`exceeds`).
        let size_squared = torque.length_squared();
        if exceeds(size_squared, cap) {
            torque *= cap / size_squared.sqrt();
        }
        *stored = torque;
        torque
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tests::contact_at;

    #[test]
    fn epsd2_is_a_rolling_spring_k_t_r_squared_capped_at_mu_r_r_fn() {
        let c = contact_at(1e-5, 5e-4);
        let model = Epsd2 {
            rolling_friction: vec![0.1],
            g_eff: vec![1e6],
        };
        let k_r = 8.0 * 1e6 * (5e-4_f64 * 1e-5).sqrt() * 25e-8;
        let mut m = Vec3::ZERO;
        let t = model.torque(
            &c,
            100.0,
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::ZERO,
            &mut m,
            1e-6,
        );
        assert!((t.y + k_r * 1e-6).abs() < 1e-12 * k_r * 1e-6 && m == t);
        // Far past the cap the torque saturates at mu_r R_eff F_n.
        let t = model.torque(&c, 1e-3, Vec3::new(0.0, 1e6, 0.0), Vec3::ZERO, &mut m, 1e-3);
        assert!((t.y + 0.1 * 5e-4 * 1e-3).abs() < 1e-18);
    }
}
