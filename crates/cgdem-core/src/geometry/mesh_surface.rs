//! A triangle surface that particles touch exactly, as LIGGGHTS's mesh walls (`fix
//! mesh/surface` with `fix wall/gran`): the contact point is the closest point on a face, an
//! edge or a vertex, and each edge and vertex shared by several triangles belongs to one of
//! them (or to none inside a flat patch), so that a particle touching the seam of a smooth
//! patch counts one contact, not one per triangle.
//!
//! The rules are LIGGGHTS 3.8's (`surface_mesh_I.h`, `tri_mesh_I.h`), learnt from its source:
//! - an edge shared by two triangles whose normals differ by less than the curvature angle
//!   ([`CURVATURE_DEG`]) is inactive in both (the face of either covers it); a shared edge
//!   of a fold is active in the triangle of the larger index only; an open edge is active;
//! - a vertex is active in the triangle of the largest index among those that share it,
//!   unless two of its edges are colinear (it lies on a straight seam or border) or none of
//!   its edges is active;
//! - the closest feature is found from the barycentric coordinates of the centre's
//!   projection, a coordinate counting as positive down to `-PRECISION / (2 r_bound)`;
//!   a contact whose feature is inactive in the triangle is not that triangle's.
//!
//! One difference, on purpose: LIGGGHTS 3.8 records a triangle's obtuse angle only when it
//! is at its third vertex (a later vertex's test overwrites an earlier one's), so near the
//! obtuse vertex of the others it measures the distance to the vertex, not to the nearer
//! edge. Here every obtuse angle is handled, so the distance is the exact one.

use super::aabb::Aabb;
use super::bvh::Bvh;
use super::mesh::TriMesh;
use crate::math::{Real, Vec3};

/// Two triangles are one smooth patch when their normals differ by less than this angle,
/// degrees (LIGGGHTS's `curvature` keyword of `fix mesh/surface`, as cgdem's decks write it).
pub const CURVATURE_DEG: Real = 1e-5;

/// LIGGGHTS's mesh precision (`EPSILON_PRECISION`, m): how far outside a triangle the
/// centre's projection may fall and still count as on its face.
const PRECISION: Real = 1e-8;

/// LIGGGHTS's `SMALL_TRIMESH`, m: the tolerance of the edge and vertex tests.
const SMALL: Real = 1e-10;

/// The closest point of one triangle to a particle centre, when the triangle owns it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Centre to closest point.
    pub distance: Real,
    pub point: Vec3,
    /// Whether the point is on the face (not an edge or vertex).
    pub face: bool,
}

/// A mesh prepared for exact contact: per triangle its corners, unit edge vectors, edge
/// lengths, normal and which of its edges and vertices are its own; the triangles of the
/// same smooth patch that share a vertex with it; and a BVH to find the triangles near a
/// point. Memory grows with the number of triangles only.
#[derive(Clone, Debug)]
pub struct MeshSurface {
    nodes: Vec<[Vec3; 3]>,
    /// `edge[i]`: unit vector from corner i to corner (i + 1) % 3.
    edges: Vec<[Vec3; 3]>,
    lengths: Vec<[Real; 3]>,
    normals: Vec<Vec3>,
    /// `PRECISION / (2 r_bound)`, r_bound the largest centroid-to-corner distance.
    tolerance: Vec<Real>,
    /// The corner with an obtuse angle, 3 for none.
    obtuse: Vec<u8>,
    /// Centroid and the largest centroid-to-corner distance: a bound that spares the exact
    /// test for triangles out of reach.
    spheres: Vec<(Vec3, Real)>,
    edge_active: Vec<[bool; 3]>,
    corner_active: Vec<[bool; 3]>,
    /// Triangles of the same patch sharing a vertex: `coplanar[start[t]..start[t + 1]]`.
    coplanar_start: Vec<u32>,
    coplanar: Vec<u32>,
    bvh: Bvh,
    bounds: Aabb,
    closed: bool,
}

impl MeshSurface {
    /// The surface of `mesh` (open or closed), or why it cannot be one: no triangles, or a
    /// triangle without area (two corners together, or all three on a line).
    pub fn new(mesh: &TriMesh) -> Result<MeshSurface, String> {
        let n = mesh.triangles.len();
        if n == 0 {
            return Err("the mesh has no triangles".into());
        }
        let cos_curvature = CURVATURE_DEG.to_radians().cos();
        let mut s = MeshSurface {
            nodes: Vec::with_capacity(n),
            edges: Vec::with_capacity(n),
            lengths: Vec::with_capacity(n),
            normals: Vec::with_capacity(n),
            tolerance: Vec::with_capacity(n),
            obtuse: Vec::with_capacity(n),
            spheres: Vec::with_capacity(n),
            edge_active: vec![[true; 3]; n],
            corner_active: vec![[true; 3]; n],
            coplanar_start: Vec::with_capacity(n + 1),
            coplanar: Vec::new(),
            bvh: Bvh::new(mesh),
            bounds: mesh.bounding_box(),
            closed: mesh.check_topology().is_closed(),
        };
        for t in 0..n {
            let p = mesh.triangle(t);
            let mut edges = [Vec3::ZERO; 3];
            let mut lengths = [0.0; 3];
            for i in 0..3 {
                let e = p[(i + 1) % 3] - p[i];
                lengths[i] = e.length();
                edges[i] = e / lengths[i];
            }
            let normal = edges[0].cross(edges[1]);
            if lengths.contains(&0.0) || normal.length() < 1e-12 {
                return Err(format!(
                    "triangle {} (corners {:?}, {:?}, {:?}) has no area",
                    t + 1,
                    p[0],
                    p[1],
                    p[2]
                ));
            }
            let center = (p[0] + p[1] + p[2]) / 3.0;
            let r_bound = p
                .iter()
                .map(|&c| (c - center).length())
                .fold(0.0, Real::max);
            let obtuse = (0..3)
                .find(|&i| edges[i].dot(edges[(i + 2) % 3]) > 0.0)
                .unwrap_or(3) as u8;
            s.nodes.push(p);
            s.edges.push(edges);
            s.lengths.push(lengths);
            // Divided, not multiplied by the reciprocal (as LIGGGHTS): an axis-aligned
            // normal comes out exact.
            s.normals.push(normal / normal.length());
            s.tolerance.push(PRECISION / (2.0 * r_bound));
            s.spheres.push((center, r_bound));
            s.obtuse.push(obtuse);
        }
        let by_vertex = triangles_by_vertex(mesh);
        s.mark_shared_edges(mesh, &by_vertex, cos_curvature);
        s.mark_corners(mesh, &by_vertex, cos_curvature);
        s.coplanar_start.push(0);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let mut patch: Vec<u32> = tri
                .iter()
                .flat_map(|&v| by_vertex[v as usize].iter().copied())
                .filter(|&o| {
                    o as usize != t && s.normals[t].dot(s.normals[o as usize]).abs() > cos_curvature
                })
                .collect();
            patch.sort_unstable();
            patch.dedup();
            s.coplanar.extend(patch);
            s.coplanar_start.push(s.coplanar.len() as u32);
        }
        Ok(s)
    }

    /// Shared edges: both inactive inside a smooth patch (unless the two triangles fold
    /// onto each other), else active in the triangle of the larger index only.
    fn mark_shared_edges(&mut self, mesh: &TriMesh, by_vertex: &[Vec<u32>], cos_curvature: Real) {
        for (i, ti) in mesh.triangles.iter().enumerate() {
            let mut others: Vec<u32> = ti
                .iter()
                .flat_map(|&v| by_vertex[v as usize].iter().copied())
                .filter(|&j| (j as usize) < i)
                .collect();
            others.sort_unstable();
            others.dedup();
            for j in others {
                let j = j as usize;
                let Some((ei, ej)) = shared_edge(ti, &mesh.triangles[j]) else {
                    continue;
                };
                let coplanar = self.normals[i].dot(self.normals[j]).abs() >= cos_curvature;
                if coplanar && !self.fold_onto(i, ei, j, ej) {
                    self.edge_active[i][ei] = false;
                    self.edge_active[j][ej] = false;
                } else {
                    self.edge_active[i][ei] = true;
                    self.edge_active[j][ej] = false;
                }
            }
        }
    }

    /// Whether two coplanar triangles sharing edge `ei` of `i` (`ej` of `j`) lie on the same
    /// side of it (LIGGGHTS's `coplanarNeighsOverlap`).
    fn fold_onto(&self, i: usize, ei: usize, j: usize, ej: usize) -> bool {
        let origin = self.nodes[i][ei];
        let out = self.edges[i][ei].cross(self.normals[i]);
        let a = (self.nodes[i][(ei + 2) % 3] - origin).dot(out);
        let b = (self.nodes[j][(ej + 2) % 3] - origin).dot(out);
        a * b > 0.0
    }

    /// Vertices: active in the sharing triangle of the largest index, unless two of the
    /// vertex's edges are colinear or none of them is active.
    fn mark_corners(&mut self, mesh: &TriMesh, by_vertex: &[Vec<u32>], cos_curvature: Real) {
        for (v, sharing) in by_vertex.iter().enumerate() {
            let mut edges = Vec::new();
            let mut any_active = false;
            for &t in sharing {
                let t = t as usize;
                let k = corner_of(&mesh.triangles[t], v as u32);
                let prev = (k + 2) % 3;
                edges.push((self.edges[t][k], mesh.triangles[t][(k + 1) % 3]));
                edges.push((self.edges[t][prev], mesh.triangles[t][prev]));
                any_active |= self.edge_active[t][k] || self.edge_active[t][prev];
            }
            let colinear = edges.iter().enumerate().any(|(a, ea)| {
                edges[a + 1..]
                    .iter()
                    .any(|eb| ea.0.dot(eb.0).abs() > cos_curvature && ea.1 != eb.1)
            });
            let owner = sharing.iter().copied().max();
            for &t in sharing {
                let k = corner_of(&mesh.triangles[t as usize], v as u32);
                self.corner_active[t as usize][k] = !colinear && any_active && Some(t) == owner;
            }
        }
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Whether every edge is shared (the surface encloses a solid).
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Bytes the surface holds (per triangle, and the BVH).
    pub fn bytes(&self) -> usize {
        let per_triangle = std::mem::size_of::<[Vec3; 3]>() * 2
            + std::mem::size_of::<[Real; 3]>()
            + std::mem::size_of::<Vec3>()
            + std::mem::size_of::<Real>()
            + 1
            + 6
            + 4;
        self.len() * per_triangle
            + 4 * self.coplanar.len()
            + std::mem::size_of_val(self.bvh.nodes())
            + std::mem::size_of_val(self.bvh.triangles())
            + std::mem::size_of_val(self.bvh.triangle_ids())
    }

    /// A distance from `p` that triangle `t` is not nearer than (from its bounding sphere;
    /// at most the exact distance).
    #[inline]
    pub fn distance_at_least(&self, t: usize, p: Vec3) -> Real {
        let (center, radius) = self.spheres[t];
        (p - center).length() - radius
    }

    /// Whether triangles `a` and `b` share a vertex and lie in one smooth patch.
    #[inline]
    pub fn coplanar(&self, a: u32, b: u32) -> bool {
        let range =
            self.coplanar_start[a as usize] as usize..self.coplanar_start[a as usize + 1] as usize;
        self.coplanar[range].binary_search(&b).is_ok()
    }

    /// The triangles whose bounding box lies within `reach` of `p`, in index order.
    pub fn triangles_near(&self, p: Vec3, reach: Real, out: &mut Vec<u32>) {
        out.clear();
        self.bvh.for_each_near(p, reach, |t| out.push(t));
        out.sort_unstable();
    }

    /// As [`MeshSurface::nearest`], searched no farther than `distance`.
    pub fn nearest_within(&self, p: Vec3, distance: Real) -> Option<(Real, Vec3)> {
        self.bvh
            .nearest_within(p, distance)
            .map(|n| (n.distance(), n.point))
    }

    /// Exact distance from `p` to the surface, with the closest point (any triangle's).
    pub fn nearest(&self, p: Vec3) -> Option<(Real, Vec3)> {
        self.bvh.nearest(p).map(|n| (n.distance(), n.point))
    }

    /// The closest point of triangle `t` to `p`, if the triangle owns its feature (a face,
    /// or an active edge or vertex); LIGGGHTS's `resolveTriSphereContactBary`.
    pub fn resolve(&self, t: usize, p: Vec3) -> Option<TriangleHit> {
        let n = &self.nodes[t];
        let e = &self.edges[t];
        let len = &self.lengths[t];
        let ap = p - n[0];
        // Barycentric coordinates of the projection (LIGGGHTS's `calcBaryTriCoords`).
        let a = ap.dot(e[0]);
        let b = ap.dot(e[2]);
        let c = e[0].dot(e[2]);
        let one_min_c2 = 1.0 - c * c;
        let b1 = (a - b * c) / (len[0] * one_min_c2);
        let b2 = (a * c - b) / (len[2] * one_min_c2);
        let b0 = 1.0 - b1 - b2;
        let tol = -self.tolerance[t];
        let sign = (b0 > tol) as u8 + 2 * (b1 > tol) as u8 + 4 * (b2 > tol) as u8;
        match sign {
            1 => self.corner(t, 0, p),
            2 => self.corner(t, 1, p),
            3 => self.edge(t, 0, p),
            4 => self.corner(t, 2, p),
            5 => self.edge(t, 2, p),
            6 => self.edge(t, 1, p),
            7 => {
                let normal = self.normals[t];
                let point = p - normal * normal.dot(ap);
                Some(hit(p, point, true))
            }
            // All three negative: not a point of the plane (NaN input).
            _ => None,
        }
    }

    /// Beyond edge `i` (LIGGGHTS's `resolveEdgeContactBary`): its closest point, or a corner's.
    fn edge(&self, t: usize, i: usize, p: Vec3) -> Option<TriangleHit> {
        let next = (i + 1) % 3;
        let n = &self.nodes[t];
        let along = (p - n[i]).dot(self.edges[t][i]);
        if along < -SMALL {
            self.corner_active[t][i].then(|| hit(p, n[i], false))
        } else if along > self.lengths[t][i] + SMALL {
            self.corner_active[t][next].then(|| hit(p, n[next], false))
        } else {
            let point = n[i] + along * self.edges[t][i];
            self.edge_active[t][i].then(|| hit(p, point, false))
        }
    }

    /// Beyond corner `k` (LIGGGHTS's `resolveCornerContactBary`): at an obtuse corner the
    /// closest point may lie on either edge.
    fn corner(&self, t: usize, k: usize, p: Vec3) -> Option<TriangleHit> {
        let (next, prev) = ((k + 1) % 3, (k + 2) % 3);
        let n = &self.nodes[t];
        let e = &self.edges[t];
        let len = &self.lengths[t];
        if self.obtuse[t] as usize == k {
            let to_p = p - n[k];
            let along = to_p.dot(e[prev]);
            if along < SMALL {
                return if along > -len[prev] {
                    let point = n[k] + along * e[prev];
                    self.edge_active[t][prev].then(|| hit(p, point, false))
                } else {
                    self.corner_active[t][prev].then(|| hit(p, n[prev], false))
                };
            }
            let along = to_p.dot(e[k]);
            if along > -SMALL {
                return if along < len[k] {
                    let point = n[k] + along * e[k];
                    self.edge_active[t][k].then(|| hit(p, point, false))
                } else {
                    self.corner_active[t][next].then(|| hit(p, n[next], false))
                };
            }
        }
        self.corner_active[t][k].then(|| hit(p, n[k], false))
    }
}

fn hit(p: Vec3, point: Vec3, face: bool) -> TriangleHit {
    TriangleHit {
        distance: (p - point).length(),
        point,
        face,
    }
}

/// For each vertex, the triangles that use it, in index order.
fn triangles_by_vertex(mesh: &TriMesh) -> Vec<Vec<u32>> {
    let mut by_vertex = vec![Vec::new(); mesh.vertices.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            if by_vertex[v as usize].last() != Some(&(t as u32)) {
                by_vertex[v as usize].push(t as u32);
            }
        }
    }
    by_vertex
}

/// The corner of `tri` at vertex `v`.
fn corner_of(tri: &[u32; 3], v: u32) -> usize {
    tri.iter()
        .position(|&w| w == v)
        .expect("the triangle uses the vertex")
}

/// The edge two triangles share, as each one's edge index (edge i joins corners i and i + 1).
fn shared_edge(a: &[u32; 3], b: &[u32; 3]) -> Option<(usize, usize)> {
    let edge = |t: &[u32; 3], i: usize| {
        let (x, y) = (t[i], t[(i + 1) % 3]);
        (x.min(y), x.max(y))
    };
    (0..3).find_map(|i| (0..3).find(|&j| edge(a, i) == edge(b, j)).map(|j| (i, j)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::accuracy::{seeded_rng, sphere_mesh, RandomPoints};
    use crate::geometry::closest_point_on_triangle;

    /// A square plate of two triangles (z = 0, side 2) sharing the diagonal.
    fn plate() -> TriMesh {
        TriMesh::new(
            vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    /// The closest active feature over all triangles, and how many triangles own one.
    fn contacts(s: &MeshSurface, p: Vec3) -> Vec<(usize, TriangleHit)> {
        (0..s.len())
            .filter_map(|t| s.resolve(t, p).map(|h| (t, h)))
            .collect()
    }

    #[test]
    fn a_flat_patch_has_no_inner_edges_and_its_straight_borders_no_vertices() {
        let s = MeshSurface::new(&plate()).unwrap();
        // The diagonal (edge 2 of triangle 0: 2 -> 0; edge 0 of triangle 1: 0 -> 2).
        assert!(!s.edge_active[0][2] && !s.edge_active[1][0]);
        assert!(s.edge_active[0][0] && s.edge_active[0][1]);
        assert!(s.coplanar(0, 1) && s.coplanar(1, 0));
        // Corners 0 and 2 are shared; each plate corner is active exactly once.
        let active: usize = s.corner_active.iter().flatten().filter(|&&a| a).count();
        assert_eq!(active, 4);
        // Above the diagonal: a face of one triangle only (the other's edge is inactive).
        let on_diagonal = Vec3::new(0.3, 0.3 + 1e-6, 0.5);
        let found = contacts(&s, on_diagonal);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].1.face && (found[0].1.distance - 0.5).abs() < 1e-15);
        // Beyond a plate corner: the vertex, counted once.
        let found = contacts(&s, Vec3::new(1.5, 1.5, 0.5));
        assert_eq!(found.len(), 1);
        assert!(!found[0].1.face && found[0].1.point == Vec3::new(1.0, 1.0, 0.0));
    }

    /// On a closed, curved mesh (no two triangles coplanar), every point sees its exact
    /// closest point in exactly one triangle: the one that owns the closest feature.
    #[test]
    fn each_point_of_a_sphere_mesh_has_one_owner_of_its_exact_closest_point() {
        let mesh = sphere_mesh(1.0, 2);
        let s = MeshSurface::new(&mesh).unwrap();
        assert!(s.is_closed());
        let mut rng = seeded_rng(7);
        let (mut on_edges, mut on_vertices) = (0, 0);
        for _ in 0..2000 {
            let p = rng.vec_in_cube(1.6);
            let exact = (0..mesh.triangles.len())
                .map(|t| {
                    let [a, b, c] = mesh.triangle(t);
                    closest_point_on_triangle(p, a, b, c).0.distance(p)
                })
                .fold(Real::INFINITY, Real::min);
            let found = contacts(&s, p);
            let nearest: Vec<_> = found
                .iter()
                .filter(|(_, h)| (h.distance - exact).abs() < 1e-12)
                .collect();
            assert_eq!(nearest.len(), 1, "p = {p:?}: {found:?}");
            if !nearest[0].1.face {
                let [a, b, c] = mesh.triangle(nearest[0].0);
                if [a, b, c].contains(&nearest[0].1.point) {
                    on_vertices += 1;
                } else {
                    on_edges += 1;
                }
            }
            // No triangle reports a point nearer than the exact closest one.
            assert!(found.iter().all(|(_, h)| h.distance >= exact - 1e-12));
        }
        assert!(on_edges > 50 && on_vertices > 5, "{on_edges} {on_vertices}");
    }

    #[test]
    fn an_obtuse_corner_gives_the_closest_point_on_its_edges() {
        // Obtuse at corner 0 (LIGGGHTS 3.8 records obtuse angles at corner 2 only).
        let mesh = TriMesh::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, -0.2, 0.0),
                Vec3::new(-1.0, -0.2, 0.0),
            ],
            vec![[0, 1, 2]],
        );
        let s = MeshSurface::new(&mesh).unwrap();
        assert_eq!(s.obtuse[0], 0);
        let p = Vec3::new(0.5, 0.3, 0.1);
        let h = s.resolve(0, p).unwrap();
        let [a, b, c] = mesh.triangle(0);
        let (exact, _) = closest_point_on_triangle(p, a, b, c);
        assert!((h.point - exact).length() < 1e-14, "{h:?} vs {exact:?}");
    }

    #[test]
    fn a_triangle_without_area_is_refused_by_number() {
        let mesh = TriMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)],
            vec![[0, 1, 2]],
        );
        let e = MeshSurface::new(&mesh).unwrap_err();
        assert!(e.contains("triangle 1") && e.contains("no area"), "{e}");
        assert!(MeshSurface::new(&TriMesh::default()).is_err());
    }
}
