//! The world and its step loop, generic over the pair law and the wall law.
//!
//! The combination of laws is fixed when the scene is built, so the compiler sees one
//! concrete force loop per scene: the seed's WCA scene has no rotation, no history and no
//! cohesion in it.

use rayon::prelude::*;

use crate::bodies::{Body, BodyLoad};
use crate::contact::{Contact, PairLaw, PairResult};
use crate::domain::Domain;
use crate::geometry::Aabb;
use crate::integrate::{drift_kick, kick, pcvv, Integrator};
use crate::math::{Real, Vec3};
use crate::neighbor::{Pair, VerletList};
use crate::particles::Particles;
use crate::walls::{WallContact, WallLaw, WallParticle, WallSet};

const CHUNK: usize = 512;

/// Neighbour-list settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeighborSettings {
    /// Verlet skin, m.
    pub skin: Real,
    /// Re-sort particles by cell every this many list builds (0 = never).
    pub resort_every: u32,
}

pub struct World<L: PairLaw, W: WallLaw> {
    pub particles: Particles,
    pub domain: Domain,
    pub walls: WallSet,
    pub law: L,
    pub wall_law: W,
    pub n_species: usize,
    pub gravity: Vec3,
    pub dt: Real,
    pub time: Real,
    pub steps: u64,
    /// Particles removed because they left the box through a bounded face.
    pub lost: u64,
    /// Moving or fixed bodies; empty for scenes without bodies, which then pay nothing.
    bodies: Vec<Body>,
    /// Per particle, per body (particle-major) load, reduced in fixed order after the gather.
    body_loads: Vec<BodyLoad>,
    /// Particles whose centre enters one of these boxes are deleted (e.g. an outlet).
    delete_regions: Vec<Aabb>,
    /// Count and mass of particles deleted by `delete_regions`.
    pub deleted: u64,
    pub deleted_mass: Real,
    neighbor: NeighborSettings,
    list: VerletList,
    history: Vec<L::History>,
    /// Per particle, per planar wall (particle-major, `wall_slots()` each) contact history;
    /// zero-sized for stateless wall laws.
    wall_history: Vec<W::History>,
    pair_result: Vec<PairResult>,
    integrator: Integrator,
    /// PCVV's `F0`, `T0` (empty for velocity Verlet).
    old_force: Vec<Vec3>,
    old_torque: Vec<Vec3>,
}

impl<L: PairLaw, W: WallLaw> World<L, W> {
    /// Whether particles carry spin: the pair law or the wall law needs it.
    pub const ROTATES: bool = L::NEEDS_ROTATION || W::NEEDS_ROTATION;

    #[allow(clippy::too_many_arguments)]
    pub fn new(
        particles: Particles,
        domain: Domain,
        walls: WallSet,
        law: L,
        wall_law: W,
        n_species: usize,
        gravity: Vec3,
        dt: Real,
        neighbor: NeighborSettings,
    ) -> Self {
        let mut particles = particles;
        if Self::ROTATES && particles.angular.is_none() {
            let mut rotating = Particles::new(true);
            for k in 0..particles.len() {
                rotating.push(
                    particles.species[k],
                    particles.position[k],
                    particles.radius[k],
                    particles.mass[k],
                );
                rotating.velocity[k] = particles.velocity[k];
            }
            particles = rotating;
        }
        let mut world = World {
            particles,
            domain,
            walls,
            law,
            wall_law,
            n_species,
            gravity,
            dt,
            time: 0.0,
            steps: 0,
            lost: 0,
            neighbor,
            list: VerletList::new(neighbor.skin),
            history: Vec::new(),
            wall_history: Vec::new(),
            pair_result: Vec::new(),
            bodies: Vec::new(),
            body_loads: Vec::new(),
            delete_regions: Vec::new(),
            deleted: 0,
            deleted_mass: 0.0,
            integrator: Integrator::VelocityVerlet,
            old_force: Vec::new(),
            old_torque: Vec::new(),
        };
        world.rebuild();
        world.compute_forces();
        world
    }

    /// Replaces the bodies (posed at the current time) and re-evaluates the forces.
    pub fn set_bodies(&mut self, bodies: Vec<Body>) {
        self.bodies = bodies;
        let time = self.time;
        for body in &mut self.bodies {
            body.set_time(time);
        }
        self.compute_forces();
    }

    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// Starts the motion of the named body now; false if there is none by that name.
    pub fn start_body(&mut self, name: &str) -> bool {
        let time = self.time;
        match self.bodies.iter_mut().find(|b| b.name == name) {
            Some(body) => {
                body.start(time);
                true
            }
            None => false,
        }
    }

    /// Boxes in which particles are deleted (checked every step).
    pub fn set_delete_regions(&mut self, regions: Vec<Aabb>) {
        self.delete_regions = regions;
    }

    /// Whether a particle has entered a delete region (then the list is rebuilt, which
    /// removes it).
    fn any_in_delete_region(&self) -> bool {
        !self.delete_regions.is_empty()
            && self
                .particles
                .position
                .iter()
                .any(|&x| self.in_delete_region(x))
    }

    /// Moves the moving bodies to their pose at time `t`.
    fn pose_bodies_at(&mut self, t: Real) {
        for body in &mut self.bodies {
            if body.is_moving() {
                body.set_time(t);
            }
        }
    }

    fn in_delete_region(&self, p: Vec3) -> bool {
        self.delete_regions
            .iter()
            .any(|r| p.cmpge(r.min).all() && p.cmple(r.max).all())
    }

    /// The current pair list (for tests and diagnostics).
    pub fn pairs(&self) -> &[Pair] {
        &self.list.pairs
    }

    /// Per-pair contact history, parallel to `pairs()`.
    pub fn history(&self) -> &[L::History] {
        &self.history
    }

    pub fn list_builds(&self) -> u64 {
        self.list.builds
    }

    /// Steps with `integrator` from now on.
    pub fn with_integrator(mut self, integrator: Integrator) -> Self {
        self.integrator = integrator;
        self
    }

    pub fn integrator(&self) -> Integrator {
        self.integrator
    }

    /// One step of the chosen scheme (chosen per step, never per particle).
    pub fn step(&mut self) {
        match self.integrator {
            Integrator::VelocityVerlet => self.step_verlet(),
            Integrator::Pcvv => self.step_pcvv(),
        }
        self.time += self.dt;
        self.steps += 1;
    }

    /// One predictor-corrector velocity-Verlet step, paper B Eq. (11)-(15).
    fn step_pcvv(&mut self) {
        let dt = self.dt;
        let p = &mut self.particles;
        pcvv::predict(&mut p.position, &mut p.velocity, &p.force, &p.inv_mass, dt);
        if Self::ROTATES {
            if let Some(a) = &mut p.angular {
                pcvv::predict_rate(&mut a.omega, &a.torque, &a.inv_inertia, dt);
            }
        }
        if self.list.needs_rebuild(&self.particles.position) || self.any_in_delete_region() {
            self.rebuild();
        }
        self.pose_bodies_at(self.time + dt);
        // F0, T0 after the rebuild, which may reorder particles.
        self.old_force.clone_from(&self.particles.force);
        if Self::ROTATES {
            if let Some(a) = &self.particles.angular {
                self.old_torque.clone_from(&a.torque);
            }
        }
        self.compute_forces();
        let p = &mut self.particles;
        pcvv::correct(&mut p.velocity, &p.force, &self.old_force, &p.inv_mass, dt);
        if Self::ROTATES {
            if let Some(a) = &mut p.angular {
                pcvv::correct(
                    &mut a.omega,
                    &a.torque,
                    &self.old_torque,
                    &a.inv_inertia,
                    dt,
                );
            }
        }
    }

    /// One velocity-Verlet step.
    fn step_verlet(&mut self) {
        let dt = self.dt;
        let p = &mut self.particles;
        drift_kick(&mut p.position, &mut p.velocity, &p.force, &p.inv_mass, dt);
        if Self::ROTATES {
            if let Some(a) = &mut p.angular {
                kick(&mut a.omega, &a.torque, &a.inv_inertia, dt);
            }
        }
        if self.list.needs_rebuild(&self.particles.position) || self.any_in_delete_region() {
            self.rebuild();
        }
        self.pose_bodies_at(self.time + dt);
        self.compute_forces();
        let p = &mut self.particles;
        kick(&mut p.velocity, &p.force, &p.inv_mass, dt);
        if Self::ROTATES {
            if let Some(a) = &mut p.angular {
                kick(&mut a.omega, &a.torque, &a.inv_inertia, dt);
            }
        }
    }

    /// Removes particles that left the box, re-sorts now and then, rebuilds the pair list
    /// and carries the contact history over.
    pub fn rebuild(&mut self) {
        let old_count = self.particles.len();
        // How far the build's wrap will move each particle, for the pairs' images.
        let wraps: Option<Vec<[i32; 3]>> = self.domain.any_periodic().then(|| {
            self.particles
                .position
                .iter()
                .map(|&x| self.domain.wrap_count(x))
                .collect()
        });
        let deleted_before = self.deleted;
        let mut remap: Option<Vec<u32>> = None;
        let mut keep: Vec<bool> = self
            .particles
            .position
            .iter()
            .map(|&x| x.is_finite() && self.domain.contains_bounded(x))
            .collect();
        if !self.delete_regions.is_empty() {
            for (k, &x) in self.particles.position.iter().enumerate() {
                if keep[k] && self.in_delete_region(x) {
                    keep[k] = false;
                    self.deleted += 1;
                    self.deleted_mass += self.particles.mass[k];
                }
            }
        }
        if keep.iter().any(|&k| !k) {
            let mut next = 0u32;
            remap = Some(
                keep.iter()
                    .map(|&k| {
                        if k {
                            next += 1;
                            next - 1
                        } else {
                            u32::MAX
                        }
                    })
                    .collect(),
            );
            self.particles.retain(&keep);
            let slots = self.wall_slots();
            if self.wall_history.len() == keep.len() * slots {
                let mut k = 0;
                self.wall_history.retain(|_| {
                    k += 1;
                    keep[(k - 1) / slots]
                });
            }
            self.lost += (old_count - self.particles.len()) as u64;
            self.lost -= self.deleted - deleted_before;
        }
        let resort = self.neighbor.resort_every > 0
            && self
                .list
                .builds
                .is_multiple_of(self.neighbor.resort_every as u64);
        let old_pairs = std::mem::take(&mut self.list.pairs);
        let old_history = std::mem::take(&mut self.history);
        if let Some(order) =
            self.list
                .build(&mut self.particles, &self.domain, self.law.reach(), resort)
        {
            // The wall history follows its particles.
            let slots = self.wall_slots();
            if self.wall_history.len() == order.len() * slots {
                let old = std::mem::take(&mut self.wall_history);
                self.wall_history = order
                    .iter()
                    .flat_map(|&o| {
                        old[o as usize * slots..(o as usize + 1) * slots]
                            .iter()
                            .copied()
                    })
                    .collect();
            }
            // Compose: old index -> (after removal) -> after re-sort.
            let mut sorted_index = vec![0u32; order.len()];
            for (new, &old) in order.iter().enumerate() {
                sorted_index[old as usize] = new as u32;
            }
            remap = Some(match remap {
                None => sorted_index,
                Some(first) => first
                    .iter()
                    .map(|&k| {
                        if k == u32::MAX {
                            k
                        } else {
                            sorted_index[k as usize]
                        }
                    })
                    .collect(),
            });
        }
        self.history =
            self.list
                .carry_history(&old_pairs, &old_history, wraps.as_deref(), remap.as_deref());
        self.pair_result
            .resize(self.list.pairs.len(), PairResult::default());
    }

    /// Pair forces (each pair once, in parallel), then a per-particle gather in a fixed
    /// order with walls and gravity. No atomics, no thread-count dependence.
    pub fn compute_forces(&mut self) {
        let p = &self.particles;
        let images: [Vec3; 27] = std::array::from_fn(|k| self.domain.image_shift(k as u8));
        let omega = p.angular.as_ref().map(|a| a.omega.as_slice());
        let law = &self.law;
        let n_species = self.n_species;
        let dt = self.dt;
        self.list
            .pairs
            .par_iter()
            .zip(self.history.par_iter_mut())
            .zip(self.pair_result.par_iter_mut())
            .with_min_len(CHUNK)
            .for_each(|((pair, history), result)| {
                *result = pair_force(law, p, omega, &images, n_species, *pair, history, dt);
            });

        if Self::ROTATES {
            self.gather_with_torques();
            return;
        }
        let p = &mut self.particles;
        let (list, results) = (&self.list, &self.pair_result);
        let (walls, wall_law, gravity) = (&self.walls, &self.wall_law, self.gravity);
        let (position, velocity, radius, mass, species) =
            (&p.position, &p.velocity, &p.radius, &p.mass, &p.species);
        let gather = |i: usize| -> (Vec3, WallParticle) {
            let mut f = mass[i] * gravity;
            let particle = WallParticle {
                species: species[i] as usize,
                position: position[i],
                velocity: velocity[i],
                radius: radius[i],
                mass: mass[i],
            };
            f += walls.force_on(wall_law, &particle, dt);
            for k in list.out_start[i]..list.out_start[i + 1] {
                f += results[k as usize].force_on_i;
            }
            for &k in &list.in_pairs[list.in_start[i] as usize..list.in_start[i + 1] as usize] {
                f -= results[k as usize].force_on_i;
            }
            (f, particle)
        };
        if self.bodies.is_empty() {
            p.force
                .par_iter_mut()
                .enumerate()
                .with_min_len(CHUNK)
                .for_each(|(i, force)| *force = gather(i).0);
            return;
        }
        let bodies = &self.bodies;
        let n_bodies = bodies.len();
        self.body_loads
            .resize(p.force.len() * n_bodies, BodyLoad::default());
        p.force
            .par_iter_mut()
            .zip(self.body_loads.par_chunks_mut(n_bodies))
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(i, (force, loads))| {
                let (mut f, particle) = gather(i);
                for (body, load) in bodies.iter().zip(loads.iter_mut()) {
                    let (f_body, l) = body_force(body, wall_law, &particle, dt);
                    f += f_body;
                    *load = l;
                }
                *force = f;
            });
        // Fixed-order reduction: bitwise identical for any thread count.
        for (b, body) in self.bodies.iter_mut().enumerate() {
            let mut total = BodyLoad::default();
            for loads in self.body_loads.chunks_exact(n_bodies) {
                total += loads[b];
            }
            body.load = total;
        }
    }

    /// History entries per particle: one per planar wall (at least one, so chunks exist).
    fn wall_slots(&self) -> usize {
        self.walls.walls.len().max(1)
    }

    /// The gather for spinning particles: forces and torques of pairs, walls and gravity.
    fn gather_with_torques(&mut self) {
        let slots = self.wall_slots();
        let n = self.particles.len();
        if self.wall_history.len() != n * slots {
            self.wall_history.resize(n * slots, W::History::default());
        }
        let wall_history = &mut self.wall_history;
        let (list, results, dt) = (&self.list, &self.pair_result, self.dt);
        let (walls, wall_law, gravity) = (&self.walls, &self.wall_law, self.gravity);
        let Particles {
            position,
            velocity,
            radius,
            mass,
            species,
            force,
            angular,
            ..
        } = &mut self.particles;
        let Some(a) = angular.as_mut() else {
            return;
        };
        let omega = &a.omega;
        force
            .par_iter_mut()
            .zip(a.torque.par_iter_mut())
            .zip(wall_history.par_chunks_mut(slots))
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(i, ((force, torque), wall_history))| {
                let mut f = mass[i] * gravity;
                let particle = WallParticle {
                    species: species[i] as usize,
                    position: position[i],
                    velocity: velocity[i],
                    radius: radius[i],
                    mass: mass[i],
                };
                let mut t = Vec3::ZERO;
                if W::NEEDS_ROTATION {
                    let (wf, wt) =
                        walls.force_and_torque_on(wall_law, &particle, omega[i], wall_history, dt);
                    f += wf;
                    t += wt;
                } else {
                    f += walls.force_on(wall_law, &particle, dt);
                }
                for k in list.out_start[i]..list.out_start[i + 1] {
                    f += results[k as usize].force_on_i;
                    t += results[k as usize].torque_on_i;
                }
                for &k in &list.in_pairs[list.in_start[i] as usize..list.in_start[i + 1] as usize] {
                    f -= results[k as usize].force_on_i;
                    t += results[k as usize].torque_on_j;
                }
                *force = f;
                *torque = t;
            });
    }

    pub fn kinetic_energy(&self) -> Real {
        self.particles.kinetic_energy()
    }
}

/// The force of one listed pair; zero (and history reset) when out of range.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn pair_force<L: PairLaw>(
    law: &L,
    p: &Particles,
    omega: Option<&[Vec3]>,
    images: &[Vec3; 27],
    n_species: usize,
    pair: Pair,
    history: &mut L::History,
    dt: Real,
) -> PairResult {
    let (i, j) = (pair.i as usize, pair.j as usize);
    let d = p.position[i] - (p.position[j] + images[pair.image as usize]);
    let distance_sq = d.length_squared();
    let (radius_i, radius_j) = (p.radius[i], p.radius[j]);
    let species_pair = p.species[i] as usize * n_species + p.species[j] as usize;
    let cutoff = law.cutoff(species_pair, radius_i, radius_j);
    if distance_sq >= cutoff * cutoff {
        *history = L::History::default();
        return PairResult::default();
    }
    let distance = distance_sq.sqrt();
    let normal = d / distance;
    let overlap = radius_i + radius_j - distance;
    let mut relative_velocity = p.velocity[i] - p.velocity[j];
    let mut spins = (Vec3::ZERO, Vec3::ZERO);
    if L::NEEDS_ROTATION {
        if let Some(omega) = omega {
            spins = (omega[i], omega[j]);
            // Contact point on the line of centres, inside each sphere by half the overlap.
            let arm_i = -normal * (radius_i - 0.5 * overlap);
            let arm_j = normal * (radius_j - 0.5 * overlap);
            relative_velocity += spins.0.cross(arm_i) - spins.1.cross(arm_j);
        }
    }
    let normal_speed = relative_velocity.dot(normal);
    let (mass_i, mass_j) = (p.mass[i], p.mass[j]);
    let contact = Contact {
        species_pair,
        normal,
        distance,
        overlap,
        radius_i,
        radius_j,
        r_eff: radius_i * radius_j / (radius_i + radius_j),
        mass_i,
        mass_j,
        m_eff: mass_i * mass_j / (mass_i + mass_j),
        relative_velocity,
        normal_speed,
        tangential_velocity: relative_velocity - normal_speed * normal,
    };
    law.evaluate(&contact, history, spins, dt)
}

/// Force of one body on one particle (the wall law with the SDF distance and normal and the
/// velocity relative to the body's surface), and the particle's load on the body.
#[inline(always)]
fn body_force<W: WallLaw>(
    body: &Body,
    law: &W,
    particle: &WallParticle,
    dt: Real,
) -> (Vec3, BodyLoad) {
    let reach = law.reach(particle.species, particle.radius);
    let Some((distance, normal)) = body.query(particle.position, reach) else {
        return (Vec3::ZERO, BodyLoad::default());
    };
    // A centre inside the body has passed through it: no force (as for planar walls).
    if distance <= 0.0 || distance >= reach {
        return (Vec3::ZERO, BodyLoad::default());
    }
    let contact_point = particle.position - distance * normal;
    let contact = WallContact {
        species: particle.species,
        normal,
        distance,
        relative_velocity: particle.velocity - body.surface_velocity(contact_point),
        radius: particle.radius,
        mass: particle.mass,
    };
    let force = law.force(&contact, dt);
    let load = BodyLoad {
        force: -force,
        torque: (contact_point - body.center()).cross(-force),
    };
    (force, load)
}
