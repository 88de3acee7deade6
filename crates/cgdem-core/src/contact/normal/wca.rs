//! The seed's repulsion, paper A Eq. (2): a purely repulsive Lennard-Jones (WCA) potential
//! `phi(r) = 4 eps [(sigma/r)^12 - (sigma/r)^6 + 1/4]` for `r <= 2^(1/6) sigma`, else 0.

use super::super::{Contact, NormalModel, NormalResponse};
use crate::math::{Real, TWO_POW_ONE_SIXTH};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WcaCoefficients {
    pub epsilon: Real,
    pub sigma: Real,
}

impl WcaCoefficients {
    /// `r_c = 2^(1/6) sigma`, where the force and the potential reach zero.
    pub fn cutoff(&self) -> Real {
        TWO_POW_ONE_SIXTH * self.sigma
    }

    /// Repulsive force magnitude `-dphi/dr` at centre distance `r` (zero beyond `r_c`).
    #[inline(always)]
    pub fn force(&self, r: Real) -> Real {
        if r >= self.cutoff() {
            return 0.0;
        }
        let s2 = self.sigma * self.sigma / (r * r);
        let s6 = s2 * s2 * s2;
        24.0 * self.epsilon * s6 * (2.0 * s6 - 1.0) / r
    }

    /// `phi(r)`, shifted to zero at `r_c`.
    pub fn potential(&self, r: Real) -> Real {
        if r >= self.cutoff() {
            return 0.0;
        }
        let s6 = (self.sigma / r).powi(6);
        4.0 * self.epsilon * (s6 * s6 - s6 + 0.25)
    }

    /// `-d(force)/dr`: the local stiffness.
    #[inline(always)]
    pub fn stiffness(&self, r: Real) -> Real {
        if r >= self.cutoff() {
            return 0.0;
        }
        let s2 = self.sigma * self.sigma / (r * r);
        let s6 = s2 * s2 * s2;
        24.0 * self.epsilon * s6 * (26.0 * s6 - 7.0) / (r * r)
    }

    /// Stiffness at the cut-off, `phi''(r_c) = 72 eps / r_c^2`: the linearized contact.
    pub fn contact_stiffness(&self) -> Real {
        72.0 * self.epsilon / (self.cutoff() * self.cutoff())
    }
}

/// WCA repulsion with coefficients per species pair.
#[derive(Clone, Debug)]
pub struct Wca {
    pub table: Vec<WcaCoefficients>,
}

impl NormalModel for Wca {
    fn cutoff(&self, species_pair: usize, _: Real, _: Real) -> Real {
        self.table[species_pair].cutoff()
    }

    #[inline(always)]
    fn response(&self, contact: &Contact) -> NormalResponse {
        let c = &self.table[contact.species_pair];
        NormalResponse {
            force: c.force(contact.distance),
            stiffness: 0.0, // viscous damping does not need it
        }
    }

    fn linear_stiffness(&self, species_pair: usize, _: Real, _: Real, _: Real) -> Real {
        self.table[species_pair].contact_stiffness()
    }

    fn elastic_energy(&self, species_pair: usize, _: Real, _: Real, distance: Real) -> Real {
        self.table[species_pair].potential(distance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn coke() -> WcaCoefficients {
        WcaCoefficients {
            epsilon: 9.434e-2,
            sigma: 1.203e-3,
        }
    }

    #[test]
    fn wca_force_vanishes_at_and_beyond_cutoff() {
        let c = coke();
        assert_eq!(c.force(c.cutoff()), 0.0);
        assert_eq!(c.force(1.5 * c.cutoff()), 0.0);
        // Continuous at the cut-off: just inside, the force is tiny.
        assert!(c.force(c.cutoff() * (1.0 - 1e-12)) < 1e-6);
        assert!(c.potential(c.cutoff() * (1.0 - 1e-9)).abs() < 1e-12);
    }

    #[test]
    fn wca_force_matches_closed_form_at_three_overlaps() {
        let c = coke();
        for overlap_fraction in [1e-4, 1e-3, 1e-2] {
            let r = c.cutoff() * (1.0 - overlap_fraction);
            // -dphi/dr by central differences of the potential, and the closed form
            // 48 eps sigma^12 / r^13 - 24 eps sigma^6 / r^7.
            let closed = 48.0 * c.epsilon * c.sigma.powi(12) / r.powi(13)
                - 24.0 * c.epsilon * c.sigma.powi(6) / r.powi(7);
            let h = r * 1e-7;
            let numeric = -(c.potential(r + h) - c.potential(r - h)) / (2.0 * h);
            assert!(
                (c.force(r) - closed).abs() <= 1e-12 * closed.abs(),
                "{overlap_fraction}"
            );
            assert!((c.force(r) - numeric).abs() <= 1e-5 * closed.abs());
            assert!(c.force(r) > 0.0);
        }
    }

    #[test]
    fn contact_stiffness_is_72_eps_over_rc_squared_and_matches_local_stiffness() {
        let c = coke();
        let k = c.contact_stiffness();
        assert!((k - c.stiffness(c.cutoff() * (1.0 - 1e-12))).abs() < 1e-6 * k);
        // Paper A (derived): about 3.73e6 N/m for coke.
        assert!((k / 3.73e6 - 1.0).abs() < 0.01, "k = {k}");
    }
}
