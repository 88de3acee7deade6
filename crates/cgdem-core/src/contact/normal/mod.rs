//! Normal (elastic repulsion) slot.

mod hertz;
mod wca;

pub use hertz::{Hertz, Material};
pub use wca::{Wca, WcaCoefficients};
