//! The shape of a body in its own frame: a signed-distance grid or an analytic SDF.

use crate::geometry::{
    Aabb, AxisAlignedBox, Cylinder, GridSample, MeshSurface, Sdf, SdfGrid, Sphere,
};
use crate::math::{Real, Vec3};

/// A body's shape in the body frame. An enum rather than a trait object: the match is
/// predictable and inlined in the force loop.
#[derive(Clone, Debug)]
pub enum BodyShape {
    /// Trilinear SDF grid (paper A Eq. 8-10), e.g. from an STL; no contact outside the grid.
    Grid(SdfGrid),
    Sphere(Sphere),
    Cylinder(Cylinder),
    Box(AxisAlignedBox),
    /// The triangles themselves (`contact = "mesh"`): particles touch the closest point of a
    /// face, an edge or a vertex (`bodies::mesh_contact`). A surface, open or closed: its
    /// distance has no sign.
    Mesh(Box<MeshSurface>),
    /// No surface: a body built of particles, which act through the pair law; `bounds` holds
    /// the particles' centres.
    Particles(Aabb),
}

/// A shape's signed distance at a point, with its normal there: computed on demand for a
/// grid (its gradient is most of a query's cost, and only touching particles need it),
/// already known for an analytic shape.
#[derive(Clone, Copy, Debug)]
pub enum ShapeSample {
    Grid(GridSample),
    Exact(Real, Vec3),
}

impl ShapeSample {
    pub fn distance(&self) -> Real {
        match self {
            ShapeSample::Grid(s) => s.distance,
            ShapeSample::Exact(d, _) => *d,
        }
    }

    /// The outward unit normal, in the shape's frame.
    pub fn normal(&self) -> Vec3 {
        match self {
            ShapeSample::Grid(s) => s.normal(),
            ShapeSample::Exact(_, n) => *n,
        }
    }
}

impl BodyShape {
    /// Signed distance (negative inside) and outward unit normal at `p`, or `None` where the
    /// shape has no data (outside a grid).
    #[inline(always)]
    pub fn query(&self, p: Vec3) -> Option<(Real, Vec3)> {
        match self {
            BodyShape::Grid(grid) => grid.query(p),
            BodyShape::Sphere(s) => Some((s.distance(p), s.normal(p))),
            BodyShape::Cylinder(c) => Some((c.distance(p), c.normal(p))),
            BodyShape::Box(b) => Some((b.distance(p), b.normal(p))),
            BodyShape::Mesh(m) => m.nearest(p).map(|(d, c)| {
                let normal = if d > 0.0 { (p - c) / d } else { Vec3::Z };
                (d, normal)
            }),
            BodyShape::Particles(_) => None,
        }
    }

    /// As [`BodyShape::query`], the normal left to be computed when asked for.
    #[inline(always)]
    pub fn sample(&self, p: Vec3) -> Option<ShapeSample> {
        match self {
            BodyShape::Grid(grid) => grid.sample(p).map(ShapeSample::Grid),
            _ => self.query(p).map(|(d, n)| ShapeSample::Exact(d, n)),
        }
    }

    /// A bound on how fast the sampled distance changes with the point, where a lookup is
    /// worth skipping: a grid's ([`SdfGrid::lipschitz`]). None for the analytic shapes,
    /// which are sampled without memory lookups.
    #[inline(always)]
    pub fn lipschitz(&self) -> Option<Real> {
        match self {
            BodyShape::Grid(grid) => Some(grid.lipschitz()),
            _ => None,
        }
    }

    /// A box in the body frame outside which the shape is not seen (a grid's extent, or the
    /// solid's bounds).
    pub fn bounds(&self) -> Aabb {
        match self {
            BodyShape::Grid(grid) => grid.bounds(),
            BodyShape::Sphere(s) => Aabb {
                min: s.center - Vec3::splat(s.radius),
                max: s.center + Vec3::splat(s.radius),
            },
            BodyShape::Cylinder(c) => {
                let a = c.axis;
                let half = Vec3::new(
                    c.radius * (1.0 - a.x * a.x).max(0.0).sqrt() + 0.5 * c.height * a.x.abs(),
                    c.radius * (1.0 - a.y * a.y).max(0.0).sqrt() + 0.5 * c.height * a.y.abs(),
                    c.radius * (1.0 - a.z * a.z).max(0.0).sqrt() + 0.5 * c.height * a.z.abs(),
                );
                Aabb {
                    min: c.center - half,
                    max: c.center + half,
                }
            }
            BodyShape::Box(b) => Aabb {
                min: b.center - b.half_extents,
                max: b.center + b.half_extents,
            },
            BodyShape::Mesh(m) => m.bounds(),
            BodyShape::Particles(bounds) => *bounds,
        }
    }
}
