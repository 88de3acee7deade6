//! Private helpers that build closed, outward-oriented triangle pieces and append them to a
//! [`TriMesh`]. Only the two public fields of `TriMesh` are used, so this module keeps working
//! when `mesh.rs` is replaced by the full implementation.

use crate::geometry::mesh::TriMesh;
use crate::math::{Real, Vec3};

/// An empty mesh.
pub(crate) fn empty() -> TriMesh {
    TriMesh {
        vertices: Vec::new(),
        triangles: Vec::new(),
    }
}

/// Appends `src` to `dst` as a separate connected component (indices shifted, nothing welded).
pub(crate) fn append(dst: &mut TriMesh, src: TriMesh) {
    let offset = u32::try_from(dst.vertices.len()).expect("mesh exceeds u32 vertex indices");
    dst.vertices.extend(src.vertices);
    dst.triangles.extend(
        src.triangles
            .into_iter()
            .map(|[a, b, c]| [a + offset, b + offset, c + offset]),
    );
}

/// Signed volume enclosed by a closed mesh: sum of the signed tetrahedra (origin, a, b, c) / 6.
/// Positive when the triangles are counter-clockwise seen from outside (outward normals).
pub(crate) fn signed_volume(mesh: &TriMesh) -> Real {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
            a.dot(b.cross(c))
        })
        .sum::<Real>()
        / 6.0
}

/// Makes a closed, consistently oriented piece outward oriented. Because the piece is closed,
/// the sign of its enclosed volume tells its orientation unambiguously; a negative one means
/// every triangle is wound inward, so all are reversed.
fn orient_outward(mut mesh: TriMesh) -> TriMesh {
    if signed_volume(&mesh) < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    mesh
}

/// Twice the signed area of a 2-D polygon (positive for counter-clockwise).
fn twice_area(poly: &[[Real; 2]]) -> Real {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let p = poly[i];
            let q = poly[(i + 1) % n];
            p[0] * q[1] - q[0] * p[1]
        })
        .sum()
}

fn cross2(o: [Real; 2], a: [Real; 2], b: [Real; 2]) -> Real {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Ear-clipping triangulation of a simple polygon (no holes, no repeated vertices).
/// The triangles have the same winding as the input loop, so a boundary edge `i -> i+1`
/// of the loop appears with that direction in exactly one triangle.
pub(crate) fn ear_clip(poly: &[[Real; 2]]) -> Vec<[usize; 3]> {
    let n = poly.len();
    assert!(n >= 3, "polygon needs at least 3 vertices");
    let ccw = twice_area(poly) > 0.0;
    // Work on a counter-clockwise index list.
    let mut idx: Vec<usize> = if ccw {
        (0..n).collect()
    } else {
        (0..n).rev().collect()
    };
    let scale = poly
        .iter()
        .flat_map(|p| p.iter())
        .fold(0.0_f64, |m, v| m.max(v.abs()))
        .max(1e-300);
    let eps = 1e-14 * scale * scale;
    let mut tris = Vec::with_capacity(n - 2);
    while idx.len() > 3 {
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (a, b, c) = (poly[ia], poly[ib], poly[ic]);
            if cross2(a, b, c) <= eps {
                continue; // reflex or degenerate corner
            }
            let blocked = idx.iter().any(|&j| {
                if j == ia || j == ib || j == ic {
                    return false;
                }
                let p = poly[j];
                cross2(a, b, p) >= -eps && cross2(b, c, p) >= -eps && cross2(c, a, p) >= -eps
            });
            if blocked {
                continue;
            }
            tris.push([ia, ib, ic]);
            idx.remove(k);
            clipped = true;
            break;
        }
        assert!(clipped, "ear clipping failed: polygon is not simple");
    }
    tris.push([idx[0], idx[1], idx[2]]);
    if !ccw {
        for t in &mut tris {
            t.swap(1, 2);
        }
    }
    tris
}

/// Closed piece swept through a sequence of rings (each ring a closed loop with the same
/// number of vertices). Consecutive rings are joined by quads (two triangles each).
/// If `closed_path`, the last ring is joined back to the first and `cap` is ignored (a
/// torus-like piece); otherwise `cap` (a triangulation of the ring, same winding as the ring
/// loop) closes both ends. The result is oriented outward.
pub(crate) fn sweep_rings(rings: &[Vec<Vec3>], cap: &[[usize; 3]], closed_path: bool) -> TriMesh {
    let nr = rings.len();
    assert!(nr >= 2, "a sweep needs at least two rings");
    let m = rings[0].len();
    assert!(rings.iter().all(|r| r.len() == m), "rings differ in size");
    let id = |k: usize, i: usize| u32::try_from(k * m + i).expect("too many vertices");
    let mut mesh = empty();
    mesh.vertices = rings.iter().flatten().copied().collect();
    let spans = if closed_path { nr } else { nr - 1 };
    for k in 0..spans {
        let k1 = (k + 1) % nr;
        for i in 0..m {
            let i1 = (i + 1) % m;
            let (a, b, c, d) = (id(k, i), id(k, i1), id(k1, i1), id(k1, i));
            mesh.triangles.push([a, b, c]);
            mesh.triangles.push([a, c, d]);
        }
    }
    if !closed_path {
        for t in cap {
            // Start cap reversed, end cap as given: together with the side quads every
            // directed edge then appears once.
            mesh.triangles.push([id(0, t[0]), id(0, t[2]), id(0, t[1])]);
            mesh.triangles
                .push([id(nr - 1, t[0]), id(nr - 1, t[1]), id(nr - 1, t[2])]);
        }
    }
    orient_outward(mesh)
}

/// A 2-D polygon given in the (y, z) plane, extruded along x through the stations `xs`
/// (strictly increasing). Closed and outward oriented.
pub(crate) fn extrude_x(poly_yz: &[[Real; 2]], xs: &[Real]) -> TriMesh {
    let cap = ear_clip(poly_yz);
    let rings: Vec<Vec<Vec3>> = xs
        .iter()
        .map(|&x| poly_yz.iter().map(|p| Vec3::new(x, p[0], p[1])).collect())
        .collect();
    sweep_rings(&rings, &cap, false)
}

/// Stations from `x0` to `x1` with spacing at most `max_step` (at least one interval).
pub(crate) fn stations(x0: Real, x1: Real, max_step: Real) -> Vec<Real> {
    let n = ((x1 - x0) / max_step).ceil().max(1.0) as usize;
    (0..=n)
        .map(|i| {
            if i == n {
                x1
            } else {
                x0 + (x1 - x0) * i as Real / n as Real
            }
        })
        .collect()
}

/// Axis-aligned rectangle in the (x, y) plane: `[x_min, x_max, y_min, y_max]`.
pub(crate) type RectXY = [Real; 4];

/// Corners of a rectangle at height z, counter-clockwise seen from +z.
pub(crate) fn rect_corners(r: RectXY, z: Real) -> [Vec3; 4] {
    [
        Vec3::new(r[0], r[2], z),
        Vec3::new(r[1], r[2], z),
        Vec3::new(r[1], r[3], z),
        Vec3::new(r[0], r[3], z),
    ]
}

/// Closed hexahedron between a rectangle at `z0` and one at `z1 > z0` (a box or a frustum).
pub(crate) fn frustum_z(z0: Real, r0: RectXY, z1: Real, r1: RectXY) -> TriMesh {
    let rings = vec![rect_corners(r0, z0).to_vec(), rect_corners(r1, z1).to_vec()];
    sweep_rings(&rings, &[[0, 1, 2], [0, 2, 3]], false)
}

/// Grows a rectangle by `d` on every side (shrinks it for negative `d`).
pub(crate) fn grow(r: RectXY, d: Real) -> RectXY {
    [r[0] - d, r[1] + d, r[2] - d, r[3] + d]
}
