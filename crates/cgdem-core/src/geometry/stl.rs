//! STL input and output. Reading welds the triangle soup into a [`TriMesh`] and, in the strict
//! reader, refuses surfaces that are not closed and consistently oriented, because their
//! inside is undefined.

use std::fmt::Write as _;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use super::mesh::{EdgeDefect, TopologyReport, TriMesh};
use crate::math::{Real, Vec3};

/// Vertices closer than this fraction of the bounding-box diagonal are one vertex.
pub const WELD_TOLERANCE: Real = 1e-7;
/// How many defective edges an error message lists.
const LISTED_EDGES: usize = 5;

#[derive(Debug, thiserror::Error)]
pub enum StlError {
    #[error("cannot read {path}: {source}")]
    Unreadable {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write {path}: {source}")]
    Unwritable {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path} is not an STL file: {reason}")]
    NotStl { path: PathBuf, reason: String },
    #[error("{path} contains no triangles")]
    Empty { path: PathBuf },
    #[error("{path}: surface is not closed, {count} open edges, e.g.{}", list_edges(.first))]
    OpenEdges {
        path: PathBuf,
        count: usize,
        first: Vec<EdgeDefect>,
    },
    #[error(
        "{path}: surface is not a consistently oriented manifold, {count} bad edges \
         (shared by more than two triangles or by two with opposite orientation), e.g.{}",
        list_edges(.first)
    )]
    BadOrientation {
        path: PathBuf,
        count: usize,
        first: Vec<EdgeDefect>,
    },
}

fn list_edges(edges: &[EdgeDefect]) -> String {
    let mut s = String::new();
    for e in edges {
        let [a, b] = e.coordinates;
        let _ = write!(
            s,
            " ({:.6}, {:.6}, {:.6})-({:.6}, {:.6}, {:.6})",
            a.x, a.y, a.z, b.x, b.y, b.z
        );
    }
    s
}

/// Reads an ASCII or binary STL and checks that it is a closed, consistently oriented surface.
/// An inward-oriented but otherwise valid surface is flipped outward.
pub fn read_stl(path: &Path) -> Result<TriMesh, StlError> {
    let bytes = std::fs::read(path).map_err(|source| StlError::Unreadable {
        path: path.to_path_buf(),
        source,
    })?;
    stl_from_bytes(&bytes, path)
}

/// [`read_stl`] of bytes already read from `path` (named in errors).
pub fn stl_from_bytes(bytes: &[u8], path: &Path) -> Result<TriMesh, StlError> {
    let (mut mesh, report) = stl_unchecked_from_bytes(bytes, path)?;
    if !report.open_edges.is_empty() {
        return Err(StlError::OpenEdges {
            path: path.to_path_buf(),
            count: report.open_edges.len(),
            first: report.open_edges.into_iter().take(LISTED_EDGES).collect(),
        });
    }
    if !report.is_closed_manifold_oriented() {
        let bad: Vec<EdgeDefect> = report
            .non_manifold_edges
            .into_iter()
            .chain(report.inconsistent_edges)
            .collect();
        return Err(StlError::BadOrientation {
            path: path.to_path_buf(),
            count: bad.len(),
            first: bad.into_iter().take(LISTED_EDGES).collect(),
        });
    }
    if mesh.volume() < 0.0 {
        mesh.flip_orientation();
    }
    Ok(mesh)
}

/// Reads and welds an STL without rejecting defects; the report says what is wrong.
pub fn read_stl_unchecked(path: &Path) -> Result<(TriMesh, TopologyReport), StlError> {
    let bytes = std::fs::read(path).map_err(|source| StlError::Unreadable {
        path: path.to_path_buf(),
        source,
    })?;
    stl_unchecked_from_bytes(&bytes, path)
}

/// [`read_stl_unchecked`] of bytes already read from `path` (named in errors).
pub fn stl_unchecked_from_bytes(
    bytes: &[u8],
    path: &Path,
) -> Result<(TriMesh, TopologyReport), StlError> {
    let soup = parse_stl(bytes).map_err(|reason| StlError::NotStl {
        path: path.to_path_buf(),
        reason,
    })?;
    let mesh = TriMesh::from_triangle_soup(&soup, WELD_TOLERANCE);
    if mesh.triangles.is_empty() {
        return Err(StlError::Empty {
            path: path.to_path_buf(),
        });
    }
    let report = mesh.check_topology();
    Ok((mesh, report))
}

/// Parses STL bytes into a triangle soup, or says why they are not STL.
pub fn parse_stl(bytes: &[u8]) -> Result<Vec<[Vec3; 3]>, String> {
    let binary_size_ok = bytes.len() >= 84 && {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        bytes.len() == 84 + 50 * n
    };
    // Binary files may also begin with "solid", so the size rule decides when both fit.
    let looks_ascii = bytes.starts_with(b"solid") && !binary_size_ok;
    if !looks_ascii && !binary_size_ok {
        return Err(if bytes.len() < 84 {
            format!(
                "{} bytes is too short for binary STL and it does not start with \"solid\"",
                bytes.len()
            )
        } else {
            "binary size does not match its triangle count and it does not start with \"solid\""
                .into()
        });
    }
    let patched;
    let data: &[u8] = if looks_ascii && !bytes.starts_with(b"solid ") {
        // stl_io wants "solid <name>"; an unnamed solid is still valid STL.
        patched = [b"solid ".as_slice(), &bytes[5..]].concat();
        &patched
    } else {
        bytes
    };
    let mut reader = Cursor::new(data);
    let triangles = stl_io::create_stl_reader(&mut reader).map_err(|e| e.to_string())?;
    let mut soup = Vec::new();
    for (i, t) in triangles.enumerate() {
        let t = t.map_err(|e| format!("triangle {}: {e}", i + 1))?;
        let tri = t
            .vertices
            .map(|v| Vec3::new(v[0] as Real, v[1] as Real, v[2] as Real));
        if !tri.iter().all(|v| v.is_finite()) {
            return Err(format!("triangle {} has a non-finite coordinate", i + 1));
        }
        soup.push(tri);
    }
    Ok(soup)
}

fn to_stl_triangles(mesh: &TriMesh) -> Vec<stl_io::Triangle> {
    let v = |p: Vec3| stl_io::Vector::new([p.x as f32, p.y as f32, p.z as f32]);
    (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.triangle(t);
            stl_io::Triangle {
                normal: v(mesh.face_normal(t)),
                vertices: [v(a), v(b), v(c)],
            }
        })
        .collect()
}

pub fn write_stl_binary(path: &Path, mesh: &TriMesh) -> Result<(), StlError> {
    let unwritable = |source| StlError::Unwritable {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::create(path).map_err(unwritable)?;
    stl_io::write_stl(&mut file, to_stl_triangles(mesh).iter()).map_err(unwritable)
}

/// ASCII STL with f32-exact coordinates (9 significant digits), so a round trip through
/// binary or ASCII gives the same mesh.
pub fn write_stl_ascii(path: &Path, mesh: &TriMesh, solid_name: &str) -> Result<(), StlError> {
    std::fs::write(path, stl_ascii(mesh, solid_name)).map_err(|source| StlError::Unwritable {
        path: path.to_path_buf(),
        source,
    })
}

/// The text of [`write_stl_ascii`] (LIGGGHTS 3.8 reads ASCII STL only).
pub fn stl_ascii(mesh: &TriMesh, solid_name: &str) -> String {
    use std::fmt::Write as _;
    let mut w = String::new();
    let _ = writeln!(w, "solid {solid_name}");
    for t in to_stl_triangles(mesh) {
        let [nx, ny, nz] = t.normal.0;
        let _ = writeln!(w, "  facet normal {nx:.8e} {ny:.8e} {nz:.8e}");
        let _ = writeln!(w, "    outer loop");
        for v in t.vertices {
            let _ = writeln!(w, "      vertex {:.8e} {:.8e} {:.8e}", v[0], v[1], v[2]);
        }
        let _ = writeln!(w, "    endloop");
        let _ = writeln!(w, "  endfacet");
    }
    let _ = writeln!(w, "endsolid {solid_name}");
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::accuracy::sphere_mesh;
    use crate::geometry::mesh::tests::unit_cube_soup;

    fn temp_path(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("cgdem-stl-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        dir.join(name)
    }

    /// Same vertex set (f32-rounded) and triangles, possibly in a different vertex order.
    fn same_surface(a: &TriMesh, b: &TriMesh) -> bool {
        a.triangles.len() == b.triangles.len()
            && (0..a.triangles.len()).all(|t| {
                let x = a.triangle(t);
                let y = b.triangle(t);
                x.iter().zip(&y).all(|(p, q)| p.distance(*q) < 1e-6)
            })
    }

    #[test]
    fn binary_stl_round_trip_keeps_the_closed_sphere() {
        let mesh = sphere_mesh(0.5, 2);
        let path = temp_path("sphere_binary.stl");
        write_stl_binary(&path, &mesh).expect("writable temp dir");
        let back = read_stl(&path).expect("valid STL");
        assert_eq!(back.vertices.len(), mesh.vertices.len());
        assert!(same_surface(&mesh, &back));
        assert!((back.volume() - mesh.volume()).abs() < 1e-6);
    }

    #[test]
    fn ascii_stl_round_trip_keeps_the_closed_sphere() {
        let mesh = sphere_mesh(0.5, 2);
        let path = temp_path("sphere_ascii.stl");
        write_stl_ascii(&path, &mesh, "sphere").expect("writable temp dir");
        let text = std::fs::read_to_string(&path).expect("just written");
        assert!(text.starts_with("solid sphere"));
        let back = read_stl(&path).expect("valid STL");
        assert_eq!(back.vertices.len(), mesh.vertices.len());
        assert!(same_surface(&mesh, &back));
    }

    #[test]
    fn open_cube_stl_is_rejected_listing_open_edges_with_coordinates() {
        let mut soup = unit_cube_soup();
        soup.drain(2..4);
        let mesh = TriMesh::from_triangle_soup(&soup, 1e-6);
        let path = temp_path("open_cube.stl");
        write_stl_binary(&path, &mesh).expect("writable temp dir");
        match read_stl(&path) {
            Err(e @ StlError::OpenEdges { count: 4, .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.contains("open_cube.stl") && msg.contains("4 open edges"),
                    "{msg}"
                );
                assert!(msg.contains("1.000000"), "{msg}");
            }
            other => panic!("expected 4 open edges, got {other:?}"),
        }
        let (_, report) = read_stl_unchecked(&path).expect("readable");
        assert_eq!(report.open_edges.len(), 4);
    }

    #[test]
    fn missing_garbage_and_empty_files_give_typed_errors() {
        let missing = temp_path("does_not_exist.stl");
        assert!(matches!(
            read_stl(&missing),
            Err(StlError::Unreadable { .. })
        ));

        let garbage = temp_path("garbage.stl");
        std::fs::write(&garbage, b"this is a text file, not a mesh").expect("writable");
        let err = read_stl(&garbage).expect_err("not STL");
        assert!(matches!(err, StlError::NotStl { .. }), "{err}");

        let empty_ascii = temp_path("empty_ascii.stl");
        std::fs::write(&empty_ascii, b"solid nothing\nendsolid nothing\n").expect("writable");
        assert!(matches!(
            read_stl(&empty_ascii),
            Err(StlError::Empty { .. })
        ));

        let empty_binary = temp_path("empty_binary.stl");
        std::fs::write(&empty_binary, [0u8; 84]).expect("writable");
        assert!(matches!(
            read_stl(&empty_binary),
            Err(StlError::Empty { .. })
        ));
    }

    #[test]
    fn inward_oriented_stl_is_flipped_outward() {
        let mut mesh = sphere_mesh(1.0, 1);
        mesh.flip_orientation();
        let path = temp_path("inward.stl");
        write_stl_binary(&path, &mesh).expect("writable temp dir");
        assert!(read_stl(&path).expect("valid").volume() > 0.0);
    }

    #[test]
    fn flipped_facet_in_stl_is_rejected_as_bad_orientation() {
        let mut soup = unit_cube_soup();
        soup[7].swap(1, 2);
        let path = temp_path("flipped.stl");
        write_stl_binary(&path, &TriMesh::from_triangle_soup(&soup, 1e-6)).expect("writable");
        assert!(matches!(
            read_stl(&path),
            Err(StlError::BadOrientation { count: 3, .. })
        ));
    }
}
