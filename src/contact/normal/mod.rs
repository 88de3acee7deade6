//! Normal (elastic repulsion) slot.

mod wca;

pub use wca::{Wca, WcaCoefficients};
