//! The force kernels of a step: the particle arrays a force pass borrows, one listed pair
//! seen from its first particle, and what acts on one particle alone (gravity, the planar
//! walls, the bodies). Generic over the laws and inlined into the subdomains' force pass.

use crate::bodies::{mesh_contacts, Body, BodyLoad, BodyShape, Clearance, NearTriangles};
use crate::contact::{Contact, PairLaw, PairResult};
use crate::guard::overlap_fraction;
use crate::math::{Real, Vec3};
use crate::neighbor::PairConstants;
use crate::particles::Particles;
use crate::walls::{WallContact, WallLaw, WallMask, WallParticle, WallSet};

/// The particle arrays a force pass reads.
#[derive(Clone, Copy)]
pub(crate) struct ParticleState<'a> {
    pub(crate) position: &'a [Vec3],
    pub(crate) velocity: &'a [Vec3],
    pub(crate) omega: Option<&'a [Vec3]>,
    pub(crate) radius: &'a [Real],
    pub(crate) mass: &'a [Real],
    pub(crate) inv_mass: &'a [Real],
    pub(crate) species: &'a [u16],
}

/// What a force pass borrows from the particles at once: the state it reads and the force
/// and torque arrays it writes (torque empty without rotation).
pub(crate) struct ForceView<'a> {
    pub(crate) state: ParticleState<'a>,
    pub(crate) force: &'a mut [Vec3],
    pub(crate) torque: &'a mut [Vec3],
}

impl<'a> ParticleState<'a> {
    /// The state of `p`, read only.
    pub(crate) fn of(p: &'a Particles) -> Self {
        ParticleState {
            position: &p.position,
            velocity: &p.velocity,
            omega: p.angular.as_ref().map(|a| a.omega.as_slice()),
            radius: &p.radius,
            mass: &p.mass,
            inv_mass: &p.inv_mass,
            species: &p.species,
        }
    }

    /// `p` split into the state a force pass reads and the arrays it writes, every array cut
    /// to the particle count (`same_length`). Inlined, so that the force pass sees where
    /// the lengths come from.
    #[inline(always)]
    pub(crate) fn split(p: &'a mut Particles) -> ForceView<'a> {
        let Particles {
            position,
            velocity,
            force,
            radius,
            mass,
            inv_mass,
            species,
            angular,
            ..
        } = p;
        let n = position.len();
        let (omega, torque) = match angular.as_mut() {
            Some(a) => (Some(&a.omega[..n]), &mut a.torque[..n]),
            None => (None, &mut [][..]),
        };
        ForceView {
            state: ParticleState {
                position,
                velocity,
                omega,
                radius,
                mass,
                inv_mass,
                species,
            }
            .same_length(),
            force: &mut force[..n],
            torque,
        }
    }

    /// Every array cut to `position.len()` (they all have that length): the compiler then
    /// sees one length for all, so the pair loop's first index check of a particle (its
    /// position) stands for the others (its velocity, spin, radius, mass, species), which it
    /// drops. The same values, so the same bits; only checks go.
    #[inline(always)]
    fn same_length(self) -> Self {
        let n = self.position.len();
        ParticleState {
            position: self.position,
            velocity: &self.velocity[..n],
            omega: self.omega.map(|w| &w[..n]),
            radius: &self.radius[..n],
            mass: &self.mass[..n],
            inv_mass: &self.inv_mass[..n],
            species: &self.species[..n],
        }
    }
}

/// What a pair needs of its first particle `i` (the lower id; owned or a ghost), read once.
#[derive(Clone, Copy)]
pub(crate) struct FirstParticle {
    pub(crate) position: Vec3,
    pub(crate) velocity: Vec3,
    pub(crate) omega: Vec3,
    pub(crate) radius: Real,
    pub(crate) inv_mass: Real,
    /// `species_i * n_species`: the row of the species-pair tables.
    pub(crate) species_row: usize,
}

impl FirstParticle {
    /// Particle `i` of `p` (no spin when `p` has none).
    #[inline(always)]
    pub(crate) fn at(p: &ParticleState, i: usize, n_species: usize) -> Self {
        FirstParticle {
            position: p.position[i],
            velocity: p.velocity[i],
            omega: p.omega.map_or(Vec3::ZERO, |w| w[i]),
            radius: p.radius[i],
            inv_mass: p.inv_mass[i],
            species_row: p.species[i] as usize * n_species,
        }
    }
}

/// The force of the pair `(i, j)` seen from `i` (`first`), with `j` at `position_j` (its
/// position, or a periodic image of it); zero (and history reset) when out of range. Also
/// returns the overlap and the smaller radius, for the guard. `constants`: the pair's
/// effective radius and mass, from the list build.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn pair_force<L: PairLaw>(
    law: &L,
    p: &ParticleState,
    first: &FirstParticle,
    j: usize,
    position_j: Vec3,
    constants: PairConstants,
    history: &mut L::History,
    dt: Real,
) -> (PairResult, Real, Real) {
    let d = first.position - position_j;
    let distance_sq = d.length_squared();
    let (radius_i, radius_j) = (first.radius, p.radius[j]);
    let species_pair = first.species_row + p.species[j] as usize;
    let cutoff = law.cutoff(species_pair, radius_i, radius_j);
    if distance_sq >= cutoff * cutoff {
        *history = L::History::default();
        return (PairResult::default(), 0.0, 1.0);
    }
    let distance = distance_sq.sqrt();
    // One division, as LIGGGHTS's `rinv`.
    let normal = d * (1.0 / distance);
    let overlap = radius_i + radius_j - distance;
    let mut relative_velocity = first.velocity - p.velocity[j];
    let mut spins = (Vec3::ZERO, Vec3::ZERO);
    if L::NEEDS_ROTATION {
        if let Some(omega) = p.omega {
            spins = (first.omega, omega[j]);
            // Contact point on the line of centres, inside each sphere by half the overlap.
            let arm_i = -normal * (radius_i - 0.5 * overlap);
            let arm_j = normal * (radius_j - 0.5 * overlap);
            relative_velocity += spins.0.cross(arm_i) - spins.1.cross(arm_j);
        }
    }
    let normal_speed = relative_velocity.dot(normal);
    let (inv_mass_i, inv_mass_j) = (first.inv_mass, p.inv_mass[j]);
    let contact = Contact {
        species_pair,
        normal,
        distance,
        overlap,
        radius_i,
        radius_j,
        r_eff: constants.r_eff,
        inv_mass_i,
        inv_mass_j,
        m_eff: constants.m_eff,
        relative_velocity,
        normal_speed,
        tangential_velocity: relative_velocity - normal_speed * normal,
    };
    (
        law.evaluate(&contact, history, spins, dt),
        overlap,
        radius_i.min(radius_j),
    )
}

/// What acts on one particle alone, besides its pairs: gravity, the planar walls and the
/// bodies (posed at the step's end), with the wall law.
pub(crate) struct Surroundings<'a, W> {
    pub(crate) wall_law: &'a W,
    pub(crate) walls: &'a WallSet,
    pub(crate) bodies: &'a [Body],
    pub(crate) gravity: Vec3,
    pub(crate) dt: Real,
}

/// One particle's slots in the arrays its surroundings keep: the walls it may reach before
/// the next list build, its contact histories (one per planar wall, then
/// `Body::history_slots` per body; empty when particles do not spin) and its clearance per
/// body.
pub(crate) struct AloneSlots<'s, WH> {
    pub(crate) near: WallMask,
    pub(crate) history: &'s mut [WH],
    pub(crate) clearances: &'s mut [Clearance],
    /// One list per body met on its triangles, in body order.
    pub(crate) near_triangles: &'s mut [NearTriangles],
}

impl<W: WallLaw> Surroundings<'_, W> {
    /// Adds to `force` and `torque` (the particle's pair sums; the torque untouched when
    /// particles do not spin) what gravity, the walls and the bodies exert on `particle`, and
    /// returns its deepest wall or body overlap as a fraction of its radius; each body's load
    /// from it is added to `loads` (one per body).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn act_on(
        &self,
        particle: &WallParticle,
        omega: Vec3,
        rotates: bool,
        slots: AloneSlots<'_, W::History>,
        loads: &mut [BodyLoad],
        force: &mut Vec3,
        torque: &mut Vec3,
    ) -> Real {
        let (law, dt) = (self.wall_law, self.dt);
        *force += particle.mass * self.gravity;
        let mut overlap;
        let bodies = self.bodies.iter().zip(slots.clearances).zip(loads);
        let mut lists = slots.near_triangles.iter_mut();
        if rotates {
            let (wall_history, body_history) = slots.history.split_at_mut(self.walls.walls.len());
            if W::NEEDS_ROTATION {
                let (f, t, o) = self.walls.force_and_torque_on(
                    law,
                    particle,
                    slots.near,
                    omega,
                    wall_history,
                    dt,
                );
                *force += f;
                *torque += t;
                overlap = o;
            } else {
                let (f, o) = self.walls.force_on(law, particle, slots.near, dt);
                *force += f;
                overlap = o;
            }
            let mut rest = body_history;
            for ((body, clearance), load) in bodies {
                let (history, tail) = std::mem::take(&mut rest).split_at_mut(body.history_slots());
                rest = tail;
                let (f, t, l, o) = match &body.shape {
                    BodyShape::Mesh(mesh) => {
                        let near = lists.next().expect("a list per mesh body");
                        mesh_contacts(
                            body, mesh, law, particle, omega, history, clearance, near, dt,
                        )
                    }
                    _ => body_force_and_torque(
                        body,
                        law,
                        particle,
                        omega,
                        &mut history[0],
                        clearance,
                        dt,
                    ),
                };
                *force += f;
                *torque += t;
                *load += l;
                overlap = larger(overlap, o);
            }
        } else {
            let (f, o) = self.walls.force_on(law, particle, slots.near, dt);
            *force += f;
            overlap = o;
            for ((body, clearance), load) in bodies {
                let (f, l, o) = match &body.shape {
                    BodyShape::Mesh(mesh) => {
                        let near = lists.next().expect("a list per mesh body");
                        let (f, _, l, o) = mesh_contacts(
                            body,
                            mesh,
                            law,
                            particle,
                            omega,
                            &mut [],
                            clearance,
                            near,
                            dt,
                        );
                        (f, l, o)
                    }
                    _ => body_force(body, law, particle, clearance, dt),
                };
                *force += f;
                *load += l;
                overlap = larger(overlap, o);
            }
        }
        overlap
    }
}

/// Force of one body on one particle (the wall law with the SDF distance and normal and the
/// velocity relative to the body's surface), the particle's load on the body and its overlap
/// with the body as a fraction of the radius. `clearance`: the particle's for this body,
/// which spares lookups far from it (the result is the same).
#[inline(always)]
pub(crate) fn body_force<W: WallLaw>(
    body: &Body,
    law: &W,
    particle: &WallParticle,
    clearance: &mut Clearance,
    dt: Real,
) -> (Vec3, BodyLoad, Real) {
    let reach = law.reach(particle.species, particle.radius);
    // Beyond both the reach and the radius: no force, and no overlap for the guard.
    let beyond = reach.max(particle.radius);
    let Some(sample) = body.sample_near(particle.position, reach, beyond, clearance) else {
        return (Vec3::ZERO, BodyLoad::default(), 0.0);
    };
    let distance = sample.distance();
    let overlap = overlap_fraction(distance, particle.radius);
    // A centre inside the body has passed through it: no force (as for planar walls).
    if distance <= 0.0 || distance >= reach {
        return (Vec3::ZERO, BodyLoad::default(), overlap);
    }
    let normal = sample.normal();
    let contact_point = particle.position - distance * normal;
    let contact = WallContact {
        species: particle.species,
        material: body.material,
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
    (force, load, overlap)
}

/// `body_force` for spinning particles: the wall law's force and torque with the contact's
/// history (tangential and rolling springs kept per particle per body, as for planar walls,
/// and reset when they part). The body's own motion enters through the surface velocity at
/// the contact point.
pub(crate) fn body_force_and_torque<W: WallLaw>(
    body: &Body,
    law: &W,
    particle: &WallParticle,
    omega: Vec3,
    history: &mut W::History,
    clearance: &mut Clearance,
    dt: Real,
) -> (Vec3, Vec3, BodyLoad, Real) {
    let reach = law.reach(particle.species, particle.radius);
    let beyond = reach.max(particle.radius);
    let reset = |history: &mut W::History| {
        if *history != W::History::default() {
            *history = W::History::default();
        }
    };
    let Some(sample) = body.sample_near(particle.position, reach, beyond, clearance) else {
        reset(history);
        return (Vec3::ZERO, Vec3::ZERO, BodyLoad::default(), 0.0);
    };
    let distance = sample.distance();
    let overlap = overlap_fraction(distance, particle.radius);
    if distance <= 0.0 || distance >= reach {
        reset(history);
        return (Vec3::ZERO, Vec3::ZERO, BodyLoad::default(), overlap);
    }
    let normal = sample.normal();
    let contact_point = particle.position - distance * normal;
    let contact = WallContact {
        species: particle.species,
        material: body.material,
        normal,
        distance,
        relative_velocity: particle.velocity - body.surface_velocity(contact_point),
        radius: particle.radius,
        mass: particle.mass,
    };
    let (force, torque) = if W::NEEDS_ROTATION {
        law.force_and_torque_with_history(&contact, omega, history, dt)
    } else {
        (law.force(&contact, dt), Vec3::ZERO)
    };
    let load = BodyLoad {
        force: -force,
        torque: (contact_point - body.center()).cross(-force),
    };
    (force, torque, load, overlap)
}

/// The larger of two overlap fractions (a plain comparison: cheaper than `f64::max`'s NaN
/// handling, and a NaN state is the non-finite guard's business).
#[inline(always)]
pub(crate) fn larger(a: Real, b: Real) -> Real {
    if b > a {
        b
    } else {
        a
    }
}
