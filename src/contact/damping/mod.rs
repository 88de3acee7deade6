//! Normal damping slot.

mod viscous;

pub use viscous::ViscousNormal;
