//! Walls: finite planes that can be removed during a run, and the particle-wall laws.

mod wca_wall;

pub use wca_wall::{restitution_damping_ratio, WcaWall, WcaWallSpecies};

use crate::geometry::FinitePlane;
use crate::math::{Real, Vec3};

/// One particle touching one wall, seen from the particle.
#[derive(Clone, Copy, Debug)]
pub struct WallContact {
    pub species: usize,
    /// Unit vector from the wall to the particle centre.
    pub normal: Vec3,
    /// Centre-to-plane distance.
    pub distance: Real,
    /// Particle velocity relative to the wall at the contact point.
    pub relative_velocity: Vec3,
    pub radius: Real,
    pub mass: Real,
}

/// A particle-wall contact law.
pub trait WallLaw: Send + Sync {
    /// Largest centre-to-plane distance at which the wall acts on `species`.
    fn reach(&self, species: usize, radius: Real) -> Real;
    /// Force on the particle; only called when `distance < reach`.
    fn force(&self, contact: &WallContact, dt: Real) -> Vec3;
    /// (stiffness, damping coefficient) of the linearized contact, for the time step.
    fn linearized(&self, species: usize, radius: Real, mass: Real) -> (Real, Real);
}

#[derive(Clone, Debug)]
pub struct Wall {
    pub name: String,
    pub plane: FinitePlane,
    pub active: bool,
}

/// The scene's walls. Removing a wall only deactivates it, so its index stays valid.
#[derive(Clone, Debug, Default)]
pub struct WallSet {
    pub walls: Vec<Wall>,
}

impl WallSet {
    /// Deactivates the named wall; false if there is none by that name.
    pub fn remove(&mut self, name: &str) -> bool {
        match self.walls.iter_mut().find(|w| w.name == name) {
            Some(wall) => {
                wall.active = false;
                true
            }
            None => false,
        }
    }

    /// Total force of the active walls on one particle.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn force_on<W: WallLaw>(
        &self,
        law: &W,
        species: usize,
        position: Vec3,
        velocity: Vec3,
        radius: Real,
        mass: Real,
        dt: Real,
    ) -> Vec3 {
        let reach = law.reach(species, radius);
        let mut total = Vec3::ZERO;
        for wall in self.walls.iter().filter(|w| w.active) {
            let Some(distance) = wall.plane.distance(position) else {
                continue;
            };
            // Only the front side repels: a particle behind a wall has left through it.
            if distance <= 0.0 || distance >= reach {
                continue;
            }
            let contact = WallContact {
                species,
                normal: wall.plane.normal,
                distance,
                relative_velocity: velocity,
                radius,
                mass,
            };
            total += law.force(&contact, dt);
        }
        total
    }
}
