//! The seed's tangential dissipation, paper A Eq. (1): `-gamma_t v_t`. No spring, no
//! Coulomb cap, no history, no rotation.

use super::super::{Contact, TangentialModel};
use crate::math::{Real, Vec3};

/// Tangential dashpot `gamma_t` (kg/s) per species pair.
#[derive(Clone, Debug)]
pub struct ViscousTangential {
    pub gamma_t: Vec<Real>,
}

impl TangentialModel for ViscousTangential {
    type History = ();
    const NEEDS_ROTATION: bool = false;

    #[inline(always)]
    fn force(&self, contact: &Contact, _: Real, _: &mut (), _: Real) -> Vec3 {
        -self.gamma_t[contact.species_pair] * contact.tangential_velocity
    }
}
