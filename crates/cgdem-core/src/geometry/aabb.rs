use crate::math::{Real, Vec3};

/// Axis-aligned bounding box. An empty box has `min > max` so that growing it by a point works.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(Real::INFINITY),
        max: Vec3::splat(Real::NEG_INFINITY),
    };

    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Aabb {
        points.into_iter().fold(Aabb::EMPTY, |b, p| b.grown(*p))
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    pub fn grown(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    pub fn diagonal(&self) -> Real {
        if self.is_empty() {
            0.0
        } else {
            self.extent().length()
        }
    }

    /// Squared distance from `p` to the box (zero inside).
    pub fn distance_squared(&self, p: Vec3) -> Real {
        let d = (self.min - p).max(p - self.max).max(Vec3::ZERO);
        d.length_squared()
    }

    /// Distance from `p` to the farthest corner: bounds the distance to anything in the box.
    pub fn max_distance(&self, p: Vec3) -> Real {
        (p - self.min).abs().max((p - self.max).abs()).length()
    }
}

/// Whether `p` lies in one of the delete regions (bounds included).
pub(crate) fn in_delete_region(regions: &[Aabb], p: Vec3) -> bool {
    regions
        .iter()
        .any(|r| p.cmpge(r.min).all() && p.cmple(r.max).all())
}
