//! Generalized winding number (Jacobson, Kavan, Sorkine-Hornung 2013): the solid angle the
//! surface subtends at a point over 4 pi. 1 inside a closed outward-oriented mesh, 0 outside,
//! and it degrades gracefully around holes, so `w > 0.5` is a robust inside test.
//! [`FastWindingNumber`] evaluates it hierarchically (Barill et al. 2018, first-order terms).

use std::f64::consts::PI;

use super::bvh::Bvh;
use super::mesh::TriMesh;
use crate::math::{Real, Vec3};

/// Signed solid angle of triangle `(a, b, c)` seen from `p` (Van Oosterom & Strackee 1983).
/// Positive when `p` is on the side the triangle's normal points away from.
pub fn triangle_solid_angle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Real {
    let (a, b, c) = (a - p, b - p, c - p);
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * numerator.atan2(denominator)
}

/// Exact winding number by summing over every triangle: O(n) per point, for tests and small
/// meshes.
pub fn winding_number(mesh: &TriMesh, p: Vec3) -> Real {
    let sum: Real = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.triangle(t);
            triangle_solid_angle(p, a, b, c)
        })
        .sum();
    sum / (4.0 * PI)
}

/// Far-field data of one BVH node: the node's triangles seen from afar act as one dipole.
#[derive(Clone, Copy, Debug)]
struct NodeMoment {
    /// Area-weighted centroid.
    center: Vec3,
    /// Sum of area-weighted normals, sum of (b - a) x (c - a) / 2.
    area_normal: Vec3,
    /// Radius around `center` that contains the node's triangles.
    radius: Real,
    area: Real,
}

/// Hierarchical winding number over a [`Bvh`]: clusters farther than `accuracy` times their
/// radius are replaced by their dipole term, nearby triangles are summed exactly.
pub struct FastWindingNumber<'a> {
    bvh: &'a Bvh,
    moments: Vec<NodeMoment>,
    accuracy: Real,
}

impl<'a> FastWindingNumber<'a> {
    /// `accuracy` = 2 gives |error| of order 1e-2 near clusters, far below the 0.5 that
    /// the inside test needs; larger is slower and more accurate.
    pub fn new(bvh: &'a Bvh) -> FastWindingNumber<'a> {
        Self::with_accuracy(bvh, 2.5)
    }

    pub fn with_accuracy(bvh: &'a Bvh, accuracy: Real) -> FastWindingNumber<'a> {
        let nodes = bvh.nodes();
        let mut moments = vec![
            NodeMoment {
                center: Vec3::ZERO,
                area_normal: Vec3::ZERO,
                radius: 0.0,
                area: 0.0,
            };
            nodes.len()
        ];
        // Children always come after their parent, so a reverse sweep sees children first.
        for i in (0..nodes.len()).rev() {
            let node = &nodes[i];
            let (weighted_center, area, area_normal) = if node.is_leaf() {
                let tris =
                    &bvh.triangles()[node.first as usize..(node.first + node.count) as usize];
                tris.iter()
                    .fold((Vec3::ZERO, 0.0, Vec3::ZERO), |(wc, ar, an), [a, b, c]| {
                        let n = 0.5 * (*b - *a).cross(*c - *a);
                        let area = n.length();
                        (wc + area * (*a + *b + *c) / 3.0, ar + area, an + n)
                    })
            } else {
                let (l, r) = (node.first as usize, node.first as usize + 1);
                let (al, ar) = (moments[l].area, moments[r].area);
                (
                    al * moments[l].center + ar * moments[r].center,
                    al + ar,
                    moments[l].area_normal + moments[r].area_normal,
                )
            };
            let center = if area > 0.0 {
                weighted_center / area
            } else {
                node.bounds.center()
            };
            moments[i] = NodeMoment {
                center,
                area_normal,
                radius: node.bounds.max_distance(center),
                area,
            };
        }
        FastWindingNumber {
            bvh,
            moments,
            accuracy,
        }
    }

    pub fn winding_number(&self, p: Vec3) -> Real {
        let nodes = self.bvh.nodes();
        if nodes.is_empty() {
            return 0.0;
        }
        let mut total = 0.0;
        let mut stack = Vec::with_capacity(64);
        stack.push(0usize);
        while let Some(i) = stack.pop() {
            let m = &self.moments[i];
            let r = m.center - p;
            let dist = r.length();
            if dist > self.accuracy * m.radius {
                // Dipole term: solid angle of a small oriented patch, n . r / |r|^3.
                total += m.area_normal.dot(r) / (dist * dist * dist);
                continue;
            }
            let node = &nodes[i];
            if node.is_leaf() {
                let tris =
                    &self.bvh.triangles()[node.first as usize..(node.first + node.count) as usize];
                for [a, b, c] in tris {
                    total += triangle_solid_angle(p, *a, *b, *c);
                }
            } else {
                stack.push(node.first as usize);
                stack.push(node.first as usize + 1);
            }
        }
        total / (4.0 * PI)
    }

    /// Inside test used for the sign of the distance field.
    pub fn is_inside(&self, p: Vec3) -> bool {
        self.winding_number(p) > 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::accuracy::{cylinder_mesh, seeded_rng, sphere_mesh, RandomPoints};

    #[test]
    fn winding_number_is_one_inside_and_zero_outside_a_closed_sphere() {
        let mesh = sphere_mesh(1.0, 3);
        let bvh = Bvh::new(&mesh);
        let fast = FastWindingNumber::new(&bvh);
        let mut rng = seeded_rng(11);
        for _ in 0..400 {
            let p = rng.vec_in_cube(2.0);
            let r = p.length();
            if (r - 1.0).abs() < 0.05 {
                continue; // faceting band
            }
            let expected = if r < 1.0 { 1.0 } else { 0.0 };
            let exact = winding_number(&mesh, p);
            assert!(
                (exact - expected).abs() < 1e-9,
                "exact w = {exact} at r = {r}"
            );
            let approx = fast.winding_number(p);
            assert!(
                (approx - exact).abs() < 0.02,
                "fast w = {approx}, exact {exact}"
            );
            assert_eq!(fast.is_inside(p), r < 1.0);
        }
    }

    #[test]
    fn inside_test_survives_a_deleted_triangle_away_from_the_hole() {
        let mut mesh = cylinder_mesh(1.0, 2.0, 64);
        // Remove one small side triangle; its centroid marks the hole.
        let t = (0..mesh.triangles.len())
            .find(|&t| mesh.face_normal(t).z.abs() < 1e-6)
            .expect("cylinder has side triangles");
        let [a, b, c] = mesh.triangle(t);
        let hole = (a + b + c) / 3.0;
        mesh.triangles.remove(t);
        assert_eq!(mesh.check_topology().open_edges.len(), 3);
        let bvh = Bvh::new(&mesh);
        let fast = FastWindingNumber::new(&bvh);
        let mut rng = seeded_rng(5);
        let mut checked = 0;
        for _ in 0..2000 {
            let p = rng.vec_in_cube(1.6);
            let radial = (p.x * p.x + p.y * p.y).sqrt();
            let boundary = (radial - 1.0).abs().min((p.z.abs() - 1.0).abs());
            if boundary < 0.02 || p.distance(hole) < 0.3 {
                continue;
            }
            let inside = radial < 1.0 && p.z.abs() < 1.0;
            assert_eq!(winding_number(&mesh, p) > 0.5, inside, "exact at {p}");
            assert_eq!(fast.is_inside(p), inside, "fast at {p}");
            checked += 1;
        }
        assert!(checked > 1000);
    }

    #[test]
    fn solid_angle_of_a_large_triangle_from_its_centroid_side() {
        // A point just behind the centroid of a triangle sees almost half the sphere: 2 pi.
        let (a, b, c) = (
            Vec3::new(-100.0, -100.0, 0.0),
            Vec3::new(100.0, -100.0, 0.0),
            Vec3::new(0.0, 150.0, 0.0),
        );
        let below = triangle_solid_angle(Vec3::new(0.0, 0.0, -1e-3), a, b, c);
        assert!((below - 2.0 * PI).abs() < 1e-3, "{below}");
        let above = triangle_solid_angle(Vec3::new(0.0, 0.0, 1e-3), a, b, c);
        assert!((above + 2.0 * PI).abs() < 1e-3, "{above}");
    }
}
