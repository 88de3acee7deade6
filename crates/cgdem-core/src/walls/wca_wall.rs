//! The seed's particle-wall law (paper A sec. 5.3): WCA repulsion, a dashpot set from a
//! restitution coefficient, and Coulomb kinetic friction, Eq. (12).
//!
//! **Normal.** The wall acts as the particle's mirror image: `Phi(h) = phi(2h)`, with `h` the
//! centre-to-plane distance and `phi` the particle-particle WCA potential of the species.
//! Contact starts at `h = r_c / 2` (one radius) and the force is `F = 2 f_pp(2h)`. The
//! linearized stiffness is `K = 4 phi''(r_c) = 4 * 72 eps / r_c^2`. (LAMMPS's
//! `fix wall/lj126` with `eps`, `sigma/2` and cut-off `r_c/2` is the same potential.)
//!
//! **Damping.** `F_d = -gamma_w v_n` with `gamma_w = 2 zeta sqrt(K m)`,
//! `zeta = -ln(e) / sqrt(pi^2 + ln(e)^2)`: the damping ratio for which a linear
//! spring-dashpot of stiffness `K` and mass `m` rebounds with restitution `e`.
//!
//! **Friction.** `f_t = -mu N v_t/|v_t|` with `N = max(F_n + F_d, 0)`. A kinetic law flips
//! sign with `v_t` and chatters around `v_t = 0` in an explicit integrator; so the magnitude
//! is capped at `m |v_t| / (2 dt)`, the force that halves `v_t` within one step and so can
//! never reverse it. Below `|v_t| = 2 dt mu N / m` (about 1e-5 m/s here) the law is a
//! strong viscous one and sliding stops smoothly instead of chattering.

use super::{WallContact, WallLaw};
use crate::contact::normal::WcaCoefficients;
use crate::math::{Real, Vec3};

/// Damping ratio of a linear spring-dashpot that rebounds with restitution `e` (0 < e <= 1).
pub fn restitution_damping_ratio(restitution: Real) -> Real {
    let ln_e = restitution.ln();
    -ln_e / (std::f64::consts::PI.powi(2) + ln_e * ln_e).sqrt()
}

#[derive(Clone, Debug)]
pub struct WcaWallSpecies {
    pub wca: WcaCoefficients,
    /// Dashpot (kg/s) from the wall restitution and the species mass.
    pub gamma: Real,
    pub friction: Real,
}

/// Per species (walls of the WCA model have no materials: `WallContact::material` is 0).
#[derive(Clone, Debug)]
pub struct WcaWall {
    pub species: Vec<WcaWallSpecies>,
}

impl WcaWall {
    /// Builds the law for species of the given WCA coefficients and masses.
    pub fn new(species: &[(WcaCoefficients, Real)], restitution: Real, friction: Real) -> Self {
        let zeta = restitution_damping_ratio(restitution);
        let species = species
            .iter()
            .map(|&(wca, mass)| {
                let stiffness = 4.0 * wca.contact_stiffness();
                WcaWallSpecies {
                    wca,
                    gamma: 2.0 * zeta * (stiffness * mass).sqrt(),
                    friction,
                }
            })
            .collect();
        WcaWall { species }
    }
}

impl WallLaw for WcaWall {
    type History = ();
    fn reach(&self, species: usize, _: Real) -> Real {
        0.5 * self.species[species].wca.cutoff()
    }

    #[inline(always)]
    fn force(&self, c: &WallContact, dt: Real) -> Vec3 {
        let s = &self.species[c.species];
        let normal_speed = c.relative_velocity.dot(c.normal);
        let normal_force = 2.0 * s.wca.force(2.0 * c.distance) - s.gamma * normal_speed;
        let tangential_velocity = c.relative_velocity - normal_speed * c.normal;
        let slip = tangential_velocity.length();
        let mut force = normal_force * c.normal;
        if slip > 0.0 {
            let coulomb = s.friction * normal_force.max(0.0);
            let no_reversal = c.mass * slip / (2.0 * dt);
            force -= coulomb.min(no_reversal) / slip * tangential_velocity;
        }
        force
    }

    fn linearized(&self, species: usize, _: usize, _: Real, _: Real) -> (Real, Real) {
        let s = &self.species[species];
        (4.0 * s.wca.contact_stiffness(), s.gamma)
    }
}
