//! Normal damping slot.

mod hertz_liggghts;
mod viscous;
mod yang;

pub use hertz_liggghts::{liggghts_damping_factor, restitution_beta, HertzDamping};
pub use viscous::ViscousNormal;
pub use yang::YangDamping;
