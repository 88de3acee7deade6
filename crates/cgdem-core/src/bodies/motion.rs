//! Prescribed rigid motion: rotation about a fixed-direction axis through a point that
//! translates at constant velocity.

use crate::math::{Real, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Unit axis of rotation (any unit vector when there is no rotation).
    pub axis: Vec3,
    /// A point on the axis at the moment the motion starts (body frame = world frame then).
    pub point: Vec3,
    /// Angular speed about `axis`, rad/s, right-handed (negative turns clockwise seen from +axis).
    pub angular_speed: Real,
    /// Translation velocity of the whole body, m/s.
    pub velocity: Vec3,
}

impl Motion {
    /// A body at rest.
    pub fn fixed() -> Motion {
        Motion {
            axis: Vec3::Z,
            point: Vec3::ZERO,
            angular_speed: 0.0,
            velocity: Vec3::ZERO,
        }
    }

    /// Rotation at `rpm` revolutions per minute about `axis` through `point` (the sign of
    /// `rpm` gives the sense, right-handed about `axis`).
    pub fn rotation_rpm(axis: Vec3, point: Vec3, rpm: Real) -> Motion {
        Motion {
            axis: axis.normalize(),
            point,
            angular_speed: rpm * std::f64::consts::TAU / 60.0,
            velocity: Vec3::ZERO,
        }
    }

    pub fn with_velocity(mut self, velocity: Vec3) -> Motion {
        self.velocity = velocity;
        self
    }

    /// Angular velocity vector, rad/s.
    pub fn omega(&self) -> Vec3 {
        self.angular_speed * self.axis
    }

    pub fn is_fixed(&self) -> bool {
        self.angular_speed == 0.0 && self.velocity == Vec3::ZERO
    }
}
