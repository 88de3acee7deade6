//! Tangential slot.

mod viscous;

pub use viscous::ViscousTangential;
