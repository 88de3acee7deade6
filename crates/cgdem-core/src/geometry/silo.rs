//! Triangle meshes of the silo of the open-source DEM comparison (Dosta et al., Comput. Phys.
//! Commun. 296 (2024) 109066, case 1; reference/silo/SOURCE.md): a cylinder on a conical
//! hopper about the z axis, open at the top and at the orifice, and the silo's inside as the
//! insertion region of its fill. The same triangles as `scripts/silo_geometry.py` (the
//! committed `validation/cases/silo/*.stl`), so that the orifice is one scene value and the
//! LAMMPS deck writer can build its cylinder and cone regions from the same dimensions.
//!
//! # Frame and units
//! SI metres, z up, the axis on the z axis; the orifice (radius `r0`) at `z = orifice_z`, the
//! hopper's top (radius `R`) at `orifice_z + (R - r0) / tan(half-angle)`, the rim
//! `cylinder_height` above it.
//!
//! # Wall (`wall_mesh`)
//! One closed solid of revolution: the cross-section inner surface up (hopper, cylinder), rim,
//! outer surface down, and the orifice's lip, the flat ring from `r0` to `r0 + t` at the
//! orifice (as in the benchmark's files), `t` the horizontal wall thickness. The inner edges
//! are cut into rings at most `max_edge` apart (no long slivers where grains touch), the
//! outer ones, which no grain touches, at four times that.
//!
//! # Fill (`fill_mesh`)
//! The silo's inside from the orifice plane up to `fill_height` above the hopper, closed by discs at both ends
//! (fans about the axis), rings at most `4 max_edge` apart.

use super::mesh::TriMesh;
use crate::math::{Real, Vec3};

/// The silo's dimensions; the defaults are the benchmark's silo (inner diameter 0.2 m, 45 deg
/// hopper, 40 mm orifice, 0.3 m of cylinder) with the orifice at z = 0 and a 10 mm wall.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SiloSpec {
    /// Inner diameter 2R, m.
    pub silo_diameter: Real,
    /// D0 = 2 r0, m.
    pub orifice_diameter: Real,
    /// The hopper's half-angle from the vertical, degrees.
    pub hopper_half_angle: Real,
    /// Height of the cylinder above the hopper, m.
    pub cylinder_height: Real,
    /// z of the orifice plane, m.
    pub orifice_z: Real,
    /// Horizontal thickness of the wall, m (the benchmark's triangles: 2 mm; 10 mm resolves
    /// in an SDF grid of a few mm, and grains touch only the inner surface).
    pub wall_thickness: Real,
    /// Divisions around the axis.
    pub segments: u32,
    /// Ring spacing along the inner outline, m.
    pub max_edge: Real,
    /// Height of the fill region's top above the hopper's top, m (at most the cylinder's);
    /// `None`: no fill region. Relative to the hopper, so that the orifice is one value.
    pub fill_height: Option<Real>,
}

impl Default for SiloSpec {
    fn default() -> Self {
        SiloSpec {
            silo_diameter: 0.2,
            orifice_diameter: 0.04,
            hopper_half_angle: 45.0,
            cylinder_height: 0.3,
            orifice_z: 0.0,
            wall_thickness: 0.01,
            segments: 96,
            max_edge: 0.01,
            fill_height: None,
        }
    }
}

/// Heights and radii that follow from a [`SiloSpec`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SiloLayout {
    pub radius: Real,
    pub orifice_radius: Real,
    pub orifice_z: Real,
    pub hopper_top_z: Real,
    pub rim_z: Real,
}

impl SiloSpec {
    /// Which field is out of range and what is allowed; `None` when the spec is valid.
    pub fn problem(&self) -> Option<(&'static str, String, &'static str)> {
        let finite_positive = |v: Real| v.is_finite() && v > 0.0;
        if !finite_positive(self.silo_diameter) {
            return Some(("silo_diameter", self.silo_diameter.to_string(), "m, > 0"));
        }
        if !(finite_positive(self.orifice_diameter) && self.orifice_diameter < self.silo_diameter) {
            return Some((
                "orifice_diameter",
                self.orifice_diameter.to_string(),
                "m, > 0 and below silo_diameter",
            ));
        }
        if !(self.hopper_half_angle > 0.0 && self.hopper_half_angle < 90.0) {
            return Some((
                "hopper_half_angle",
                self.hopper_half_angle.to_string(),
                "degrees from the vertical, between 0 and 90",
            ));
        }
        if !finite_positive(self.cylinder_height) {
            return Some((
                "cylinder_height",
                self.cylinder_height.to_string(),
                "m, > 0",
            ));
        }
        if !self.orifice_z.is_finite() {
            return Some(("orifice_z", self.orifice_z.to_string(), "m, finite"));
        }
        if !finite_positive(self.wall_thickness) {
            return Some(("wall_thickness", self.wall_thickness.to_string(), "m, > 0"));
        }
        if self.segments < 8 {
            return Some(("segments", self.segments.to_string(), "at least 8"));
        }
        if !finite_positive(self.max_edge) {
            return Some(("max_edge", self.max_edge.to_string(), "m, > 0"));
        }
        if let Some(height) = self.fill_height {
            if !(height > 0.0 && height <= self.cylinder_height) {
                return Some((
                    "fill_height",
                    height.to_string(),
                    "m above the hopper's top, > 0 and at most cylinder_height",
                ));
            }
        }
        None
    }

    pub fn layout(&self) -> SiloLayout {
        let radius = 0.5 * self.silo_diameter;
        let orifice_radius = 0.5 * self.orifice_diameter;
        let hopper_top_z =
            self.orifice_z + (radius - orifice_radius) / self.hopper_half_angle.to_radians().tan();
        SiloLayout {
            radius,
            orifice_radius,
            orifice_z: self.orifice_z,
            hopper_top_z,
            rim_z: hopper_top_z + self.cylinder_height,
        }
    }
}

/// The silo's wall: one closed, outward-oriented solid of revolution.
pub fn wall_mesh(spec: &SiloSpec) -> TriMesh {
    let l = spec.layout();
    let (r0, rr, t, e) = (
        l.orifice_radius,
        l.radius,
        spec.wall_thickness,
        spec.max_edge,
    );
    let outline = [
        (r0, l.orifice_z),
        (rr, l.hopper_top_z),
        (rr, l.rim_z),
        (rr + t, l.rim_z),
        (rr + t, l.hopper_top_z),
        (r0 + t, l.orifice_z),
    ];
    let edges = [e, e, 4.0 * e, 4.0 * e, 4.0 * e, e];
    revolve(&profile_points(&outline, &edges), spec.segments)
}

/// The silo's inside from the orifice plane to `fill_height` above the hopper's top (None
/// without it).
pub fn fill_mesh(spec: &SiloSpec) -> Option<TriMesh> {
    let l = spec.layout();
    // On a whole nanometre: the sum's last bit (0.08 + 0.08 = 0.16000000000000003) would
    // otherwise add a ring to a height that is a whole number of ring spacings, and the
    // scripts/silo_geometry.py meshes were made with the top written to 6 digits.
    let top = ((l.hopper_top_z + spec.fill_height?) * 1e9).round() / 1e9;
    let outline = [
        (0.0, l.orifice_z),
        (l.orifice_radius, l.orifice_z),
        (l.radius, l.hopper_top_z),
        (l.radius, top),
        (0.0, top),
    ];
    let edges = [4.0 * spec.max_edge; 5];
    Some(revolve(&profile_points(&outline, &edges), spec.segments))
}

/// The closed outline (r, z) with edge i cut into pieces at most `max_edges[i]` long.
fn profile_points(outline: &[(Real, Real)], max_edges: &[Real]) -> Vec<(Real, Real)> {
    let mut points = Vec::new();
    for (i, &a) in outline.iter().enumerate() {
        let b = outline[(i + 1) % outline.len()];
        let length = (b.0 - a.0).hypot(b.1 - a.1);
        let n = ((length / max_edges[i]).ceil() as usize).max(1);
        for k in 0..n {
            let s = k as Real / n as Real;
            points.push((a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1)));
        }
    }
    points
}

/// The closed outline turned about z into `segments` divisions; a point on the axis is one
/// vertex (fans there), so the surface is closed. Oriented outward.
fn revolve(points: &[(Real, Real)], segments: u32) -> TriMesh {
    let n = segments as usize;
    let mut vertices = Vec::new();
    // First vertex of each outline point's ring (one vertex on the axis).
    let mut first = Vec::with_capacity(points.len());
    for &(r, z) in points {
        first.push(vertices.len() as u32);
        if r > 0.0 {
            for j in 0..n {
                let angle = 2.0 * std::f64::consts::PI * j as Real / n as Real;
                vertices.push(Vec3::new(r * angle.cos(), r * angle.sin(), z));
            }
        } else {
            vertices.push(Vec3::new(0.0, 0.0, z));
        }
    }
    let index = |i: usize, j: usize| -> u32 {
        if points[i].0 > 0.0 {
            first[i] + (j % n) as u32
        } else {
            first[i]
        }
    };
    let mut triangles = Vec::new();
    for i in 0..points.len() {
        let next = (i + 1) % points.len();
        for j in 0..n {
            let (a0, a1, b0, b1) = (
                index(i, j),
                index(i, j + 1),
                index(next, j),
                index(next, j + 1),
            );
            if points[i].0 > 0.0 {
                triangles.push([a0, b0, a1]);
            }
            if points[next].0 > 0.0 {
                triangles.push([a1, b0, b1]);
            }
        }
    }
    let mut mesh = TriMesh::new(vertices, triangles);
    if mesh.volume() < 0.0 {
        mesh.flip_orientation();
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::read_stl;
    use std::path::Path;

    /// The case files' meshes (`scripts/silo_geometry.py --preset cases`): name, orifice
    /// diameter, cylinder height, fill above the hopper's top, ring spacing.
    const PRESET_CASES: [(&str, Real, Real, Real, Real); 4] = [
        ("full_d40", 0.04, 0.45, 0.40, 0.02),
        ("full_d60", 0.06, 0.45, 0.40, 0.02),
        ("reduced_d40", 0.04, 0.12, 0.08, 0.01),
        ("reduced_d60", 0.06, 0.12, 0.08, 0.01),
    ];

    fn preset(d0: Real, height: Real, fill: Real, edge: Real) -> SiloSpec {
        SiloSpec {
            orifice_diameter: d0,
            cylinder_height: height,
            max_edge: edge,
            fill_height: Some(fill),
            ..SiloSpec::default()
        }
    }

    /// Largest distance between corresponding vertices of corresponding triangles (the
    /// STL's f32 vertices), None when the counts differ.
    fn largest_vertex_gap(a: &TriMesh, b: &TriMesh) -> Option<Real> {
        (a.triangles.len() == b.triangles.len()).then(|| {
            (0..a.triangles.len())
                .flat_map(|t| {
                    let (p, q) = (a.triangle(t), b.triangle(t));
                    (0..3).map(move |k| p[k].distance(q[k]))
                })
                .fold(0.0, Real::max)
        })
    }

    #[test]
    fn the_built_in_silo_gives_the_committed_triangles_of_every_case_file() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../validation/cases/silo");
        for (name, d0, height, fill, edge) in PRESET_CASES {
            let spec = preset(d0, height, fill, edge);
            assert_eq!(spec.problem(), None);
            let stl = read_stl(&dir.join(format!("{name}.stl"))).unwrap();
            let gap = largest_vertex_gap(&wall_mesh(&spec), &stl);
            // The STL holds f32 vertices: 0.5 m in f32 is within 3e-8 m.
            assert!(gap.is_some_and(|g| g < 1e-7), "{name}: {gap:?}");
            let stl = read_stl(&dir.join(format!("{name}_fill.stl"))).unwrap();
            let gap = largest_vertex_gap(&fill_mesh(&spec).unwrap(), &stl);
            assert!(gap.is_some_and(|g| g < 1e-7), "{name}_fill: {gap:?}");
        }
    }

    #[test]
    fn wall_and_fill_are_closed_outward_and_enclose_the_expected_volumes() {
        let spec = preset(0.06, 0.12, 0.08, 0.01);
        let l = spec.layout();
        assert!((l.hopper_top_z - 0.07).abs() < 1e-12);
        let pi = std::f64::consts::PI;
        let frustum = |h: Real, r1: Real, r2: Real| pi * h / 3.0 * (r1 * r1 + r1 * r2 + r2 * r2);
        let wall = wall_mesh(&spec);
        assert!(wall.check_topology().is_closed_manifold_oriented());
        // The shell: outer minus inner solid of revolution, to the polygon's area deficit
        // (96 divisions: sin(2 pi / 96) / (2 pi / 96) = 0.99929).
        let (t, rr, r0) = (spec.wall_thickness, l.radius, l.orifice_radius);
        let exact = frustum(l.hopper_top_z, r0 + t, rr + t) - frustum(l.hopper_top_z, r0, rr)
            + pi * ((rr + t).powi(2) - rr * rr) * spec.cylinder_height;
        assert!(
            (wall.volume() / exact - 1.0).abs() < 2e-3,
            "{}",
            wall.volume()
        );
        let fill = fill_mesh(&spec).unwrap();
        assert!(fill.check_topology().is_closed_manifold_oriented());
        let exact = frustum(l.hopper_top_z, r0, rr) + pi * rr * rr * 0.08;
        assert!(
            (fill.volume() / exact - 1.0).abs() < 2e-3,
            "{}",
            fill.volume()
        );
    }

    /// A scene with the built-in silo as its body and fill; `silo` is the `[silo]` table's
    /// text (None: no table).
    fn silo_scene(silo: Option<&str>, fill: &str) -> Result<crate::scene::Scene, String> {
        let table = silo.map(|t| format!("[silo]\n{t}\n")).unwrap_or_default();
        let text = format!(
            r#"
name = "silo"
[domain]
lo = [-0.125, -0.125, -0.05]
hi = [0.125, 0.125, 0.205]
[[species]]
name = "m1"
diameter = 4e-3
density = 2500.0
[contact]
model = "hertz"
youngs_modulus = 5e6
poisson_ratio = 0.2
restitution = 0.5
friction = 0.3
[time]
dt = 1.25e-5
{table}
[[body]]
name = "silo"
mesh = "silo:wall"
cell_size = 1.5e-3
[[insert]]
species = "m1"
lo = [-0.1, -0.1, 0.0]
hi = [0.1, 0.1, 0.16]
count = 10
mesh = "{fill}"
[[stage]]
name = "s"
duration = 0.1
"#
        );
        crate::scene::Scene::parse(&text, Path::new("case.toml")).map_err(|e| e.to_string())
    }

    #[test]
    fn a_scene_takes_the_silo_from_its_silo_table_and_names_what_is_missing() {
        use crate::scene::{MeshSource, SiloPart};
        let scene = silo_scene(
            Some("orifice_diameter = 0.06\nfill_height = 0.08\ncylinder_height = 0.12"),
            "silo:fill",
        )
        .unwrap();
        let MeshSource::Silo(SiloPart::Wall, spec) = &scene.bodies[0].mesh else {
            panic!("{:?}", scene.bodies[0].mesh)
        };
        assert_eq!(
            (spec.orifice_diameter, spec.silo_diameter, spec.segments),
            (0.06, 0.2, 96)
        );
        assert!(matches!(
            scene.insertions[0].mesh,
            Some(MeshSource::Silo(SiloPart::Fill, _))
        ));
        // The insertions are checked before the bodies.
        let e = silo_scene(None, "silo:fill").unwrap_err();
        assert!(e.contains("insert[0].mesh") && e.contains("[silo]"), "{e}");
        let e = silo_scene(Some("cylinder_height = 0.12"), "silo:fill").unwrap_err();
        assert!(e.contains("silo.fill_height"), "{e}");
        let e = silo_scene(Some("fill_height = 0.08"), "silo:top").unwrap_err();
        assert!(
            e.contains("insert[0].mesh") && e.contains("silo:wall"),
            "{e}"
        );
        let e = silo_scene(Some("orifice_diameter = 0.3"), "silo:fill").unwrap_err();
        assert!(e.contains("silo.orifice_diameter"), "{e}");
        let e = silo_scene(Some("orifice = 0.03"), "silo:fill").unwrap_err();
        assert!(e.contains("orifice"), "{e}");
    }

    #[test]
    fn a_spec_out_of_range_names_its_field() {
        let bad = |spec: SiloSpec| spec.problem().map(|p| p.0);
        let d = SiloSpec::default();
        assert_eq!(
            bad(SiloSpec {
                orifice_diameter: 0.2,
                ..d.clone()
            }),
            Some("orifice_diameter")
        );
        assert_eq!(
            bad(SiloSpec {
                hopper_half_angle: 90.0,
                ..d.clone()
            }),
            Some("hopper_half_angle")
        );
        assert_eq!(
            bad(SiloSpec {
                fill_height: Some(0.35),
                ..d.clone()
            }),
            Some("fill_height")
        );
        assert_eq!(bad(d), None);
    }
}
