//! The world: the scene's physics (laws, walls, bodies, gravity), its clock, counters and
//! guards, and the subdomains that hold the particles and step them.
//!
//! Every world is a grid of subdomains (`decomposition`), one subdomain for a small scene.
//! A step asks them for its three parts in turn: `Decomposition::advance` (the first half
//! of the integrator), a `Decomposition::rebuild` when a particle moved past half the skin
//! (the removals it makes are accounted here), and `Decomposition::forces` (the forces,
//! then the second half). The world is generic over the pair law and the wall law, fixed
//! when the scene is built, so the compiler sees one concrete force loop per scene: the
//! seed's WCA scene has no rotation, no history and no cohesion in it.

mod diagnosis;
pub(crate) mod network;
mod state;

pub use network::{ContactNetwork, PairContact};
pub use state::WorldState;

use crate::bodies::{Body, KinematicParticles};
use crate::contact::PairLaw;
use crate::decomposition::{
    placement::{place, place_scene_grid},
    removal::{RemovalRule, Removals},
    step::{Decomposition, Drive, ForceSums, Physics},
    BalanceSpec, Comm, DecomposedState, DecompositionSummary, Grid, GridSpec, HistoryRows,
};
use crate::domain::{potential_origin, Domain};
use crate::force::Surroundings;
use crate::geometry::Aabb;
use crate::guard::{GuardPeaks, GuardSettings, GuardState, GuardTrip};
use crate::integrate::Integrator;
use crate::math::{Real, Vec3};
use crate::memory_use::MemoryUse;
use crate::particles::Particles;
use crate::walls::{WallLaw, WallSet};

/// Neighbour-list settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeighborSettings {
    /// Verlet skin, m.
    pub skin: Real,
    /// Re-sort particles by cell every this many list builds (0 = never).
    pub resort_every: u32,
}

/// How a world is cut into subdomains, and the processes it runs on.
#[derive(Clone, Debug, Default)]
pub struct Decompose {
    /// `--grid`; `None`: chosen from the scene ([`crate::decomposition::placement`]).
    pub grid: Option<GridSpec>,
    /// `--balance`: when the cut planes move at a rebuild.
    pub balance: BalanceSpec,
    /// One process, or the ranks of an `mpirun`.
    pub comm: Comm,
}

/// What a world is built from: the particles, the box, the laws and what acts on the
/// particles besides each other.
pub struct WorldSetup<L, W> {
    pub particles: Particles,
    pub domain: Domain,
    pub walls: WallSet,
    pub law: L,
    pub wall_law: W,
    /// Species, for the laws' species-pair tables.
    pub n_species: usize,
    pub gravity: Vec3,
    pub dt: Real,
    pub neighbor: NeighborSettings,
    pub integrator: Integrator,
    /// Moving or fixed bodies (posed at time 0); none for scenes without bodies.
    pub bodies: Vec<Body>,
    /// Frozen particles that move with a body (bodies built of particles).
    pub kinematic: Vec<KinematicParticles>,
    /// Particles whose centre enters one of these boxes are deleted (an outlet).
    pub delete_regions: Vec<Aabb>,
    pub guard: GuardSettings,
}

impl<L, W> WorldSetup<L, W> {
    /// A setup with no walls, bodies or delete regions, velocity Verlet and the default
    /// guards; the fields are public for the rest.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        particles: Particles,
        domain: Domain,
        law: L,
        wall_law: W,
        n_species: usize,
        gravity: Vec3,
        dt: Real,
        neighbor: NeighborSettings,
    ) -> Self {
        WorldSetup {
            particles,
            domain,
            walls: WallSet::default(),
            law,
            wall_law,
            n_species,
            gravity,
            dt,
            neighbor,
            integrator: Integrator::VelocityVerlet,
            bodies: Vec::new(),
            kinematic: Vec::new(),
            delete_regions: Vec::new(),
            guard: GuardSettings::default(),
        }
    }
}

pub struct World<L: PairLaw, W: WallLaw> {
    /// The owned particles of every subdomain side by side, as last gathered
    /// ([`World::sync_particles`]): what the outputs read. The step never writes them.
    particles: Particles,
    /// The step at which `particles` was gathered.
    gathered_at: Option<u64>,
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
    /// Count and mass of particles deleted by the delete regions.
    pub deleted: u64,
    pub deleted_mass: Real,
    integrator: Integrator,
    neighbor: NeighborSettings,
    /// Moving or fixed bodies; empty for scenes without bodies, which then pay nothing.
    bodies: Vec<Body>,
    kinematic: Vec<KinematicParticles>,
    delete_regions: Vec<Aabb>,
    guard: GuardState,
    subdomains: Decomposition<L::History, W::History>,
    /// The grid as chosen and why (`summary.json`).
    grid_reason: String,
}

/// How often a particle in a delete region forces a list rebuild (which deletes it), in
/// steps; every rebuild deletes what is in the regions. A discharging silo sends a grain into
/// its delete box every few steps: rebuilding the lists for each one took 40% of the
/// discharge's time (reports/silo/NOTE.md, "Deleting at rebuilds"). A deleted grain has left
/// the flow 20 mm below the orifice; 100 steps are a fraction of a millisecond at the cases'
/// time steps, well below their 0.01 s samples.
pub const DELETE_EVERY: u64 = 100;

impl<L: PairLaw, W: WallLaw> World<L, W> {
    /// Whether particles carry spin: the pair law or the wall law needs it.
    pub const ROTATES: bool = L::NEEDS_ROTATION || W::NEEDS_ROTATION;

    /// The world of `setup`, its particles dealt out over the grid `decompose` gives (or
    /// the scene's), the forces evaluated. An error, for the user, when the grid does not
    /// fit the box or the ranks.
    pub fn new(setup: WorldSetup<L, W>, decompose: &Decompose) -> Result<Self, String> {
        let mut particles = setup.particles;
        if Self::ROTATES && particles.angular.is_none() {
            particles = particles.with_rotation();
        }
        let widths = Widths::of(&particles, setup.law.reach(), setup.neighbor.skin);
        let comm = decompose.comm.clone();
        let domain = setup.domain;
        let (grid, grid_reason) = match decompose.grid {
            Some(spec) => {
                let placed = widths.place(spec, &domain, &particles.position, comm.size())?;
                (placed, format!("--grid {spec}"))
            }
            None => place_scene_grid(
                &domain,
                &particles.position,
                setup.gravity,
                widths.ghost,
                widths.contact,
                comm.size(),
            )?,
        };
        let slots = wall_slots(&setup.walls, &setup.bodies);
        let wall_history = vec![W::History::default(); particles.len() * slots];
        let mut subdomains = Decomposition::new(
            grid,
            &particles,
            &wall_history,
            &HistoryRows::none(particles.len()),
            &domain,
            slots,
            widths.ghost,
            setup.law.reach() + setup.neighbor.skin,
            setup.neighbor.skin,
            comm,
        );
        subdomains.balance.threshold = decompose.balance.threshold();
        let mut world = World {
            particles,
            gathered_at: None,
            domain,
            walls: setup.walls,
            law: setup.law,
            wall_law: setup.wall_law,
            n_species: setup.n_species,
            gravity: setup.gravity,
            dt: setup.dt,
            time: 0.0,
            steps: 0,
            lost: 0,
            deleted: 0,
            deleted_mass: 0.0,
            integrator: setup.integrator,
            neighbor: setup.neighbor,
            bodies: setup.bodies,
            kinematic: setup.kinematic,
            delete_regions: setup.delete_regions,
            guard: GuardState {
                settings: setup.guard,
                finite: true,
                ..Default::default()
            },
            subdomains,
            grid_reason,
        };
        world.evaluate_forces(None);
        world.sync_particles();
        world.guard.initial_overlap = Some(world.max_overlap_fraction());
        world.reset_energy_reference();
        Ok(world)
    }

    /// Takes up the subdomains of a restart file: on the stored grid each as it was (the
    /// run steps on bit for bit on any number of threads or ranks), on another grid the
    /// owned particles dealt out again with their histories, on planes by count (as a
    /// rebuild with a rebalance), the stored forces kept.
    fn restore_subdomains(
        &mut self,
        stored: DecomposedState,
        grid: Option<GridSpec>,
    ) -> Result<(), String> {
        let comm = self.subdomains.comm.clone();
        let threshold = self.subdomains.balance.threshold;
        let slots = wall_slots(&self.walls, &self.bodies);
        let same = match grid {
            None => true,
            Some(GridSpec::Given(counts)) => counts == stored.grid.counts,
            Some(GridSpec::Auto(n)) => n == stored.grid.len(),
        };
        if same {
            if comm.size() > stored.grid.len() {
                let [x, y, z] = stored.grid.counts;
                return Err(format!(
                    "{} MPI ranks need at least as many subdomains, and the stored grid {x}x{y}x{z} has {}; resume with --grid of at least {} subdomains (the particles are dealt out again)",
                    comm.size(),
                    stored.grid.len(),
                    comm.size()
                ));
            }
            self.subdomains =
                Decomposition::from_state(stored, comm, threshold, Self::ROTATES, slots)?;
        } else {
            let spec = grid.expect("another grid was given");
            let (particles, wall_history, rows) =
                Decomposition::<L::History, W::History>::gathered_from_state(
                    &stored,
                    Self::ROTATES,
                    slots,
                )?;
            self.particles = particles;
            self.gathered_at = None;
            let widths = Widths {
                contact: stored.width - stored.skin,
                ghost: stored.width,
            };
            let placed = widths.place(spec, &self.domain, &self.particles.position, comm.size())?;
            let mut d = Decomposition::new(
                placed,
                &self.particles,
                &wall_history,
                &rows,
                &self.domain,
                slots,
                stored.width,
                stored.extra,
                stored.skin,
                comm,
            );
            d.builds = stored.builds + 1;
            d.balance.threshold = threshold;
            self.subdomains = d;
            self.grid_reason = format!("--grid {spec} (resumed from another grid)");
        }
        self.sync_particles();
        Ok(())
    }

    /// The grid the world steps on (subdomains along x, y, z).
    pub fn grid(&self) -> [usize; 3] {
        self.subdomains.grid.counts
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

    /// Appends mobile particles at rest (ids after the largest so far), deals all out again
    /// over the same cut planes (still thick enough) and evaluates the forces, once (a
    /// second evaluation would advance the tangential springs twice); the energy guard
    /// takes the new state as reference. Under MPI every rank gathers every particle, adds
    /// the same ones and deals out its own again.
    pub fn add_particles(&mut self, species: u16, positions: &[Vec3], radius: Real, mass: Real) {
        if positions.is_empty() {
            return;
        }
        let mut rows = self.subdomains.gathered_rows();
        let (particles, mut wall_history) = self.subdomains.gathered();
        self.particles = particles;
        self.gathered_at = None;
        let next = self.particles.id.iter().max().map_or(0, |&m| m + 1);
        for (n, &x) in positions.iter().enumerate() {
            self.particles.push(species, x, radius, mass);
            *self.particles.id.last_mut().expect("just pushed") = next + n as u32;
            rows.push(&[]);
        }
        let slots = wall_slots(&self.walls, &self.bodies);
        wall_history.resize(self.particles.len() * slots, Default::default());
        let old = &self.subdomains;
        let mut d = Decomposition::new(
            old.grid.clone(),
            &self.particles,
            &wall_history,
            &rows,
            &self.domain,
            slots,
            old.width,
            old.extra,
            old.skin,
            old.comm.clone(),
        );
        d.balance = old.balance.clone();
        d.builds += old.builds;
        d.bytes_sent += old.bytes_sent;
        self.subdomains = d;
        self.evaluate_forces(None);
        self.sync_particles();
        self.reset_energy_reference();
    }

    /// Every listed pair once, by particle id (lower first), with its contact history.
    /// Collective under MPI.
    pub fn pair_histories(&self) -> Vec<(u32, u32, L::History)> {
        self.subdomains.pair_histories()
    }

    /// Pairs listed over all subdomains (a pair across a boundary on both sides).
    /// Collective under MPI.
    pub fn listed_pairs(&self) -> usize {
        self.subdomains.listed_pairs()
    }

    /// List builds so far, over the run.
    pub fn list_builds(&self) -> u64 {
        self.subdomains.builds
    }

    pub fn integrator(&self) -> Integrator {
        self.integrator
    }

    /// One step of the chosen scheme: the first half (drift or predictor), a rebuild if a
    /// particle moved past half the skin or, on every [`DELETE_EVERY`]-th step, sits in a
    /// delete region, the forces and the second half (closing kick or corrector), then the
    /// guards.
    pub fn step(&mut self) {
        let dt = self.dt;
        // The bodies at the step's end: they move their particles after the drift.
        for body in self.bodies.iter_mut().filter(|b| b.is_moving()) {
            body.set_time(self.time + dt);
        }
        // A particle in a delete region calls for a rebuild only every DELETE_EVERY steps
        // (LAMMPS's `fix evaporate N`); a rebuild due to motion deletes it sooner.
        let deletes_now = (self.steps + 1).is_multiple_of(DELETE_EVERY);
        let drive = Drive {
            bodies: &self.bodies,
            kinematic: &self.kinematic,
            delete_regions: if deletes_now {
                &self.delete_regions
            } else {
                &[]
            },
            rotates: Self::ROTATES,
        };
        let rebuild = self.subdomains.advance(dt, self.integrator, &drive);
        if rebuild {
            self.rebuild();
        }
        self.evaluate_forces(Some(self.integrator));
        self.time += dt;
        self.steps += 1;
        self.check_guards();
    }

    /// A list rebuild: the particles that left the box or entered a delete region removed
    /// (and accounted), exchange, borders and lists.
    fn rebuild(&mut self) {
        let rule = RemovalRule {
            domain: &self.domain,
            delete_regions: &self.delete_regions,
            stop_on_lost: self.guard.settings.stop_on_lost,
            tripped: self.guard.trip.is_some(),
            gravity: self.gravity,
            origin: potential_origin(self.gravity, self.domain.lo, self.domain.hi),
        };
        let resort = self.neighbor.resort_every > 0
            && self
                .subdomains
                .builds
                .is_multiple_of(self.neighbor.resort_every as u64);
        let slots = wall_slots(&self.walls, &self.bodies);
        let removals = self.subdomains.rebuild(&rule, slots, resort);
        self.account(removals);
    }

    /// The counters and guards take what a rebuild removed.
    fn account(&mut self, removals: Removals) {
        self.lost += removals.lost;
        self.deleted += removals.deleted;
        self.deleted_mass += removals.deleted_mass;
        self.guard.left_box.extend(removals.left_box);
        self.guard.removed_energy += removals.energy;
        self.guard.removed_non_finite.extend(removals.non_finite);
    }

    /// Forces (the ghosts brought up to date first), then the second half of a step of
    /// `closing`, if given; the guard's overlaps and finiteness, the bodies' loads.
    fn evaluate_forces(&mut self, closing: Option<Integrator>) {
        let physics = Physics {
            law: &self.law,
            surroundings: Surroundings {
                wall_law: &self.wall_law,
                walls: &self.walls,
                bodies: &self.bodies,
                gravity: self.gravity,
                dt: self.dt,
            },
            kinematic: &self.kinematic,
            n_species: self.n_species,
            wall_slots: wall_slots(&self.walls, &self.bodies),
            rotates: Self::ROTATES,
        };
        let sums = self.subdomains.forces(&physics, closing);
        self.take(sums, closing.is_some());
    }

    /// The guard's values and the bodies' loads of a force pass: each body's load through
    /// its surface, plus the load on its particles for bodies built of particles.
    fn take(&mut self, sums: ForceSums, closed: bool) {
        self.guard.pair_overlap = sums.deepest_pair;
        self.guard.wall_overlap = sums.deepest_wall;
        if closed {
            self.guard.finite = sums.finite;
        }
        for (body, load) in self.bodies.iter_mut().zip(&sums.body_loads) {
            body.load = *load;
        }
        for (group, load) in self.kinematic.iter().zip(&sums.kinematic_loads) {
            self.bodies[group.body].load += *load;
        }
    }

    /// Brings the subdomains' owned particles (every rank's under MPI) into the world's
    /// copy, in subdomain order: call before [`World::particles`]. The step itself never
    /// writes that copy, so that no step pays for what only outputs read. Collective: every
    /// rank must call it at the same step.
    pub fn sync_particles(&mut self) {
        self.particles = self.subdomains.gathered().0;
        self.gathered_at = Some(self.steps);
    }

    /// `sync_particles` for what only rank 0 writes: under MPI only rank 0 receives the
    /// particles, the other ranks' copy stays as it was (call `sync_particles` where every
    /// rank takes a decision from them). Collective.
    pub fn sync_particles_for_output(&mut self) {
        if let Some((particles, _)) = self.subdomains.gathered_to(true) {
            self.particles = particles;
        }
        self.gathered_at = Some(self.steps);
    }

    /// [`World::sync_particles`], then [`World::particles`].
    pub fn synced_particles(&mut self) -> &Particles {
        self.sync_particles();
        &self.particles
    }

    /// The owned particles of every subdomain side by side, as gathered by the last
    /// [`World::sync_particles`], which must have come after the last step: a stale copy
    /// would pass for the present state, so reading one panics.
    pub fn particles(&self) -> &Particles {
        assert_eq!(
            self.gathered_at,
            Some(self.steps),
            "World::particles read after a step without World::sync_particles"
        );
        &self.particles
    }

    /// Particles in the world, over all subdomains and ranks (`particles` is refreshed only
    /// by `sync_particles`).
    pub fn particle_count(&self) -> usize {
        self.subdomains.total
    }

    /// The processes the world is stepped on.
    pub fn comm(&self) -> Comm {
        self.subdomains.comm.clone()
    }

    /// The grid and why, ranks, particles per subdomain, imbalance and bytes sent between
    /// ranks per step. Collective under MPI.
    pub fn decomposition_summary(&self) -> DecompositionSummary {
        let stop_on_lost = self.guard.settings.stop_on_lost;
        let domain = &self.domain;
        let keep = |x: Vec3| x.is_finite() && (stop_on_lost || domain.contains_bounded(x));
        self.subdomains
            .summary(&self.grid_reason, self.steps, domain, &keep)
    }

    /// The memory the subdomains of this rank hold (ghosts included), plus the gathered
    /// particles the outputs read.
    pub fn memory_use(&self) -> MemoryUse {
        let mut m = self.subdomains.memory_use();
        m.particle_bytes += self.particles.array_bytes();
        m
    }

    /// Kinetic energy of the gathered particles.
    pub fn kinetic_energy(&self) -> Real {
        self.particles().kinetic_energy()
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
        let elastic = self
            .subdomains
            .pair_elastic_energy(&self.law, self.n_species);
        self.guard.energy_reference = Some(energy + elastic);
        self.guard.removed_energy = 0.0;
    }

    /// The largest overlap of the last force evaluation, as a fraction of the smaller radius
    /// (pairs) or of the radius (walls, bodies).
    pub fn max_overlap_fraction(&self) -> Real {
        self.guard.pair_overlap.max(self.guard.wall_overlap)
    }

    /// Kinetic plus gravitational energy of the gathered particles, above the box's lowest
    /// corner along gravity.
    pub fn mechanical_energy(&self) -> Real {
        let (g, corner) = (self.gravity, self.potential_origin());
        let p = self.particles();
        let potential: Real = p
            .position
            .iter()
            .zip(&p.mass)
            .map(|(&x, &m)| -m * g.dot(x - corner))
            .sum();
        self.kinetic_energy() + potential
    }

    /// Mechanical energy and mobile mass for the energy guard, summed per subdomain (so the
    /// same on any number of threads or ranks, and without gathering).
    fn guard_energy(&self) -> (Real, Real) {
        self.subdomains
            .energy_and_mobile_mass(self.gravity, self.potential_origin())
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
        } else if overlap > s.max_overlap_fraction {
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
}

/// History entries per particle for walls and bodies: one per planar wall, then
/// `Body::history_slots` per body (at least one, so chunks exist).
fn wall_slots(walls: &WallSet, bodies: &[Body]) -> usize {
    (walls.walls.len() + bodies.iter().map(Body::history_slots).sum::<usize>()).max(1)
}

/// The distances a grid must respect.
struct Widths {
    /// The largest contact distance: largest diameter plus the law's reach.
    contact: Real,
    /// The ghost layer: the contact distance plus the skin.
    ghost: Real,
}

impl Widths {
    fn of(particles: &Particles, reach: Real, skin: Real) -> Widths {
        let max_radius = particles.radius.iter().cloned().fold(0.0, Real::max);
        let contact = 2.0 * max_radius + reach;
        Widths {
            contact,
            ghost: contact + skin,
        }
    }

    /// The grid of `spec` over `positions`, thick enough for these widths.
    fn place(
        &self,
        spec: GridSpec,
        domain: &Domain,
        positions: &[Vec3],
        ranks: usize,
    ) -> Result<Grid, String> {
        place(spec, domain, positions, self.ghost, self.contact, ranks)
    }
}

impl<L: PairLaw, W: WallLaw> std::fmt::Debug for World<L, W> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y, z] = self.grid();
        write!(
            f,
            "World {{ particles: {}, time: {}, steps: {}, grid: {x}x{y}x{z} }}",
            self.particle_count(),
            self.time,
            self.steps
        )
    }
}
