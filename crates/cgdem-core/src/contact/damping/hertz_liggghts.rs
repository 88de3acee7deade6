//! LIGGGHTS `model hertz` normal dashpot (the same as LAMMPS `damping tsuji` with the mapped
//! coefficient, reference/MAPPING.md):
//! `F_d = -gamma_n v_n`, `gamma_n = -2 sqrt(5/6) beta sqrt(S_n m_eff)`,
//! `beta = ln e / sqrt(ln^2 e + pi^2)`, `S_n` the local Hertz stiffness.

use super::super::{Contact, DampingModel, NormalResponse};
use crate::math::Real;

/// `beta(e) = ln e / sqrt(ln^2 e + pi^2)` (<= 0; 0 for e = 1).
pub fn restitution_beta(restitution: Real) -> Real {
    let ln_e = restitution.ln();
    ln_e / (ln_e * ln_e + std::f64::consts::PI.powi(2)).sqrt()
}

/// `2 sqrt(5/6) |beta|`: `gamma = factor sqrt(S m_eff)`.
pub fn liggghts_damping_factor(restitution: Real) -> Real {
    -2.0 * (5.0_f64 / 6.0).sqrt() * restitution_beta(restitution)
}

/// Per species pair: `2 sqrt(5/6) |beta(e)|`.
#[derive(Clone, Debug)]
pub struct HertzDamping {
    pub factor: Vec<Real>,
}

impl HertzDamping {
    pub fn from_restitution(restitution: &[Real]) -> Self {
        HertzDamping {
            factor: restitution
                .iter()
                .map(|&e| liggghts_damping_factor(e))
                .collect(),
        }
    }
}

impl DampingModel for HertzDamping {
    #[inline(always)]
    fn force(&self, contact: &Contact, elastic: &NormalResponse) -> Real {
        -self.factor[contact.species_pair]
            * (elastic.stiffness * contact.m_eff).sqrt()
            * contact.normal_speed
    }

    fn linear_coefficient(&self, species_pair: usize, stiffness: Real, m_eff: Real) -> Real {
        self.factor[species_pair] * (stiffness * m_eff).sqrt()
    }
}
