//! Rolling-resistance slot.

mod constant_torque;
mod epsd2;

pub use constant_torque::ConstantTorque;
pub use epsd2::Epsd2;

use super::{Contact, RollingModel};
use crate::math::{Real, Vec3};

/// No rolling resistance: costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRolling;

impl RollingModel for NoRolling {
    type History = ();
    const NEEDS_ROTATION: bool = false;

    #[inline(always)]
    fn torque(&self, _: &Contact, _: Real, _: Vec3, _: Vec3, _: &mut (), _: Real) -> Vec3 {
        Vec3::ZERO
    }
}
