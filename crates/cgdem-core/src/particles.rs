//! Particle state, one array per field (structure of arrays).
//!
//! Angular state exists only when the scene's contact law needs rotation; the seed's
//! WCA model never allocates it.

use crate::math::{Real, Vec3};

/// Spin, torque and inverse moment of inertia, present only for laws with rotation.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct AngularState {
    pub omega: Vec<Vec3>,
    pub torque: Vec<Vec3>,
    pub inv_inertia: Vec<Real>,
}

/// All particles of a scene. Index order follows space (re-sorted by cell now and then);
/// `id` is the stable identity used in outputs.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Particles {
    pub id: Vec<u32>,
    pub species: Vec<u16>,
    pub position: Vec<Vec3>,
    pub velocity: Vec<Vec3>,
    pub force: Vec<Vec3>,
    pub radius: Vec<Real>,
    pub mass: Vec<Real>,
    pub inv_mass: Vec<Real>,
    pub angular: Option<AngularState>,
}

impl Particles {
    pub fn new(with_rotation: bool) -> Self {
        Particles {
            angular: with_rotation.then(AngularState::default),
            ..Default::default()
        }
    }

    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Bytes the per-particle arrays hold (at their capacity).
    pub fn array_bytes(&self) -> usize {
        fn bytes<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let mut total = bytes(&self.id)
            + bytes(&self.species)
            + bytes(&self.position)
            + bytes(&self.velocity)
            + bytes(&self.force)
            + bytes(&self.radius)
            + bytes(&self.mass)
            + bytes(&self.inv_mass);
        if let Some(a) = &self.angular {
            total += bytes(&a.omega) + bytes(&a.torque) + bytes(&a.inv_inertia);
        }
        total
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Appends a particle at rest. `mass` in kg; a solid sphere's inertia if rotating.
    pub fn push(&mut self, species: u16, position: Vec3, radius: Real, mass: Real) {
        let next_id = self.id.last().map_or(0, |&last| last + 1);
        self.id.push(next_id);
        self.species.push(species);
        self.position.push(position);
        self.velocity.push(Vec3::ZERO);
        self.force.push(Vec3::ZERO);
        self.radius.push(radius);
        self.mass.push(mass);
        self.inv_mass.push(1.0 / mass);
        if let Some(angular) = &mut self.angular {
            angular.omega.push(Vec3::ZERO);
            angular.torque.push(Vec3::ZERO);
            angular
                .inv_inertia
                .push(1.0 / (0.4 * mass * radius * radius));
        }
    }

    /// Appends a copy of particle `k` of `src` (every per-particle array; spin state when
    /// both have it): how a particle moves to another subdomain or becomes a ghost there.
    pub fn push_copy(&mut self, src: &Particles, k: usize) {
        self.id.push(src.id[k]);
        self.species.push(src.species[k]);
        self.position.push(src.position[k]);
        self.velocity.push(src.velocity[k]);
        self.force.push(src.force[k]);
        self.radius.push(src.radius[k]);
        self.mass.push(src.mass[k]);
        self.inv_mass.push(src.inv_mass[k]);
        if let (Some(to), Some(from)) = (&mut self.angular, &src.angular) {
            to.omega.push(from.omega[k]);
            to.torque.push(from.torque[k]);
            to.inv_inertia.push(from.inv_inertia[k]);
        }
    }

    /// Keeps the first `n` particles.
    pub fn truncate(&mut self, n: usize) {
        self.id.truncate(n);
        self.species.truncate(n);
        self.position.truncate(n);
        self.velocity.truncate(n);
        self.force.truncate(n);
        self.radius.truncate(n);
        self.mass.truncate(n);
        self.inv_mass.truncate(n);
        if let Some(a) = &mut self.angular {
            a.omega.truncate(n);
            a.torque.truncate(n);
            a.inv_inertia.truncate(n);
        }
    }

    /// Fixes particle `k` in place (LIGGGHTS/LAMMPS `fix freeze`): zero inverse mass and
    /// inertia, so the integrator never moves it and its contacts see an infinite mass.
    pub fn freeze(&mut self, k: usize) {
        self.velocity[k] = Vec3::ZERO;
        self.inv_mass[k] = 0.0;
        if let Some(angular) = &mut self.angular {
            angular.omega[k] = Vec3::ZERO;
            angular.inv_inertia[k] = 0.0;
        }
    }

    /// Whether particle `k` is frozen (see [`Particles::freeze`]).
    #[inline(always)]
    pub fn is_frozen(&self, k: usize) -> bool {
        self.inv_mass[k] == 0.0
    }

    /// The same particles with spin state (at rest); frozen particles stay frozen.
    pub fn with_rotation(&self) -> Particles {
        let mut rotating = Particles::new(true);
        for k in 0..self.len() {
            rotating.push(
                self.species[k],
                self.position[k],
                self.radius[k],
                self.mass[k],
            );
            rotating.velocity[k] = self.velocity[k];
            rotating.id[k] = self.id[k];
            if self.is_frozen(k) {
                rotating.freeze(k);
            }
        }
        rotating
    }

    /// Reorders rows of `slots` values per particle (wall and body contact histories) as
    /// [`Particles::permute`] reorders the particles: new row `k` is old row `order[k]`.
    pub fn permute_rows<T: Copy>(rows: &[T], order: &[u32], slots: usize) -> Vec<T> {
        order
            .iter()
            .flat_map(|&o| {
                rows[o as usize * slots..(o as usize + 1) * slots]
                    .iter()
                    .copied()
            })
            .collect()
    }

    /// Reorders every per-particle array: new index `k` holds old particle `order[k]`.
    pub fn permute(&mut self, order: &[u32]) {
        fn apply<T: Copy>(values: &mut Vec<T>, order: &[u32]) {
            let reordered: Vec<T> = order.iter().map(|&old| values[old as usize]).collect();
            *values = reordered;
        }
        apply(&mut self.id, order);
        apply(&mut self.species, order);
        apply(&mut self.position, order);
        apply(&mut self.velocity, order);
        apply(&mut self.force, order);
        apply(&mut self.radius, order);
        apply(&mut self.mass, order);
        apply(&mut self.inv_mass, order);
        if let Some(angular) = &mut self.angular {
            apply(&mut angular.omega, order);
            apply(&mut angular.torque, order);
            apply(&mut angular.inv_inertia, order);
        }
    }

    /// Keeps only the particles for which `keep` is true, preserving order.
    pub fn retain(&mut self, keep: &[bool]) {
        let order: Vec<u32> = (0..self.len() as u32)
            .filter(|&k| keep[k as usize])
            .collect();
        self.permute(&order);
    }

    /// Total kinetic energy (translational plus rotational), J.
    pub fn kinetic_energy(&self) -> Real {
        // Frozen particles moved with a body are not material: their motion is prescribed.
        let translational: Real = self
            .velocity
            .iter()
            .zip(&self.mass)
            .zip(&self.inv_mass)
            .filter(|(_, &inv_m)| inv_m > 0.0)
            .map(|((v, m), _)| 0.5 * m * v.length_squared())
            .sum();
        let rotational: Real = (0..self.len()).map(|k| self.spin_energy(k)).sum();
        translational + rotational
    }

    /// Rotational kinetic energy of particle `k`, J (zero without spin, or frozen).
    pub fn spin_energy(&self, k: usize) -> Real {
        self.angular.as_ref().map_or(0.0, |a| {
            let inv_i = a.inv_inertia[k];
            if inv_i > 0.0 {
                0.5 * a.omega[k].length_squared() / inv_i
            } else {
                0.0
            }
        })
    }

    pub fn total_mass(&self) -> Real {
        self.mass.iter().sum()
    }

    /// Mass of the particles that move (all but the frozen), kg: kinetic energy per mass is
    /// per this mass.
    pub fn mobile_mass(&self) -> Real {
        self.mass
            .iter()
            .zip(&self.inv_mass)
            .filter(|(_, &inv)| inv > 0.0)
            .map(|(m, _)| m)
            .sum()
    }
}
