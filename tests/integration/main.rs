//! Integration tests, one binary: physics of the seed's model, coarse-graining invariants,
//! determinism across thread counts, scene validation, the solver guards and the command line.

mod bodies;
mod cli;
mod common;
mod guards;
mod physics;
mod scenes;
