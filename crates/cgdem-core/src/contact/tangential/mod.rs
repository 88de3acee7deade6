//! Tangential slot.

mod mindlin;
mod viscous;
mod yang;

pub use mindlin::Mindlin;
pub use viscous::ViscousTangential;
pub use yang::{YangTangential, MAX_CONTACTS};
