//! Constant-torque rolling resistance, paper B Eq. (10):
//! `T_i = -mu_r R_eff |F_n| w/|w|`, `T_j = -T_i`, with `w = omega_i - omega_j` less its
//! component along the normal (torsion is excluded, as in LIGGGHTS's default).
//!
//! Paper B writes `R_i`; for two equal spheres `R_i = 2 R_eff`, so its `mu_r` is half of ours.
//! LIGGGHTS `epsd2` (see `Epsd2`) is a rolling spring capped at the same `mu_r R_eff |F_n|`;
//! the two agree once the cap binds (steady rolling), not in elastic rolling oscillations.
//!
//! `w/|w|` flips with `w`; the torque is capped so it can remove at most `1/MAX_CONTACTS` of
//! `|w|` in one step: `|T| <= |w| / (MAX_CONTACTS dt (1/I_i + 1/I_j))`, solid spheres
//! `I = (2/5) m R^2`, so that all the contacts of a sphere together cannot reverse its spin
//! (see `tangential::yang`).

use super::super::{Contact, RollingModel};
use crate::contact::tangential::MAX_CONTACTS;
use crate::math::{Real, Vec3};

/// `mu_r` per species pair (dimensionless).
#[derive(Clone, Debug)]
pub struct ConstantTorque {
    pub rolling_friction: Vec<Real>,
}

impl RollingModel for ConstantTorque {
    type History = ();
    const NEEDS_ROTATION: bool = true;

    #[inline(always)]
    fn torque(
        &self,
        contact: &Contact,
        normal_force: Real,
        omega_i: Vec3,
        omega_j: Vec3,
        _: &mut (),
        dt: Real,
    ) -> Vec3 {
        let n = contact.normal;
        let relative = omega_i - omega_j;
        let w = relative - relative.dot(n) * n;
        let spin = w.length();
        if spin == 0.0 {
            return Vec3::ZERO;
        }
        let torque =
            self.rolling_friction[contact.species_pair] * contact.r_eff * normal_force.abs();
        let inv_inertia = 2.5 * contact.inv_mass_i / (contact.radius_i * contact.radius_i)
            + 2.5 * contact.inv_mass_j / (contact.radius_j * contact.radius_j);
        let no_reversal = spin / (MAX_CONTACTS * dt * inv_inertia);
        -(torque.min(no_reversal) / spin) * w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tests::contact_at;

    #[test]
    fn rolling_torque_is_mu_r_r_eff_fn_against_the_relative_spin_without_torsion() {
        let c = contact_at(1e-5, 5e-4);
        let model = ConstantTorque {
            rolling_friction: vec![0.1],
        };
        // Spin about y (rolling) plus about the normal x (torsion, ignored).
        let t = model.torque(&c, 2.0, Vec3::new(5.0, 3.0, 0.0), Vec3::ZERO, &mut (), 1e-6);
        assert!((t - Vec3::new(0.0, -0.1 * 5e-4 * 2.0, 0.0)).length() < 1e-15);
        // A tiny spin is only braked, never reversed.
        let t = model.torque(
            &c,
            2.0,
            Vec3::new(0.0, 1e-9, 0.0),
            Vec3::ZERO,
            &mut (),
            1e-6,
        );
        assert!(t.y < 0.0 && t.y.abs() < 0.1 * 5e-4 * 2.0);
    }
}
