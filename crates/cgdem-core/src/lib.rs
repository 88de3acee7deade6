//! cgdem-core: the cgdem solver, a discrete-element method for powders and granular flow, with
//! coarse-graining.
//!
//! The solver core (particles, neighbour search, contact slots, walls, integration,
//! coarse-graining, scenes) never depends on the validation harness or on plotting.
//!
//! A run ([`run::run`]) reads a [`scene::Scene`] once, coarse-grains its parameters
//! ([`coarse_graining`]: a transform of the scene, never a branch in the force loop), picks
//! the compiled combination of contact slots the scene uses (`run::laws`: absent slots are
//! zero-sized types), places the particles and drives the stages. Each step is the
//! integrator's first half, a neighbour-list rebuild when a particle has moved half the skin
//! (with the exchange of particles between subdomains), the forces of pairs (each once, from
//! its owner, gathered per particle in a fixed order so that any thread count gives the same
//! bits), walls and bodies, the second half, the guards, and the observers that are due
//! (time series, VTK, repose, conveying, packing), which write through [`io`] and
//! [`output_format`]. Restart files ([`run::restart`]) hold the whole state, so a killed
//! run resumes to the same bytes.
//!
//! Layers, lowest first: a module imports only modules listed before it here, so there is
//! no import circle (`scripts/module-graph.py crates/cgdem-core/src`, run by
//! `scripts/test.sh`, checks that).
//! - physics: `math`; `domain`, `geometry`, `particles`, `contact`, `guard`, `timestep`;
//!   `lammps_data` (the data-file format); `neighbor`, `integrate`, `walls`, `bodies`.
//! - input: `scene` (the scene file and its validation: never the world or its outputs);
//!   `coarse_graining`, `insertion` (a scene transformed, particles placed from it).
//! - world (physics only, no scene): `force`, `memory_use` (shared by the two below);
//!   `decomposition`; `simulation` (the `World`).
//! - outputs: `io` (files), then `analysis` (measurements written with it), then
//!   `output_format` (the files every code's run is written into: summary, time series, heap).
//! - `run`: the stage driver, on top of everything.

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
pub mod output_format;
pub mod particles;
pub mod run;
pub mod scene;
pub mod simulation;
pub mod timestep;
pub mod walls;
