//! Hertz particle-wall law: the particle law with the wall's radius taken as infinite, so
//! `R_eff = r` and `m_eff = m`, and `1/Y_eff = (1 - nu_p^2)/Y_p + (1 - nu_w^2)/Y_w`.
//!
//! **Normal.** The pair's slots `normal::Hertz` and `damping::HertzDamping` with the wall as a
//! partner of infinite radius and mass (`WallContact::as_pair`): `F_n = (4/3) Y_eff sqrt(r
//! delta) delta`, `delta = r - h` (h the centre-to-plane distance), with the LIGGGHTS
//! restitution dashpot `-2 sqrt(5/6) |beta(e_w)| sqrt(S_n m) v_n`.
//!
//! Used with paper B's laws (`rolling = "constant_torque"`, `yang`); scenes with LIGGGHTS's
//! keywords (`tangential = "history"`, rolling none or epsd2) get `HertzHistoryWall`, whose
//! springs are LIGGGHTS's.
//!
//! **Friction.** Not the history spring: the regularized kinetic Coulomb law of the seed's wall (`wca_wall`):
//! `-mu N v_t/|v_t|`, `N = max(F_n, 0)`, its magnitude capped at `m_c |v_t| / (2 dt)` so it can
//! at most halve the contact-point slip per step; `m_c = (2/7) m` is the effective mass of the
//! contact point of a solid sphere (`1/m_c = 1/m + r^2/I`). The contact-point velocity
//! includes the spin, and the force exerts a torque about the centre. Static friction is
//! therefore approximated by a stiff viscous law at tiny slip (about `2 dt F_t / m_c`).
//!
//! **Rolling.** Optional constant torque `-mu_r r N w/|w|` (`w` the spin less its component
//! along the normal), capped to at most halve `|w|` in one step.

use super::{WallContact, WallLaw};
use crate::contact::damping::HertzDamping;
use crate::contact::normal::Hertz;
use crate::contact::{normal_force, DampingModel};
use crate::math::{Real, Vec3};

/// The normal and damping slots of the pair law (tables by the particle's species and the
/// wall's material, `WallContact::pair_index`; the wall a partner of infinite radius and
/// mass), with the wall's friction laws beside them.
#[derive(Clone, Debug)]
pub struct HertzWall {
    /// Wall materials: the tables have one row per species and material.
    pub materials: usize,
    /// `Y_eff` of the particle-wall pair, and the impact speed at which the contact is
    /// linearized for the time step.
    pub normal: Hertz,
    /// `2 sqrt(5/6) |beta(e_w)|`.
    pub damping: HertzDamping,
    pub friction: Vec<Real>,
    pub rolling_friction: Vec<Real>,
}

impl HertzWall {
    /// One wall material: `y_eff` per species, one restitution and friction for all.
    pub fn new(
        y_eff: &[Real],
        restitution: Real,
        friction: Real,
        rolling_friction: Real,
        characteristic_velocity: Real,
    ) -> Self {
        let n = y_eff.len();
        HertzWall::from_tables(
            1,
            y_eff.to_vec(),
            &vec![restitution; n],
            vec![friction; n],
            vec![rolling_friction; n],
            characteristic_velocity,
        )
    }

    /// `materials` wall materials; the tables by `species * materials + material`.
    pub fn from_tables(
        materials: usize,
        y_eff: Vec<Real>,
        restitution: &[Real],
        friction: Vec<Real>,
        rolling_friction: Vec<Real>,
        characteristic_velocity: Real,
    ) -> Self {
        HertzWall {
            materials,
            normal: Hertz {
                y_eff,
                characteristic_velocity,
            },
            damping: HertzDamping::from_restitution(restitution),
            friction,
            rolling_friction,
        }
    }
}

impl WallLaw for HertzWall {
    const NEEDS_ROTATION: bool = true;
    type History = ();

    fn reach(&self, _: usize, radius: Real) -> Real {
        radius
    }

    fn force(&self, contact: &WallContact, dt: Real) -> Vec3 {
        self.force_and_torque(contact, Vec3::ZERO, dt).0
    }

    #[inline(always)]
    fn force_and_torque(&self, c: &WallContact, omega: Vec3, dt: Real) -> (Vec3, Vec3) {
        let n = c.normal;
        let arm = -n * c.distance; // centre to contact point
        let v = c.relative_velocity + omega.cross(arm);
        let normal_speed = v.dot(n);
        let tangential_velocity = v - normal_speed * n;
        let pair = c.pair_index(self.materials);
        let contact = c.as_pair(pair, v, normal_speed, tangential_velocity);
        let normal_force = normal_force(&self.normal, &self.damping, &contact);
        let load = normal_force.max(0.0);
        let mut force = normal_force * n;
        let mut torque = Vec3::ZERO;
        let slip = tangential_velocity.length();
        if slip > 0.0 {
            let no_reversal = (2.0 / 7.0) * c.mass * slip / (2.0 * dt);
            let friction =
                -(self.friction[pair] * load).min(no_reversal) / slip * tangential_velocity;
            force += friction;
            torque += arm.cross(friction);
        }
        let rolling_friction = self.rolling_friction[pair];
        if rolling_friction > 0.0 {
            let w = omega - omega.dot(n) * n;
            let spin = w.length();
            if spin > 0.0 {
                let no_reversal = spin * 0.4 * c.mass * c.radius * c.radius / (2.0 * dt);
                torque -= (rolling_friction * c.radius * load).min(no_reversal) / spin * w;
            }
        }
        (force, torque)
    }

    fn linearized(
        &self,
        species: usize,
        material: usize,
        radius: Real,
        mass: Real,
    ) -> (Real, Real) {
        let pair = species * self.materials + material;
        let k = self.normal.stiffness_at_impact(pair, radius, mass);
        (k, self.damping.linear_coefficient(pair, k, mass))
    }
}
