//! A mesh body that is a closed cylinder (a regular N-gon prism with both end caps), read
//! from its triangles so that a LAMMPS deck can write it as a `region ... cylinder`
//! (LAMMPS has no mesh walls). LAMMPS's cylinder regions lie along x, y or z, so the axis
//! must be one of those.

use cgdem_core::geometry::TriMesh;
use cgdem_core::math::{Real, Vec3};

/// A closed cylinder about a coordinate axis, as read from a mesh.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Cylinder {
    /// The axis: 0, 1, 2 for x, y, z.
    pub dim: usize,
    /// The axis's coordinates in the other two dimensions, in LAMMPS's order (x before y
    /// before z), m.
    pub centre: [Real; 2],
    /// Distance of the lateral vertices from the axis (the N-gon's corners), m.
    pub radius: Real,
    /// Distance of the lateral faces from the axis (the N-gon's apothem), m.
    pub apothem: Real,
    /// The end caps' coordinates along the axis, m.
    pub lo: Real,
    pub hi: Real,
    /// Sides of the N-gon (distinct angles of the lateral vertices).
    pub sides: usize,
}

impl Cylinder {
    /// LAMMPS's name of the axis.
    pub fn dim_name(&self) -> &'static str {
        ["x", "y", "z"][self.dim]
    }
}

/// Relative tolerance of the shape tests: binary STL stores single precision (7 digits).
const TOLERANCE: Real = 1e-5;

/// The closed cylinder the triangles of `mesh` form about the line through `point` along
/// `axis`, or why they do not: every triangle must lie either along the axis with its
/// vertices at one distance R from it (the lateral faces, sides of a regular N-gon) or
/// across it in one of two planes that bound the lateral faces (the end caps), and the
/// surface must be closed.
pub(crate) fn closed_cylinder(mesh: &TriMesh, point: Vec3, axis: Vec3) -> Result<Cylinder, String> {
    if !axis.is_finite() || axis.length() == 0.0 {
        return Err("it has no axis".into());
    }
    let a = axis / axis.length();
    let dim = (0..3)
        .find(|&k| (a[k].abs() - 1.0).abs() < 1e-9)
        .ok_or_else(|| {
            format!(
                "its axis [{}, {}, {}] is not along x, y or z, as LAMMPS's cylinder regions are",
                a.x, a.y, a.z
            )
        })?;
    // Distance along the axis and from it, per vertex.
    let along = |v: Vec3| (v - point).dot(a);
    let off = |v: Vec3| {
        let d = v - point;
        (d - a * d.dot(a)).length()
    };
    let size = mesh
        .vertices
        .iter()
        .map(|&v| off(v).max(along(v).abs()))
        .fold(0.0, Real::max);
    if !size.is_finite() || size == 0.0 || mesh.triangles.is_empty() {
        return Err("its mesh is empty".into());
    }
    let tol = TOLERANCE * size;
    let others = match dim {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    };
    let Faces {
        lateral_radii,
        face_distances,
        mut angles,
        caps,
    } = faces(mesh, point, a, others, tol)?;
    let radius = lateral_radii.iter().copied().fold(0.0, Real::max);
    let r_min = lateral_radii
        .iter()
        .copied()
        .fold(Real::INFINITY, Real::min);
    if lateral_radii.is_empty() || radius - r_min > tol {
        return Err(format!(
            "its faces along the axis have vertices from {r_min} to {radius} m off the axis, not all at one radius"
        ));
    }
    let sides = distinct_angles(&mut angles);
    let apothem = face_distances
        .iter()
        .copied()
        .fold(Real::INFINITY, Real::min);
    let expected = radius * (std::f64::consts::PI / sides as Real).cos();
    let a_max = face_distances.iter().copied().fold(0.0, Real::max);
    if sides < 3 || (apothem - expected).abs() > tol || (a_max - expected).abs() > tol {
        return Err(format!(
            "its faces along the axis are not the sides of a regular polygon ({sides} corners at {radius} m, faces {apothem} to {a_max} m from the axis)"
        ));
    }
    // The ends: the lateral faces' extent along the axis, each a plane of caps.
    let lateral_along: Vec<Real> = mesh
        .triangles
        .iter()
        .flat_map(|tri| tri.map(|i| mesh.vertices[i as usize]))
        .filter(|&v| (off(v) - radius).abs() <= tol)
        .map(along)
        .collect();
    let s_lo = lateral_along
        .iter()
        .copied()
        .fold(Real::INFINITY, Real::min);
    let s_hi = lateral_along
        .iter()
        .copied()
        .fold(-Real::INFINITY, Real::max);
    for &(t, s) in &caps {
        if (s - s_lo).abs() > tol && (s - s_hi).abs() > tol {
            return Err(format!(
                "triangle {t} lies across the axis {s} m along it, between the ends at {s_lo} and {s_hi} m"
            ));
        }
    }
    for (end, s) in [("lower", s_lo), ("upper", s_hi)] {
        if !caps.iter().any(|&(_, c)| (c - s).abs() <= tol) {
            return Err(format!(
                "it has no {end} end cap ({s} m along the axis): an open cylinder; LAMMPS decks write closed ones"
            ));
        }
    }
    let report = mesh.check_topology();
    if !report.is_closed() {
        return Err(format!(
            "its surface has {} open edges; LAMMPS decks write closed cylinders",
            report.open_edges.len()
        ));
    }
    let (e0, e1) = (point[dim] + s_lo * a[dim], point[dim] + s_hi * a[dim]);
    Ok(Cylinder {
        dim,
        centre: [point[others[0]], point[others[1]]],
        radius,
        apothem,
        lo: e0.min(e1),
        hi: e0.max(e1),
        sides,
    })
}

/// A mesh's triangles sorted into the lateral faces and the caps of a cylinder.
struct Faces {
    /// Distance from the axis of each lateral face's vertices.
    lateral_radii: Vec<Real>,
    /// Distance from the axis of each lateral face's plane.
    face_distances: Vec<Real>,
    /// Angle about the axis of each lateral face's vertices.
    angles: Vec<Real>,
    /// (triangle, distance along the axis) of each face across the axis.
    caps: Vec<(usize, Real)>,
}

/// The triangles of `mesh` along the unit `axis` through `point` and across it; any
/// other triangle is refused. `others` are the dimensions across the axis.
fn faces(
    mesh: &TriMesh,
    point: Vec3,
    a: Vec3,
    others: [usize; 2],
    tol: Real,
) -> Result<Faces, String> {
    let along = |v: Vec3| (v - point).dot(a);
    let mut f = Faces {
        lateral_radii: Vec::new(),
        face_distances: Vec::new(),
        angles: Vec::new(),
        caps: Vec::new(),
    };
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [p, q, r] = tri.map(|i| mesh.vertices[i as usize]);
        let n = (q - p).cross(r - p);
        if n.length() == 0.0 {
            continue;
        }
        let n = n / n.length();
        let cos = n.dot(a).abs();
        if cos > 1.0 - TOLERANCE {
            let s = along(p);
            if [q, r].iter().any(|&v| (along(v) - s).abs() > tol) {
                return Err(format!(
                    "triangle {t} lies across the axis but not in one plane"
                ));
            }
            f.caps.push((t, s));
        } else if cos < TOLERANCE {
            f.face_distances.push((p - point).dot(n).abs());
            for v in [p, q, r] {
                let d = v - point;
                f.lateral_radii.push((d - a * d.dot(a)).length());
                f.angles.push(d[others[1]].atan2(d[others[0]]));
            }
        } else {
            return Err(format!(
                "triangle {t} is neither along the axis nor across it (a cone, a helix or another shape)"
            ));
        }
    }
    Ok(f)
}

/// The number of distinct angles (radians, -pi..pi) in `angles`, which it sorts; angles
/// closer than 1e-6 rad are one, also across -pi/pi.
fn distinct_angles(angles: &mut [Real]) -> usize {
    const SAME: Real = 1e-6;
    angles.sort_by(Real::total_cmp);
    let Some((&first, &last)) = angles.first().zip(angles.last()) else {
        return 0;
    };
    let mut n = 1 + angles.windows(2).filter(|w| w[1] - w[0] > SAME).count();
    if n > 1 && first + std::f64::consts::TAU - last <= SAME {
        n -= 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A prism of `sides` about y through the origin, radius `r`, from y = -w/2 to w/2,
    /// with `caps` of its two ends, and `cone` shrinking its upper ring to `cone` times r.
    fn prism(sides: usize, r: Real, w: Real, caps: [bool; 2], cone: Real) -> TriMesh {
        let mut vertices = Vec::new();
        for (y, scale) in [(-0.5 * w, 1.0), (0.5 * w, cone)] {
            for k in 0..sides {
                let t = std::f64::consts::TAU * k as Real / sides as Real;
                vertices.push(Vec3::new(scale * r * t.cos(), y, scale * r * t.sin()));
            }
        }
        let n = sides as u32;
        let mut triangles = Vec::new();
        for k in 0..n {
            let k1 = (k + 1) % n;
            triangles.push([k, k1, n + k1]);
            triangles.push([k, n + k1, n + k]);
        }
        for (end, offset) in [(0, 0), (1, n)] {
            if caps[end] {
                for k in 1..n - 1 {
                    triangles.push(if end == 0 {
                        [offset, offset + k + 1, offset + k]
                    } else {
                        [offset, offset + k, offset + k + 1]
                    });
                }
            }
        }
        TriMesh::new(vertices, triangles)
    }

    #[test]
    fn a_closed_prism_is_read_with_its_axis_radius_and_ends() {
        let m = prism(40, 0.1, 0.02, [true, true], 1.0);
        let c = closed_cylinder(&m, Vec3::ZERO, Vec3::new(0.0, -1.0, 0.0)).unwrap();
        assert_eq!((c.dim, c.sides), (1, 40));
        assert!((c.radius - 0.1).abs() < 1e-12, "{c:?}");
        let apothem = 0.1 * (std::f64::consts::PI / 40.0).cos();
        assert!((c.apothem - apothem).abs() < 1e-12, "{c:?}");
        assert!(
            (c.lo + 0.01).abs() < 1e-12 && (c.hi - 0.01).abs() < 1e-12,
            "{c:?}"
        );
        assert_eq!(c.centre, [0.0, 0.0]);
    }

    #[test]
    fn open_cylinders_cones_and_other_axes_are_refused() {
        let y = Vec3::new(0.0, 1.0, 0.0);
        let open = prism(40, 0.1, 0.02, [true, false], 1.0);
        let e = closed_cylinder(&open, Vec3::ZERO, y).unwrap_err();
        assert!(e.contains("no upper end cap"), "{e}");
        let tube = prism(40, 0.1, 0.02, [false, false], 1.0);
        let e = closed_cylinder(&tube, Vec3::ZERO, y).unwrap_err();
        assert!(e.contains("open cylinder"), "{e}");
        let cone = prism(40, 0.1, 0.02, [true, true], 0.5);
        let e = closed_cylinder(&cone, Vec3::ZERO, y).unwrap_err();
        assert!(e.contains("neither along the axis nor across it"), "{e}");
        let closed = prism(40, 0.1, 0.02, [true, true], 1.0);
        // The right shape about another line: off its axis, the vertices' radii differ.
        let e = closed_cylinder(&closed, Vec3::new(0.01, 0.0, 0.0), y).unwrap_err();
        assert!(e.contains("not all at one radius"), "{e}");
        let e = closed_cylinder(&closed, Vec3::ZERO, Vec3::new(0.0, 1.0, 1.0)).unwrap_err();
        assert!(e.contains("not along x, y or z"), "{e}");
    }
}
