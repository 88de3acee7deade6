//! Analytic signed distance functions: negative inside, positive outside.

use crate::math::{Real, Vec3};

/// A signed distance field. `normal` is the unit gradient of `distance` (outward on the
/// surface); the default takes it by central differences.
pub trait Sdf {
    fn distance(&self, p: Vec3) -> Real;

    fn normal(&self, p: Vec3) -> Vec3 {
        numerical_normal(self, p)
    }
}

/// Unit gradient by central differences, step scaled to the coordinates so f64 keeps ~9 digits.
pub fn numerical_normal<S: Sdf + ?Sized>(sdf: &S, p: Vec3) -> Vec3 {
    let h = 1e-7 * (1.0 + p.abs().max_element());
    let d = |e: Vec3| sdf.distance(p + h * e) - sdf.distance(p - h * e);
    Vec3::new(d(Vec3::X), d(Vec3::Y), d(Vec3::Z)).normalize_or_zero()
}

impl<S: Sdf + ?Sized> Sdf for &S {
    fn distance(&self, p: Vec3) -> Real {
        (**self).distance(p)
    }
    fn normal(&self, p: Vec3) -> Vec3 {
        (**self).normal(p)
    }
}

impl<S: Sdf + ?Sized> Sdf for Box<S> {
    fn distance(&self, p: Vec3) -> Real {
        (**self).distance(p)
    }
    fn normal(&self, p: Vec3) -> Vec3 {
        (**self).normal(p)
    }
}

/// Half-space behind a plane: the solid is where `(p - point) . normal < 0`.
#[derive(Clone, Copy, Debug)]
pub struct HalfSpace {
    pub point: Vec3,
    /// Unit outward normal.
    pub normal: Vec3,
}

impl HalfSpace {
    pub fn new(point: Vec3, normal: Vec3) -> HalfSpace {
        HalfSpace {
            point,
            normal: normal.normalize(),
        }
    }
}

impl Sdf for HalfSpace {
    fn distance(&self, p: Vec3) -> Real {
        (p - self.point).dot(self.normal)
    }
    fn normal(&self, _p: Vec3) -> Vec3 {
        self.normal
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: Real,
}

impl Sdf for Sphere {
    fn distance(&self, p: Vec3) -> Real {
        p.distance(self.center) - self.radius
    }
    fn normal(&self, p: Vec3) -> Vec3 {
        // At the centre every direction is a gradient; pick one rather than NaN.
        (p - self.center).try_normalize().unwrap_or(Vec3::Z)
    }
}

/// Local (radial, axial) coordinates of `p` around an axis through `center`.
fn radial_axial(p: Vec3, center: Vec3, axis: Vec3) -> (Real, Real) {
    let v = p - center;
    let y = v.dot(axis);
    ((v - y * axis).length(), y)
}

/// Finite cylinder with flat caps, centred on `center`, of total length `height` along `axis`.
#[derive(Clone, Copy, Debug)]
pub struct Cylinder {
    pub center: Vec3,
    /// Unit axis.
    pub axis: Vec3,
    pub radius: Real,
    pub height: Real,
}

impl Cylinder {
    pub fn new(center: Vec3, axis: Vec3, radius: Real, height: Real) -> Cylinder {
        Cylinder {
            center,
            axis: axis.normalize(),
            radius,
            height,
        }
    }
}

impl Sdf for Cylinder {
    fn distance(&self, p: Vec3) -> Real {
        let (x, y) = radial_axial(p, self.center, self.axis);
        let dx = x - self.radius;
        let dy = y.abs() - 0.5 * self.height;
        dx.max(dy).min(0.0) + Vec3::new(dx.max(0.0), dy.max(0.0), 0.0).length()
    }
}

/// Capped cone (frustum) along `axis`, centred on `center`: radius `bottom_radius` at
/// `-height/2`, `top_radius` at `+height/2`. Exact distance (after I. Quilez's sdCappedCone).
#[derive(Clone, Copy, Debug)]
pub struct Cone {
    pub center: Vec3,
    /// Unit axis, bottom to top.
    pub axis: Vec3,
    pub bottom_radius: Real,
    pub top_radius: Real,
    pub height: Real,
}

impl Cone {
    pub fn new(
        center: Vec3,
        axis: Vec3,
        bottom_radius: Real,
        top_radius: Real,
        height: Real,
    ) -> Cone {
        Cone {
            center,
            axis: axis.normalize(),
            bottom_radius,
            top_radius,
            height,
        }
    }
}

impl Sdf for Cone {
    fn distance(&self, p: Vec3) -> Real {
        let (x, y) = radial_axial(p, self.center, self.axis);
        let h = 0.5 * self.height;
        let (r1, r2) = (self.bottom_radius, self.top_radius);
        // 2D problem in the (radial, axial) half-plane against the trapezoid profile.
        let cap_r = if y < 0.0 { r1 } else { r2 };
        let ca = (x - x.min(cap_r), y.abs() - h);
        let k1 = (r2, h);
        let k2 = (r2 - r1, 2.0 * h);
        let t =
            (((k1.0 - x) * k2.0 + (k1.1 - y) * k2.1) / (k2.0 * k2.0 + k2.1 * k2.1)).clamp(0.0, 1.0);
        let cb = (x - k1.0 + k2.0 * t, y - k1.1 + k2.1 * t);
        let sign = if cb.0 < 0.0 && ca.1 < 0.0 { -1.0 } else { 1.0 };
        sign * (ca.0 * ca.0 + ca.1 * ca.1)
            .min(cb.0 * cb.0 + cb.1 * cb.1)
            .sqrt()
    }
}

/// Axis-aligned box.
#[derive(Clone, Copy, Debug)]
pub struct AxisAlignedBox {
    pub center: Vec3,
    pub half_extents: Vec3,
}

impl Sdf for AxisAlignedBox {
    fn distance(&self, p: Vec3) -> Real {
        let q = (p - self.center).abs() - self.half_extents;
        q.max(Vec3::ZERO).length() + q.max_element().min(0.0)
    }
}

/// Union of two solids. Exact outside; inside it underestimates depth where the parts overlap.
#[derive(Clone, Copy, Debug)]
pub struct Union<A, B>(pub A, pub B);

impl<A: Sdf, B: Sdf> Sdf for Union<A, B> {
    fn distance(&self, p: Vec3) -> Real {
        self.0.distance(p).min(self.1.distance(p))
    }
    fn normal(&self, p: Vec3) -> Vec3 {
        if self.0.distance(p) <= self.1.distance(p) {
            self.0.normal(p)
        } else {
            self.1.normal(p)
        }
    }
}

/// Intersection. A lower bound of the true distance outside near concave creases.
#[derive(Clone, Copy, Debug)]
pub struct Intersection<A, B>(pub A, pub B);

impl<A: Sdf, B: Sdf> Sdf for Intersection<A, B> {
    fn distance(&self, p: Vec3) -> Real {
        self.0.distance(p).max(self.1.distance(p))
    }
    fn normal(&self, p: Vec3) -> Vec3 {
        if self.0.distance(p) >= self.1.distance(p) {
            self.0.normal(p)
        } else {
            self.1.normal(p)
        }
    }
}

/// `A` with `B` cut away, max(dA, -dB); a bound like [`Intersection`].
#[derive(Clone, Copy, Debug)]
pub struct Difference<A, B>(pub A, pub B);

impl<A: Sdf, B: Sdf> Sdf for Difference<A, B> {
    fn distance(&self, p: Vec3) -> Real {
        self.0.distance(p).max(-self.1.distance(p))
    }
    fn normal(&self, p: Vec3) -> Vec3 {
        if self.0.distance(p) >= -self.1.distance(p) {
            self.0.normal(p)
        } else {
            -self.1.normal(p)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::accuracy::{seeded_rng, RandomPoints};

    fn assert_close(a: Real, b: Real) {
        assert!((a - b).abs() < 1e-12, "{a} != {b}");
    }

    #[test]
    fn half_space_distance_is_height_above_the_plane() {
        let floor = HalfSpace::new(Vec3::new(0.0, 0.0, 1.0), Vec3::Z * 3.0);
        assert_close(floor.distance(Vec3::new(5.0, -2.0, 3.5)), 2.5);
        assert_close(floor.distance(Vec3::new(0.0, 0.0, 0.0)), -1.0);
        assert_eq!(floor.normal(Vec3::ZERO), Vec3::Z);
    }

    #[test]
    fn cylinder_distance_to_side_cap_and_rim() {
        let c = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, 2.0);
        assert_close(c.distance(Vec3::new(3.0, 0.0, 0.5)), 2.0); // side
        assert_close(c.distance(Vec3::new(0.2, 0.0, 4.0)), 3.0); // cap
        assert_close(c.distance(Vec3::new(4.0, 0.0, 5.0)), 5.0); // rim, 3-4-5
        assert_close(c.distance(Vec3::new(0.0, 0.0, 0.0)), -1.0); // centre: nearest is the side
        assert_close(c.distance(Vec3::new(0.0, 0.0, 0.9)), -0.1); // near the cap
        let n = c.normal(Vec3::new(0.0, 2.0, 0.0));
        assert!(n.distance(Vec3::Y) < 1e-6);
    }

    #[test]
    fn cone_reduces_to_cylinder_with_equal_radii_and_matches_slant_distance() {
        let cone = Cone::new(Vec3::ZERO, Vec3::Z, 1.0, 1.0, 2.0);
        let cyl = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, 2.0);
        let mut rng = seeded_rng(1);
        for _ in 0..200 {
            let p = rng.vec_in_cube(3.0);
            assert!((cone.distance(p) - cyl.distance(p)).abs() < 1e-12);
        }
        // Cone of half-angle 45 deg: radius 2 at bottom, 0 at top, height 2.
        let cone = Cone::new(Vec3::ZERO, Vec3::Z, 2.0, 0.0, 2.0);
        let on_slant = Vec3::new(1.0, 0.0, 0.0);
        assert_close(cone.distance(on_slant), 0.0);
        let out = on_slant + Vec3::new(1.0, 0.0, 1.0).normalize() * 0.3;
        assert_close(cone.distance(out), 0.3);
        assert!(cone.distance(Vec3::new(0.0, 0.0, -0.5)) < 0.0);
        assert_close(cone.distance(Vec3::new(0.0, 0.0, -2.0)), 1.0); // below the base
    }

    #[test]
    fn box_distance_to_face_edge_and_inside() {
        let b = AxisAlignedBox {
            center: Vec3::ZERO,
            half_extents: Vec3::new(1.0, 2.0, 3.0),
        };
        assert_close(b.distance(Vec3::new(2.0, 0.0, 0.0)), 1.0);
        assert_close(b.distance(Vec3::new(4.0, 6.0, 0.0)), 5.0);
        assert_close(b.distance(Vec3::new(0.5, 0.0, 0.0)), -0.5);
    }

    #[test]
    fn combinators_follow_min_max_and_take_the_active_normal() {
        let a = Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        };
        let b = Sphere {
            center: Vec3::X * 1.5,
            radius: 1.0,
        };
        let p = Vec3::new(-2.0, 0.0, 0.0);
        assert_close(Union(a, b).distance(p), 1.0);
        assert_close(Intersection(a, b).distance(p), 2.5);
        assert_close(Difference(a, b).distance(Vec3::new(0.7, 0.0, 0.0)), 0.2);
        assert!(
            Difference(a, b)
                .normal(Vec3::new(0.45, 0.0, 0.0))
                .distance(Vec3::X)
                < 1e-12
        );
        let boxed: Box<dyn Sdf> = Box::new(Union(a, b));
        assert_close(boxed.distance(p), 1.0);
    }
}
