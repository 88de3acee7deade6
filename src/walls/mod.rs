//! Walls: finite planes that can be removed during a run, and the particle-wall laws.

mod hertz_history_wall;
mod hertz_wall;
mod wca_wall;

pub use hertz_history_wall::{HertzHistoryWall, HertzHistoryWallSpecies};
pub use hertz_wall::{HertzWall, HertzWallSpecies};
pub use wca_wall::{restitution_damping_ratio, WcaWall, WcaWallSpecies};

use crate::geometry::FinitePlane;
use crate::math::{Real, Vec3};
use crate::neighbor::PairHistory;

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
    /// Whether the law uses the particle spin and exerts torques (then the world calls
    /// `force_and_torque` instead of `force`).
    const NEEDS_ROTATION: bool = false;
    /// State of one particle-wall contact (e.g. tangential and rolling springs), kept per
    /// particle per planar wall and reset when they part; `()` for stateless laws.
    type History: PairHistory;
    /// Largest centre-to-plane distance at which the wall acts on `species`.
    fn reach(&self, species: usize, radius: Real) -> Real;
    /// Force on the particle; only called when `distance < reach`.
    fn force(&self, contact: &WallContact, dt: Real) -> Vec3;
    /// Force and torque on a spinning particle; `contact.relative_velocity` is the centre's.
    fn force_and_torque(&self, contact: &WallContact, _omega: Vec3, dt: Real) -> (Vec3, Vec3) {
        (self.force(contact, dt), Vec3::ZERO)
    }
    /// `force_and_torque` with the contact's history (planar walls; bodies use `force`).
    fn force_and_torque_with_history(
        &self,
        contact: &WallContact,
        omega: Vec3,
        _history: &mut Self::History,
        dt: Real,
    ) -> (Vec3, Vec3) {
        self.force_and_torque(contact, omega, dt)
    }
    /// (stiffness, damping coefficient) of the linearized contact, for the time step.
    fn linearized(&self, species: usize, radius: Real, mass: Real) -> (Real, Real);
}

/// The state of one particle that walls act on.
#[derive(Clone, Copy, Debug)]
pub struct WallParticle {
    pub species: usize,
    pub position: Vec3,
    pub velocity: Vec3,
    pub radius: Real,
    pub mass: Real,
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

    /// The contacts of the active walls with one particle.
    #[inline(always)]
    fn contacts<'a, W: WallLaw>(
        &'a self,
        law: &W,
        particle: &'a WallParticle,
    ) -> impl Iterator<Item = WallContact> + 'a {
        let reach = law.reach(particle.species, particle.radius);
        self.walls
            .iter()
            .filter(|w| w.active)
            .filter_map(move |wall| {
                let distance = wall.plane.distance(particle.position)?;
                // Only the front side repels: a particle behind a wall has left through it.
                (distance > 0.0 && distance < reach).then_some(WallContact {
                    species: particle.species,
                    normal: wall.plane.normal,
                    distance,
                    relative_velocity: particle.velocity,
                    radius: particle.radius,
                    mass: particle.mass,
                })
            })
    }

    /// Total force of the active walls on one particle.
    #[inline(always)]
    pub fn force_on<W: WallLaw>(&self, law: &W, particle: &WallParticle, dt: Real) -> Vec3 {
        self.contacts(law, particle)
            .map(|c| law.force(&c, dt))
            .sum()
    }

    /// Total force and torque of the active walls on one spinning particle; `history` holds
    /// one entry per wall (index order), reset for walls the particle does not touch.
    #[inline(always)]
    pub fn force_and_torque_on<W: WallLaw>(
        &self,
        law: &W,
        particle: &WallParticle,
        omega: Vec3,
        history: &mut [W::History],
        dt: Real,
    ) -> (Vec3, Vec3) {
        let reach = law.reach(particle.species, particle.radius);
        let mut total = (Vec3::ZERO, Vec3::ZERO);
        for (wall, state) in self.walls.iter().zip(history.iter_mut()) {
            let touching = wall
                .active
                .then(|| wall.plane.distance(particle.position))
                .flatten()
                .filter(|&d| d > 0.0 && d < reach);
            let Some(distance) = touching else {
                *state = W::History::default();
                continue;
            };
            let contact = WallContact {
                species: particle.species,
                normal: wall.plane.normal,
                distance,
                relative_velocity: particle.velocity,
                radius: particle.radius,
                mass: particle.mass,
            };
            let (f, t) = law.force_and_torque_with_history(&contact, omega, state, dt);
            total.0 += f;
            total.1 += t;
        }
        total
    }
}
