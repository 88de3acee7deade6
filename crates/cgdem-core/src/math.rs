//! Numeric types used everywhere: one switch for precision.
//!
//! The solver works in SI units and double precision. `Vec3` is glam's `DVec3`
//! (three `f64`, no padding), so a `Vec<Vec3>` is one contiguous array per field.

pub use glam::DVec3 as Vec3;

/// Scalar type of the solver.
pub type Real = f64;

/// 2^(1/6): the WCA cut-off in units of sigma.
pub const TWO_POW_ONE_SIXTH: Real = 1.122_462_048_309_373;
