//! A rectangle in space that repels particles on its front side.

use crate::math::{Real, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct FinitePlane {
    pub point: Vec3,
    /// Unit normal pointing to the side particles live on.
    pub normal: Vec3,
    /// In-plane unit axes and half-lengths along them (infinite for an unbounded plane).
    pub axis_u: Vec3,
    pub axis_v: Vec3,
    pub half_u: Real,
    pub half_v: Real,
}

impl FinitePlane {
    /// A plane through `point` with normal `normal` (normalized here), bounded to
    /// `half_u` x `half_v` around `point` along two in-plane axes chosen from the normal.
    pub fn new(point: Vec3, normal: Vec3, half_u: Real, half_v: Real) -> Self {
        let normal = normal.normalize();
        let axis_u = normal.any_orthonormal_vector();
        let axis_v = normal.cross(axis_u);
        FinitePlane {
            point,
            normal,
            axis_u,
            axis_v,
            half_u,
            half_v,
        }
    }

    /// Signed distance of `p` from the plane along its normal, if `p` projects inside the
    /// rectangle.
    #[inline(always)]
    pub fn distance(&self, p: Vec3) -> Option<Real> {
        let d = p - self.point;
        let inside =
            d.dot(self.axis_u).abs() <= self.half_u && d.dot(self.axis_v).abs() <= self.half_v;
        inside.then(|| d.dot(self.normal))
    }
}
