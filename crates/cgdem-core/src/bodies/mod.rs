//! Moving bodies: rigid shapes (an SDF grid from an STL or an analytic SDF) with prescribed
//! motion, acting on particles through the scene's wall law (paper A sec. 5.3).

mod body;
mod mesh_contact;
mod motion;
mod particle_body;
mod shape;

pub use body::{Body, BodyLoad, BodySample, BodyState, Clearance};
pub(crate) use mesh_contact::mesh_contacts;
pub use mesh_contact::{NearTriangles, MESH_CONTACTS};
pub use motion::Motion;
pub use particle_body::{fcc_sites_inside, KinematicParticles};
pub use shape::{BodyShape, ShapeSample};
