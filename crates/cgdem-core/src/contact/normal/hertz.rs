//! Hertz elastic repulsion, LIGGGHTS `model hertz` / LAMMPS `hertz/material`:
//! `F_n = (4/3) Y_eff sqrt(R_eff delta) delta`, local stiffness
//! `S_n = dF_n/d(delta) = 2 Y_eff sqrt(R_eff delta)`,
//! `1/Y_eff = (1 - nu_i^2)/Y_i + (1 - nu_j^2)/Y_j`.
//!
//! Paper B Eq. (4) writes `(2/3) E sqrt(R) xi^(3/2)` with `E = Y/(1 - nu^2)` of one material:
//! for identical particles `Y_eff = E/2`, so `(4/3) Y_eff = (2/3) E` and both are the same law.

use super::super::{Contact, NormalModel, NormalResponse};
use crate::math::Real;

/// An elastic material: Young's modulus (Pa) and Poisson's ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub youngs_modulus: Real,
    pub poisson_ratio: Real,
}

impl Material {
    /// `Y_eff` with `1/Y_eff = (1 - nu_a^2)/Y_a + (1 - nu_b^2)/Y_b`.
    pub fn y_eff(a: Material, b: Material) -> Real {
        1.0 / ((1.0 - a.poisson_ratio.powi(2)) / a.youngs_modulus
            + (1.0 - b.poisson_ratio.powi(2)) / b.youngs_modulus)
    }

    /// `G_eff` with `1/G_eff = 2 (2 - nu_a)(1 + nu_a)/Y_a + 2 (2 - nu_b)(1 + nu_b)/Y_b`
    /// (LIGGGHTS `model hertz`, `tangential history`).
    pub fn g_eff(a: Material, b: Material) -> Real {
        let part = |m: Material| {
            2.0 * (2.0 - m.poisson_ratio) * (1.0 + m.poisson_ratio) / m.youngs_modulus
        };
        1.0 / (part(a) + part(b))
    }
}

/// Hertz repulsion with `Y_eff` per species pair.
#[derive(Clone, Debug)]
pub struct Hertz {
    pub y_eff: Vec<Real>,
    /// Impact speed (m/s) at which the contact is linearized for the time step: the
    /// stiffness reported is `S_n` at the largest overlap of an undamped impact at this speed.
    pub characteristic_velocity: Real,
}

impl Hertz {
    /// Largest overlap of an undamped head-on impact at relative speed `v`:
    /// `delta_max = (15 m_eff v^2 / (16 Y_eff sqrt(R_eff)))^(2/5)`.
    pub fn max_overlap(y_eff: Real, r_eff: Real, m_eff: Real, v: Real) -> Real {
        (15.0 * m_eff * v * v / (16.0 * y_eff * r_eff.sqrt())).powf(0.4)
    }

    /// `S_n` at the largest overlap of an undamped impact at `characteristic_velocity`.
    pub fn stiffness_at_impact(&self, species_pair: usize, r_eff: Real, m_eff: Real) -> Real {
        let y = self.y_eff[species_pair];
        let delta = Hertz::max_overlap(y, r_eff, m_eff, self.characteristic_velocity);
        2.0 * y * (r_eff * delta).sqrt()
    }

    /// Duration of an undamped Hertz impact, `2.87 (m_eff^2 / (R_eff Y_eff^2 v))^(1/5)`.
    pub fn contact_time(y_eff: Real, r_eff: Real, m_eff: Real, v: Real) -> Real {
        2.868 * (m_eff * m_eff / (r_eff * y_eff * y_eff * v)).powf(0.2)
    }
}

impl NormalModel for Hertz {
    fn cutoff(&self, _: usize, radius_i: Real, radius_j: Real) -> Real {
        radius_i + radius_j
    }

    #[inline(always)]
    fn response(&self, contact: &Contact) -> NormalResponse {
        let y = self.y_eff[contact.species_pair];
        let a = (contact.r_eff * contact.overlap.max(0.0)).sqrt();
        NormalResponse {
            force: 4.0 / 3.0 * y * a * contact.overlap,
            stiffness: 2.0 * y * a,
        }
    }

    fn linear_stiffness(
        &self,
        species_pair: usize,
        radius_i: Real,
        radius_j: Real,
        m_eff: Real,
    ) -> Real {
        let r_eff = radius_i * radius_j / (radius_i + radius_j);
        self.stiffness_at_impact(species_pair, r_eff, m_eff)
    }

    /// `(8/15) Y_eff sqrt(R_eff) delta^(5/2)`, the integral of the force over the overlap.
    fn elastic_energy(
        &self,
        species_pair: usize,
        radius_i: Real,
        radius_j: Real,
        distance: Real,
    ) -> Real {
        let overlap = radius_i + radius_j - distance;
        if overlap <= 0.0 {
            return 0.0;
        }
        let r_eff = radius_i * radius_j / (radius_i + radius_j);
        8.0 / 15.0 * self.y_eff[species_pair] * r_eff.sqrt() * overlap.powf(2.5)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_particles_give_paper_b_prefactor_two_thirds_e() {
        let m = Material {
            youngs_modulus: 5e6,
            poisson_ratio: 0.3,
        };
        let e = m.youngs_modulus / (1.0 - 0.09);
        assert!((4.0 / 3.0 * Material::y_eff(m, m) - 2.0 / 3.0 * e).abs() < 1e-9 * e);
    }

    #[test]
    fn stiffness_is_derivative_of_force() {
        let hertz = Hertz {
            y_eff: vec![3e6],
            characteristic_velocity: 1.0,
        };
        let force = |delta: Real| 4.0 / 3.0 * 3e6 * (5e-4 * delta).sqrt() * delta;
        let contact = |delta: Real| crate::contact::tests::contact_at(delta, 5e-4);
        let delta = 1e-5;
        let r = hertz.response(&contact(delta));
        assert!((r.force - force(delta)).abs() < 1e-12 * r.force);
        let numeric = (force(delta * (1.0 + 1e-6)) - force(delta * (1.0 - 1e-6))) / (2e-6 * delta);
        assert!((r.stiffness - numeric).abs() < 1e-6 * numeric);
    }
}
