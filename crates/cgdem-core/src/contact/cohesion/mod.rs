//! Cohesion slot.

mod van_der_waals;

pub use van_der_waals::{vdw_force, vdw_reach, VanDerWaals};

use super::{CohesionModel, Contact};
use crate::math::Real;

/// No cohesion: costs nothing and adds nothing to the neighbour cut-off.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCohesion;

impl CohesionModel for NoCohesion {
    const ATTRACTS: bool = false;

    #[inline(always)]
    fn reach(&self) -> Real {
        0.0
    }

    #[inline(always)]
    fn force(&self, _: &Contact) -> Real {
        0.0
    }
}
