//! Paper B Eq. (4) dashpot (Yang, Zou & Yu 2000): `F_d = -gamma_n E sqrt(R) sqrt(xi_n) v_n`,
//! `gamma_n` in seconds. With `E = 2 Y_eff` (see `normal::Hertz`) this is
//! `-gamma_n S_n v_n`, `S_n = 2 Y_eff sqrt(R_eff xi_n)` the local Hertz stiffness.
//! Restitution then depends on the impact speed (unlike the LIGGGHTS form).

use super::super::{Contact, DampingModel, NormalResponse};
use crate::math::Real;

/// `gamma_n` (s) per species pair.
#[derive(Clone, Debug)]
pub struct YangDamping {
    pub gamma_n: Vec<Real>,
}

impl DampingModel for YangDamping {
    #[inline(always)]
    fn force(&self, contact: &Contact, elastic: &NormalResponse) -> Real {
        -self.gamma_n[contact.species_pair] * elastic.stiffness * contact.normal_speed
    }

    fn linear_coefficient(&self, species_pair: usize, stiffness: Real, _: Real) -> Real {
        self.gamma_n[species_pair] * stiffness
    }
}
