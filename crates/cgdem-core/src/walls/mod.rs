//! Walls: finite planes that can be removed during a run, and the particle-wall laws.

mod hertz_history_wall;
mod hertz_wall;
mod wca_wall;

pub use hertz_history_wall::HertzHistoryWall;
pub use hertz_wall::HertzWall;
pub use wca_wall::{restitution_damping_ratio, WcaWall, WcaWallSpecies};

use crate::contact::{Contact, PairHistory};
use crate::geometry::FinitePlane;
use crate::guard::overlap_fraction;
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

impl WallContact {
    /// The contact as the pair slots see it: the wall is a partner of infinite radius and
    /// mass (as in LIGGGHTS), so `R_eff = r`, `m_eff = m`, and the overlap is `r - h`.
    /// `relative_velocity` is the particle's against the wall, as the law takes it (with or
    /// without the spin), split into `normal_speed` and `tangential_velocity` by the caller.
    #[inline(always)]
    pub fn as_pair(
        &self,
        relative_velocity: Vec3,
        normal_speed: Real,
        tangential_velocity: Vec3,
    ) -> Contact {
        Contact {
            species_pair: self.species,
            normal: self.normal,
            distance: self.distance,
            overlap: self.radius - self.distance,
            radius_i: self.radius,
            radius_j: Real::INFINITY,
            r_eff: self.radius,
            inv_mass_i: 1.0 / self.mass,
            inv_mass_j: 0.0,
            m_eff: self.mass,
            relative_velocity,
            normal_speed,
            tangential_velocity,
        }
    }
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

/// A set of walls by index, one bit each (walls from 64 on are always in it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct WallMask(pub u64);

impl WallMask {
    pub const ALL: WallMask = WallMask(u64::MAX);

    #[inline(always)]
    pub fn has(self, k: usize) -> bool {
        k >= 64 || self.0 & (1 << k) != 0
    }
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

    /// The walls a particle at `position` may reach before it moves `margin` (at most half
    /// the skin until the next list build), as a bit per wall: those whose plane is closer
    /// than its reach plus `margin`, or behind it (for the guard), whatever the wall's
    /// extent. All walls when there are more than 64.
    pub fn near<W: WallLaw>(&self, law: &W, particle: &WallParticle, margin: Real) -> WallMask {
        if self.walls.len() > 64 {
            return WallMask::ALL;
        }
        let reach = law.reach(particle.species, particle.radius) + margin;
        let mut bits = 0u64;
        for (k, wall) in self.walls.iter().enumerate() {
            let plane = &wall.plane;
            if (particle.position - plane.point).dot(plane.normal) < reach {
                bits |= 1 << k;
            }
        }
        WallMask(bits)
    }

    /// Total force of the active walls on one particle, and its deepest overlap with one of
    /// them as a fraction of its radius (for the overlap guard, from the same distances).
    /// Only the walls of `near` are looked at: the others are out of reach.
    #[inline(always)]
    pub fn force_on<W: WallLaw>(
        &self,
        law: &W,
        particle: &WallParticle,
        near: WallMask,
        dt: Real,
    ) -> (Vec3, Real) {
        let (mut force, mut overlap) = (Vec3::ZERO, 0.0);
        self.each_wall(law, particle, near, &mut overlap, |_, contact| {
            if let Some(c) = contact {
                force += law.force(&c, dt);
            }
        });
        (force, overlap)
    }

    /// Total force and torque of the active walls on one spinning particle, and its deepest
    /// overlap fraction; `history` holds one entry per wall (index order), reset for walls
    /// of `near` the particle does not touch (those beyond `near` are at rest already).
    #[inline(always)]
    pub fn force_and_torque_on<W: WallLaw>(
        &self,
        law: &W,
        particle: &WallParticle,
        near: WallMask,
        omega: Vec3,
        history: &mut [W::History],
        dt: Real,
    ) -> (Vec3, Vec3, Real) {
        let (mut force, mut torque, mut overlap) = (Vec3::ZERO, Vec3::ZERO, 0.0);
        self.each_wall(
            law,
            particle,
            near,
            &mut overlap,
            |k, contact| match contact {
                Some(c) => {
                    let (f, t) = law.force_and_torque_with_history(&c, omega, &mut history[k], dt);
                    force += f;
                    torque += t;
                }
                // Most particles are far from most walls: testing costs a read, an
                // unconditional reset a write of every particle's history every step.
                None => {
                    if history[k] != W::History::default() {
                        history[k] = W::History::default();
                    }
                }
            },
        );
        (force, torque, overlap)
    }

    /// Calls `act(k, contact)` for every wall k of `near`: the contact when the particle
    /// touches it (an active wall, within reach, on its front side), None otherwise; keeps
    /// the deepest overlap (a centre behind a wall counts, for the guard).
    #[inline(always)]
    fn each_wall<W: WallLaw>(
        &self,
        law: &W,
        particle: &WallParticle,
        near: WallMask,
        overlap: &mut Real,
        mut act: impl FnMut(usize, Option<WallContact>),
    ) {
        let reach = law.reach(particle.species, particle.radius);
        for (k, wall) in self.walls.iter().enumerate() {
            if !near.has(k) {
                continue;
            }
            let distance = wall
                .active
                .then(|| wall.plane.distance(particle.position))
                .flatten()
                .filter(|&d| d < reach);
            let contact = distance.and_then(|distance| {
                *overlap = overlap.max(overlap_fraction(distance, particle.radius));
                // Only the front side repels: a particle behind a wall has left through it.
                (distance > 0.0).then_some(WallContact {
                    species: particle.species,
                    normal: wall.plane.normal,
                    distance,
                    relative_velocity: particle.velocity,
                    radius: particle.radius,
                    mass: particle.mass,
                })
            });
            act(k, contact);
        }
    }
}
