//! cgdem-core: the cgdem solver, a discrete-element method for powders and granular flow, with
//! coarse-graining.
//!
//! The solver core (particles, neighbour search, contact slots, walls, integration,
//! coarse-graining, scenes) never depends on the validation harness or on plotting.


pub mod analysis;
pub mod bodies;
pub mod coarse_graining;
pub mod contact;
pub mod decomposition;
pub mod domain;
pub(crate) mod force;
pub mod geometry;
pub mod guard;
pub mod insertion;
pub mod integrate;
pub mod io;
pub mod lammps_data;
pub mod math;
pub mod memory_use;
pub mod neighbor;
pub mod particles;
pub mod run;
pub mod scene;
pub mod simulation;
pub mod timestep;
pub mod walls;
