//! Rolling-resistance slot.

mod constant_torque;

pub use constant_torque::ConstantTorque;

use super::{Contact, RollingModel};
use crate::math::{Real, Vec3};

/// No rolling resistance: costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRolling;

impl RollingModel for NoRolling {
    const NEEDS_ROTATION: bool = false;

    #[inline(always)]
    fn torque(&self, _: &Contact, _: Real, _: Vec3, _: Vec3, _: Real) -> Vec3 {
        Vec3::ZERO
    }
}
