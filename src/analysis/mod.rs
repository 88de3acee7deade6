//! Post-processing shared by every code: cgdem's own state and the reference codes' dumps
//! go through the same functions.

pub mod heap;
