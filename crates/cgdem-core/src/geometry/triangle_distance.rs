//! Closest point on a triangle (Ericson, Real-Time Collision Detection, sec. 5.1.5).

use crate::math::{Real, Vec3};

/// Which part of the triangle the closest point lies on. Edge `i` joins vertex `i` and `(i+1)%3`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriangleFeature {
    Vertex(u8),
    Edge(u8),
    Face,
}

/// Exact closest point to `p` on triangle `(a, b, c)` and the feature it lies on.
/// Works by Voronoi regions, so degenerate (zero-area) triangles still give a point on them.
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, TriangleFeature) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, TriangleFeature::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, TriangleFeature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, TriangleFeature::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, TriangleFeature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, TriangleFeature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), TriangleFeature::Edge(1));
    }
    let denom = va + vb + vc;
    if denom.abs() <= Real::MIN_POSITIVE {
        // Degenerate triangle that slipped past the region tests: nearest vertex is exact enough.
        let best = [a, b, c]
            .into_iter()
            .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
            .unwrap_or(a);
        return (best, TriangleFeature::Face);
    }
    let v = vb / denom;
    let w = vc / denom;
    (a + ab * v + ac * w, TriangleFeature::Face)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::accuracy::{seeded_rng, RandomPoints};

    #[test]
    fn closest_point_on_triangle_matches_brute_force_sampling() {
        let mut rng = seeded_rng(7);
        for _ in 0..300 {
            let a = rng.vec_in_cube(1.0);
            let b = rng.vec_in_cube(1.0);
            let c = rng.vec_in_cube(1.0);
            let p = rng.vec_in_cube(2.0);
            let (q, _) = closest_point_on_triangle(p, a, b, c);
            // q must lie on the triangle: barycentric sampling never beats it.
            let exact = q.distance(p);
            let n = 120;
            let mut best = Real::INFINITY;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let u = i as Real / n as Real;
                    let v = j as Real / n as Real;
                    let s = a + u * (b - a) + v * (c - a);
                    best = best.min(s.distance(p));
                }
            }
            let edge = (b - a).length().max((c - a).length()).max((c - b).length());
            assert!(
                exact <= best + 1e-12,
                "closest point not closest: {exact} > {best}"
            );
            assert!(
                best - exact <= edge / n as Real,
                "sampling far below: {best} vs {exact}"
            );
            // The point is in the triangle's plane and inside its edges.
            let n_tri = (b - a).cross(c - a);
            if n_tri.length() > 1e-9 {
                assert!((q - a).dot(n_tri.normalize()).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn closest_point_features_of_unit_triangle() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let f = |p| closest_point_on_triangle(p, a, b, c);
        let (q, feature) = f(Vec3::new(0.2, 0.2, 1.0));
        assert!(q.distance(Vec3::new(0.2, 0.2, 0.0)) < 1e-12);
        assert_eq!(feature, TriangleFeature::Face);
        assert_eq!(f(Vec3::new(-1.0, -1.0, 0.0)).1, TriangleFeature::Vertex(0));
        assert_eq!(
            f(Vec3::new(0.5, -1.0, 0.0)),
            (Vec3::new(0.5, 0.0, 0.0), TriangleFeature::Edge(0))
        );
        assert_eq!(f(Vec3::new(1.0, 1.0, 0.0)).1, TriangleFeature::Edge(1));
        assert_eq!(f(Vec3::new(-1.0, 0.5, 0.0)).1, TriangleFeature::Edge(2));
    }
}
