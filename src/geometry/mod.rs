//! Shapes particles collide with: analytic walls (and, later, SDF bodies from STL).

mod finite_plane;

pub use finite_plane::FinitePlane;
