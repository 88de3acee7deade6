//! Neighbour search: linked cells feeding a Verlet pair list with a skin.
//!
//! The list is a *half* list (each pair once, `i < j`, with the periodic image of `j`), so a
//! pair's force and history are computed and stored once. Forces are gathered per particle
//! over its incident pairs in a fixed order, which keeps results independent of the thread
//! count without atomics.

mod cell_grid;
mod verlet_list;

pub use cell_grid::CellGrid;
pub use verlet_list::{brute_force_pairs, DisplacementCheck, Pair, VerletList};
