//! Neighbour search: linked cells ([`CellGrid`]) feeding each subdomain's Verlet pair list
//! with a skin ([`PairList`], a half list: each pair's force and history computed and stored
//! once per side), and a pair search over a whole set of particles with periodic images
//! ([`pairs_within`]) for what reads the gathered particles.

mod cell_grid;
mod pair_list;
mod pair_search;

pub use cell_grid::CellGrid;
pub use pair_list::{HistoryRows, ImagePair, PairConstants, PairList};
pub use pair_search::{brute_force_pairs, pairs_within, Pair};
