//! Rolling-resistance slot.

use super::{Contact, RollingModel};
use crate::math::Vec3;

/// No rolling resistance: costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRolling;

impl RollingModel for NoRolling {
    const NEEDS_ROTATION: bool = false;

    #[inline(always)]
    fn torque(&self, _: &Contact, _: f64, _: Vec3, _: Vec3) -> Vec3 {
        Vec3::ZERO
    }
}
