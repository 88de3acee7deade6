//! Bounding-volume hierarchy over the triangles of a mesh, for nearest-triangle queries.

use super::aabb::Aabb;
use super::mesh::TriMesh;
use super::triangle_distance::{closest_point_on_triangle, TriangleFeature};
use crate::math::{Real, Vec3};

const MAX_LEAF_TRIANGLES: usize = 4;
/// Median splits keep the tree balanced, so depth stays near log2(n / 4); 64 covers any mesh
/// that fits in memory.
const STACK_DEPTH: usize = 64;

#[derive(Clone, Copy, Debug)]
pub struct BvhNode {
    pub bounds: Aabb,
    /// Leaf: first entry in [`Bvh::triangles`]. Internal: index of the left child; the right child
    /// follows it.
    pub first: u32,
    /// Number of triangles in a leaf; zero for an internal node.
    pub count: u32,
}

impl BvhNode {
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Result of a nearest-triangle query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// Index of the triangle in the source mesh.
    pub triangle: u32,
    pub point: Vec3,
    pub distance_squared: Real,
    pub feature: TriangleFeature,
}

impl Nearest {
    pub fn distance(&self) -> Real {
        self.distance_squared.sqrt()
    }
}

#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
    /// Triangle corners in leaf order, copied so that a leaf is one contiguous read.
    triangles: Vec<[Vec3; 3]>,
    /// Source-mesh index of each entry of `triangles`.
    triangle_ids: Vec<u32>,
}

impl Bvh {
    pub fn new(mesh: &TriMesh) -> Bvh {
        let n = mesh.triangles.len();
        let mut items: Vec<(Vec3, u32)> = (0..n)
            .map(|t| {
                let [a, b, c] = mesh.triangle(t);
                ((a + b + c) / 3.0, t as u32)
            })
            .collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * n / MAX_LEAF_TRIANGLES + 1),
            triangles: Vec::with_capacity(n),
            triangle_ids: Vec::with_capacity(n),
        };
        if n == 0 {
            return bvh;
        }
        bvh.nodes.push(BvhNode {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
        });
        bvh.build(mesh, 0, &mut items, 0);
        bvh
    }

    fn build(&mut self, mesh: &TriMesh, node: usize, items: &mut [(Vec3, u32)], depth: usize) {
        let bounds = items
            .iter()
            .flat_map(|&(_, t)| mesh.triangle(t as usize))
            .fold(Aabb::EMPTY, Aabb::grown);
        self.nodes[node].bounds = bounds;
        if items.len() <= MAX_LEAF_TRIANGLES || depth + 2 >= STACK_DEPTH {
            self.nodes[node].first = self.triangles.len() as u32;
            self.nodes[node].count = items.len() as u32;
            for &(_, t) in items.iter() {
                self.triangles.push(mesh.triangle(t as usize));
                self.triangle_ids.push(t);
            }
            return;
        }
        let centroid_box = Aabb::from_points(items.iter().map(|(c, _)| c));
        let e = centroid_box.extent();
        let axis = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
        let left = self.nodes.len();
        let child = BvhNode {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
        };
        self.nodes.push(child);
        self.nodes.push(child);
        self.nodes[node].first = left as u32;
        let (lo, hi) = items.split_at_mut(mid);
        self.build(mesh, left, lo, depth + 1);
        self.build(mesh, left + 1, hi, depth + 1);
    }

    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// Triangle corners in leaf order (see [`BvhNode::first`]).
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    pub fn triangle_ids(&self) -> &[u32] {
        &self.triangle_ids
    }

    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// Calls `f` with the source index of every triangle whose bounding box lies within
    /// `reach` of `p` (in tree order; a superset of those within `reach`).
    pub fn for_each_near(&self, p: Vec3, reach: Real, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let reach2 = reach * reach;
        let mut stack = [0u32; STACK_DEPTH];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = &self.nodes[stack[len] as usize];
            if node.bounds.distance_squared(p) > reach2 {
                continue;
            }
            if node.is_leaf() {
                for k in node.first..node.first + node.count {
                    let [a, b, c] = self.triangles[k as usize];
                    let lo = a.min(b).min(c);
                    let hi = a.max(b).max(c);
                    let d = (lo - p).max(p - hi).max(Vec3::ZERO);
                    if d.length_squared() <= reach2 {
                        f(self.triangle_ids[k as usize]);
                    }
                }
                continue;
            }
            stack[len] = node.first;
            stack[len + 1] = node.first + 1;
            len += 2;
        }
    }

    /// Closest triangle to `p`, or `None` for an empty mesh.
    pub fn nearest(&self, p: Vec3) -> Option<Nearest> {
        self.nearest_within(p, Real::INFINITY)
    }

    /// Closest triangle to `p` no farther than `max_distance`. A good bound (e.g. the distance
    /// at a neighbouring grid node plus the spacing) prunes most of the tree.
    pub fn nearest_within(&self, p: Vec3, max_distance: Real) -> Option<Nearest> {
        let root = self.nodes.first()?;
        let mut best2 = max_distance * max_distance;
        let mut best: Option<Nearest> = None;
        if root.bounds.distance_squared(p) > best2 {
            return None;
        }
        let mut stack = [0u32; STACK_DEPTH];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = &self.nodes[stack[len] as usize];
            if node.bounds.distance_squared(p) > best2 {
                continue; // best improved since this node was pushed
            }
            if node.is_leaf() {
                let range = node.first as usize..(node.first + node.count) as usize;
                for (k, [a, b, c]) in self.triangles[range.clone()].iter().enumerate() {
                    let (q, feature) = closest_point_on_triangle(p, *a, *b, *c);
                    let d2 = q.distance_squared(p);
                    if d2 <= best2 {
                        best2 = d2;
                        best = Some(Nearest {
                            triangle: self.triangle_ids[range.start + k],
                            point: q,
                            distance_squared: d2,
                            feature,
                        });
                    }
                }
                continue;
            }
            let l = node.first as usize;
            let dl = self.nodes[l].bounds.distance_squared(p);
            let dr = self.nodes[l + 1].bounds.distance_squared(p);
            // Push the farther child first so the nearer one is searched first.
            let (near, d_near, far, d_far) = if dl <= dr {
                (l, dl, l + 1, dr)
            } else {
                (l + 1, dr, l, dl)
            };
            if d_far <= best2 {
                stack[len] = far as u32;
                len += 1;
            }
            if d_near <= best2 {
                stack[len] = near as u32;
                len += 1;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::accuracy::{seeded_rng, sphere_mesh, RandomPoints};

    #[test]
    fn bvh_nearest_matches_brute_force_over_all_triangles() {
        let mut mesh = sphere_mesh(1.0, 3);
        // Jitter the vertices so that ties between triangles are rare and the test is sharp.
        let mut rng = seeded_rng(3);
        for v in &mut mesh.vertices {
            *v += rng.vec_in_cube(0.02);
        }
        let bvh = Bvh::new(&mesh);
        for _ in 0..500 {
            let p = rng.vec_in_cube(2.5);
            let got = bvh.nearest(p).expect("mesh is not empty");
            let brute = (0..mesh.triangles.len())
                .map(|t| {
                    let [a, b, c] = mesh.triangle(t);
                    closest_point_on_triangle(p, a, b, c).0.distance_squared(p)
                })
                .fold(Real::INFINITY, Real::min);
            assert!(
                (got.distance_squared - brute).abs() <= 1e-12,
                "{} vs {}",
                got.distance_squared,
                brute
            );
            let [a, b, c] = mesh.triangle(got.triangle as usize);
            let again = closest_point_on_triangle(p, a, b, c).0;
            assert!(again.distance(got.point) < 1e-12);
        }
    }

    #[test]
    fn nearest_within_a_too_small_bound_finds_nothing() {
        let bvh = Bvh::new(&sphere_mesh(1.0, 2));
        assert!(bvh.nearest_within(Vec3::new(3.0, 0.0, 0.0), 1.5).is_none());
        let hit = bvh.nearest_within(Vec3::new(3.0, 0.0, 0.0), 2.5);
        assert!(hit.is_some_and(|n| (n.distance() - 2.0).abs() < 0.1));
        assert!(Bvh::new(&TriMesh::default()).nearest(Vec3::ZERO).is_none());
    }
}
