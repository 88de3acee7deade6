//! Tangential slot.

mod coulomb_mindlin;
mod mindlin;
mod viscous;
mod yang;

pub use coulomb_mindlin::CoulombMindlin;
pub use mindlin::Mindlin;
pub use viscous::ViscousTangential;
pub use yang::{YangTangential, MAX_CONTACTS};

/// The tangential slots built on `Mindlin`'s spring; the walls' epsd2 rolling spring takes
/// its `G_eff`.
pub trait MindlinSpring {
    fn mindlin(&self) -> &Mindlin;
}

impl MindlinSpring for Mindlin {
    fn mindlin(&self) -> &Mindlin {
        self
    }
}

impl MindlinSpring for CoulombMindlin {
    fn mindlin(&self) -> &Mindlin {
        &self.0
    }
}
