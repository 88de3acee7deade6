//! The decomposed world: subdomains stepped each on its own task (velocity Verlet), with
//! the four phases of communication between them, and the global arrays the outputs read
//! kept as the subdomains' owned particles side by side.

use rayon::prelude::*;

use super::borders::borders;
use super::exchange::exchange;
use super::forward::{forward, GhostState};
use super::list::LocalList;
use super::{Grid, HistoryRows, Subdomain};
use crate::contact::PairHistory;
use crate::contact::PairLaw;
use crate::domain::{Domain, NO_IMAGE};
use crate::math::{Real, Vec3};
use crate::neighbor::{CellGrid, Pair};
use crate::particles::{AngularState, Particles};
use crate::simulation::{larger, pair_force, ForceView, Owner, ParticleState};
use crate::walls::{WallLaw, WallParticle, WallSet};

/// The laws and what acts on a particle alone, for one force pass.
pub struct Physics<'a, L, W> {
    pub law: &'a L,
    pub wall_law: &'a W,
    pub walls: &'a WallSet,
    pub gravity: Vec3,
    pub n_species: usize,
    pub dt: Real,
    pub wall_slots: usize,
    pub rotates: bool,
}

#[derive(Clone, Debug)]
pub struct Decomposition<H, WH> {
    pub grid: Grid,
    pub subdomains: Vec<Subdomain<H, WH>>,
    /// Ghost layer thickness: largest diameter + contact reach + skin.
    pub width: Real,
    /// What the list adds to `r_i + r_j`: contact reach + skin.
    pub extra: Real,
    pub skin: Real,
    pub builds: u64,
    buffers: Vec<Vec<Vec<GhostState>>>,
}

impl<H: PairHistory, WH: PairHistory> Decomposition<H, WH> {
    /// Deals `particles` (with their wall histories and contact-history rows, one per
    /// particle) out to the subdomains of `grid` and builds ghosts and lists.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        grid: Grid,
        particles: &Particles,
        wall_history: &[WH],
        rows: &HistoryRows<H>,
        domain: &Domain,
        wall_slots: usize,
        width: Real,
        extra: Real,
        skin: Real,
    ) -> Self {
        let rotation = particles.angular.is_some();
        let mut subdomains: Vec<Subdomain<H, WH>> = (0..grid.len())
            .map(|s| Subdomain::new(s, &grid, rotation))
            .collect();
        let first = &mut subdomains[0];
        for k in 0..particles.len() {
            first.particles.push_copy(particles, k);
            first.rows.push(rows.of(k));
        }
        first.wall_history = wall_history.to_vec();
        first.n_owned = particles.len();
        exchange(&mut subdomains, &grid, domain, wall_slots, &|_| true);
        let mut d = Decomposition {
            grid,
            subdomains,
            width,
            extra,
            skin,
            builds: 0,
            buffers: Vec::new(),
        };
        d.borders_and_lists(false);
        d
    }

    /// Ghosts and lists after an exchange (owned particles re-sorted by cell first if asked).
    fn borders_and_lists(&mut self, resort: bool) {
        let width = self.width;
        if resort {
            self.subdomains
                .par_iter_mut()
                .for_each(|sub| resort_by_cell(sub, width));
        }
        borders(&mut self.subdomains, &self.grid, width);
        let extra = self.extra;
        self.subdomains.par_iter_mut().for_each(|sub| {
            sub.list = LocalList::build(sub, extra, width);
            sub.rows = HistoryRows::default();
        });
        self.builds += 1;
    }

    /// A list rebuild: histories into rows, exchange (dropping particles `keep` refuses),
    /// borders, lists.
    pub fn rebuild(
        &mut self,
        domain: &Domain,
        wall_slots: usize,
        keep: &(impl Fn(Vec3) -> bool + Sync),
        resort: bool,
    ) {
        self.subdomains.par_iter_mut().for_each(|sub| {
            sub.rows = sub.list.rows(&sub.particles.id, sub.n_owned);
        });
        exchange(&mut self.subdomains, &self.grid, domain, wall_slots, keep);
        self.borders_and_lists(resort);
    }

    /// The owned particles of all subdomains side by side (the world's arrays after a
    /// rebuild), with their wall histories.
    pub fn gathered(&self) -> (Particles, Vec<WH>) {
        let rotation = self.subdomains[0].particles.angular.is_some();
        let mut all = Particles::new(rotation);
        let mut wall = Vec::new();
        for sub in &self.subdomains {
            for k in 0..sub.n_owned {
                all.push_copy(&sub.particles, k);
            }
            wall.extend_from_slice(&sub.wall_history);
        }
        (all, wall)
    }

    /// The contact-history rows of every owned particle, in the gathered order.
    pub fn gathered_rows(&self) -> HistoryRows<H> {
        let mut rows = HistoryRows::default();
        for sub in &self.subdomains {
            let own = sub.list.rows(&sub.particles.id, sub.n_owned);
            for k in 0..sub.n_owned {
                rows.push(own.of(k));
            }
        }
        rows
    }

    /// Half kick and drift of the owned particles; whether one moved past half the skin.
    pub fn drift_kick(&mut self, dt: Real) -> bool {
        let limit_sq = 0.25 * self.skin * self.skin;
        self.subdomains
            .par_iter_mut()
            .map(|sub| drift_kick(sub, dt, limit_sq))
            .reduce(|| false, |a, b| a || b)
    }

    /// Ghosts take their owners' state.
    pub fn forward(&mut self) {
        forward(&mut self.subdomains, &mut self.buffers);
    }

    /// Forces on the owned particles, then (if `kick`) the closing half kick, and the new
    /// state copied into `world`'s arrays (the subdomains' owned particles side by side).
    /// Returns the deepest pair and wall overlaps and whether every value is finite.
    pub fn forces<L: PairLaw<History = H>, W: WallLaw<History = WH>>(
        &mut self,
        physics: &Physics<'_, L, W>,
        kick: bool,
        world: &mut Particles,
    ) -> (Real, Real, bool) {
        let mut views = world_views(world, self.subdomains.iter().map(|s| s.n_owned));
        self.subdomains
            .par_iter_mut()
            .zip(views.par_iter_mut())
            .map(|(sub, view)| {
                let (pairs, walls) = forces(sub, physics);
                let finite = !kick || closing_kick(sub, physics.dt);
                view.copy_from(&sub.particles);
                (pairs, walls, finite)
            })
            .reduce(
                || (0.0, 0.0, true),
                |a, b| (larger(a.0, b.0), larger(a.1, b.1), a.2 && b.2),
            )
    }

    /// Elastic energy of the listed pairs, each counted once: owned pairs, and pairs with a
    /// ghost from the side of the lower id.
    pub fn pair_elastic_energy<L: PairLaw>(&self, law: &L, n_species: usize) -> Real {
        self.subdomains
            .iter()
            .map(|sub| {
                let p = &sub.particles;
                sub.list
                    .pairs
                    .iter()
                    .filter(|&&[i, j]| {
                        (j as usize) < sub.n_owned || p.id[i as usize] < p.id[j as usize]
                    })
                    .map(|&[i, j]| {
                        let (i, j) = (i as usize, j as usize);
                        let distance = (p.position[i] - p.position[j]).length();
                        let species_pair =
                            p.species[i] as usize * n_species + p.species[j] as usize;
                        law.elastic_energy(species_pair, p.radius[i], p.radius[j], distance)
                    })
                    .sum::<Real>()
            })
            .sum()
    }

    /// Pairs listed over all subdomains (a pair across a boundary twice).
    pub fn listed_pairs(&self) -> usize {
        self.subdomains.iter().map(|s| s.list.pairs.len()).sum()
    }

    /// Ghosts over all subdomains.
    pub fn ghosts(&self) -> usize {
        self.subdomains.iter().map(|s| s.ghosts()).sum()
    }
}

/// Re-sorts `sub`'s owned particles by cell (memory order follows space), carrying their
/// wall histories and rows.
fn resort_by_cell<H: PairHistory, WH: PairHistory>(sub: &mut Subdomain<H, WH>, cell_size: Real) {
    let n = sub.n_owned;
    if n == 0 {
        return;
    }
    let bounded = Domain {
        lo: Vec3::ZERO,
        hi: Vec3::ONE,
        periodic: [false; 3],
    };
    sub.particles.truncate(n);
    let order = CellGrid::build(&bounded, &sub.particles.position, cell_size).items;
    sub.particles.permute(&order);
    let slots = sub.wall_history.len() / n;
    sub.wall_history = Particles::permute_rows(&sub.wall_history, &order, slots);
    let old = std::mem::take(&mut sub.rows);
    for &o in &order {
        sub.rows.push(old.of(o as usize));
    }
}

/// The world's per-particle arrays the step writes, cut at the subdomains' owned counts.
struct WorldView<'a> {
    position: &'a mut [Vec3],
    velocity: &'a mut [Vec3],
    force: &'a mut [Vec3],
    omega: &'a mut [Vec3],
    torque: &'a mut [Vec3],
}

impl WorldView<'_> {
    fn copy_from(&mut self, p: &Particles) {
        let n = self.position.len();
        self.position.copy_from_slice(&p.position[..n]);
        self.velocity.copy_from_slice(&p.velocity[..n]);
        self.force.copy_from_slice(&p.force[..n]);
        if let Some(a) = &p.angular {
            self.omega.copy_from_slice(&a.omega[..n]);
            self.torque.copy_from_slice(&a.torque[..n]);
        }
    }
}

fn world_views(world: &mut Particles, counts: impl Iterator<Item = usize>) -> Vec<WorldView<'_>> {
    let Particles {
        position,
        velocity,
        force,
        angular,
        ..
    } = world;
    let (mut omega, mut torque): (&mut [Vec3], &mut [Vec3]) = match angular {
        Some(AngularState { omega, torque, .. }) => (omega, torque),
        None => (&mut [], &mut []),
    };
    let (mut position, mut velocity, mut force) =
        (&mut position[..], &mut velocity[..], &mut force[..]);
    let mut views = Vec::new();
    for n in counts {
        let (p, rest_p) = position.split_at_mut(n);
        let (v, rest_v) = velocity.split_at_mut(n);
        let (f, rest_f) = force.split_at_mut(n);
        let (w, rest_w) = omega.split_at_mut(if omega.is_empty() { 0 } else { n });
        let (t, rest_t) = torque.split_at_mut(if torque.is_empty() { 0 } else { n });
        views.push(WorldView {
            position: p,
            velocity: v,
            force: f,
            omega: w,
            torque: t,
        });
        (position, velocity, force, omega, torque) = (rest_p, rest_v, rest_f, rest_w, rest_t);
    }
    views
}

/// `v += dt/2 F/m; x += dt v` (and the spin's half kick) for the owned particles; whether
/// one moved farther than `sqrt(limit_sq)` from its position at the last build.
fn drift_kick<H: PairHistory, WH: PairHistory>(
    sub: &mut Subdomain<H, WH>,
    dt: Real,
    limit_sq: Real,
) -> bool {
    let half = 0.5 * dt;
    let n = sub.n_owned;
    let p = &mut sub.particles;
    let mut moved = false;
    for k in 0..n {
        p.velocity[k] += half * p.inv_mass[k] * p.force[k];
        p.position[k] += dt * p.velocity[k];
        moved |= (p.position[k] - sub.list.reference[k]).length_squared() > limit_sq;
    }
    if let Some(a) = p.angular.as_mut() {
        for k in 0..n {
            a.omega[k] += half * a.inv_inertia[k] * a.torque[k];
        }
    }
    moved
}

/// `v += dt/2 F/m` (and spins) for the owned particles; whether all stay finite.
fn closing_kick<H: PairHistory, WH: PairHistory>(sub: &mut Subdomain<H, WH>, dt: Real) -> bool {
    let half = 0.5 * dt;
    let p = &mut sub.particles;
    let mut finite = true;
    for k in 0..sub.n_owned {
        p.velocity[k] += half * p.inv_mass[k] * p.force[k];
        finite &= p.velocity[k].is_finite();
    }
    if let Some(a) = p.angular.as_mut() {
        for k in 0..sub.n_owned {
            a.omega[k] += half * a.inv_inertia[k] * a.torque[k];
            finite &= a.omega[k].is_finite();
        }
    }
    finite
}

/// Forces (and torques) on `sub`'s owned particles: every listed pair evaluated with the
/// lower id first and added to whichever of its particles are owned here (both for an owned
/// pair: a half list without stored reactions), then gravity and the planar walls. Returns
/// the deepest pair and wall overlaps.
fn forces<L: PairLaw, W: WallLaw>(
    sub: &mut Subdomain<L::History, W::History>,
    physics: &Physics<'_, L, W>,
) -> (Real, Real) {
    let n = sub.n_owned;
    let ForceView {
        id,
        state,
        force,
        torque,
    } = ParticleState::split(&mut sub.particles);
    let images = [Vec3::ZERO; 27];
    let rotates = physics.rotates;
    force[..n].fill(Vec3::ZERO);
    if rotates {
        torque[..n].fill(Vec3::ZERO);
    }
    let mut deepest_pair: Real = 0.0;
    let list = &mut sub.list;
    for (k, &[i, j]) in list.pairs.iter().enumerate() {
        let (a, b) = if id[i as usize] < id[j as usize] {
            (i as usize, j as usize)
        } else {
            (j as usize, i as usize)
        };
        let owner = Owner {
            index: a,
            position: state.position[a],
            velocity: state.velocity[a],
            omega: state.omega.map_or(Vec3::ZERO, |w| w[a]),
            radius: state.radius[a],
            inv_mass: state.inv_mass[a],
            species_row: state.species[a] as usize * physics.n_species,
        };
        let pair = Pair {
            i: a as u32,
            j: b as u32,
            image: NO_IMAGE,
        };
        let (result, overlap, smaller_radius) = pair_force(
            physics.law,
            &state,
            &images,
            &owner,
            pair,
            &mut list.history[k],
            physics.dt,
        );
        if overlap > deepest_pair * smaller_radius {
            deepest_pair = overlap / smaller_radius;
        }
        if a < n {
            force[a] += result.force_on_i;
            if rotates {
                torque[a] += result.torque_on_i;
            }
        }
        if b < n {
            force[b] -= result.force_on_i;
            if rotates {
                torque[b] += result.torque_on_j;
            }
        }
    }
    let mut deepest_wall: Real = 0.0;
    let walls = physics.walls;
    for i in 0..n {
        let particle = WallParticle {
            species: state.species[i] as usize,
            position: state.position[i],
            velocity: state.velocity[i],
            radius: state.radius[i],
            mass: state.mass[i],
        };
        let mut f = force[i] + state.mass[i] * physics.gravity;
        let overlap = if rotates && W::NEEDS_ROTATION {
            let slots = &mut sub.wall_history[i * physics.wall_slots..][..physics.wall_slots];
            let (wall_history, _) = slots.split_at_mut(walls.walls.len());
            let omega = state.omega.map_or(Vec3::ZERO, |w| w[i]);
            let (wf, wt, o) = walls.force_and_torque_on(
                physics.wall_law,
                &particle,
                omega,
                wall_history,
                physics.dt,
            );
            f += wf;
            torque[i] += wt;
            o
        } else {
            let (wf, o) = walls.force_on(physics.wall_law, &particle, physics.dt);
            f += wf;
            o
        };
        force[i] = f;
        deepest_wall = larger(deepest_wall, overlap);
    }
    (deepest_pair, deepest_wall)
}
