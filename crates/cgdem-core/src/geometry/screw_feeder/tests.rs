use std::collections::HashMap;

use super::*;
use crate::geometry::mesh_builder::signed_volume;

/// Every directed edge appears exactly once and its reverse exists: closed (each undirected
/// edge in exactly two triangles) and consistently oriented.
fn assert_closed_and_oriented(mesh: &TriMesh, name: &str) {
    assert!(!mesh.triangles.is_empty(), "{name}: no triangles");
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "{name}: degenerate triangle {t:?}"
        );
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "{name}: directed edge {a}->{b} appears {n} times");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "{name}: edge {a}->{b} has no opposite (open boundary)"
        );
    }
    // No zero-area triangles either.
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        assert!(
            (b - a).cross(c - a).length() > 1e-14,
            "{name}: sliver {t:?}"
        );
    }
}

/// Generalized winding number of `p` with respect to the mesh (sum of signed solid angles
/// / 4π, Van Oosterom & Strackee). For a union of closed outward pieces it counts the pieces
/// containing `p`.
fn winding_number(mesh: &TriMesh, p: Vec3) -> Real {
    let mut omega = 0.0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize] - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        omega += 2.0 * num.atan2(den);
    }
    omega / (4.0 * PI)
}

fn inside(mesh: &TriMesh, p: Vec3) -> bool {
    winding_number(mesh, p) > 0.5
}

/// Does the segment p->q cross any triangle (Möller–Trumbore)?
fn segment_hits(mesh: &TriMesh, p: Vec3, q: Vec3) -> bool {
    let d = q - p;
    mesh.triangles.iter().any(|t| {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let (e1, e2) = (b - a, c - a);
        let h = d.cross(e2);
        let det = e1.dot(h);
        if det.abs() < 1e-18 {
            return false;
        }
        let s = p - a;
        let u = s.dot(h) / det;
        let qv = s.cross(e1);
        let v = d.dot(qv) / det;
        let w = e2.dot(qv) / det;
        (0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&w)
    })
}

fn all_meshes(spec: &ScrewFeederSpec) -> Vec<(&'static str, TriMesh)> {
    vec![
        ("screw", screw_mesh(spec)),
        ("casing", casing_mesh(spec)),
        ("hopper", hopper_mesh(spec)),
        ("insertion", insertion_region_mesh(spec)),
    ]
}

#[test]
fn default_spec_is_valid() {
    ScrewFeederSpec::default().validate().expect("default spec");
}

#[test]
fn swept_volume_per_turn_matches_paper_eq7() {
    let v = swept_volume_per_turn(&ScrewFeederSpec::default());
    assert!((v - 4.595e-3).abs() < 0.001e-3, "got {v}");
}

#[test]
fn every_mesh_is_closed_oriented_and_outward() {
    for spec in [
        ScrewFeederSpec::default(),
        ScrewFeederSpec {
            segments_per_turn: 12,
            radial_segments: 1,
            casing_segments: 12,
            discharge_end_plate: true,
            ..Default::default()
        },
    ] {
        for (name, mesh) in all_meshes(&spec) {
            assert_closed_and_oriented(&mesh, name);
            let v = signed_volume(&mesh);
            assert!(v > 0.0, "{name}: signed volume {v} is not positive");
        }
    }
}

#[test]
fn each_piece_has_positive_volume() {
    // A union whose pieces had mixed orientation could still sum to a positive volume:
    // check the sign piece by piece (pieces are the connected components).
    let spec = ScrewFeederSpec::default();
    for (name, mesh) in all_meshes(&spec) {
        for (k, piece) in components(&mesh).iter().enumerate() {
            let v = signed_volume(piece);
            assert!(v > 0.0, "{name}: piece {k} has volume {v}");
        }
    }
}

fn components(mesh: &TriMesh) -> Vec<TriMesh> {
    let n = mesh.vertices.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for t in &mesh.triangles {
        let r0 = find(&mut parent, t[0] as usize);
        for &v in &t[1..] {
            let r = find(&mut parent, v as usize);
            parent[r] = r0;
        }
    }
    let mut by_root: HashMap<usize, TriMesh> = HashMap::new();
    for t in &mesh.triangles {
        let r = find(&mut parent, t[0] as usize);
        let piece = by_root.entry(r).or_insert_with(|| TriMesh {
            vertices: mesh.vertices.clone(),
            triangles: Vec::new(),
        });
        piece.triangles.push(*t);
    }
    by_root.into_values().collect()
}

#[test]
fn screw_volume_matches_shaft_plus_flight() {
    let spec = ScrewFeederSpec::default();
    let l = spec.layout();
    let rs = 0.5 * spec.shaft_diameter;
    let ro = 0.5 * spec.screw_outer_diameter;
    let r_in = rs - spec.flight_root_embedding;
    let shaft = PI * rs * rs * (l.shaft_x[1] - l.shaft_x[0]);
    // Helical slab of axial thickness e over angle Θ: e Θ (R^2 - r^2) / 2.
    let theta = 2.0 * PI * spec.flight_turns;
    let flight = spec.flight_thickness * theta * 0.5 * (ro * ro - r_in * r_in);
    let v = signed_volume(&screw_mesh(&spec));
    let expected = shaft + flight;
    assert!(
        (v - expected).abs() < 0.02 * expected,
        "mesh {v}, analytic {expected}"
    );
    // At the default resolution it is much better than 2 %.
    assert!((v - expected).abs() < 0.002 * expected);
}

#[test]
fn screw_radii_and_extent() {
    let spec = ScrewFeederSpec::default();
    let mesh = screw_mesh(&spec);
    let r_max = mesh
        .vertices
        .iter()
        .map(|v| v.y.hypot(v.z))
        .fold(0.0, Real::max);
    assert!((r_max - 0.1025).abs() < 1e-12);
    let l = spec.layout();
    let (x_min, x_max) = mesh
        .vertices
        .iter()
        .fold((Real::MAX, Real::MIN), |(a, b), v| (a.min(v.x), b.max(v.x)));
    assert!((x_min - l.shaft_x[0]).abs() < 1e-12 && (x_max - l.shaft_x[1]).abs() < 1e-12);
    // A point in the flight at mid-radius, half a pitch in, is inside; the gap between turns
    // is not.
    let x_flight = 0.5 * spec.flight_thickness + 0.5 * spec.pitch; // θ = π: -y side
    assert!(inside(&mesh, Vec3::new(x_flight, -0.07, 0.0)));
    assert!(!inside(
        &mesh,
        Vec3::new(x_flight + 0.5 * spec.pitch, -0.07, 0.0)
    ));
    assert!(inside(
        &mesh,
        Vec3::new(x_flight + 0.5 * spec.pitch, 0.0, 0.0)
    )); // shaft
}

#[test]
fn casing_inner_radius_is_the_bore() {
    let spec = ScrewFeederSpec::default();
    let l = spec.layout();
    let mesh = casing_mesh(&spec);
    let ri = 0.5 * spec.casing_inner_diameter;
    let mut on_bore = 0;
    for v in &mesh.vertices {
        let r = v.y.hypot(v.z);
        // Plate disks reach r = 0; everything else keeps out of the bore.
        let in_plate = v.x <= l.end_plate_x[1] + 1e-12;
        if !in_plate {
            assert!(r >= ri - 1e-12, "vertex {v} inside the bore (r = {r})");
        }
        if !in_plate && r < ri + 0.5 * spec.casing_wall_thickness {
            assert!((r - ri).abs() < 1e-12, "inner vertex at r = {r}");
            on_bore += 1;
        }
    }
    assert!(on_bore > 1000, "only {on_bore} vertices on the bore");
    // Sample points just inside the bore are outside the solid, just inside the wall inside.
    for x in [0.45, 0.50] {
        for k in 0..16 {
            let a = 2.0 * PI * (k as Real + 0.3) / 16.0;
            let dir = Vec3::new(0.0, a.cos(), a.sin());
            let p_bore = Vec3::new(x, 0.0, 0.0) + dir * (ri - 1e-3);
            let p_wall = Vec3::new(x, 0.0, 0.0) + dir * (ri + 1e-3);
            assert!(!inside(&mesh, p_bore));
            assert!(inside(&mesh, p_wall));
        }
    }
}

#[test]
fn inlet_and_outlet_are_holes() {
    let spec = ScrewFeederSpec::default();
    let l = spec.layout();
    let casing = casing_mesh(&spec);
    let wall_mid = l.bore_radius + 0.5 * spec.casing_wall_thickness;
    let x_in = 0.5 * (l.inlet_x[0] + l.inlet_x[1]);
    let x_out = 0.5 * (l.outlet_x[0] + l.outlet_x[1]);
    let x_closed = 0.5 * (l.inlet_x[1] + l.outlet_x[0]);
    // Where the wall would be: solid in the closed tube, empty over the openings.
    assert!(inside(&casing, Vec3::new(x_closed, 0.0, wall_mid)));
    assert!(inside(&casing, Vec3::new(x_closed, 0.0, -wall_mid)));
    assert!(!inside(&casing, Vec3::new(x_in, 0.0, wall_mid)));
    assert!(!inside(&casing, Vec3::new(x_out, 0.0, -wall_mid)));
    // A particle can fall straight through: from the hopper top down the axis plane into the
    // bore, and from the bore out through the outlet, without crossing any casing or hopper
    // triangle.
    let hopper = hopper_mesh(&spec);
    for dy in [-0.1, 0.0, 0.1] {
        for dx in [-0.14, 0.0, 0.14] {
            let top = Vec3::new(x_in + dx, dy, l.hopper_top_z + 0.05);
            let bottom = Vec3::new(x_in + dx, dy, 0.0);
            assert!(
                !segment_hits(&casing, top, bottom),
                "inlet blocked at {top}"
            );
            assert!(
                !segment_hits(&hopper, top, bottom),
                "hopper blocked at {top}"
            );
            let o0 = Vec3::new(x_out + dx, dy, 0.0);
            let o1 = Vec3::new(x_out + dx, dy, -0.5);
            assert!(!segment_hits(&casing, o0, o1), "outlet blocked at {o0}");
        }
    }
    // Closed sections block the same paths.
    let p = Vec3::new(x_closed, 0.0, 0.0);
    assert!(segment_hits(&casing, p, p + Vec3::new(0.0, 0.0, 0.5)));
    assert!(segment_hits(&casing, p, p - Vec3::new(0.0, 0.0, 0.5)));
}

#[test]
fn inlet_chute_and_hopper_are_sealed() {
    // Points in the walls around the inlet (gables, cheeks, hopper) are solid, so particles in
    // the hopper cannot leak out above the tube.
    let spec = ScrewFeederSpec::default();
    let l = spec.layout();
    let casing = casing_mesh(&spec);
    let hopper = hopper_mesh(&spec);
    let t = spec.casing_wall_thickness;
    let ri = l.bore_radius;
    let z = 0.5 * (ri + l.hopper_bottom_z); // between the bore top and the chute top
    assert!(inside(&casing, Vec3::new(l.inlet_x[0] - 0.5 * t, 0.09, z)));
    assert!(inside(&casing, Vec3::new(l.inlet_x[1] + 0.5 * t, -0.09, z)));
    assert!(inside(&casing, Vec3::new(0.1, ri + 0.5 * t, 0.05)));
    assert!(inside(&casing, Vec3::new(0.1, -ri - 0.5 * t, 0.05)));
    let zh = l.hopper_bottom_z + 1e-3;
    assert!(inside(&hopper, Vec3::new(0.1, ri + 0.5 * t, zh)));
    assert!(inside(&hopper, Vec3::new(l.inlet_x[1] + 0.5 * t, 0.0, zh)));
    assert!(!inside(&hopper, Vec3::new(0.1, 0.0, zh)));
}

#[test]
fn insertion_region_lies_in_free_space() {
    let spec = ScrewFeederSpec::default();
    let region = insertion_region_mesh(&spec);
    let solids = [casing_mesh(&spec), hopper_mesh(&spec), screw_mesh(&spec)];
    for v in &region.vertices {
        for s in &solids {
            assert!(!inside(s, *v), "insertion vertex {v} inside a solid");
        }
    }
    let v = signed_volume(&region);
    assert!(v > 0.02 && v < 0.05, "insertion volume {v} m3");
}

#[test]
fn invalid_spec_names_the_field() {
    let spec = ScrewFeederSpec {
        shaft_diameter: 0.3,
        ..Default::default()
    };
    match spec.validate() {
        Err(ScrewFeederError::InvalidSpec { field, .. }) => assert_eq!(field, "shaft_diameter"),
        other => panic!("expected InvalidSpec, got {other:?}"),
    }
    let spec = ScrewFeederSpec {
        pitch: Real::NAN,
        ..Default::default()
    };
    assert!(spec.validate().is_err());
}

#[test]
fn writes_four_binary_stl_files() {
    let dir = std::env::temp_dir().join(format!("screwgeo-test-{}", std::process::id()));
    let spec = ScrewFeederSpec::default();
    let paths = write_stl_files(&spec, &dir).expect("write");
    let names: Vec<_> = paths
        .iter()
        .filter_map(|p| p.file_name()?.to_str().map(String::from))
        .collect();
    assert_eq!(
        names,
        ["screw.stl", "casing.stl", "hopper.stl", "insertion.stl"]
    );
    for (path, (_, mesh)) in paths.iter().zip(all_meshes(&spec)) {
        let bytes = std::fs::read(path).expect("read back");
        assert_eq!(bytes.len(), 84 + 50 * mesh.triangles.len());
        let mut f = std::fs::File::open(path).expect("open");
        let read = stl_io::read_stl(&mut f).expect("parse");
        assert_eq!(read.faces.len(), mesh.triangles.len());
    }
    std::fs::remove_dir_all(&dir).ok();
    // A file in place of the directory gives an error naming it.
    let file = std::env::temp_dir().join(format!("screwgeo-file-{}", std::process::id()));
    std::fs::write(&file, b"x").expect("write");
    match write_stl_files(&spec, &file) {
        Err(ScrewFeederError::Io { path, .. }) => assert_eq!(path, file),
        other => panic!("expected Io error, got {other:?}"),
    }
    std::fs::remove_file(&file).ok();
}
