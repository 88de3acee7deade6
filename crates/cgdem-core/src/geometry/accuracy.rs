//! Accuracy of [`SdfGrid`] against known shapes, and the closed meshes used for it.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::aabb::Aabb;
use super::analytic::{Cylinder, Sdf, Sphere};
use super::bvh::Bvh;
use super::mesh::TriMesh;
use super::sdf_grid::{SdfGrid, SdfGridError};
use super::triangle_distance::TriangleFeature;
use super::winding_number::FastWindingNumber;
use crate::math::{Real, Vec3};

/// A seeded generator (`Pcg64`, as insertion uses) so accuracy runs are reproducible.
pub fn seeded_rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

/// Random numbers and points for the accuracy study and the geometry tests, from any `rand`
/// generator.
pub trait RandomPoints: Rng {
    /// Uniform in [0, 1).
    fn uniform(&mut self) -> Real {
        self.gen::<Real>()
    }

    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.uniform()
    }

    fn vec_in_cube(&mut self, half: Real) -> Vec3 {
        Vec3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }

    fn vec_in_box(&mut self, b: Aabb) -> Vec3 {
        Vec3::new(
            self.range(b.min.x, b.max.x),
            self.range(b.min.y, b.max.y),
            self.range(b.min.z, b.max.z),
        )
    }
}

impl<R: Rng + ?Sized> RandomPoints for R {}

/// Sphere centred at the origin from a subdivided icosahedron: 20 * 4^subdivisions triangles,
/// vertices on the sphere, outward oriented.
pub fn sphere_mesh(radius: Real, subdivisions: u32) -> TriMesh {
    let t = (1.0 + (5.0 as Real).sqrt()) / 2.0;
    let mut vertices: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        // Shared edge midpoints keep the surface welded.
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (vertices[a as usize] + vertices[b as usize]).normalize();
                vertices.push(m);
                vertices.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(4 * triangles.len());
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut vertices);
            let bc = midpoint(b, c, &mut vertices);
            let ca = midpoint(c, a, &mut vertices);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    for v in &mut vertices {
        *v *= radius;
    }
    TriMesh::new(vertices, triangles)
}

/// Closed cylinder along z from `-height/2` to `height/2`, `segments` sides (vertices on the
/// circle), flat caps fanned from their centres, outward oriented.
pub fn cylinder_mesh(radius: Real, height: Real, segments: u32) -> TriMesh {
    let n = segments.max(3);
    let mut vertices = Vec::with_capacity(2 * n as usize + 2);
    for z in [-0.5 * height, 0.5 * height] {
        for i in 0..n {
            let a = 2.0 * PI * i as Real / n as Real;
            vertices.push(Vec3::new(radius * a.cos(), radius * a.sin(), z));
        }
    }
    vertices.push(Vec3::new(0.0, 0.0, -0.5 * height));
    vertices.push(Vec3::new(0.0, 0.0, 0.5 * height));
    let (bottom_center, top_center) = (2 * n, 2 * n + 1);
    let mut triangles = Vec::with_capacity(4 * n as usize);
    for i in 0..n {
        let j = (i + 1) % n;
        let (b0, b1, t0, t1) = (i, j, n + i, n + j);
        triangles.push([b0, b1, t1]);
        triangles.push([b0, t1, t0]);
        triangles.push([top_center, t0, t1]);
        triangles.push([bottom_center, b1, b0]);
    }
    TriMesh::new(vertices, triangles)
}

/// Helicoid screw flight: the solid swept by a radial bar `[inner_radius, outer_radius]` of
/// axial `thickness` rising by `pitch` per turn about the z axis, starting at angle 0, z = 0.
#[derive(Clone, Copy, Debug)]
pub struct ScrewFlight {
    pub inner_radius: Real,
    pub outer_radius: Real,
    pub pitch: Real,
    pub thickness: Real,
    pub turns: Real,
}

impl ScrewFlight {
    /// Exact volume: the helical shear preserves the annulus-times-thickness volume.
    pub fn volume(&self) -> Real {
        PI * (self.outer_radius.powi(2) - self.inner_radius.powi(2)) * self.thickness * self.turns
    }

    /// Closed, outward-oriented mesh with `4 * radial_segments + 4` triangles per angular step.
    pub fn mesh(&self, segments_per_turn: u32, radial_segments: u32) -> TriMesh {
        let nr = radial_segments.max(1) as usize;
        let steps = ((segments_per_turn as Real * self.turns).ceil() as usize).max(1);
        let cols = steps + 1;
        let per_side = (nr + 1) * cols;
        let index = |side: usize, i: usize, j: usize| (side * per_side + j * (nr + 1) + i) as u32;
        let mut vertices = Vec::with_capacity(2 * per_side);
        for side in 0..2 {
            let dz = (side as Real - 0.5) * self.thickness;
            for j in 0..cols {
                let theta = 2.0 * PI * self.turns * j as Real / steps as Real;
                let z = self.pitch * theta / (2.0 * PI) + dz;
                for i in 0..=nr {
                    let r = self.inner_radius
                        + (self.outer_radius - self.inner_radius) * i as Real / nr as Real;
                    vertices.push(Vec3::new(r * theta.cos(), r * theta.sin(), z));
                }
            }
        }
        let mut triangles = Vec::with_capacity(steps * (4 * nr + 4) + 4 * nr);
        let mut quad = |a: u32, b: u32, c: u32, d: u32| {
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        };
        for j in 0..steps {
            for i in 0..nr {
                // Top face: (r, theta) is right-handed about +z.
                quad(
                    index(1, i, j),
                    index(1, i + 1, j),
                    index(1, i + 1, j + 1),
                    index(1, i, j + 1),
                );
                quad(
                    index(0, i, j),
                    index(0, i, j + 1),
                    index(0, i + 1, j + 1),
                    index(0, i + 1, j),
                );
            }
            quad(
                index(0, nr, j),
                index(0, nr, j + 1),
                index(1, nr, j + 1),
                index(1, nr, j),
            );
            quad(
                index(0, 0, j),
                index(1, 0, j),
                index(1, 0, j + 1),
                index(0, 0, j + 1),
            );
        }
        for i in 0..nr {
            quad(
                index(0, i, 0),
                index(0, i + 1, 0),
                index(1, i + 1, 0),
                index(1, i, 0),
            );
            quad(
                index(0, i, steps),
                index(1, i, steps),
                index(1, i + 1, steps),
                index(0, i + 1, steps),
            );
        }
        TriMesh::new(vertices, triangles)
    }
}

/// A shape whose SDF accuracy is measured.
#[derive(Clone, Copy, Debug)]
pub enum TestShape {
    Sphere {
        radius: Real,
        subdivisions: u32,
    },
    Cylinder {
        radius: Real,
        height: Real,
        segments: u32,
    },
    ScrewFlight {
        flight: ScrewFlight,
        segments_per_turn: u32,
        radial_segments: u32,
    },
}

impl TestShape {
    pub fn name(&self) -> String {
        match self {
            TestShape::Sphere {
                radius,
                subdivisions,
            } => format!("sphere r={radius} ico{subdivisions}"),
            TestShape::Cylinder {
                radius,
                height,
                segments,
            } => {
                format!("cylinder r={radius} h={height} n={segments}")
            }
            TestShape::ScrewFlight { flight: f, .. } => format!(
                "screw flight ri={} ro={} pitch={} t={}",
                f.inner_radius, f.outer_radius, f.pitch, f.thickness
            ),
        }
    }

    pub fn mesh(&self) -> TriMesh {
        match *self {
            TestShape::Sphere {
                radius,
                subdivisions,
            } => sphere_mesh(radius, subdivisions),
            TestShape::Cylinder {
                radius,
                height,
                segments,
            } => cylinder_mesh(radius, height, segments),
            TestShape::ScrewFlight {
                flight,
                segments_per_turn,
                radial_segments,
            } => flight.mesh(segments_per_turn, radial_segments),
        }
    }
}

/// One line of the accuracy table. Errors are grid minus ground truth at random points within
/// +-2 cells of the surface.
#[derive(Clone, Debug)]
pub struct AccuracyRow {
    pub shape: String,
    pub triangles: usize,
    pub cell_size: Real,
    pub max_abs_distance_error: Real,
    pub rms_distance_error: Real,
    /// Over points farther than 3 cells from edges and 2 cells from the medial surface.
    pub max_normal_error_deg: Real,
    pub p95_normal_error_deg: Real,
    pub memory_bytes: usize,
    pub build_seconds: Real,
    pub samples: usize,
    pub normal_samples: usize,
}

/// Ground truth for one shape: signed distance, and the outward normal where it is defined
/// away from edges (None near edges and the medial surface).
trait Truth {
    fn eval(&self, p: Vec3, h: Real) -> (Real, Option<Vec3>);
}

struct SphereTruth(Sphere);

impl Truth for SphereTruth {
    fn eval(&self, p: Vec3, _h: Real) -> (Real, Option<Vec3>) {
        (self.0.distance(p), Some(self.0.normal(p)))
    }
}

struct CylinderTruth(Cylinder);

impl Truth for CylinderTruth {
    fn eval(&self, p: Vec3, h: Real) -> (Real, Option<Vec3>) {
        let c = &self.0;
        let radial = (p.x * p.x + p.y * p.y).sqrt();
        let rim = (radial - c.radius).hypot(p.z.abs() - 0.5 * c.height);
        let d = c.distance(p);
        // Inside, the medial surface leaves the rim at 45 degrees: a kink, not a face.
        let side_minus_cap = (c.radius - radial) - (0.5 * c.height - p.z.abs());
        let near_medial = d < 0.0 && side_minus_cap.abs() < 2.0 * h;
        let normal = (rim > 3.0 * h && !near_medial).then(|| c.normal(p));
        (d, normal)
    }
}

/// Screw flight truth = the exact distance to its (fine) triangle mesh, signed by the winding
/// number, because the helicoid has no closed-form distance.
struct MeshTruth<'a> {
    mesh: &'a TriMesh,
    bvh: &'a Bvh,
    winding: FastWindingNumber<'a>,
    flight: ScrewFlight,
}

impl Truth for MeshTruth<'_> {
    fn eval(&self, p: Vec3, h: Real) -> (Real, Option<Vec3>) {
        let Some(near) = self.bvh.nearest(p) else {
            return (Real::INFINITY, None);
        };
        let inside = self.winding.is_inside(p);
        let d = if inside {
            -near.distance()
        } else {
            near.distance()
        };
        let f = &self.flight;
        let radial = (p.x * p.x + p.y * p.y).sqrt();
        let end_margin = f.thickness + 3.0 * h + f.pitch * 3.0 * h / (2.0 * PI * f.inner_radius);
        let z_end = f.pitch * f.turns;
        let near_edge = radial - f.inner_radius < 3.0 * h
            || f.outer_radius - radial < 3.0 * h
            || p.z < end_margin
            || p.z > z_end - end_margin;
        let near_medial = inside && -d > 0.5 * f.thickness - 2.0 * h;
        let normal = if near_edge || near_medial {
            None
        } else if near.feature == TriangleFeature::Face {
            Some(self.mesh.face_normal(near.triangle as usize))
        } else {
            (p - near.point)
                .try_normalize()
                .map(|n| if inside { -n } else { n })
        };
        (d, normal)
    }
}

/// Random points on the mesh surface (area-weighted) pushed along the face normal by up to
/// `band` either way.
fn band_samples(mesh: &TriMesh, band: Real, n: usize, rng: &mut Pcg64) -> Vec<Vec3> {
    let mut cumulative = Vec::with_capacity(mesh.triangles.len());
    let mut total = 0.0;
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.triangle(t);
        total += 0.5 * (b - a).cross(c - a).length();
        cumulative.push(total);
    }
    (0..n)
        .map(|_| {
            let x = rng.uniform() * total;
            let t = cumulative
                .partition_point(|&c| c < x)
                .min(mesh.triangles.len() - 1);
            let [a, b, c] = mesh.triangle(t);
            let (mut u, mut v) = (rng.uniform(), rng.uniform());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let on_surface = a + u * (b - a) + v * (c - a);
            on_surface + mesh.face_normal(t) * rng.range(-band, band)
        })
        .collect()
}

/// Builds an [`SdfGrid`] of `shape` for each cell size and measures it at `samples` points
/// within +-2 cells of the surface. Padding is 3 cells.
pub fn sdf_accuracy(
    shape: &TestShape,
    cell_sizes: &[Real],
    samples: usize,
    seed: u64,
) -> Result<Vec<AccuracyRow>, SdfGridError> {
    let mesh = shape.mesh();
    if mesh.triangles.is_empty() {
        return Err(SdfGridError::EmptyMesh);
    }
    let bvh = Bvh::new(&mesh);
    let truth: Box<dyn Truth + '_> = match *shape {
        TestShape::Sphere { radius, .. } => Box::new(SphereTruth(Sphere {
            center: Vec3::ZERO,
            radius,
        })),
        TestShape::Cylinder { radius, height, .. } => Box::new(CylinderTruth(Cylinder::new(
            Vec3::ZERO,
            Vec3::Z,
            radius,
            height,
        ))),
        TestShape::ScrewFlight { flight, .. } => Box::new(MeshTruth {
            mesh: &mesh,
            bvh: &bvh,
            winding: FastWindingNumber::new(&bvh),
            flight,
        }),
    };
    let mut rows = Vec::with_capacity(cell_sizes.len());
    for &h in cell_sizes {
        let start = Instant::now();
        let grid = SdfGrid::from_mesh(&mesh, h, 3.0 * h)?;
        let build_seconds = start.elapsed().as_secs_f64();
        let mut rng = seeded_rng(seed);
        let (mut max_err, mut sum_sq, mut count) = (0.0 as Real, 0.0, 0usize);
        let mut angles = Vec::new();
        for p in band_samples(&mesh, 2.0 * h, samples, &mut rng) {
            let (exact, normal) = truth.eval(p, h);
            let Some((d, n)) = grid.query(p) else {
                continue;
            };
            if exact.abs() > 2.0 * h {
                continue;
            }
            let err = d - exact;
            max_err = max_err.max(err.abs());
            sum_sq += err * err;
            count += 1;
            if let Some(expected) = normal {
                angles.push(n.angle_between(expected).to_degrees());
            }
        }
        angles.sort_by(|a, b| a.total_cmp(b));
        let p95 = match angles.len() {
            0 => Real::NAN,
            len => angles[((0.95 * len as Real).ceil() as usize).clamp(1, len) - 1],
        };
        rows.push(AccuracyRow {
            shape: shape.name(),
            triangles: mesh.triangles.len(),
            cell_size: h,
            max_abs_distance_error: max_err,
            rms_distance_error: (sum_sq / count.max(1) as Real).sqrt(),
            max_normal_error_deg: angles.last().copied().unwrap_or(Real::NAN),
            p95_normal_error_deg: p95,
            memory_bytes: grid.memory_bytes(),
            build_seconds,
            samples: count,
            normal_samples: angles.len(),
        });
    }
    Ok(rows)
}

/// Plain-text table of accuracy rows.
pub fn format_accuracy_table(rows: &[AccuracyRow]) -> String {
    let mut s = format!(
        "{:<44} {:>7} {:>9} {:>10} {:>10} {:>8} {:>8} {:>10} {:>8} {:>6}\n",
        "shape",
        "tris",
        "cell",
        "max|dd|",
        "rms dd",
        "max deg",
        "p95 deg",
        "memory B",
        "build s",
        "n"
    );
    for r in rows {
        s += &format!(
            "{:<44} {:>7} {:>9.3e} {:>10.3e} {:>10.3e} {:>8.3} {:>8.3} {:>10} {:>8.3} {:>6}\n",
            r.shape,
            r.triangles,
            r.cell_size,
            r.max_abs_distance_error,
            r.rms_distance_error,
            r.max_normal_error_deg,
            r.p95_normal_error_deg,
            r.memory_bytes,
            r.build_seconds,
            r.samples
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_meshes_are_closed_outward_and_have_the_right_volume() {
        let sphere = sphere_mesh(2.0, 4);
        assert!(sphere.check_topology().is_closed_manifold_oriented());
        let exact = 4.0 / 3.0 * PI * 8.0;
        assert!(sphere.volume() > 0.0 && (sphere.volume() - exact).abs() / exact < 0.01);

        let cyl = cylinder_mesh(1.0, 3.0, 256);
        assert!(cyl.check_topology().is_closed_manifold_oriented());
        assert!((cyl.volume() - 3.0 * PI).abs() / (3.0 * PI) < 1e-3);

        let flight = ScrewFlight {
            inner_radius: 0.01,
            outer_radius: 0.05,
            pitch: 0.06,
            thickness: 0.005,
            turns: 2.0,
        };
        let mesh = flight.mesh(360, 4);
        assert!(mesh.check_topology().is_closed_manifold_oriented());
        let rel = (mesh.volume() - flight.volume()).abs() / flight.volume();
        assert!(mesh.volume() > 0.0 && rel < 1e-3, "volume off by {rel}");
    }

    #[test]
    fn accuracy_rows_for_a_sphere_shrink_with_the_cell_size() {
        let shape = TestShape::Sphere {
            radius: 1.0,
            subdivisions: 5,
        };
        let rows = sdf_accuracy(&shape, &[0.2, 0.05], 2000, 1).expect("valid grids");
        assert_eq!(rows.len(), 2);
        assert!(rows[1].max_abs_distance_error < rows[0].max_abs_distance_error);
        assert!(rows[1].memory_bytes > rows[0].memory_bytes);
        assert!(rows.iter().all(|r| r.samples > 1500));
    }

    /// Prints the accuracy table and timings: `cargo test --release -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn report_accuracy_table() {
        let flight = ScrewFlight {
            inner_radius: 0.015,
            outer_radius: 0.05,
            pitch: 0.05,
            thickness: 0.006,
            turns: 2.0,
        };
        let shapes = [
            (
                TestShape::Sphere {
                    radius: 0.05,
                    subdivisions: 6,
                },
                vec![0.01, 0.005, 0.0025],
            ),
            (
                TestShape::Cylinder {
                    radius: 0.05,
                    height: 0.1,
                    segments: 1024,
                },
                vec![0.01, 0.005, 0.0025],
            ),
            (
                TestShape::ScrewFlight {
                    flight,
                    segments_per_turn: 1440,
                    radial_segments: 16,
                },
                vec![0.004, 0.002, 0.001],
            ),
        ];
        let mut rows = Vec::new();
        for (shape, cells) in &shapes {
            rows.extend(sdf_accuracy(shape, cells, 5_000, 42).expect("valid grids"));
        }
        println!("{}", format_accuracy_table(&rows));
    }

    /// Build time of a screw-sized grid: `cargo test --release -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn report_screw_grid_build_time() {
        let flight = ScrewFlight {
            inner_radius: 0.015,
            outer_radius: 0.05,
            pitch: 0.1,
            thickness: 0.006,
            turns: 5.0,
        };
        for (label, spt, nr, h) in [
            ("~20k triangles, ~1M nodes", 145u32, 6u32, 0.00179),
            ("~100k triangles, 100x100x450 nodes", 720, 6, 0.00107),
        ] {
            let mesh = flight.mesh(spt, nr);
            let start = Instant::now();
            let grid = SdfGrid::from_mesh(&mesh, h, 2.0 * h).expect("valid grid");
            println!(
                "{label}: {} triangles, dims {:?} = {} nodes, {:.2} s, {} MB",
                mesh.triangles.len(),
                grid.dims(),
                grid.dims().iter().product::<usize>(),
                start.elapsed().as_secs_f64(),
                grid.memory_bytes() / 1_000_000
            );
        }
    }
}
