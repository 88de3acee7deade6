//! LIGGGHTS's particle-wall contact for `model hertz tangential history [rolling_friction
//! epsd2]` (`fix wall/gran ... primitive`): the pair law with the wall's radius and mass taken
//! as infinite (`R_eff = r`, `m_eff = m`), with a tangential and a rolling spring per particle
//! per wall (the contact's history, zeroed when they part).
//!
//! With `delta = r - h` (h the centre-to-plane distance), `a = sqrt(r delta)` and the contact
//! point at `c = r - delta/2` from the centre (LIGGGHTS `cri`):
//! - normal: `(4/3) Y_eff a delta - 2 sqrt(5/6) |beta(e_w)| sqrt(2 Y_eff a m) v_n`;
//! - tangential (LIGGGHTS `tangential_model_history.h`): the slip `v_t + c n x omega` is added
//!   to the shear displacement, which is then projected onto the tangent plane (no
//!   rescaling); `F_t = -k_t u`, `k_t = 8 G_eff a`; if `|F_t| > mu |F_n|` it is truncated and
//!   `u = -F_t/k_t` (no dashpot that step), else the dashpot `-2 sqrt(5/6)|beta| sqrt(k_t m) v_slip`
//!   is added; torque `(-c n) x F_t`;
//! - rolling (epsd2, `rolling_model_epsd2.h`): `M += k_t r^2 w_t dt`, capped at `mu_r r |F_n|`,
//!   torque `-M`; `F_n` is the total normal force (elastic + dashpot). For walls LIGGGHTS feeds
//!   `w = omega c/h` (its `cdata.wr`, the spin scaled by contact radius over distance), not
//!   `omega`: kept here, since the keyword promises LIGGGHTS's model.
//!
//! Bodies (SDF) use the same law with a history slot per particle per body, the relative
//! velocity taken against the body's surface velocity at the contact point. The stateless
//! `force` (the normal force and kinetic Coulomb friction of `HertzWall`) serves the time
//! step and particles that do not spin.
//!
//! The tangential slot is the pair law's: `Mindlin` (`tangential = "history"`, LIGGGHTS's) or
//! `CoulombMindlin` (`"coulomb"`), whose bound on the rolling torque (`cap_load`) applies here
//! too. All tables are by the particle's species and the wall's material
//! (`WallContact::pair_index`).
//!
//! `LIMIT_FORCE` (`limit_force = true`, LIGGGHTS `limitForce on`) clamps the normal force at
//! zero, as `contact::damping::LimitForce` does for pairs; a compile-time switch, so the
//! default wall is the same code as before.

use super::{HertzWall, WallContact, WallLaw};
use crate::contact::damping::liggghts_damping_factor;
use crate::contact::tangential::{Mindlin, MindlinSpring};
use crate::contact::TangentialModel;
use crate::contact::{exceeds, normal_force};
use crate::math::{Real, Vec3};

#[derive(Clone, Debug)]
pub struct HertzHistoryWall<T = Mindlin, const LIMIT_FORCE: bool = false> {
    /// The stateless law for bodies and the time step; its normal and damping slots give the
    /// normal force here too.
    pub stateless: HertzWall,
    /// The pair law's tangential slot.
    pub tangential: T,
    /// epsd2's `mu_r`; 0 = no rolling spring.
    pub rolling_friction: Vec<Real>,
}

impl HertzHistoryWall<Mindlin> {
    /// One wall material: per species `(Y_eff, G_eff)` of the particle-wall pair.
    pub fn new(
        moduli: &[(Real, Real)],
        restitution: Real,
        friction: Real,
        rolling_friction: Real,
        characteristic_velocity: Real,
    ) -> Self {
        let y_eff: Vec<Real> = moduli.iter().map(|m| m.0).collect();
        HertzHistoryWall {
            stateless: HertzWall::new(&y_eff, restitution, friction, 0.0, characteristic_velocity),
            tangential: Mindlin {
                g_eff: moduli.iter().map(|m| m.1).collect(),
                damping_factor: vec![liggghts_damping_factor(restitution); moduli.len()],
                friction: vec![friction; moduli.len()],
            },
            rolling_friction: vec![rolling_friction; moduli.len()],
        }
    }
}

impl<T: TangentialModel<History = Vec3> + MindlinSpring, const LIMIT_FORCE: bool> WallLaw
    for HertzHistoryWall<T, LIMIT_FORCE>
{
    const NEEDS_ROTATION: bool = true;
    /// (shear displacement, stored rolling torque).
    type History = (Vec3, Vec3);

    fn reach(&self, _: usize, radius: Real) -> Real {
        radius
    }

    fn force(&self, contact: &WallContact, dt: Real) -> Vec3 {
        self.stateless.force(contact, dt)
    }

    #[inline(always)]
    fn force_and_torque_with_history(
        &self,
        c: &WallContact,
        omega: Vec3,
        (shear, rolling): &mut (Vec3, Vec3),
        dt: Real,
    ) -> (Vec3, Vec3) {
        let n = c.normal;
        let delta = c.radius - c.distance;
        let normal_speed = c.relative_velocity.dot(n);
        let arm = c.radius - 0.5 * delta;
        let slip = c.relative_velocity - normal_speed * n + arm * n.cross(omega);
        let pair = c.pair_index(self.stateless.materials);
        let contact = c.as_pair(pair, c.relative_velocity, normal_speed, slip);
        let stateless = &self.stateless;
        let mut normal_force = normal_force(&stateless.normal, &stateless.damping, &contact);
        if LIMIT_FORCE {
            normal_force = normal_force.max(0.0);
        }
        let tangential = self.tangential.force(&contact, normal_force, shear, dt);
        let mut torque = (-arm * n).cross(tangential);

        let rolling_friction = self.rolling_friction[pair];
        if rolling_friction > 0.0 {
            let a = (c.radius * delta).sqrt();
            let k_t = 8.0 * self.tangential.mindlin().g_eff[pair] * a;
            let w = omega * (arm / c.distance);
            let w_t = w - w.dot(n) * n;
            *rolling += k_t * c.radius * c.radius * dt * w_t;
            let limit = rolling_friction * c.radius * T::cap_load(normal_force);
            // `|rolling| > limit` on squares: no square root below the cap (`exceeds`).
            let size_squared = rolling.length_squared();
            if exceeds(size_squared, limit) {
                *rolling *= limit / size_squared.sqrt();
            }
            torque -= *rolling;
        }
        (normal_force * n + tangential, torque)
    }

    fn linearized(
        &self,
        species: usize,
        material: usize,
        radius: Real,
        mass: Real,
    ) -> (Real, Real) {
        self.stateless.linearized(species, material, radius, mass)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact(delta: Real, v: Vec3) -> WallContact {
        WallContact {
            species: 0,
            material: 0,
            normal: Vec3::Z,
            distance: 1e-3 - delta,
            relative_velocity: v,
            radius: 1e-3,
            mass: 1e-5,
        }
    }

    fn law(rolling_friction: Real) -> HertzHistoryWall {
        HertzHistoryWall::new(&[(2.7e6, 1.0e6)], 0.5, 0.5, rolling_friction, 1.0)
    }

    #[test]
    fn sliding_is_capped_at_mu_fn_and_the_spring_truncated() {
        let c = contact(1e-5, Vec3::new(10.0, 0.0, 0.0));
        let mut h = (Vec3::ZERO, Vec3::ZERO);
        let (f, _) = law(0.0).force_and_torque_with_history(&c, Vec3::ZERO, &mut h, 1e-4);
        assert!((f.x.abs() - 0.5 * f.z).abs() < 1e-12 * f.z && f.x < 0.0);
        let k_t = 8.0 * 1.0e6 * (1e-3_f64 * 1e-5).sqrt();
        assert!((k_t * h.0.x - 0.5 * f.z).abs() < 1e-12 * f.z);
    }

    #[test]
    fn rolling_torque_opposes_the_spin_and_saturates_at_mu_r_r_fn() {
        let c = contact(1e-5, Vec3::ZERO);
        let mut h = (Vec3::ZERO, Vec3::ZERO);
        let (f, t) =
            law(0.1).force_and_torque_with_history(&c, Vec3::new(0.0, 1e6, 0.0), &mut h, 1e-3);
        // Spin about y makes the contact point slip along -x... the friction torque and the
        // rolling torque both oppose the spin; the rolling part is at its cap.
        assert!(t.y < 0.0);
        assert!((h.1.length() - 0.1 * 1e-3 * f.z).abs() < 1e-12 * f.z * 1e-3);
    }
}
