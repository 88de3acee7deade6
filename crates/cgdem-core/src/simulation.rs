//! The world and its step loop, generic over the pair law and the wall law.
//!
//! The combination of laws is fixed when the scene is built, so the compiler sees one
//! concrete force loop per scene: the seed's WCA scene has no rotation, no history and no
//! cohesion in it.

pub(crate) mod network;

pub use network::{ContactNetwork, PairContact};

use rayon::prelude::*;

use crate::bodies::{Body, BodyLoad, Clearance, KinematicParticles};
use crate::contact::PairHistory;
use crate::contact::{Contact, PairLaw};
use crate::decomposition::step::{Decomposition, Drive, Physics};
use crate::decomposition::HistoryRows;
use crate::decomposition::{
    balance, choose_counts, BalanceSpec, Comm, DecompositionSummary, Grid, GridSpec,
};
use crate::domain::{potential_origin, Domain};
use crate::force::{
    body_force, body_force_and_torque, larger, pair_force, ForceView, Owner, ParticleState,
};
use crate::geometry::aabb::in_delete_region;
use crate::geometry::Aabb;
use crate::guard::{
    forced_step_cause, overlap_cause, overlap_fraction, undamped_limit, GuardKind, GuardPeaks,
    GuardSettings, GuardState, GuardTrip,
};
use crate::integrate::{complete_and_kick, drift_kick, pcvv, Integrator};
use crate::math::{Real, Vec3};
use crate::memory_use::MemoryUse;
use crate::neighbor::{Pair, VerletList};
use crate::particles::Particles;
use crate::walls::{WallContact, WallLaw, WallParticle, WallSet};

const CHUNK: usize = 512;

/// Everything a world carries from one step to the next that its scene does not give: the
/// particles (with the forces and torques the next step's first half-kick uses), the pair
/// list as built (its pair order is the force summation order, and its reference positions
/// decide the next rebuild), the contact and wall histories, the bodies' poses, the
/// counters and the guards' state. A world built from the same scene and given this state
/// steps on bit for bit as the world it was taken from (`run::restart`).
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct WorldState<H: PairHistory, WH: PairHistory> {
    particles: Particles,
    time: Real,
    steps: u64,
    lost: u64,
    deleted: u64,
    deleted_mass: Real,
    wall_active: Vec<bool>,
    bodies: Vec<crate::bodies::BodyState>,
    body_loads: Vec<BodyLoad>,
    list: VerletList,
    history: Vec<H>,
    wall_history: Vec<WH>,
    reaction_force: Vec<Vec3>,
    reaction_spin: Vec<[Vec3; 2]>,
    old_force: Vec<Vec3>,
    old_torque: Vec<Vec3>,
    guard: GuardState,
    /// The arrays' capacities, given back on restore so that `MemoryUse` (in summary.json)
    /// and later growth are those of the run the state was taken from.
    capacities: Vec<usize>,
    /// The subdomains, when decomposed (`--grid`): then they hold the particles' state and
    /// the list, and `particles` is the world's copy as last gathered.
    decomposed: Option<crate::decomposition::DecomposedState>,
}

/// Applies `$m!` to each array of a world whose capacity `MemoryUse` counts, in a fixed
/// order (the particles' spin arrays last, when there are any).
macro_rules! world_arrays {
    ($w:expr, $m:ident, $angular:ident) => {{
        $m!($w.particles.id);
        $m!($w.particles.species);
        $m!($w.particles.position);
        $m!($w.particles.velocity);
        $m!($w.particles.force);
        $m!($w.particles.radius);
        $m!($w.particles.mass);
        $m!($w.particles.inv_mass);
        $m!($w.body_loads);
        $m!($w.history);
        $m!($w.wall_history);
        $m!($w.reaction_force);
        $m!($w.reaction_spin);
        $m!($w.old_force);
        $m!($w.old_torque);
        $m!($w.list.pairs);
        $m!($w.list.out_start);
        $m!($w.list.in_start);
        $m!($w.list.in_pairs);
        $m!($w.list.reference);
        if let Some(a) = $w.particles.angular.$angular() {
            $m!(a.omega);
            $m!(a.torque);
            $m!(a.inv_inertia);
        }
    }};
}

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
    /// Per particle, per body (particle-major) load, reduced in fixed order after the owner
    /// pass.
    body_loads: Vec<BodyLoad>,
    /// Per particle, per body (particle-major): where it needs no SDF lookup. Not part of
    /// the state: it only spares work, so a world without it steps on the same.
    body_clearances: Vec<Clearance>,
    /// Frozen particles that move with a body (a body built of particles).
    kinematic: Vec<KinematicParticles>,
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
    /// Per listed pair, the force on its `j` (empty when particles spin).
    reaction_force: Vec<Vec3>,
    /// Per listed pair, the force and torque on its `j`, side by side so the closing kick reads
    /// one place (empty without spin).
    reaction_spin: Vec<[Vec3; 2]>,
    integrator: Integrator,
    /// PCVV's `F0`, `T0` (empty for velocity Verlet).
    old_force: Vec<Vec3>,
    old_torque: Vec<Vec3>,
    guard: GuardState,
    /// Subdomains with ghosts (`--grid`); when set they hold the state, and `particles` is
    /// their owned particles side by side, refreshed every step.
    decomposition: Option<Box<Decomposition<L::History, W::History>>>,
    /// Subdomains from a restart file, taken up by the next `set_grid`.
    restored_grid: Option<Box<crate::decomposition::DecomposedState>>,
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
            particles = particles.with_rotation();
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
            reaction_force: Vec::new(),
            reaction_spin: Vec::new(),
            bodies: Vec::new(),
            body_loads: Vec::new(),
            body_clearances: Vec::new(),
            kinematic: Vec::new(),
            delete_regions: Vec::new(),
            deleted: 0,
            deleted_mass: 0.0,
            integrator: Integrator::VelocityVerlet,
            old_force: Vec::new(),
            old_torque: Vec::new(),
            guard: GuardState {
                finite: true,
                ..Default::default()
            },
            decomposition: None,
            restored_grid: None,
        };
        world.rebuild();
        world.compute_forces();
        world.guard.initial_overlap = Some(world.max_overlap_fraction());
        world.reset_energy_reference();
        world
    }

    /// The world's changing state, for a restart file. When decomposed (`--grid`) the
    /// subdomains' state is gathered from every rank (collective).
    pub fn state(&self) -> WorldState<L::History, W::History> {
        let mut state = WorldState {
            particles: self.particles.clone(),
            time: self.time,
            steps: self.steps,
            lost: self.lost,
            deleted: self.deleted,
            deleted_mass: self.deleted_mass,
            wall_active: self.walls.walls.iter().map(|w| w.active).collect(),
            bodies: self.bodies.iter().map(Body::state).collect(),
            body_loads: self.body_loads.clone(),
            list: self.list.clone(),
            history: self.history.clone(),
            wall_history: self.wall_history.clone(),
            reaction_force: self.reaction_force.clone(),
            reaction_spin: self.reaction_spin.clone(),
            old_force: self.old_force.clone(),
            old_torque: self.old_torque.clone(),
            guard: self.guard.clone(),
            capacities: Vec::new(),
            decomposed: self.decomposition.as_ref().map(|d| d.state()),
        };
        // The clones have their lengths as capacities; keep this world's.
        let mut capacities = Vec::new();
        macro_rules! record {
            ($v:expr) => {
                capacities.push($v.capacity())
            };
        }
        world_arrays!(self, record, as_ref);
        state.capacities = capacities;
        state
    }

    /// Puts back a state taken by [`World::state`] from a world built from the same scene
    /// (the guard settings stay this world's); an error when the walls or bodies differ. A
    /// decomposed state's subdomains wait for [`World::set_grid`].
    pub fn set_state(&mut self, state: WorldState<L::History, W::History>) -> Result<(), String> {
        if state.wall_active.len() != self.walls.walls.len()
            || state.bodies.len() != self.bodies.len()
        {
            return Err(format!(
                "the stored state has {} walls and {} bodies, the scene {} and {}",
                state.wall_active.len(),
                state.bodies.len(),
                self.walls.walls.len(),
                self.bodies.len()
            ));
        }
        if self.decomposition.is_some() {
            return Err("a decomposed world (--grid) cannot take a stored state".into());
        }
        for (wall, &active) in self.walls.walls.iter_mut().zip(&state.wall_active) {
            wall.active = active;
        }
        for (body, s) in self.bodies.iter_mut().zip(&state.bodies) {
            body.set_state(s);
        }
        let settings = std::mem::take(&mut self.guard.settings);
        self.particles = state.particles;
        self.time = state.time;
        self.steps = state.steps;
        self.lost = state.lost;
        self.deleted = state.deleted;
        self.deleted_mass = state.deleted_mass;
        self.body_loads = state.body_loads;
        self.list = state.list;
        self.history = state.history;
        self.wall_history = state.wall_history;
        self.reaction_force = state.reaction_force;
        self.reaction_spin = state.reaction_spin;
        self.old_force = state.old_force;
        self.old_torque = state.old_torque;
        self.guard = state.guard;
        self.guard.settings = settings;
        let mut capacities = state.capacities.into_iter();
        macro_rules! reserve {
            ($v:expr) => {
                if let Some(c) = capacities.next() {
                    if c > $v.capacity() {
                        $v.reserve_exact(c - $v.len());
                    }
                }
            };
        }
        world_arrays!(self, reserve, as_mut);
        self.restored_grid = state.decomposed.map(Box::new);
        Ok(())
    }

    /// The grid of the subdomains a restored state holds (taken up by `set_grid`).
    pub fn restored_grid(&self) -> Option<[usize; 3]> {
        self.restored_grid.as_ref().map(|d| d.grid.counts)
    }

    /// Replaces the bodies (posed at the current time) and re-evaluates the forces.
    pub fn set_bodies(&mut self, bodies: Vec<Body>) {
        self.bodies = bodies;
        // Bodies take history slots after the planar walls': start them empty.
        self.wall_history.clear();
        self.body_clearances.clear();
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

    /// Frozen particles that move with bodies (each body's `Particles` shape); their
    /// positions and velocities are set from the bodies' motion from the next step on.
    pub fn set_kinematic(&mut self, kinematic: Vec<KinematicParticles>) {
        self.kinematic = kinematic;
    }

    /// Moves the particles of bodies built of particles to the bodies' pose at time `t`
    /// (`KinematicParticles::drive`); all zero before the motion starts. They are frozen
    /// (zero inverse mass), so the integrator never changes them.
    fn drive_kinematic_particles(&mut self, t: Real) {
        if self.kinematic.is_empty() {
            return;
        }
        self.pose_bodies_at(t);
        let n = self.particles.len();
        for group in &self.kinematic {
            group.drive(&self.bodies[group.body], &mut self.particles, n);
        }
    }

    /// Adds the load of the grains on the particles of bodies built of particles (contact
    /// force `F - m g` on each, torque about the body's axis point) to the bodies' loads,
    /// after the force evaluation.
    fn record_kinematic_loads(&mut self) {
        if let Some(d) = &self.decomposition {
            // Summed by the subdomains in the last force pass.
            for (group, load) in self.kinematic.iter().zip(&d.kinematic_loads) {
                self.bodies[group.body].load += *load;
            }
            return;
        }
        let p = &self.particles;
        for group in &self.kinematic {
            let body = &mut self.bodies[group.body];
            let mut load = BodyLoad::default();
            for k in 0..p.id.len() {
                if group.reference_of(p.id[k]).is_some() {
                    let f = p.force[k] - p.mass[k] * self.gravity;
                    load.force += f;
                    load.torque += (p.position[k] - body.center()).cross(f);
                }
            }
            body.load += load;
        }
    }

    /// Appends mobile particles at rest (ids after the largest so far), rebuilds the pair
    /// list and re-evaluates the forces; the energy guard takes the new state as reference.
    pub fn add_particles(&mut self, species: u16, positions: &[Vec3], radius: Real, mass: Real) {
        if positions.is_empty() {
            return;
        }
        let next = self.particles.id.iter().max().map_or(0, |&m| m + 1);
        let decomposed = self.decomposition.take();
        // Under MPI every rank gathers every particle, adds the same ones and deals out its
        // own again.
        let rows = decomposed.as_ref().map(|d| d.gathered_rows());
        if let Some(d) = &decomposed {
            // The wall histories live in the subdomains between rebuilds.
            (self.particles, self.wall_history) = d.gathered();
        }
        for (n, &x) in positions.iter().enumerate() {
            self.particles.push(species, x, radius, mass);
            *self.particles.id.last_mut().expect("just pushed") = next + n as u32;
        }
        match (decomposed, rows) {
            (Some(d), Some(mut rows)) => {
                // Dealt out again over the same cut planes (still thick enough); that
                // evaluates the forces, once: a second evaluation would advance the
                // tangential springs twice.
                for _ in 0..positions.len() {
                    rows.push(&[]);
                }
                let balance = d.balance.clone();
                self.decompose(d.grid, rows, d.comm);
                if let Some(d) = self.decomposition.as_mut() {
                    d.balance = balance;
                }
            }
            _ => {
                self.rebuild();
                self.compute_forces();
            }
        }
        self.record_kinematic_loads();
        self.reset_energy_reference();
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
        in_delete_region(&self.delete_regions, p)
    }

    /// The current pair list (for tests and diagnostics).
    pub fn pairs(&self) -> &[Pair] {
        &self.list.pairs
    }

    /// Per-pair contact history, parallel to `pairs()`.
    pub fn history(&self) -> &[L::History] {
        &self.history
    }

    /// The memory the world's arrays hold now.
    pub fn memory_use(&self) -> MemoryUse {
        fn bytes<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let p = &self.particles;
        let particle_bytes = p.array_bytes()
            + bytes(&self.wall_history)
            + bytes(&self.body_loads)
            + bytes(&self.body_clearances)
            + bytes(&self.old_force)
            + bytes(&self.old_torque)
            + self.list.particle_bytes();
        let global = MemoryUse {
            particles: p.len(),
            particle_bytes,
            pairs: self.list.pairs.len(),
            pair_bytes: self.list.pair_bytes()
                + bytes(&self.history)
                + bytes(&self.reaction_force)
                + bytes(&self.reaction_spin),
            history_entries: self.history.len(),
        };
        match &self.decomposition {
            // This rank's subdomains (ghosts included) and their lists, per particle it
            // owns, plus the world's arrays the outputs read (gathered when read, on every
            // rank: all particles; the global list stays empty).
            Some(d) => {
                let local = d.memory_use();
                MemoryUse {
                    particle_bytes: global.particle_bytes
                        + global.pair_bytes
                        + local.particle_bytes,
                    ..local
                }
            }
            None => global,
        }
    }

    pub fn list_builds(&self) -> u64 {
        if let Some(d) = &self.decomposition {
            return d.builds;
        }
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
        self.record_kinematic_loads();
        self.check_guards();
    }

    /// One predictor-corrector velocity-Verlet step, paper B Eq. (11)-(15).
    fn step_pcvv(&mut self) {
        if self.decomposition.is_some() {
            self.step_decomposed();
            return;
        }
        let dt = self.dt;
        let p = &mut self.particles;
        pcvv::par_predict(&mut p.position, &mut p.velocity, &p.force, &p.inv_mass, dt);
        if Self::ROTATES {
            if let Some(a) = &mut p.angular {
                pcvv::par_predict_rate(&mut a.omega, &a.torque, &a.inv_inertia, dt);
            }
        }
        self.drive_kinematic_particles(self.time + dt);
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
        let mut finite =
            pcvv::par_correct(&mut p.velocity, &p.force, &self.old_force, &p.inv_mass, dt);
        if Self::ROTATES {
            if let Some(a) = &mut p.angular {
                finite &= pcvv::par_correct(
                    &mut a.omega,
                    &a.torque,
                    &self.old_torque,
                    &a.inv_inertia,
                    dt,
                );
            }
        }
        self.guard.finite = finite;
    }

    /// One velocity-Verlet step.
    fn step_verlet(&mut self) {
        if self.decomposition.is_some() {
            self.step_decomposed();
            return;
        }
        let dt = self.dt;
        // The list's displacement test runs inside the drift, unless bodies built of
        // particles move some particles after it: then it runs once they have moved.
        let rebuild = if self.kinematic.is_empty() {
            let check = self.list.displacement_check(self.particles.len());
            let must_rebuild = check.is_none();
            drift_kick(&mut self.particles, dt, check) || must_rebuild
        } else {
            drift_kick(&mut self.particles, dt, None);
            self.drive_kinematic_particles(self.time + dt);
            self.list.needs_rebuild(&self.particles.position)
        };
        if rebuild || self.any_in_delete_region() {
            self.rebuild();
        }
        self.pose_bodies_at(self.time + dt);
        self.owner_pass();
        let (reactions, p) = self.reactions_and_particles();
        let finite = complete_and_kick(p, dt, |i, f, t| reactions.add_to(i, f, t));
        self.guard.finite = finite;
    }

    /// The reactions the owner pass stored, beside the particles they complete.
    fn reactions_and_particles(&mut self) -> (Reactions<'_>, &mut Particles) {
        let reactions = Reactions {
            list: &self.list,
            force: &self.reaction_force,
            spin: &self.reaction_spin,
        };
        (reactions, &mut self.particles)
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
        // A particle that left through a bounded face is removed, unless that stops the run:
        // then it stays where it is, so the outputs hold it, and the guard names it.
        let stop_on_lost = self.guard.settings.stop_on_lost;
        let mut keep: Vec<bool> = Vec::with_capacity(old_count);
        for (k, &x) in self.particles.position.iter().enumerate() {
            let inside = self.domain.contains_bounded(x);
            if stop_on_lost && x.is_finite() && !inside && self.guard.trip.is_none() {
                let p = &self.particles;
                self.guard.left_box.push((p.id[k], x, p.velocity[k]));
            }
            keep.push(x.is_finite() && (inside || stop_on_lost));
        }
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
            // The energy guard's reference loses what the removed particles carried; a
            // non-finite position is the non-finite guard's business, not a lost particle.
            for (k, _) in keep.iter().enumerate().filter(|(_, &kept)| !kept) {
                let e = self.particle_energy(k);
                if e.is_finite() {
                    self.guard.removed_energy += e;
                } else {
                    self.guard.removed_non_finite.push(self.particles.id[k]);
                }
            }
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
                self.wall_history = Particles::permute_rows(&self.wall_history, &order, slots);
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
    }

    /// Every particle's force and torque: the owner pass, then the reactions.
    pub fn compute_forces(&mut self) {
        if self.decomposition.is_some() {
            self.decomposed_forces(None);
            return;
        }
        self.owner_pass();
        let (reactions, p) = self.reactions_and_particles();
        match p.angular.as_mut() {
            Some(a) => p
                .force
                .par_iter_mut()
                .zip(a.torque.par_iter_mut())
                .enumerate()
                .with_min_len(CHUNK)
                .for_each(|(i, (f, t))| reactions.add_to(i, f, t)),
            None => p
                .force
                .par_iter_mut()
                .enumerate()
                .with_min_len(CHUNK)
                .for_each(|(i, f)| reactions.add_to(i, f, &mut Vec3::default())),
        }
    }

    /// Leaves in each particle's force (and torque) everything but the reactions of pairs
    /// owned by other particles, which it stores per pair. No atomics, no thread-count
    /// dependence.
    ///
    /// Each pair is evaluated once, by its owner `i` (the list holds `i < j`, grouped by `i`):
    /// the owner sums its own share as it goes, then gravity, its walls and bodies (it has
    /// its position and velocity at hand), and stores only what `j` receives (the reaction
    /// force, and the torque on `j` when particles spin). Whoever completes the forces adds
    /// those in list order: `compute_forces`, or the closing kick of a velocity-Verlet step,
    /// which so reads each particle once instead of twice.
    fn owner_pass(&mut self) {
        let n = self.particles.len();
        let pairs = self.list.pairs.len();
        let wall_slots = self.wall_slots();
        if Self::ROTATES {
            self.reaction_spin.resize(pairs, [Vec3::ZERO; 2]);
            if self.wall_history.len() != n * wall_slots {
                self.wall_history
                    .resize(n * wall_slots, W::History::default());
            }
        } else {
            self.reaction_force.resize(pairs, Vec3::ZERO);
        }
        let n_bodies = self.bodies.len();
        self.body_loads.resize(n * n_bodies, BodyLoad::default());
        // Allocated to the size exactly, so that the memory summary.json reports does not
        // depend on the run's history (a resumed run starts without clearances).
        if self.body_clearances.len() != n * n_bodies {
            self.body_clearances = vec![Clearance::NONE; n * n_bodies];
        }
        let ForceView {
            state,
            force,
            torque,
            ..
        } = ParticleState::split(&mut self.particles);
        let pass = OwnerPass {
            law: &self.law,
            wall_law: &self.wall_law,
            state,
            images: std::array::from_fn(|k| self.domain.image_shift(k as u8)),
            n_species: self.n_species,
            dt: self.dt,
            pairs: &self.list.pairs,
            out_start: &self.list.out_start,
            walls: &self.walls,
            bodies: &self.bodies,
            gravity: self.gravity,
            rotates: Self::ROTATES,
            wall_slots,
        };
        // The largest overlap fractions, for the overlap guard (max is exact in any order).
        let deepest = pass.run(
            0,
            OwnerSlices {
                force,
                torque,
                history: &mut self.history,
                reaction_force: &mut self.reaction_force,
                reaction_spin: &mut self.reaction_spin,
                wall_history: &mut self.wall_history,
                body_loads: &mut self.body_loads,
                body_clearances: &mut self.body_clearances,
            },
        );
        self.guard.pair_overlap = deepest.pairs;
        self.guard.wall_overlap = deepest.walls;
        if n_bodies > 0 {
            self.reduce_body_loads();
        }
    }

    /// Sums the per-particle body loads into the bodies, in a fixed order: bitwise identical
    /// for any thread count.
    fn reduce_body_loads(&mut self) {
        let n_bodies = self.bodies.len();
        for (b, body) in self.bodies.iter_mut().enumerate() {
            let mut total = BodyLoad::default();
            for loads in self.body_loads.chunks_exact(n_bodies) {
                total += loads[b];
            }
            body.load = total;
        }
    }

    /// History entries per particle: one per planar wall, then one per body (at least one,
    /// so chunks exist).
    fn wall_slots(&self) -> usize {
        (self.walls.walls.len() + self.bodies.len()).max(1)
    }

    /// Splits the world into the subdomains of `spec` (`--grid`): from now on each steps
    /// its own particles and ghosts (either integrator, walls, bodies, delete regions).
    /// Under MPI (`comm` of several ranks) each rank steps the subdomains it owns.
    pub fn set_grid(&mut self, spec: GridSpec, comm: Comm) -> Result<(), String> {
        if let Some(stored) = self.restored_grid.take() {
            return self.resume_grid(spec, comm, *stored);
        }
        let grid = self.grid_for(spec, self.ghost_width(), comm.size())?;
        // Histories by partner id, in the pair's canonical orientation (lower id first).
        let p = &self.particles;
        let mut entries = Vec::new();
        for (pair, &h) in self.list.pairs.iter().zip(&self.history) {
            if h == L::History::default() {
                continue;
            }
            let (i, j) = (pair.i, pair.j);
            let (id_i, id_j) = (p.id[i as usize], p.id[j as usize]);
            let h = if id_i < id_j { h } else { h.mirrored() };
            entries.push((i, id_j, h));
            entries.push((j, id_i, h));
        }
        let rows = HistoryRows::from_entries(p.len(), entries);
        self.decompose(grid, rows, comm);
        self.list = VerletList::new(self.neighbor.skin);
        self.history = Vec::new();
        self.reaction_force = Vec::new();
        self.reaction_spin = Vec::new();
        Ok(())
    }

    /// Takes up the subdomains of a restart file: on the grid they were (the same counts)
    /// each as it was, so the run steps on bit for bit on any number of threads or ranks; on
    /// another grid the owned particles dealt out again with their histories, on planes by
    /// count (as a rebuild with a rebalance), the stored forces kept.
    fn resume_grid(
        &mut self,
        spec: GridSpec,
        comm: Comm,
        stored: crate::decomposition::DecomposedState,
    ) -> Result<(), String> {
        let slots = self.wall_slots();
        let same = match spec {
            GridSpec::Given(counts) => counts == stored.grid.counts,
            GridSpec::Auto(n) => n == stored.grid.len(),
        };
        let decomposition = if same && comm.size() <= stored.grid.len() {
            let threshold = None;
            Decomposition::from_state(stored, comm, threshold, Self::ROTATES, slots)?
        } else {
            let (particles, wall_history, rows) =
                Decomposition::<L::History, W::History>::gathered_from_state(
                    &stored,
                    Self::ROTATES,
                    slots,
                )?;
            self.particles = particles;
            self.wall_history = wall_history;
            let grid = self.grid_for(spec, stored.width, comm.size())?;
            let mut d = Decomposition::new(
                grid,
                &self.particles,
                &self.wall_history,
                &rows,
                &self.domain,
                slots,
                stored.width,
                stored.extra,
                stored.skin,
                comm,
            );
            d.builds = stored.builds + 1;
            d
        };
        self.decomposition = Some(Box::new(decomposition));
        self.list = VerletList::new(self.neighbor.skin);
        self.history = Vec::new();
        self.reaction_force = Vec::new();
        self.reaction_spin = Vec::new();
        self.sync_particles();
        Ok(())
    }

    /// The grid of `spec` over the particles, its planes by count and at least `width`
    /// apart; an error when no placement is thick enough or `ranks` outnumber its
    /// subdomains.
    fn grid_for(&self, spec: GridSpec, width: Real, ranks: usize) -> Result<Grid, String> {
        let p = &self.particles;
        let counts = match spec {
            GridSpec::Given(counts) => counts,
            GridSpec::Auto(count) => {
                let mut extent = self.domain.length();
                for a in 0..3 {
                    let (lo, hi) = p
                        .position
                        .iter()
                        .fold((Real::MAX, Real::MIN), |(lo, hi), x| {
                            (lo.min(x[a]), hi.max(x[a]))
                        });
                    if !self.domain.periodic[a] && hi > lo {
                        extent[a] = hi - lo;
                    }
                }
                choose_counts(count, extent, self.domain.periodic)
            }
        };
        let mut grid = Grid::balanced(counts, &self.domain, &p.position);
        if grid.check_width(width).is_err() {
            // By count the planes crowd where the particles do: moved apart to a ghost layer
            // (as a balance shift would be); refused only if no placement is thick enough.
            balance::clamp_to_width(&mut grid, width);
        }
        grid.check_width(width)?;
        // The ghost layer is the contact distance plus the skin.
        grid.check_periodic_images(width - self.neighbor.skin)?;
        if ranks > grid.len() {
            return Err(format!(
                "{ranks} MPI ranks need at least as many subdomains, and the grid {}x{}x{} has {}; give a grid of at least {ranks} subdomains",
                counts[0],
                counts[1],
                counts[2],
                grid.len(),
            ));
        }
        Ok(grid)
    }

    /// `--balance`: whether the cut planes move by count at a rebuild when the imbalance
    /// passes the threshold (call after `set_grid`; nothing to do undecomposed).
    pub fn set_balance(&mut self, spec: BalanceSpec) {
        if let Some(d) = self.decomposition.as_mut() {
            d.balance.threshold = spec.threshold();
        }
    }

    /// The ghost layer: largest diameter plus the law's reach plus the skin.
    fn ghost_width(&self) -> Real {
        let max_radius = self.particles.radius.iter().cloned().fold(0.0, Real::max);
        2.0 * max_radius + self.law.reach() + self.neighbor.skin
    }

    /// Deals the particles out over `grid` with their histories and evaluates the forces.
    fn decompose(&mut self, grid: Grid, rows: HistoryRows<L::History>, comm: Comm) {
        let slots = self.wall_slots();
        self.wall_history
            .resize(self.particles.len() * slots, W::History::default());
        let decomposition = Decomposition::new(
            grid,
            &self.particles,
            &self.wall_history,
            &rows,
            &self.domain,
            slots,
            self.ghost_width(),
            self.law.reach() + self.neighbor.skin,
            self.neighbor.skin,
            comm,
        );
        self.decomposition = Some(Box::new(decomposition));
        // The subdomains keep their own clearances.
        self.body_clearances = Vec::new();
        self.decomposed_forces(None);
        // The forces live in the subdomains: gather them (every rank).
        self.sync_particles();
    }

    /// While decomposed, brings the subdomains' owned particles (every rank's under MPI)
    /// into `particles`, in subdomain order: call before reading `particles`. The step
    /// itself never writes `particles` (threads and ranks alike), so that no step pays for
    /// a copy that only outputs read. Collective: every rank must call it at the same step.
    /// Nothing to do when not decomposed.
    pub fn sync_particles(&mut self) {
        if let Some(d) = &self.decomposition {
            (self.particles, self.wall_history) = d.gathered();
        }
    }

    /// `sync_particles` for what only rank 0 writes: under MPI only rank 0 receives the
    /// particles, the other ranks' `particles` stay as they were (call `sync_particles`
    /// where every rank takes a decision from them). Collective.
    pub fn sync_particles_for_output(&mut self) {
        if let Some(d) = &self.decomposition {
            if let Some(gathered) = d.gathered_to(true) {
                (self.particles, self.wall_history) = gathered;
            }
        }
    }

    /// Particles in the world (while decomposed, over all subdomains and ranks: `particles`
    /// is refreshed only by `sync_particles`).
    pub fn particle_count(&self) -> usize {
        match &self.decomposition {
            Some(d) => d.total,
            None => self.particles.len(),
        }
    }

    /// The grid, ranks, particles per subdomain, imbalance and bytes sent between ranks per
    /// step, when decomposed. Collective under MPI.
    pub fn decomposition_summary(&self) -> Option<DecompositionSummary> {
        let d = self.decomposition.as_ref()?;
        let counts: Vec<usize> = d
            .comm
            .gather_by_subdomain(d.subdomains.len(), |s, out| {
                out.push(d.subdomains[s].n_owned as Real)
            })
            .iter()
            .map(|w| w[0] as usize)
            .collect();
        let mean = counts.iter().sum::<usize>() as Real / counts.len().max(1) as Real;
        let most = counts.iter().copied().max().unwrap_or(0) as Real;
        let bytes = d.comm.sum(d.bytes_sent) as Real;
        // What the start's planes would give the particles where they are now (those the
        // next rebuild keeps).
        let stop_on_lost = self.guard.settings.stop_on_lost;
        let domain = &self.domain;
        let keep = |x: Vec3| x.is_finite() && (stop_on_lost || domain.contains_bounded(x));
        let b = &d.balance;
        let static_now = balance::imbalance(&d.counts_over(&[&b.start], domain, &keep)[0]);
        Some(DecompositionSummary {
            grid: d.grid.counts,
            ranks: d.comm.size(),
            subdomain_particles: counts,
            imbalance: if mean > 0.0 { most / mean } else { 1.0 },
            bytes_sent_between_ranks_per_step: bytes / self.steps.max(1) as Real,
            balance_threshold: b.threshold,
            shifts: b.shifts,
            imbalance_max_after_first_shift: b.worst_after_first_shift,
            static_imbalance: static_now,
            static_imbalance_max: b.static_worst.max(static_now),
        })
    }

    /// The processes the world is stepped on (one unless decomposed under MPI).
    pub fn comm(&self) -> Comm {
        self.decomposition
            .as_ref()
            .map_or_else(Comm::local, |d| d.comm.clone())
    }

    /// The subdomains' grid and particle counts, when decomposed.
    pub fn decomposition(&self) -> Option<(&Grid, Vec<usize>)> {
        self.decomposition
            .as_ref()
            .map(|d| (&d.grid, d.subdomains.iter().map(|s| s.n_owned).collect()))
    }

    /// One step of the subdomains (velocity Verlet or PCVV): drift or predictor, then
    /// exchange and borders if a particle moved past half the skin or forward otherwise,
    /// then forces and the closing kick or corrector.
    fn step_decomposed(&mut self) {
        let dt = self.dt;
        // The bodies at the step's end: they move their particles after the drift.
        self.pose_bodies_at(self.time + dt);
        let d = self.decomposition.as_mut().expect("decomposed");
        let drive = Drive {
            bodies: &self.bodies,
            kinematic: &self.kinematic,
            delete_regions: &self.delete_regions,
            rotates: Self::ROTATES,
        };
        if d.advance_and_pack(dt, self.integrator, &drive) {
            self.rebuild_decomposed();
            self.decomposed_forces(Some(self.integrator));
        } else {
            self.decomposed_forces_forwarded();
        }
    }

    /// Forces from the current ghosts (then the second half of a step of `closing`, if
    /// given); the guard's overlaps and finiteness, the bodies' loads.
    fn decomposed_forces(&mut self, closing: Option<Integrator>) {
        self.decomposed_pass(closing, false);
    }

    /// The ghosts take their owners' states packed by the drift, then forces and the
    /// second half of the step.
    fn decomposed_forces_forwarded(&mut self) {
        self.decomposed_pass(Some(self.integrator), true);
    }

    fn decomposed_pass(&mut self, closing: Option<Integrator>, forward: bool) {
        let d = self.decomposition.as_mut().expect("decomposed");
        let physics = Physics {
            law: &self.law,
            wall_law: &self.wall_law,
            walls: &self.walls,
            bodies: &self.bodies,
            kinematic: &self.kinematic,
            gravity: self.gravity,
            n_species: self.n_species,
            dt: self.dt,
            wall_slots: (self.walls.walls.len() + self.bodies.len()).max(1),
            rotates: Self::ROTATES,
        };
        let sums = match (forward, closing) {
            (true, Some(integrator)) => d.forward_and_forces(&physics, integrator),
            _ => d.forces(&physics, closing),
        };
        self.guard.pair_overlap = sums.deepest_pair;
        self.guard.wall_overlap = sums.deepest_wall;
        if closing.is_some() {
            self.guard.finite = sums.finite;
        }
        for (body, load) in self.bodies.iter_mut().zip(&sums.body_loads) {
            body.load = *load;
        }
        // Added to the bodies by `record_kinematic_loads`, as the undecomposed step does.
        d.kinematic_loads = sums.kinematic_loads;
    }

    /// `rebuild` for the subdomains: the same removal of particles that left the box or
    /// entered a delete region (and its accounting), then exchange, borders and lists.
    fn rebuild_decomposed(&mut self) {
        let stop_on_lost = self.guard.settings.stop_on_lost;
        let domain = self.domain.clone();
        let stays = |x: Vec3| x.is_finite() && (stop_on_lost || domain.contains_bounded(x));
        let regions = &self.delete_regions;
        let keep = |x: Vec3| stays(x) && !in_delete_region(regions, x);
        let origin = self.potential_origin();
        let gravity = self.gravity;
        let tripped = self.guard.trip.is_some();
        let d = self.decomposition.as_mut().expect("decomposed");
        // Per subdomain, in order, the particles that left the box or are removed: (id,
        // position, velocity, energy, left the box, removed, deleted, mass), gathered from
        // every rank, so the counts and sums are the same on any number of threads or ranks.
        let events = d.comm.gather_by_subdomain(d.subdomains.len(), |s, out| {
            let sub = &d.subdomains[s];
            let p = &sub.particles;
            for k in 0..sub.n_owned {
                let x = p.position[k];
                let left = stop_on_lost && x.is_finite() && !domain.contains_bounded(x) && !tripped;
                let removed = !keep(x);
                if !left && !removed {
                    continue;
                }
                // In a delete region and not otherwise removed: deleted, not lost.
                let deleted = removed && stays(x);
                let e = 0.5 * p.mass[k] * p.velocity[k].length_squared() + p.spin_energy(k)
                    - p.mass[k] * gravity.dot(x - origin);
                out.push(p.id[k] as Real);
                out.extend_from_slice(&x.to_array());
                out.extend_from_slice(&p.velocity[k].to_array());
                out.extend_from_slice(&[e, left as u8 as Real, removed as u8 as Real]);
                out.extend_from_slice(&[deleted as u8 as Real, p.mass[k]]);
            }
        });
        for words in &events {
            for w in words.chunks_exact(12) {
                let id = w[0] as u32;
                if w[8] != 0.0 {
                    let (x, v) = (Vec3::new(w[1], w[2], w[3]), Vec3::new(w[4], w[5], w[6]));
                    self.guard.left_box.push((id, x, v));
                }
                if w[9] == 0.0 {
                    continue;
                }
                if w[10] != 0.0 {
                    self.deleted += 1;
                    self.deleted_mass += w[11];
                } else {
                    self.lost += 1;
                }
                if w[7].is_finite() {
                    self.guard.removed_energy += w[7];
                } else {
                    self.guard.removed_non_finite.push(id);
                }
            }
        }
        let resort = self.neighbor.resort_every > 0
            && d.builds.is_multiple_of(self.neighbor.resort_every as u64);
        let slots = (self.walls.walls.len() + self.bodies.len()).max(1);
        d.rebuild(&domain, slots, &keep, resort);
    }

    pub fn kinetic_energy(&self) -> Real {
        self.particles.kinetic_energy()
    }

    /// Sets the guard thresholds (and the scene's stable step, for messages).
    pub fn set_guard_settings(&mut self, settings: GuardSettings) {
        self.guard.settings = settings;
    }

    /// How close the run came to the guards' thresholds so far.
    pub fn guard_peaks(&self) -> GuardPeaks {
        self.guard.peaks
    }

    /// The guard that fired in the last step, if any. Until it is taken no other fires.
    pub fn take_guard_trip(&mut self) -> Option<GuardTrip> {
        self.guard.trip.take()
    }

    /// The energy guard takes the present state as its reference (call when walls are
    /// removed or bodies start: both change what is stored or supplied): kinetic plus
    /// gravitational energy, plus the elastic energy stored in overlapping pairs, which may
    /// turn into motion (particles placed overlapping push apart).
    pub fn reset_energy_reference(&mut self) {
        let (energy, _) = self.guard_energy();
        self.guard.energy_reference = Some(energy + self.pair_elastic_energy());
        self.guard.removed_energy = 0.0;
    }

    /// Elastic energy stored in the listed pairs (the normal law's potential); walls and
    /// bodies are not counted. The list must be current (as after a rebuild).
    pub fn pair_elastic_energy(&self) -> Real {
        if let Some(d) = &self.decomposition {
            return d.pair_elastic_energy(&self.law, self.n_species);
        }
        let p = &self.particles;
        let images: [Vec3; 27] = std::array::from_fn(|k| self.domain.image_shift(k as u8));
        self.list
            .pairs
            .iter()
            .map(|pair| {
                let (i, j) = (pair.i as usize, pair.j as usize);
                let distance =
                    (p.position[i] - (p.position[j] + images[pair.image as usize])).length();
                let species_pair = p.species[i] as usize * self.n_species + p.species[j] as usize;
                self.law
                    .elastic_energy(species_pair, p.radius[i], p.radius[j], distance)
            })
            .sum()
    }

    /// The largest overlap of the last force evaluation, as a fraction of the smaller radius
    /// (pairs) or of the radius (walls, bodies).
    pub fn max_overlap_fraction(&self) -> Real {
        self.guard.pair_overlap.max(self.guard.wall_overlap)
    }

    /// Kinetic energy plus gravitational energy above the box's lowest corner along gravity.
    pub fn mechanical_energy(&self) -> Real {
        let (g, corner) = (self.gravity, self.potential_origin());
        let p = &self.particles;
        let potential: Real = p
            .position
            .iter()
            .zip(&p.mass)
            .map(|(&x, &m)| -m * g.dot(x - corner))
            .sum();
        self.kinetic_energy() + potential
    }

    /// Mechanical energy and mobile mass for the energy guard: decomposed, summed per
    /// subdomain (so the same on any number of threads or ranks, and without gathering).
    fn guard_energy(&self) -> (Real, Real) {
        match &self.decomposition {
            Some(d) => d.energy_and_mobile_mass(self.gravity, self.potential_origin()),
            None => (self.mechanical_energy(), self.particles.mobile_mass()),
        }
    }

    /// Kinetic plus gravitational energy of particle `k` (as in `mechanical_energy`).
    fn particle_energy(&self, k: usize) -> Real {
        let p = &self.particles;
        0.5 * p.mass[k] * p.velocity[k].length_squared() + p.spin_energy(k)
            - p.mass[k] * self.gravity.dot(p.position[k] - self.potential_origin())
    }

    /// The box corner lowest along gravity: gravitational energy is counted from it.
    fn potential_origin(&self) -> Vec3 {
        potential_origin(self.gravity, self.domain.lo, self.domain.hi)
    }

    /// Whether the energy guard applies: no attraction, no moving body doing work, and no
    /// gravity along a periodic axis (which does work without end).
    fn energy_guard_applies(&self) -> bool {
        let g = self.gravity.to_array();
        !L::ATTRACTS
            && !self.bodies.iter().any(|b| b.is_moving())
            && (0..3).all(|k| !self.domain.periodic[k] || g[k] == 0.0)
    }

    /// The per-step checks; the costly part (naming the particles) only runs when one fires.
    fn check_guards(&mut self) {
        if self.guard.trip.is_some() {
            return;
        }
        let s = self.guard.settings;
        let overlap = self.max_overlap_fraction();
        let peaks = &mut self.guard.peaks;
        peaks.overlap_fraction = peaks.overlap_fraction.max(overlap);
        let non_finite = !self.guard.finite || !self.guard.removed_non_finite.is_empty();
        let lost = !self.guard.left_box.is_empty() && s.stop_on_lost;
        if non_finite || overlap > s.max_overlap_fraction || lost {
            // The diagnosis names particles: every rank gathers them (the reduced overlaps,
            // finiteness and removal events are the same on all, so all trip together).
            self.sync_particles();
        }
        self.guard.trip = if non_finite {
            Some(self.diagnose_non_finite())
        } else if self.max_overlap_fraction() > s.max_overlap_fraction {
            if self.decomposition.is_some() {
                // The global list (unused while decomposed) names the pair.
                let reach = self.law.reach();
                self.list
                    .build(&mut self.particles, &self.domain, reach, false);
            }
            Some(self.diagnose_overlap())
        } else if !self.guard.left_box.is_empty() {
            let left = std::mem::take(&mut self.guard.left_box);
            s.stop_on_lost.then(|| self.diagnose_lost(&left))
        } else if s.energy_every > 0
            && self.steps.is_multiple_of(s.energy_every)
            && self.energy_guard_applies()
        {
            self.check_energy()
        } else {
            None
        };
    }

    fn check_energy(&mut self) -> Option<GuardTrip> {
        let s = self.guard.settings;
        let (energy, mobile_mass) = self.guard_energy();
        let removed = std::mem::take(&mut self.guard.removed_energy);
        if let Some(reference) = &mut self.guard.energy_reference {
            *reference -= removed;
        }
        match self.guard.energy_reference {
            Some(reference) => {
                let scale = reference.max(mobile_mass * s.energy_floor_per_mass);
                let rise = (energy - reference) / scale;
                self.guard.peaks.energy_rise = self.guard.peaks.energy_rise.max(rise);
                if rise <= s.energy_growth {
                    return None;
                }
                // The diagnosis names particles: every rank gathers them (all trip together).
                self.sync_particles();
                Some(self.diagnose_energy(energy, reference))
            }
            None => {
                self.guard.energy_reference = Some(energy);
                None
            }
        }
    }

    fn trip(
        &self,
        kind: GuardKind,
        particles: Vec<u32>,
        detail: String,
        cause: String,
    ) -> GuardTrip {
        GuardTrip {
            kind,
            step: self.steps,
            time: self.time,
            particles,
            detail,
            cause,
            dt: self.dt,
            stable_dt: self.guard.settings.stable_dt,
        }
    }

    fn diagnose_non_finite(&mut self) -> GuardTrip {
        let p = &self.particles;
        let mut ids = std::mem::take(&mut self.guard.removed_non_finite);
        let bad: Vec<usize> = (0..p.len())
            .filter(|&k| {
                let spin_ok = p
                    .angular
                    .as_ref()
                    .is_none_or(|a| a.omega[k].is_finite() && a.torque[k].is_finite());
                !(p.position[k].is_finite()
                    && p.velocity[k].is_finite()
                    && p.force[k].is_finite()
                    && spin_ok)
            })
            .collect();
        let cause = forced_step_cause(self.dt, self.guard.settings.stable_dt).unwrap_or_else(|| {
            "a force too large for the step: a contact far stiffer than the step was chosen for (an impact faster than the scene's contact time scale, or particles placed overlapping)".into()
        });
        let count = ids.len() + bad.len();
        ids.extend(bad.iter().map(|&k| p.id[k]));
        ids.truncate(5);
        self.trip(
            GuardKind::NonFinite,
            ids,
            format!("{count} particle(s) with a non-finite position, velocity, force or spin"),
            cause,
        )
    }

    /// Names the deepest contact (pair, wall or body) and the step its stiffness at that
    /// overlap allows.
    fn diagnose_overlap(&self) -> GuardTrip {
        let p = &self.particles;
        let s = self.guard.settings;
        let images: [Vec3; 27] = std::array::from_fn(|k| self.domain.image_shift(k as u8));
        // (fraction, ids, relative normal speed, local stable step, what)
        let mut worst: (Real, Vec<u32>, Real, Real, String) =
            (0.0, Vec::new(), 0.0, Real::NAN, String::new());
        for pair in &self.list.pairs {
            let (i, j) = (pair.i as usize, pair.j as usize);
            let d = p.position[i] - (p.position[j] + images[pair.image as usize]);
            let distance = d.length();
            let (r_i, r_j) = (p.radius[i], p.radius[j]);
            let fraction = (r_i + r_j - distance) / r_i.min(r_j);
            if fraction > worst.0 {
                let normal = d / distance;
                let speed = (p.velocity[i] - p.velocity[j]).dot(normal);
                let m_eff = 1.0 / (p.inv_mass[i] + p.inv_mass[j]);
                let species_pair = p.species[i] as usize * self.n_species + p.species[j] as usize;
                let force_at = |distance: Real| {
                    let contact = Contact {
                        species_pair,
                        normal: Vec3::Z,
                        distance,
                        overlap: r_i + r_j - distance,
                        radius_i: r_i,
                        radius_j: r_j,
                        r_eff: r_i * r_j / (r_i + r_j),
                        inv_mass_i: p.inv_mass[i],
                        inv_mass_j: p.inv_mass[j],
                        m_eff,
                        relative_velocity: Vec3::ZERO,
                        normal_speed: 0.0,
                        tangential_velocity: Vec3::ZERO,
                    };
                    let mut history = L::History::default();
                    self.law
                        .evaluate(&contact, &mut history, (Vec3::ZERO, Vec3::ZERO), self.dt)
                        .force_on_i
                        .z
                };
                let h = 1e-6 * (r_i + r_j);
                let stiffness = (force_at(distance - h) - force_at(distance)) / h;
                worst = (
                    fraction,
                    vec![p.id[i], p.id[j]],
                    -speed,
                    undamped_limit(stiffness, m_eff),
                    "pair".into(),
                );
            }
        }
        for k in 0..p.len() {
            let particle = WallParticle {
                species: p.species[k] as usize,
                position: p.position[k],
                velocity: p.velocity[k],
                radius: p.radius[k],
                mass: p.mass[k],
            };
            for wall in self.walls.walls.iter().filter(|w| w.active) {
                let Some(distance) = wall.plane.distance(particle.position) else {
                    continue;
                };
                let fraction = overlap_fraction(distance, particle.radius);
                if fraction > worst.0 {
                    let force_at = |distance: Real| {
                        let contact = WallContact {
                            species: particle.species,
                            material: wall.material,
                            normal: Vec3::Z,
                            distance,
                            relative_velocity: Vec3::ZERO,
                            radius: particle.radius,
                            mass: particle.mass,
                        };
                        self.wall_law.force(&contact, self.dt).z
                    };
                    let h = 1e-6 * particle.radius;
                    let stiffness = if distance > h {
                        (force_at(distance - h) - force_at(distance)) / h
                    } else {
                        Real::NAN // the centre has passed the wall
                    };
                    worst = (
                        fraction,
                        vec![p.id[k]],
                        -particle.velocity.dot(wall.plane.normal),
                        undamped_limit(stiffness, particle.mass),
                        format!("wall `{}`", wall.name),
                    );
                }
            }
            for body in &self.bodies {
                let reach = self.wall_law.reach(particle.species, particle.radius);
                if let Some((distance, normal)) = body.query(particle.position, reach) {
                    let fraction = overlap_fraction(distance, particle.radius);
                    if fraction > worst.0 {
                        let surface = body.surface_velocity(particle.position - distance * normal);
                        worst = (
                            fraction,
                            vec![p.id[k]],
                            -(particle.velocity - surface).dot(normal),
                            Real::NAN,
                            format!("body `{}`", body.name),
                        );
                    }
                }
            }
        }
        let (fraction, ids, speed, local_limit, what) = worst;
        let initial = self.guard.initial_overlap.unwrap_or(0.0);
        let cause = if initial > s.max_overlap_fraction {
            format!("the particles were placed overlapping (largest overlap {:.0}% of the radius before the first step)", 100.0 * initial)
        } else if let Some(forced) = forced_step_cause(self.dt, s.stable_dt) {
            forced
        } else {
            let smallest_radius = p.radius.iter().cloned().fold(Real::INFINITY, Real::min);
            overlap_cause(fraction, speed, self.dt, local_limit, smallest_radius)
        };
        let mut trip = self.trip(
            GuardKind::Overlap,
            ids,
            format!(
                "{what} overlap {:.1}% of the radius exceeds the limit of {:.1}%{}",
                100.0 * fraction,
                100.0 * s.max_overlap_fraction,
                if local_limit.is_finite() {
                    format!("; at this overlap the contact allows dt <= {local_limit:.3e} s (undamped 2/omega)")
                } else {
                    String::new()
                }
            ),
            cause,
        );
        if local_limit.is_finite() {
            trip.stable_dt = trip.stable_dt.min(local_limit);
        }
        trip
    }

    fn diagnose_lost(&self, left: &[(u32, Vec3, Vec3)]) -> GuardTrip {
        let (id, x, v) = left
            .iter()
            .copied()
            .max_by(|a, b| a.2.length_squared().total_cmp(&b.2.length_squared()))
            .expect("called with at least one particle");
        let (lo, hi) = (self.domain.lo, self.domain.hi);
        let face = (0..3)
            .find_map(|a| {
                if self.domain.periodic[a] {
                    None
                } else if x[a] < lo[a] {
                    Some(format!("{}lo", ["x", "y", "z"][a]))
                } else if x[a] > hi[a] {
                    Some(format!("{}hi", ["x", "y", "z"][a]))
                } else {
                    None
                }
            })
            .unwrap_or_else(|| "a bounded face".into());
        let initial = self.guard.initial_overlap.unwrap_or(0.0);
        let cause = if let Some(forced) = forced_step_cause(self.dt, self.guard.settings.stable_dt)
        {
            forced
        } else if initial > 0.01 && self.time < 0.1 {
            format!("the particles were placed overlapping (largest overlap {:.0}% of the radius before the first step) and the elastic energy released threw them out", 100.0 * initial)
        } else {
            "the box does not hold the motion: enlarge it, close it with walls, or catch such particles with a [[delete]] region (or set [domain] lost = \"warn\" to remove them with a warning)".into()
        };
        self.trip(
            GuardKind::LostParticles,
            left.iter().map(|l| l.0).collect(),
            format!(
                "{} particle(s) left the box through a bounded face; the fastest, id {id}, crossed {face} at ({:.4e}, {:.4e}, {:.4e}) m moving at {:.3} m/s",
                left.len(),
                x.x,
                x.y,
                x.z,
                v.length()
            ),
            cause,
        )
    }

    fn diagnose_energy(&self, energy: Real, reference: Real) -> GuardTrip {
        let p = &self.particles;
        let s = self.guard.settings;
        let mut by_energy: Vec<(Real, u32)> = (0..p.len())
            .map(|k| (p.mass[k] * p.velocity[k].length_squared(), p.id[k]))
            .collect();
        by_energy.sort_by(|a, b| b.0.total_cmp(&a.0));
        let initial = self.guard.initial_overlap.unwrap_or(0.0);
        let cause = if let Some(forced) = forced_step_cause(self.dt, s.stable_dt) {
            forced
        } else if initial > 0.01 {
            format!("the particles were placed overlapping (largest overlap {:.0}% of the radius before the first step) and their elastic energy was released", 100.0 * initial)
        } else {
            "energy created at contacts the step does not resolve (a contact stiffer or an impact faster than the step was chosen for)".into()
        };
        self.trip(
            GuardKind::EnergyGrowth,
            by_energy.iter().take(3).map(|e| e.1).collect(),
            format!(
                "kinetic plus gravitational energy rose to {energy:.4e} J, above the {reference:.4e} J held at the start of the run or stage (kinetic, gravitational and elastic in overlapping pairs; allowed: +{:.0}%), with no work done on the particles; the particles named move fastest",
                100.0 * s.energy_growth
            ),
            cause,
        )
    }
}

/// Particles per leaf of the owner pass's recursive split.
const OWNER_LEAF: usize = 256;

/// What the owner pass reads: the laws, the particles, the list, and what acts on one
/// particle alone (gravity, planar walls, bodies).
struct OwnerPass<'a, L: PairLaw, W: WallLaw> {
    law: &'a L,
    wall_law: &'a W,
    state: ParticleState<'a>,
    images: [Vec3; 27],
    n_species: usize,
    dt: Real,
    pairs: &'a [Pair],
    out_start: &'a [u32],
    walls: &'a WallSet,
    bodies: &'a [Body],
    gravity: Vec3,
    /// Whether torques are summed and stored (a constant of the world's laws).
    rotates: bool,
    /// Wall-history entries per particle (used when particles spin).
    wall_slots: usize,
}

/// What the owner pass writes, for the particles from `first` on and their pairs. Slices a
/// scene does not use are empty: torques and wall histories without spin, the force-only
/// reactions with spin, body loads without bodies.
struct OwnerSlices<'s, H, WH> {
    force: &'s mut [Vec3],
    torque: &'s mut [Vec3],
    history: &'s mut [H],
    reaction_force: &'s mut [Vec3],
    reaction_spin: &'s mut [[Vec3; 2]],
    wall_history: &'s mut [WH],
    body_loads: &'s mut [BodyLoad],
    body_clearances: &'s mut [Clearance],
}

impl<'s, H, WH> OwnerSlices<'s, H, WH> {
    /// Splits after `particles` particles, which own the first `pairs` pairs.
    fn split(
        self,
        particles: usize,
        pairs: usize,
        wall_slots: usize,
        bodies: usize,
    ) -> (Self, Self) {
        let (force_a, force_b) = self.force.split_at_mut(particles);
        let (torque_a, torque_b) = split_or_empty(self.torque, particles);
        let (history_a, history_b) = self.history.split_at_mut(pairs);
        let (reaction_force_a, reaction_force_b) = split_or_empty(self.reaction_force, pairs);
        let (reaction_spin_a, reaction_spin_b) = split_or_empty(self.reaction_spin, pairs);
        let (wall_history_a, wall_history_b) =
            split_or_empty(self.wall_history, particles * wall_slots);
        let (body_loads_a, body_loads_b) = self.body_loads.split_at_mut(particles * bodies);
        let (clearances_a, clearances_b) = self.body_clearances.split_at_mut(particles * bodies);
        (
            OwnerSlices {
                force: force_a,
                torque: torque_a,
                history: history_a,
                reaction_force: reaction_force_a,
                reaction_spin: reaction_spin_a,
                wall_history: wall_history_a,
                body_loads: body_loads_a,
                body_clearances: clearances_a,
            },
            OwnerSlices {
                force: force_b,
                torque: torque_b,
                history: history_b,
                reaction_force: reaction_force_b,
                reaction_spin: reaction_spin_b,
                wall_history: wall_history_b,
                body_loads: body_loads_b,
                body_clearances: clearances_b,
            },
        )
    }
}

/// Splits a slice at `at`, or gives two empty slices when it is empty (unused arrays).
fn split_or_empty<T>(slice: &mut [T], at: usize) -> (&mut [T], &mut [T]) {
    if slice.is_empty() {
        (&mut [], &mut [])
    } else {
        slice.split_at_mut(at)
    }
}

/// The deepest overlaps the owner pass met, as fractions of the radius.
#[derive(Clone, Copy, Default)]
struct Deepest {
    /// Between two particles, of the smaller radius.
    pairs: Real,
    /// With a wall or body.
    walls: Real,
}

impl Deepest {
    fn larger(self, other: Deepest) -> Deepest {
        Deepest {
            pairs: larger(self.pairs, other.pairs),
            walls: larger(self.walls, other.walls),
        }
    }
}

impl<L: PairLaw, W: WallLaw> OwnerPass<'_, L, W> {
    /// Evaluates the pairs owned by particles `first..first + out.force.len()` and what acts
    /// on those particles alone, halving the range in parallel down to leaves.
    fn run(&self, first: usize, mut out: OwnerSlices<'_, L::History, W::History>) -> Deepest {
        let n = out.force.len();
        if n > OWNER_LEAF {
            let mid = n / 2;
            let split = (self.out_start[first + mid] - self.out_start[first]) as usize;
            let (a, b) = out.split(mid, split, self.wall_slots, self.bodies.len());
            let (a, b) = rayon::join(|| self.run(first, a), || self.run(first + mid, b));
            return a.larger(b);
        }
        let s = self.state;
        let pair_base = self.out_start[first] as usize;
        let mut deepest = Deepest::default();
        for local in 0..n {
            let i = first + local;
            let owner = Owner {
                index: i,
                position: s.position[i],
                velocity: s.velocity[i],
                omega: s.omega.map_or(Vec3::ZERO, |w| w[i]),
                radius: s.radius[i],
                inv_mass: s.inv_mass[i],
                species_row: s.species[i] as usize * self.n_species,
            };
            let (mut force, mut torque) = (Vec3::ZERO, Vec3::ZERO);
            for k in self.out_start[i] as usize..self.out_start[i + 1] as usize {
                let slot = k - pair_base;
                let (result, overlap, smaller_radius) = pair_force(
                    self.law,
                    &s,
                    &self.images,
                    &owner,
                    self.pairs[k],
                    &mut out.history[slot],
                    self.dt,
                );
                // The deepest overlap as a fraction of the smaller radius, dividing only
                // when it grows.
                if overlap > deepest.pairs * smaller_radius {
                    deepest.pairs = overlap / smaller_radius;
                }
                force += result.force_on_i;
                if self.rotates {
                    torque += result.torque_on_i;
                    out.reaction_spin[slot] = [-result.force_on_i, result.torque_on_j];
                } else {
                    out.reaction_force[slot] = -result.force_on_i;
                }
            }
            let overlap = self.act_alone(local, &owner, force, torque, &mut out);
            deepest.walls = larger(deepest.walls, overlap);
        }
        deepest
    }

    /// Adds what acts on owner `i` alone (gravity, planar walls, bodies) to the sum of its
    /// pairs and stores its force (and torque); returns its deepest wall or body overlap.
    #[inline(always)]
    fn act_alone(
        &self,
        local: usize,
        owner: &Owner,
        mut force: Vec3,
        mut torque: Vec3,
        out: &mut OwnerSlices<'_, L::History, W::History>,
    ) -> Real {
        let s = self.state;
        let i = owner.index;
        force += s.mass[i] * self.gravity;
        let particle = WallParticle {
            species: s.species[i] as usize,
            position: owner.position,
            velocity: owner.velocity,
            radius: owner.radius,
            mass: s.mass[i],
        };
        let n_bodies = self.bodies.len();
        let loads = &mut out.body_loads[local * n_bodies..(local + 1) * n_bodies];
        let clearances = &mut out.body_clearances[local * n_bodies..(local + 1) * n_bodies];
        let mut overlap;
        if self.rotates {
            let slots = &mut out.wall_history[local * self.wall_slots..][..self.wall_slots];
            let (wall_history, body_history) = slots.split_at_mut(self.walls.walls.len());
            if W::NEEDS_ROTATION {
                let (f, t, o) = self.walls.force_and_torque_on(
                    self.wall_law,
                    &particle,
                    owner.omega,
                    wall_history,
                    self.dt,
                );
                force += f;
                torque += t;
                overlap = o;
            } else {
                let (f, o) = self.walls.force_on(self.wall_law, &particle, self.dt);
                force += f;
                overlap = o;
            }
            let with_history = self.bodies.iter().zip(loads).zip(body_history);
            for (((body, load), history), clearance) in with_history.zip(clearances) {
                let (f, t, l, o) = body_force_and_torque(
                    body,
                    self.wall_law,
                    &particle,
                    owner.omega,
                    history,
                    clearance,
                    self.dt,
                );
                force += f;
                torque += t;
                *load = l;
                overlap = larger(overlap, o);
            }
            out.torque[local] = torque;
        } else {
            let (f, o) = self.walls.force_on(self.wall_law, &particle, self.dt);
            force += f;
            overlap = o;
            for ((body, load), clearance) in self.bodies.iter().zip(loads).zip(clearances) {
                let (f, l, o) = body_force(body, self.wall_law, &particle, clearance, self.dt);
                force += f;
                *load = l;
                overlap = larger(overlap, o);
            }
        }
        out.force[local] = force;
        overlap
    }
}

/// The reactions the owner pass stored per pair, which complete the forces: particle `j`
/// receives those of the pairs it is the second particle of, in list order.
struct Reactions<'a> {
    list: &'a VerletList,
    /// Force on `j` per pair (when particles do not spin).
    force: &'a [Vec3],
    /// Force and torque on `j` per pair (when they spin).
    spin: &'a [[Vec3; 2]],
}

impl Reactions<'_> {
    #[inline(always)]
    fn add_to(&self, j: usize, force: &mut Vec3, torque: &mut Vec3) {
        let list = self.list;
        let incoming = &list.in_pairs[list.in_start[j] as usize..list.in_start[j + 1] as usize];
        if self.spin.is_empty() {
            for &k in incoming {
                *force += self.force[k as usize];
            }
        } else {
            for &k in incoming {
                let [f, t] = self.spin[k as usize];
                *force += f;
                *torque += t;
            }
        }
    }
}
