//! Signed distance grid of a body (paper A, sec. 5): node values are exact distances to the
//! mesh, signed by the winding number; queries interpolate trilinearly (Eq. 9) and take the
//! normal as the gradient of that interpolant (Eq. 10), so a query costs the same at any
//! resolution.

use rayon::prelude::*;

use super::aabb::Aabb;
use super::analytic::Sdf;
use super::bvh::Bvh;
use super::mesh::TriMesh;
use super::winding_number::FastWindingNumber;
use crate::math::{Real, Vec3};

/// Refuses grids above this many nodes (4 bytes each): a wrong unit in the cell size should
/// fail with a message, not exhaust memory.
pub const MAX_GRID_NODES: usize = 1 << 30;
/// Node values are exact within max(padding, this many cells) of the surface.
pub const EXACT_BAND_CELLS: Real = 3.0;
/// Spacing ratio of the exact lattice that bounds the far field.
const COARSE: usize = 4;

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SdfGridError {
    #[error("SDF cell size must be positive and finite, got {0}")]
    InvalidCellSize(Real),
    #[error("SDF padding must be non-negative and finite, got {0}")]
    InvalidPadding(Real),
    #[error("cannot build an SDF of a mesh with no triangles")]
    EmptyMesh,
    #[error(
        "SDF grid of {nodes} nodes ({dims:?}) exceeds the limit of {limit}; use a larger cell size"
    )]
    TooManyNodes {
        nodes: usize,
        dims: [usize; 3],
        limit: usize,
    },
}

/// Regular grid of signed distances, negative inside the body.
#[derive(Clone, Debug)]
pub struct SdfGrid {
    origin: Vec3,
    cell_size: Real,
    /// Node counts along x, y, z; node (i, j, k) is at `origin + cell_size * (i, j, k)`.
    dims: [usize; 3],
    /// x fastest. f32 halves memory; its rounding (1e-7 relative) is far below the
    /// interpolation error of any usable cell size.
    values: Vec<f32>,
    /// A bound on the interpolant's gradient ([`SdfGrid::lipschitz`]).
    lipschitz: Real,
}

impl SdfGrid {
    /// Builds the grid over the mesh's bounding box grown by `padding` on every side.
    /// Padding should cover the largest distance at which contacts are looked up.
    pub fn from_mesh(
        mesh: &TriMesh,
        cell_size: Real,
        padding: Real,
    ) -> Result<SdfGrid, SdfGridError> {
        if !(cell_size > 0.0 && cell_size.is_finite()) {
            return Err(SdfGridError::InvalidCellSize(cell_size));
        }
        if !(padding >= 0.0 && padding.is_finite()) {
            return Err(SdfGridError::InvalidPadding(padding));
        }
        if mesh.triangles.is_empty() {
            return Err(SdfGridError::EmptyMesh);
        }
        let bbox = mesh.bounding_box();
        let (origin, dims) = grid_layout(bbox, cell_size, padding)?;
        let bvh = Bvh::new(mesh);
        let winding = FastWindingNumber::new(&bvh);
        let [nx, ny, _] = dims;
        // Exact distances on a lattice COARSE times coarser bound every fine node from both
        // sides (1-Lipschitz). Nodes whose lower bound clears the band get the interpolated
        // coarse value; only the band pays for an exact query. Far-field queries dominate
        // the cost otherwise (10x on a screw).
        let band = padding.max(EXACT_BAND_CELLS * cell_size);
        let cdims = dims.map(|n| (n - 1).div_ceil(COARSE) + 1);
        let coarse_h = cell_size * COARSE as Real;
        let coarse: Vec<Real> = (0..cdims.iter().product::<usize>())
            .into_par_iter()
            .map(|idx| {
                let (i, j, k) = (
                    idx % cdims[0],
                    (idx / cdims[0]) % cdims[1],
                    idx / (cdims[0] * cdims[1]),
                );
                let p = origin + coarse_h * Vec3::new(i as Real, j as Real, k as Real);
                bvh.nearest(p).map_or(Real::INFINITY, |n| n.distance())
            })
            .collect();
        let mut values = vec![0f32; dims.iter().product()];
        values
            .par_chunks_mut(nx)
            .enumerate()
            .for_each(|(row, out)| {
                let (j, k) = (row % ny, row / ny);
                let base = origin + cell_size * Vec3::new(0.0, j as Real, k as Real);
                // (distance or its lower bound, inside) of the previous node in the row.
                let mut prev: Option<(Real, bool)> = None;
                for (i, value) in out.iter_mut().enumerate() {
                    let p = base + Vec3::X * (cell_size * i as Real);
                    let bounds = coarse_bounds(&coarse, cdims, coarse_h, [i, j, k]);
                    let (d, d_low) = if bounds.lower > band {
                        (
                            bounds.interpolated.min(bounds.upper).max(bounds.lower),
                            bounds.lower,
                        )
                    } else {
                        let d = bvh
                            .nearest_within(p, bounds.upper * (1.0 + 1e-9) + 1e-12)
                            .or_else(|| bvh.nearest(p))
                            .map_or(Real::INFINITY, |n| n.distance());
                        (d, d)
                    };
                    // A ball of radius d around a node holds no surface, so if it reaches the
                    // previous node both lie on the same side.
                    let inside = match prev {
                        Some((d_prev, inside_prev))
                            if d_low.max(d_prev) > cell_size * (1.0 + 1e-9) =>
                        {
                            inside_prev
                        }
                        _ => winding.is_inside(p),
                    };
                    *value = if inside { -d } else { d } as f32;
                    prev = Some((d_low, inside));
                }
            });
        Ok(SdfGrid::new(origin, cell_size, dims, values))
    }

    /// Samples any SDF on the same layout (e.g. an analytic shape, for comparison).
    pub fn from_sdf<S: Sdf + Sync>(
        sdf: &S,
        bounds: Aabb,
        cell_size: Real,
        padding: Real,
    ) -> Result<SdfGrid, SdfGridError> {
        if !(cell_size > 0.0 && cell_size.is_finite()) {
            return Err(SdfGridError::InvalidCellSize(cell_size));
        }
        if !(padding >= 0.0 && padding.is_finite()) {
            return Err(SdfGridError::InvalidPadding(padding));
        }
        let (origin, dims) = grid_layout(bounds, cell_size, padding)?;
        let [nx, ny, _] = dims;
        let mut values = vec![0f32; dims.iter().product()];
        values
            .par_chunks_mut(nx)
            .enumerate()
            .for_each(|(row, out)| {
                let (j, k) = (row % ny, row / ny);
                for (i, value) in out.iter_mut().enumerate() {
                    let p = origin + cell_size * Vec3::new(i as Real, j as Real, k as Real);
                    *value = sdf.distance(p) as f32;
                }
            });
        Ok(SdfGrid::new(origin, cell_size, dims, values))
    }

    fn new(origin: Vec3, cell_size: Real, dims: [usize; 3], values: Vec<f32>) -> SdfGrid {
        let lipschitz = lipschitz_bound(&values, dims) / cell_size;
        SdfGrid {
            origin,
            cell_size,
            dims,
            values,
            lipschitz,
        }
    }

    /// A bound on the gradient of the interpolant, over the whole grid: its value at two
    /// points of the grid differs by at most this times their distance, whatever the node
    /// values (a true SDF sampled gives about 1 to 1.7; a sign error, more). A particle
    /// that far beyond contact is known to be out of reach without a lookup
    /// ([`crate::bodies::Clearance`]).
    pub fn lipschitz(&self) -> Real {
        self.lipschitz
    }

    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    pub fn cell_size(&self) -> Real {
        self.cell_size
    }

    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Region where [`SdfGrid::query`] answers.
    pub fn bounds(&self) -> Aabb {
        let n = Vec3::new(
            (self.dims[0] - 1) as Real,
            (self.dims[1] - 1) as Real,
            (self.dims[2] - 1) as Real,
        );
        Aabb {
            min: self.origin,
            max: self.origin + self.cell_size * n,
        }
    }

    pub fn node_value(&self, i: usize, j: usize, k: usize) -> Real {
        self.values[i + self.dims[0] * (j + self.dims[1] * k)] as Real
    }

    /// Heap memory of the node values plus the struct itself.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>() + self.values.capacity() * std::mem::size_of::<f32>()
    }

    /// Signed distance and unit normal at `p`, or `None` outside the grid. The normal is the
    /// normalized gradient of the trilinear interpolant (zero where that gradient vanishes).
    pub fn query(&self, p: Vec3) -> Option<(Real, Vec3)> {
        self.sample(p).map(|s| (s.distance, s.normal()))
    }

    /// The signed distance at `p`, with what its normal needs ([`GridSample::normal`]), or
    /// `None` outside the grid: a contact test needs the distance of every particle near the
    /// body, the normal only of those that touch it.
    pub fn sample(&self, p: Vec3) -> Option<GridSample> {
        let u = (p - self.origin) / self.cell_size;
        for a in 0..3 {
            if !(u[a] >= 0.0 && u[a] <= (self.dims[a] - 1) as Real) {
                return None; // also rejects NaN
            }
        }
        Some(self.sample_at(u))
    }

    /// Interpolates at continuous node coordinates `u`, clamped into the grid.
    fn interpolate_at(&self, u: Vec3) -> (Real, Vec3) {
        let s = self.sample_at(u);
        (s.distance, s.normal())
    }

    fn sample_at(&self, u: Vec3) -> GridSample {
        let mut cell = [0usize; 3];
        let mut t = [0.0; 3];
        for a in 0..3 {
            let last = (self.dims[a] - 1) as Real;
            let ua = u[a].clamp(0.0, last);
            // Points on the far face use the last cell with t = 1. `ua` is not negative
            // here, so the cast truncates as `floor` would (without its libm call).
            let c = (ua as usize).min(self.dims[a] - 2);
            cell[a] = c;
            t[a] = ua - c as Real;
        }
        let [i, j, k] = cell;
        let (nx, nxy) = (self.dims[0], self.dims[0] * self.dims[1]);
        let base = i + nx * j + nxy * k;
        let v = |o: usize| self.values[base + o] as Real;
        let corners = [
            v(0),
            v(1),
            v(nx),
            v(nx + 1),
            v(nxy),
            v(nxy + 1),
            v(nxy + nx),
            v(nxy + nx + 1),
        ];
        let [c00, c10, c01, c11] = GridSample::edges(&corners, t[0]);
        let (c0, c1) = (lerp(c00, c10, t[1]), lerp(c01, c11, t[1]));
        GridSample {
            corners,
            t,
            distance: lerp(c0, c1, t[2]),
        }
    }
}

/// The trilinear interpolant at one point of an [`SdfGrid`]: its value, and the cell's
/// corner values for the normal.
#[derive(Clone, Copy, Debug)]
pub struct GridSample {
    /// v000, v100, v010, v110, v001, v101, v011, v111.
    corners: [Real; 8],
    t: [Real; 3],
    pub distance: Real,
}

impl GridSample {
    /// The interpolant along x on the cell's four x edges: c00, c10, c01, c11.
    fn edges(v: &[Real; 8], tx: Real) -> [Real; 4] {
        [
            lerp(v[0], v[1], tx),
            lerp(v[2], v[3], tx),
            lerp(v[4], v[5], tx),
            lerp(v[6], v[7], tx),
        ]
    }

    /// The normalized gradient of the trilinear interpolant (zero where it vanishes): the
    /// exact partial derivatives, computed as they were with the distance, so that the
    /// normal is the same to the bit whether asked for or not.
    pub fn normal(&self) -> Vec3 {
        let v = &self.corners;
        let [tx, ty, tz] = self.t;
        let [c00, c10, c01, c11] = Self::edges(v, tx);
        let (c0, c1) = (lerp(c00, c10, ty), lerp(c01, c11, ty));
        let gx = lerp(
            lerp(v[1] - v[0], v[3] - v[2], ty),
            lerp(v[5] - v[4], v[7] - v[6], ty),
            tz,
        );
        let gy = lerp(c10 - c00, c11 - c01, tz);
        let gz = c1 - c0;
        Vec3::new(gx, gy, gz).normalize_or_zero()
    }
}

/// The largest gradient of the trilinear interpolant in node units (times the cell size).
/// Within a cell, the derivative along x is a weighted mean of the four x edges' differences
/// (likewise y and z), so it is at most the largest of them; the interpolant is continuous
/// across cells, so the largest bound over the cells holds along any segment in the grid.
fn lipschitz_bound(values: &[f32], dims: [usize; 3]) -> Real {
    let [nx, ny, nz] = dims;
    let (sx, sy, sz) = (1, nx, nx * ny);
    let v = |n: usize| values[n] as Real;
    let slab = |k: usize| {
        let mut most: Real = 0.0;
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let n = i * sx + j * sy + k * sz;
                let corners = [n, n + sy, n + sz, n + sy + sz];
                let edge = |step: usize, from: [usize; 4]| {
                    from.iter()
                        .map(|&a| (v(a + step) - v(a)).abs())
                        .fold(0.0, Real::max)
                };
                let gx = edge(sx, corners);
                let gy = edge(sy, [n, n + sx, n + sz, n + sx + sz]);
                let gz = edge(sz, [n, n + sx, n + sy, n + sx + sy]);
                most = most.max((gx * gx + gy * gy + gz * gz).sqrt());
            }
        }
        most
    };
    // A maximum: the same in any order.
    (0..nz - 1)
        .into_par_iter()
        .map(slab)
        .reduce(|| 0.0, Real::max)
}

#[inline(always)]
fn lerp(a: Real, b: Real, t: Real) -> Real {
    a + (b - a) * t
}

/// Outside the grid the distance continues as `d(q) + |p - q|` with `q` the nearest grid
/// point: continuous at the boundary and an upper bound of the true distance, fine because
/// the padding keeps the surface away from the boundary. The normal there is taken at `q`.
impl Sdf for SdfGrid {
    fn distance(&self, p: Vec3) -> Real {
        let u = (p - self.origin) / self.cell_size;
        let (d, _) = self.interpolate_at(u);
        let b = self.bounds();
        d + p.distance(p.clamp(b.min, b.max))
    }

    fn normal(&self, p: Vec3) -> Vec3 {
        self.interpolate_at((p - self.origin) / self.cell_size).1
    }
}

struct CoarseBounds {
    lower: Real,
    upper: Real,
    interpolated: Real,
}

/// Trilinear value and Lipschitz bounds at fine node `n` from the 8 surrounding coarse nodes.
fn coarse_bounds(
    coarse: &[Real],
    cdims: [usize; 3],
    coarse_h: Real,
    n: [usize; 3],
) -> CoarseBounds {
    let mut c = [0usize; 3];
    let mut t = [0.0; 3];
    for a in 0..3 {
        c[a] = (n[a] / COARSE).min(cdims[a] - 2);
        t[a] = (n[a] - c[a] * COARSE) as Real / COARSE as Real;
    }
    let (mut lower, mut upper, mut interpolated) = (Real::NEG_INFINITY, Real::INFINITY, 0.0);
    for corner in 0..8 {
        let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
        let mut w = 1.0;
        let mut gap2 = 0.0;
        for a in 0..3 {
            let s = o[a] as Real;
            w *= if o[a] == 1 { t[a] } else { 1.0 - t[a] };
            gap2 += (s - t[a]) * (s - t[a]);
        }
        let d = coarse[(c[0] + o[0]) + cdims[0] * ((c[1] + o[1]) + cdims[1] * (c[2] + o[2]))];
        let gap = coarse_h * gap2.sqrt(); // |p - corner|
        lower = lower.max(d - gap);
        upper = upper.min(d + gap);
        interpolated += w * d;
    }
    CoarseBounds {
        lower,
        upper,
        interpolated,
    }
}

fn grid_layout(
    bbox: Aabb,
    cell_size: Real,
    padding: Real,
) -> Result<(Vec3, [usize; 3]), SdfGridError> {
    let span = bbox.extent() + Vec3::splat(2.0 * padding);
    let cells = (span / cell_size).ceil().max(Vec3::ONE);
    let to_count = |c: Real| if c < 1e15 { c as usize + 1 } else { usize::MAX };
    let dims = [to_count(cells.x), to_count(cells.y), to_count(cells.z)];
    let nodes = dims
        .iter()
        .try_fold(1usize, |acc, &n| acc.checked_mul(n))
        .unwrap_or(usize::MAX);
    if nodes > MAX_GRID_NODES {
        return Err(SdfGridError::TooManyNodes {
            nodes,
            dims,
            limit: MAX_GRID_NODES,
        });
    }
    // Centre the grid on the box so the padding is the same on both sides.
    let origin = bbox.center() - 0.5 * cell_size * cells;
    Ok((origin, dims))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::accuracy::{cylinder_mesh, seeded_rng, sphere_mesh, RandomPoints};
    use crate::geometry::analytic::{Cylinder, Sphere};

    /// Random points within `band` of the analytic surface, as (point, exact distance).
    fn band_points<S: Sdf>(
        shape: &S,
        bounds: Aabb,
        band: Real,
        n: usize,
        seed: u64,
    ) -> Vec<(Vec3, Real)> {
        let mut rng = seeded_rng(seed);
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let p = rng.vec_in_box(bounds);
            let d = shape.distance(p);
            if d.abs() <= band {
                out.push((p, d));
            }
        }
        out
    }

    #[test]
    fn sphere_sdf_from_mesh_matches_analytic_distance_and_normal() {
        let radius = 1.0;
        let h = radius / 25.0;
        // Level 6 icosphere: faceting error below 1e-4 R, normals within 0.3 deg.
        let grid = SdfGrid::from_mesh(&sphere_mesh(radius, 6), h, 3.0 * h).expect("valid grid");
        let sphere = Sphere {
            center: Vec3::ZERO,
            radius,
        };
        let bounds = Aabb {
            min: Vec3::splat(-1.1),
            max: Vec3::splat(1.1),
        };
        let mut worst_angle: Real = 0.0;
        for (p, exact) in band_points(&sphere, bounds, 2.0 * h, 3000, 17) {
            let (d, n) = grid.query(p).expect("inside the padded grid");
            assert!((d - exact).abs() < 0.5 * h, "d = {d}, exact {exact} at {p}");
            let angle = n.angle_between(sphere.normal(p)).to_degrees();
            worst_angle = worst_angle.max(angle);
        }
        assert!(worst_angle < 2.0, "normal error {worst_angle} deg");
        assert!(grid.query(Vec3::splat(5.0)).is_none());
    }

    #[test]
    fn cylinder_sdf_from_mesh_matches_analytic_distance_and_normal_away_from_rims() {
        let (radius, height) = (1.0, 2.0);
        let h = 0.05;
        let grid = SdfGrid::from_mesh(&cylinder_mesh(radius, height, 512), h, 3.0 * h)
            .expect("valid grid");
        let cyl = Cylinder::new(Vec3::ZERO, Vec3::Z, radius, height);
        let bounds = Aabb {
            min: Vec3::new(-1.1, -1.1, -1.1),
            max: Vec3::new(1.1, 1.1, 1.1),
        };
        let mut worst_angle: Real = 0.0;
        for (p, exact) in band_points(&cyl, bounds, 2.0 * h, 3000, 23) {
            let (d, n) = grid.query(p).expect("inside the padded grid");
            assert!((d - exact).abs() < 0.5 * h, "d = {d}, exact {exact} at {p}");
            let rim = {
                let r = (p.x * p.x + p.y * p.y).sqrt();
                ((r - radius).powi(2) + (p.z.abs() - 0.5 * height).powi(2)).sqrt()
            };
            // Inside, the medial surface runs from the rim at 45 degrees: a kink, not a face.
            let side_minus_cap =
                (radius - (p.x * p.x + p.y * p.y).sqrt()) - (0.5 * height - p.z.abs());
            let near_medial = exact < 0.0 && side_minus_cap.abs() < 2.0 * h;
            if rim > 3.0 * h && !near_medial {
                worst_angle = worst_angle.max(n.angle_between(cyl.normal(p)).to_degrees());
            }
        }
        assert!(worst_angle < 2.0, "normal error {worst_angle} deg");
    }

    #[test]
    fn grid_normal_is_gradient_of_trilinear_interpolant() {
        // A linear field is reproduced exactly by trilinear interpolation, gradient included.
        let plane =
            crate::geometry::analytic::HalfSpace::new(Vec3::ZERO, Vec3::new(1.0, 2.0, -0.5));
        let bounds = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let grid = SdfGrid::from_sdf(&plane, bounds, 0.13, 0.0).expect("valid grid");
        let mut rng = seeded_rng(2);
        for _ in 0..200 {
            let p = rng.vec_in_box(bounds);
            let (d, n) = grid.query(p).expect("inside");
            assert!((d - plane.distance(p)).abs() < 1e-6);
            assert!(n.distance(plane.normal) < 1e-6);
        }
    }

    #[test]
    fn bad_cell_size_and_empty_mesh_are_errors() {
        let mesh = sphere_mesh(1.0, 1);
        assert_eq!(
            SdfGrid::from_mesh(&mesh, 0.0, 0.1).err(),
            Some(SdfGridError::InvalidCellSize(0.0))
        );
        assert!(matches!(
            SdfGrid::from_mesh(&mesh, 1e-6, 0.1),
            Err(SdfGridError::TooManyNodes { .. })
        ));
        assert_eq!(
            SdfGrid::from_mesh(&TriMesh::default(), 0.1, 0.1).err(),
            Some(SdfGridError::EmptyMesh)
        );
    }

    #[test]
    fn sdf_trait_outside_grid_continues_with_positive_upper_bound() {
        let grid = SdfGrid::from_mesh(&sphere_mesh(1.0, 3), 0.1, 0.2).expect("valid grid");
        let far = Vec3::new(10.0, 0.0, 0.0);
        let d = grid.distance(far);
        assert!((8.99..9.5).contains(&d), "{d}");
        assert!(grid.normal(far).x > 0.9);
        assert!(grid.memory_bytes() >= 4 * grid.dims().iter().product::<usize>());
    }

    /// The bound holds between any two points of the grid, is near 1 for a sampled SDF, and
    /// grows with a wrong node (a sign error of the winding number, say).
    #[test]
    fn the_lipschitz_bound_holds_between_any_two_points() {
        let mut grid = SdfGrid::from_mesh(&sphere_mesh(1.0, 3), 0.1, 0.2).expect("valid grid");
        let l = grid.lipschitz();
        assert!((1.0..1.75).contains(&l), "{l}");
        let b = grid.bounds();
        let mut rng = seeded_rng(3);
        for _ in 0..20_000 {
            let (p, q) = (rng.vec_in_box(b), rng.vec_in_box(b));
            let q = p + (q - p) * 0.05; // mostly short segments, where the bound is tight
            let (dp, dq) = (grid.sample(p).unwrap(), grid.sample(q).unwrap());
            let change = (dp.distance - dq.distance).abs();
            assert!(
                change <= l * p.distance(q) * (1.0 + 1e-9),
                "{change} over {}",
                p.distance(q)
            );
        }
        let k = grid.values.len() / 2;
        grid.values[k] = -grid.values[k] - 1.0;
        let wrong = SdfGrid::new(grid.origin, grid.cell_size, grid.dims, grid.values.clone());
        assert!(wrong.lipschitz() > 5.0, "{}", wrong.lipschitz());
    }
}
