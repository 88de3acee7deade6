use std::collections::HashMap;

use super::aabb::Aabb;
use crate::math::{Real, Vec3};

/// Indexed triangle mesh. Outward orientation = counter-clockwise seen from outside.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub vertices: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// An edge that makes the surface not a closed, consistently oriented 2-manifold.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeDefect {
    pub vertices: [u32; 2],
    pub coordinates: [Vec3; 2],
    /// Triangles that use the edge.
    pub triangles: Vec<u32>,
}

/// Result of [`TriMesh::check_topology`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TopologyReport {
    /// Edges used by one triangle only: holes in the surface.
    pub open_edges: Vec<EdgeDefect>,
    /// Edges shared by more than two triangles.
    pub non_manifold_edges: Vec<EdgeDefect>,
    /// Edges shared by two triangles that traverse it in the same direction (one is flipped).
    pub inconsistent_edges: Vec<EdgeDefect>,
}

impl TopologyReport {
    pub fn is_closed(&self) -> bool {
        self.open_edges.is_empty()
    }

    pub fn is_closed_manifold_oriented(&self) -> bool {
        self.open_edges.is_empty()
            && self.non_manifold_edges.is_empty()
            && self.inconsistent_edges.is_empty()
    }
}

impl TriMesh {
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> TriMesh {
        TriMesh {
            vertices,
            triangles,
        }
    }

    /// Builds an indexed mesh from an STL-style triangle soup, merging vertices closer than
    /// `relative_tolerance` times the bounding-box diagonal. Triangles that collapse to a
    /// line or point after welding are dropped: they carry no area and break edge counting.
    pub fn from_triangle_soup(soup: &[[Vec3; 3]], relative_tolerance: Real) -> TriMesh {
        let bbox = Aabb::from_points(soup.iter().flatten());
        let tol = (relative_tolerance * bbox.diagonal()).max(Real::MIN_POSITIVE);
        let inv = 1.0 / tol;
        let cell_of = |p: Vec3| {
            let q = ((p - bbox.min) * inv).floor();
            (q.x as i64, q.y as i64, q.z as i64)
        };
        let mut cells: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
        let mut vertices: Vec<Vec3> = Vec::new();
        let mut triangles = Vec::with_capacity(soup.len());
        let tol2 = tol * tol;
        for tri in soup {
            let mut idx = [0u32; 3];
            for (k, &p) in tri.iter().enumerate() {
                let (cx, cy, cz) = cell_of(p);
                let mut found = None;
                // A match within tol can sit in any of the 27 neighbouring cells.
                'search: for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            if let Some(list) = cells.get(&(cx + dx, cy + dy, cz + dz)) {
                                for &v in list {
                                    if vertices[v as usize].distance_squared(p) <= tol2 {
                                        found = Some(v);
                                        break 'search;
                                    }
                                }
                            }
                        }
                    }
                }
                idx[k] = match found {
                    Some(v) => v,
                    None => {
                        let v = vertices.len() as u32;
                        vertices.push(p);
                        cells.entry((cx, cy, cz)).or_default().push(v);
                        v
                    }
                };
            }
            if idx[0] != idx[1] && idx[1] != idx[2] && idx[0] != idx[2] {
                triangles.push(idx);
            }
        }
        TriMesh {
            vertices,
            triangles,
        }
    }

    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Unit normal from the winding order (zero for a degenerate triangle).
    pub fn face_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangle(t);
        (b - a).cross(c - a).normalize_or_zero()
    }

    pub fn bounding_box(&self) -> Aabb {
        Aabb::from_points(&self.vertices)
    }

    /// Enclosed volume by the divergence theorem; negative if the mesh is oriented inward.
    /// Only meaningful for a closed mesh. Vertices are taken relative to the box centre so that
    /// a body far from the origin does not lose digits.
    pub fn volume(&self) -> Real {
        let o = self.bounding_box().center();
        let six_v: Real = (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.triangle(t);
                (a - o).dot((b - o).cross(c - o))
            })
            .sum();
        six_v / 6.0
    }

    pub fn surface_area(&self) -> Real {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.triangle(t);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Flips every triangle (turns an inward-oriented mesh outward).
    pub fn flip_orientation(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }

    /// The pieces that share no vertex (by index), each with its own vertices, in order of
    /// their first triangle. A mesh assembled from separate closed solids (the screw feeder's
    /// casing: prisms touching along faces) splits into those solids; LIGGGHTS refuses their
    /// union, whose seam edges belong to four triangles.
    pub fn components(&self) -> Vec<TriMesh> {
        let mut parent: Vec<u32> = (0..self.vertices.len() as u32).collect();
        fn root(parent: &mut [u32], mut v: u32) -> u32 {
            while parent[v as usize] != v {
                parent[v as usize] = parent[parent[v as usize] as usize];
                v = parent[v as usize];
            }
            v
        }
        for t in &self.triangles {
            for &v in &t[1..] {
                let (a, b) = (root(&mut parent, t[0]), root(&mut parent, v));
                parent[a as usize] = b;
            }
        }
        let mut piece_of_root: Vec<Option<usize>> = vec![None; self.vertices.len()];
        let mut pieces: Vec<(TriMesh, Vec<Option<u32>>)> = Vec::new();
        for t in &self.triangles {
            let r = root(&mut parent, t[0]) as usize;
            let k = *piece_of_root[r].get_or_insert_with(|| {
                pieces.push((
                    TriMesh::new(Vec::new(), Vec::new()),
                    vec![None; self.vertices.len()],
                ));
                pieces.len() - 1
            });
            let (mesh, index) = &mut pieces[k];
            let tri = t.map(|v| {
                *index[v as usize].get_or_insert_with(|| {
                    mesh.vertices.push(self.vertices[v as usize]);
                    mesh.vertices.len() as u32 - 1
                })
            });
            mesh.triangles.push(tri);
        }
        pieces.into_iter().map(|(mesh, _)| mesh).collect()
    }

    /// Finds every open, non-manifold and inconsistently oriented edge.
    pub fn check_topology(&self) -> TopologyReport {
        // (lower vertex, higher vertex, triangle, forward?) sorted so uses of an edge are adjacent.
        let mut uses: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(3 * self.triangles.len());
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                uses.push((a.min(b), a.max(b), t as u32, a < b));
            }
        }
        uses.sort_unstable();
        let mut report = TopologyReport::default();
        for group in uses.chunk_by(|x, y| x.0 == y.0 && x.1 == y.1) {
            let defect = || EdgeDefect {
                vertices: [group[0].0, group[0].1],
                coordinates: [
                    self.vertices[group[0].0 as usize],
                    self.vertices[group[0].1 as usize],
                ],
                triangles: group.iter().map(|u| u.2).collect(),
            };
            match group.len() {
                1 => report.open_edges.push(defect()),
                2 if group[0].3 == group[1].3 => report.inconsistent_edges.push(defect()),
                2 => {}
                _ => report.non_manifold_edges.push(defect()),
            }
        }
        report
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn components_split_solids_that_share_no_vertex_and_keep_their_triangles() {
        let tet = |o: Vec3| {
            TriMesh::new(
                vec![o, o + Vec3::X, o + Vec3::Y, o + Vec3::Z],
                vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            )
        };
        let mut two = tet(Vec3::ZERO);
        crate::geometry::mesh_builder::append(&mut two, tet(Vec3::X)); // touching, not welded
        let pieces = two.components();
        assert_eq!(pieces.len(), 2);
        // The same triangles, in order (vertices renumbered in order of first use).
        for (piece, o) in pieces.iter().zip([Vec3::ZERO, Vec3::X]) {
            let whole = tet(o);
            assert_eq!(piece.triangles.len(), 4);
            for t in 0..4 {
                assert_eq!(piece.triangle(t), whole.triangle(t));
            }
        }
    }

    /// Unit cube [0,1]^3 as a triangle soup, outward oriented, 12 triangles (2 per face).
    pub(crate) fn unit_cube_soup() -> Vec<[Vec3; 3]> {
        let v = |i: u32| {
            Vec3::new(
                (i & 1) as Real,
                ((i >> 1) & 1) as Real,
                ((i >> 2) & 1) as Real,
            )
        };
        // Each face as a CCW quad seen from outside.
        let quads = [
            [0, 2, 3, 1], // z = 0
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        quads
            .iter()
            .flat_map(|q| [[v(q[0]), v(q[1]), v(q[2])], [v(q[0]), v(q[2]), v(q[3])]])
            .collect()
    }

    #[test]
    fn welding_a_cube_soup_gives_8_vertices_and_a_closed_oriented_surface() {
        let mesh = TriMesh::from_triangle_soup(&unit_cube_soup(), 1e-6);
        assert_eq!(mesh.vertices.len(), 8);
        assert_eq!(mesh.triangles.len(), 12);
        assert!(mesh.check_topology().is_closed_manifold_oriented());
        assert!((mesh.volume() - 1.0).abs() < 1e-12);
        assert!((mesh.surface_area() - 6.0).abs() < 1e-12);
        let b = mesh.bounding_box();
        assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::ONE));
    }

    #[test]
    fn welding_merges_vertices_within_tolerance_relative_to_box() {
        let mut soup = unit_cube_soup();
        soup[0][0] += Vec3::splat(1e-9); // float noise as in an exported STL
        let mesh = TriMesh::from_triangle_soup(&soup, 1e-6);
        assert_eq!(mesh.vertices.len(), 8);
    }

    #[test]
    fn cube_missing_a_face_reports_its_four_open_edges() {
        let mut soup = unit_cube_soup();
        soup.drain(2..4); // the z = 1 face
        let mesh = TriMesh::from_triangle_soup(&soup, 1e-6);
        let report = mesh.check_topology();
        assert_eq!(report.open_edges.len(), 4);
        assert!(report.non_manifold_edges.is_empty());
        assert!(report.inconsistent_edges.is_empty());
        for e in &report.open_edges {
            assert!(e.coordinates.iter().all(|p| p.z == 1.0), "{e:?}");
            assert_eq!(e.triangles.len(), 1);
        }
    }

    #[test]
    fn flipped_triangle_is_reported_as_inconsistently_oriented() {
        let mut mesh = TriMesh::from_triangle_soup(&unit_cube_soup(), 1e-6);
        mesh.triangles[5].swap(1, 2);
        let report = mesh.check_topology();
        assert!(report.open_edges.is_empty());
        assert_eq!(report.inconsistent_edges.len(), 3);
        assert!(report
            .inconsistent_edges
            .iter()
            .all(|e| e.triangles.contains(&5)));
    }

    #[test]
    fn inward_oriented_cube_has_negative_volume() {
        let mut mesh = TriMesh::from_triangle_soup(&unit_cube_soup(), 1e-6);
        mesh.flip_orientation();
        assert!((mesh.volume() + 1.0).abs() < 1e-12);
        assert!(mesh.check_topology().is_closed_manifold_oriented());
    }

    #[test]
    fn third_triangle_on_an_edge_is_non_manifold() {
        let mut mesh = TriMesh::from_triangle_soup(&unit_cube_soup(), 1e-6);
        // A fin sharing the edge (0,0,0)-(1,0,0).
        mesh.vertices.push(Vec3::new(0.5, -1.0, -1.0));
        let fin = mesh.vertices.len() as u32 - 1;
        let a = mesh.vertices.iter().position(|p| *p == Vec3::ZERO).unwrap() as u32;
        let b = mesh.vertices.iter().position(|p| *p == Vec3::X).unwrap() as u32;
        mesh.triangles.push([a, b, fin]);
        let report = mesh.check_topology();
        assert_eq!(report.non_manifold_edges.len(), 1);
        assert_eq!(report.non_manifold_edges[0].triangles.len(), 3);
    }
}
