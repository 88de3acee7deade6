//! The seed's normal dissipation, paper A Eq. (1): `-gamma_n v_n`, a constant dashpot.

use super::super::{Contact, DampingModel, NormalResponse};
use crate::math::Real;

/// Normal dashpot `gamma_n` (kg/s) per species pair.
#[derive(Clone, Debug)]
pub struct ViscousNormal {
    pub gamma_n: Vec<Real>,
}

impl DampingModel for ViscousNormal {
    #[inline(always)]
    fn force(&self, contact: &Contact, _: &NormalResponse) -> Real {
        -self.gamma_n[contact.species_pair] * contact.normal_speed
    }

    fn linear_coefficient(&self, species_pair: usize, _: Real, _: Real) -> Real {
        self.gamma_n[species_pair]
    }
}
