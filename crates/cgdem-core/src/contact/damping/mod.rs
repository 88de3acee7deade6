//! Normal damping slot.

mod hertz_liggghts;
mod limit_force;
mod viscous;
mod yang;

pub use hertz_liggghts::{liggghts_damping_factor, restitution_beta, HertzDamping};
pub use limit_force::{clamped_damping_factor, clamped_restitution, LimitForce};
pub use viscous::ViscousNormal;
pub use yang::YangDamping;
