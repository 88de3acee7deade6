//! Paper B Eq. (5) (Yang, Zou & Yu 2000, a Mindlin-Deresiewicz form):
//! `F_t = -mu |F_n| (1 - (1 - min(xi_s, xi_max)/xi_max)^(3/2)) v_t/|v_t|`,
//! `xi_max = mu (2 - nu) / (2 (1 - nu)) xi_n`, `xi_s = integral of |v_t| dt` since the contact
//! began (the history, a scalar, the same seen from either particle).
//!
//! `v_t/|v_t|` flips with `v_t` and would chatter around `v_t = 0` in an explicit scheme; the
//! magnitude is capped at `m_t |v_t| / (MAX_CONTACTS dt)`, the force that removes
//! `1/MAX_CONTACTS` of the contact-point slip in one step, with `m_t = (2/7) m_eff` the
//! effective mass of the contact point of two solid spheres
//! (`1/m_t = 1/m_i + 1/m_j + R_i^2/I_i + R_j^2/I_j`). A sphere among equal spheres has at most
//! 12 contacts, so all of them together cannot reverse its slip. (A cap that halves the slip
//! per contact overshoots once a sphere has five or more contacts: the slip then chatters with
//! speeds of order `mu F_n dt / m_t`, which for 1 um spheres held by van der Waals is about
//! 0.1 m/s, a kinetic energy that never decays.)

use super::super::{Contact, TangentialModel};
use crate::math::{Real, Vec3};

/// The most contacts one sphere has among equal spheres; each contact's regularized friction
/// may remove at most this fraction of the slip per step.
pub const MAX_CONTACTS: Real = 12.0;

/// Per species pair: `mu` and `mu (2 - nu) / (2 (1 - nu))`.
#[derive(Clone, Debug)]
pub struct YangTangential {
    pub friction: Vec<Real>,
    pub slip_factor: Vec<Real>,
}

impl YangTangential {
    pub fn slip_factor(friction: Real, poisson_ratio: Real) -> Real {
        friction * (2.0 - poisson_ratio) / (2.0 * (1.0 - poisson_ratio))
    }

    /// The slip factor of two materials (Mindlin): `mu Y*/(4 G*)`, which for one material
    /// is `mu (2 - nu)/(2 (1 - nu))` (`slip_factor`), since then `Y* = E/(2 (1 - nu^2))` and
    /// `G* = E/(4 (2 - nu)(1 + nu))`.
    pub fn slip_factor_of_pair(friction: Real, y_eff: Real, g_eff: Real) -> Real {
        friction * y_eff / (4.0 * g_eff)
    }
}

impl TangentialModel for YangTangential {
    type History = Real;
    const NEEDS_ROTATION: bool = true;

    #[inline(always)]
    fn force(&self, contact: &Contact, normal_force: Real, slip: &mut Real, dt: Real) -> Vec3 {
        let sp = contact.species_pair;
        let speed = contact.tangential_velocity.length();
        *slip += speed * dt;
        let xi_max = self.slip_factor[sp] * contact.overlap;
        if speed == 0.0 || xi_max <= 0.0 {
            return Vec3::ZERO;
        }
        let mobilized = 1.0 - (1.0 - slip.min(xi_max) / xi_max).powf(1.5);
        let magnitude = self.friction[sp] * normal_force.abs() * mobilized;
        let no_reversal = (2.0 / 7.0) * contact.m_eff * speed / (MAX_CONTACTS * dt);
        -(magnitude.min(no_reversal) / speed) * contact.tangential_velocity
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tests::contact_at;

    #[test]
    fn full_slip_gives_coulomb_friction_opposite_to_slip() {
        let model = YangTangential {
            friction: vec![0.3],
            slip_factor: vec![YangTangential::slip_factor(0.3, 0.3)],
        };
        let mut c = contact_at(1e-5, 5e-4);
        c.tangential_velocity = Vec3::new(0.0, 0.0, 1.0);
        let mut slip = 1.0; // far beyond xi_max
        let f = model.force(&c, 2.0, &mut slip, 1e-6);
        assert!((f.z + 0.6).abs() < 1e-12);
        // Half mobilized at xi_s = xi_max (1 - 2^(-3/2)).
        let mut slip = 0.0;
        let xi_max = YangTangential::slip_factor(0.3, 0.3) * 1e-5;
        c.tangential_velocity = Vec3::new(0.0, 0.0, xi_max * 1e6);
        let f = model.force(&c, 2.0, &mut slip, 1e-6);
        assert!((slip - xi_max).abs() < 1e-18 && (f.z + 0.6).abs() < 1e-12);
    }
}
