//! Integration tests, one binary: physics of the seed's model, coarse-graining invariants,
//! determinism across thread counts, scene validation and the command line.

mod bodies;
mod cli;
mod common;
mod physics;
mod scenes;
