//! Shapes particles collide with: analytic walls, STL meshes and their signed distance
//! grids, analytic SDFs, the seed's screw-feeder geometry and the benchmark silo.

pub mod aabb;
pub mod accuracy;
pub mod analytic;
pub mod bvh;
mod finite_plane;
pub mod mesh;
mod mesh_builder;
pub mod mesh_surface;
pub mod screw_feeder;
pub mod sdf_grid;
pub mod silo;
pub mod stl;
pub mod triangle_distance;
pub mod winding_number;

pub use aabb::Aabb;
pub use accuracy::{cylinder_mesh, sdf_accuracy, sphere_mesh, AccuracyRow, ScrewFlight, TestShape};
pub use analytic::{
    AxisAlignedBox, Cone, Cylinder, Difference, HalfSpace, Intersection, Sdf, Sphere, Union,
};
pub use bvh::{Bvh, Nearest};
pub use finite_plane::FinitePlane;
pub use mesh::{EdgeDefect, TopologyReport, TriMesh};
pub use mesh_surface::{MeshSurface, TriangleHit};
pub use sdf_grid::{GridSample, SdfGrid, SdfGridError};
pub use stl::{read_stl, read_stl_unchecked, write_stl_ascii, write_stl_binary, StlError};
pub use triangle_distance::{closest_point_on_triangle, TriangleFeature};
pub use winding_number::{winding_number, FastWindingNumber};
