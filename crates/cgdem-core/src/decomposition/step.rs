//! The step of the subdomains: each stepped on the thread (or rank) that owns it, with the
//! three phases of communication between them (`exchange` and `borders` at a rebuild, the
//! `forward` every step). The world asks for the three parts of a step in turn:
//! `Decomposition::advance` (the first half of the integrator, the ghosts' new states
//! packed), a `Decomposition::rebuild` when a particle moved past half the skin, and
//! `Decomposition::forces` (the ghosts' states unpacked, the force pass of `force_pass`,
//! then the second half). The owned particles of all subdomains side
//! by side are what the outputs read (`Decomposition::gathered`).

use super::balance::{imbalance, Balance};
use super::borders::borders;
use super::exchange::exchange;
use super::force_pass;
use super::forward::Forward;
use super::removal::{RemovalRule, Removals};
use super::transport::{read_histories, write_histories};
use super::transport::{Comm, Wire};
use super::{Grid, HistoryRows, Subdomain};
use crate::bodies::{Body, BodyLoad, KinematicParticles};
use crate::contact::PairHistory;
use crate::contact::PairLaw;
use crate::domain::Domain;
use crate::force::{larger, Surroundings};
use crate::geometry::aabb::in_delete_region;
use crate::geometry::Aabb;
use crate::integrate::{closing_kick, kick, kick_then_drift, pcvv, Integrator};
use crate::math::{Real, Vec3};
use crate::memory_use::MemoryUse;
use crate::neighbor::{CellGrid, PairList};
use crate::particles::Particles;
use crate::walls::WallLaw;
use multiversion::multiversion;

/// The laws and what acts on a particle alone, for one force pass.
pub(crate) struct Physics<'a, L, W> {
    pub(crate) law: &'a L,
    /// Gravity, walls and bodies (posed at the step's end; their history slots follow the
    /// walls'), with the wall law and the step.
    pub(crate) surroundings: Surroundings<'a, W>,
    /// The particles of bodies built of particles, whose load goes to their bodies.
    pub(crate) kinematic: &'a [KinematicParticles],
    pub(crate) n_species: usize,
    pub(crate) wall_slots: usize,
    pub(crate) rotates: bool,
}

/// What moves or removes particles in a step besides the integrator.
pub struct Drive<'a> {
    /// Posed at the step's end: they move their particles (`kinematic`) after the drift.
    pub bodies: &'a [Body],
    pub kinematic: &'a [KinematicParticles],
    /// The delete regions checked this step (every `DELETE_EVERY`-th; none on the others): a
    /// particle in one calls for a rebuild, which deletes it.
    pub delete_regions: &'a [Aabb],
    /// Whether spins are integrated (the world's laws need them).
    pub rotates: bool,
}

/// What a force pass leaves for the world, over all subdomains: the deepest overlaps,
/// whether every value stayed finite, and the loads on the bodies, summed per subdomain
/// and then over the subdomains in order (the same numbers on any number of threads or
/// ranks).
#[derive(Clone, Debug, PartialEq)]
pub struct ForceSums {
    pub deepest_pair: Real,
    pub deepest_wall: Real,
    pub finite: bool,
    /// Per body, the load of the particles through its SDF contact.
    pub body_loads: Vec<BodyLoad>,
    /// Per group of particles of a body built of particles, their load on the body.
    pub kinematic_loads: Vec<BodyLoad>,
}

impl ForceSums {
    /// `self` (earlier subdomains) and then `later`.
    fn then(mut self, later: ForceSums) -> ForceSums {
        self.deepest_pair = larger(self.deepest_pair, later.deepest_pair);
        self.deepest_wall = larger(self.deepest_wall, later.deepest_wall);
        self.finite &= later.finite;
        for (a, b) in self.body_loads.iter_mut().zip(later.body_loads) {
            *a += b;
        }
        for (a, b) in self.kinematic_loads.iter_mut().zip(later.kinematic_loads) {
            *a += b;
        }
        self
    }

    fn write(&self, out: &mut Vec<Real>) {
        let finite = if self.finite { 1.0 } else { 0.0 };
        out.extend_from_slice(&[self.deepest_pair, self.deepest_wall, finite]);
        for load in self.body_loads.iter().chain(&self.kinematic_loads) {
            out.extend_from_slice(&load.force.to_array());
            out.extend_from_slice(&load.torque.to_array());
        }
    }

    fn read(words: &[Real], bodies: usize) -> ForceSums {
        let loads: Vec<BodyLoad> = words[3..]
            .chunks_exact(6)
            .map(|w| BodyLoad {
                force: Vec3::new(w[0], w[1], w[2]),
                torque: Vec3::new(w[3], w[4], w[5]),
            })
            .collect();
        let (body_loads, kinematic_loads) = loads.split_at(bodies);
        ForceSums {
            deepest_pair: words[0],
            deepest_wall: words[1],
            finite: words[2] != 0.0,
            body_loads: body_loads.to_vec(),
            kinematic_loads: kinematic_loads.to_vec(),
        }
    }
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
    /// The processes the subdomains are spread over; this one steps those it owns.
    pub comm: Comm,
    /// Owned particles over all subdomains (all ranks), as of the last rebuild.
    pub total: usize,
    /// Bytes this rank sent to other ranks (exchange, borders, forward) since the start.
    pub bytes_sent: u64,
    /// Whether and how the cut planes follow the particles, and what it saw.
    pub balance: Balance,
    /// The ghosts' update of every step between rebuilds.
    pub(super) forward: Forward,
}

impl<H: PairHistory, WH: PairHistory> Decomposition<H, WH> {
    /// Deals `particles` (with their wall histories and contact-history rows, one per
    /// particle; the same on every rank) out to the subdomains of `grid` that `comm` owns
    /// here, in order, and builds ghosts and lists.
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
        comm: Comm,
    ) -> Self {
        let rotation = particles.angular.is_some();
        let count = grid.len();
        let mut subdomains: Vec<Subdomain<H, WH>> = (0..count)
            .map(|s| Subdomain::new(s, &grid, rotation))
            .collect();
        for k in 0..particles.len() {
            let x = domain.wrap(particles.position[k]);
            let owner = grid.owner(x);
            if !comm.owns(owner, count) {
                continue;
            }
            let sub = &mut subdomains[owner];
            sub.particles.push_copy(particles, k);
            *sub.particles.position.last_mut().expect("just pushed") = x;
            sub.rows.push(rows.of(k));
            sub.wall_history
                .extend_from_slice(&wall_history[k * wall_slots..(k + 1) * wall_slots]);
            sub.n_owned += 1;
        }
        let mut d = Decomposition {
            balance: Balance::new(grid.clone(), None),
            grid,
            subdomains,
            width,
            extra,
            skin,
            builds: 0,
            comm,
            total: particles.len(),
            bytes_sent: 0,
            forward: Forward::default(),
        };
        d.borders_and_lists(false);
        d
    }

    /// Ghosts and lists after an exchange (owned particles re-sorted by cell first if asked).
    fn borders_and_lists(&mut self, resort: bool) {
        let width = self.width;
        if resort {
            self.comm
                .each_owned(&mut self.subdomains, |sub| resort_by_cell(sub, width));
        }
        self.bytes_sent += borders(&mut self.subdomains, &self.grid, width, &self.comm);
        self.forward.ghosts_rebuilt();
        let (extra, list_box) = (self.extra, self.grid.list_box());
        self.comm.each_owned(&mut self.subdomains, |sub| {
            let p = &sub.particles;
            sub.list = PairList::build(p, sub.n_owned, &sub.rows, extra, width, &list_box);
            sub.rows = HistoryRows::default();
            sub.near_walls.clear();
        });
        self.builds += 1;
    }

    /// The subdomains this rank steps.
    pub fn owned(&self) -> impl Iterator<Item = &Subdomain<H, WH>> {
        let (comm, count) = (&self.comm, self.subdomains.len());
        self.subdomains
            .iter()
            .filter(move |sub| comm.owns(sub.index, count))
    }

    /// A list rebuild: the particles `rule` removes (or reports) gathered from every
    /// subdomain in order, histories into rows, the cut planes moved if the balance asks,
    /// exchange (dropping the removed particles), borders, lists.
    pub(crate) fn rebuild(
        &mut self,
        rule: &RemovalRule<'_>,
        wall_slots: usize,
        resort: bool,
    ) -> Removals {
        let events = self
            .comm
            .gather_by_subdomain(self.subdomains.len(), |s, out| {
                let sub = &self.subdomains[s];
                for k in 0..sub.n_owned {
                    rule.record(&sub.particles, k, out);
                }
            });
        let mut removals = Removals::default();
        for words in &events {
            removals.add_words(words);
        }
        self.comm.each_owned(&mut self.subdomains, |sub| {
            sub.rows = sub.list.rows(&sub.particles.id, sub.n_owned);
        });
        let keep = |x: Vec3| rule.keeps(x);
        self.rebalance(rule.domain, &keep);
        self.bytes_sent += exchange(
            &mut self.subdomains,
            &self.grid,
            rule.domain,
            wall_slots,
            &keep,
            &self.comm,
        );
        self.borders_and_lists(resort);
        let counts = self.owned_counts();
        self.total = counts.iter().sum::<u64>() as usize;
        let now = imbalance(&counts);
        let b = &mut self.balance;
        if b.shifts > 0 {
            b.worst_after_first_shift = Some(b.worst_after_first_shift.unwrap_or(0.0).max(now));
        }
        if b.threshold.is_none() {
            // The planes never moved: the owned counts are the static split's.
            b.static_worst = b.static_worst.max(now);
        }
        removals
    }

    /// The owned particles of all subdomains side by side (the world's arrays after a
    /// rebuild), with their wall histories; under MPI gathered from every rank (to every
    /// rank, so each takes the same decisions from them).
    pub fn gathered(&self) -> (Particles, Vec<WH>) {
        self.gathered_to(false).expect("gathered to every rank")
    }

    /// `gathered`, and with `to_root` under MPI at rank 0 only (None on the others): for
    /// what only rank 0 writes. Collective.
    pub fn gathered_to(&self, to_root: bool) -> Option<(Particles, Vec<WH>)> {
        let rotation = self.subdomains[0].particles.angular.is_some();
        let mut all = Particles::new(rotation);
        let mut wall = Vec::new();
        if !self.comm.is_distributed() {
            for sub in &self.subdomains {
                for k in 0..sub.n_owned {
                    all.push_copy(&sub.particles, k);
                }
                wall.extend_from_slice(&sub.wall_history);
            }
            return Some((all, wall));
        }
        let encode = |s: usize, out: &mut Vec<Real>| {
            let sub = &self.subdomains[s];
            let mut owned = sub.particles.clone();
            owned.truncate(sub.n_owned);
            owned.write(out);
            write_histories(&sub.wall_history, out);
        };
        let count = self.subdomains.len();
        if to_root {
            let per_sub = self.comm.gather_by_subdomain_to_root(count, encode);
            if !self.comm.is_root() {
                return None;
            }
            return Some(Self::concatenated(per_sub, rotation));
        }
        let per_sub = self.comm.gather_by_subdomain(count, encode);
        Some(Self::concatenated(per_sub, rotation))
    }

    /// The particles and wall histories each subdomain's words hold, side by side.
    fn concatenated(per_sub: Vec<Vec<Real>>, rotation: bool) -> (Particles, Vec<WH>) {
        let mut all = Particles::new(rotation);
        let mut wall = Vec::new();
        for words in per_sub {
            let mut input = &words[..];
            let p = Particles::read(&mut input);
            for k in 0..p.len() {
                all.push_copy(&p, k);
            }
            wall.extend_from_slice(&read_histories::<WH>(&mut input));
        }
        (all, wall)
    }

    /// The contact-history rows of every owned particle, in the gathered order.
    pub fn gathered_rows(&self) -> HistoryRows<H> {
        let mut rows = HistoryRows::default();
        let per_sub = self
            .comm
            .gather_by_subdomain(self.subdomains.len(), |s, out| {
                let sub = &self.subdomains[s];
                let own = sub.list.rows(&sub.particles.id, sub.n_owned);
                out.push(sub.n_owned as Real);
                out.extend(own.start.iter().map(|&v| v as Real));
                out.extend(own.rows.iter().map(|r| r.0 as Real));
                let histories: Vec<H> = own.rows.iter().map(|r| r.1).collect();
                write_histories(&histories, out);
            });
        for words in per_sub {
            if words.is_empty() {
                continue;
            }
            let n = words[0] as usize;
            let start: Vec<usize> = words[1..n + 2].iter().map(|&v| v as usize).collect();
            let m = start[n];
            let partners = &words[n + 2..n + 2 + m];
            let mut input = &words[n + 2 + m..];
            let histories: Vec<H> = read_histories(&mut input);
            for k in 0..n {
                let own: Vec<(u32, H)> = (start[k]..start[k + 1])
                    .map(|r| (partners[r] as u32, histories[r]))
                    .collect();
                rows.push(&own);
            }
        }
        rows
    }

    /// What `summary.json` says of the grid: `reason` it is what it is, the particles per
    /// subdomain, the imbalance, the balance's record (`keep`: the particles the next
    /// rebuild keeps, for what the start's planes would give now) and the bytes sent between
    /// ranks per step over `steps`. Collective under MPI.
    pub fn summary(
        &self,
        reason: &str,
        steps: u64,
        domain: &Domain,
        keep: &(impl Fn(Vec3) -> bool + Sync),
    ) -> super::DecompositionSummary {
        let counts: Vec<usize> = self
            .comm
            .gather_by_subdomain(self.subdomains.len(), |s, out| {
                out.push(self.subdomains[s].n_owned as Real)
            })
            .iter()
            .map(|w| w[0] as usize)
            .collect();
        let mean = counts.iter().sum::<usize>() as Real / counts.len().max(1) as Real;
        let most = counts.iter().copied().max().unwrap_or(0) as Real;
        let bytes = self.comm.sum(self.bytes_sent) as Real;
        let b = &self.balance;
        let static_now = imbalance(&self.counts_over(&[&b.start], domain, keep)[0]);
        super::DecompositionSummary {
            grid: self.grid.counts,
            grid_reason: reason.to_string(),
            ranks: self.comm.size(),
            subdomain_particles: counts,
            imbalance: if mean > 0.0 { most / mean } else { 1.0 },
            bytes_sent_between_ranks_per_step: bytes / steps.max(1) as Real,
            balance_threshold: b.threshold,
            shifts: b.shifts,
            imbalance_max_after_first_shift: b.worst_after_first_shift,
            static_imbalance: static_now,
            static_imbalance_max: b.static_worst.max(static_now),
        }
    }

    /// The first half of a step of `integrator` for the owned particles (velocity
    /// Verlet's half kick and drift, or PCVV's predictor), then the particles of bodies
    /// built of particles moved to their bodies' pose, and the new states packed for the
    /// ghosts ([`Forward`]), in one pass per subdomain. Whether a rebuild is due, on any
    /// rank: a particle moved past half the skin, or entered one of the delete regions (the
    /// rebuild removes it, and drops the packed states).
    pub(crate) fn advance(&mut self, dt: Real, integrator: Integrator, drive: &Drive<'_>) -> bool {
        let limit_sq = 0.25 * self.skin * self.skin;
        let regions = drive.delete_regions;
        let mut packing = self.forward.start_packing(&mut self.subdomains);
        let due = self
            .comm
            .each_owned(&mut packing, |(sub, out)| {
                let moved = first_half(sub, dt, integrator, drive, limit_sq);
                Forward::pack(sub, out);
                let p = &sub.particles.position[..sub.n_owned];
                moved || (!regions.is_empty() && p.iter().any(|&x| in_delete_region(regions, x)))
            })
            .into_iter()
            .any(|due| due == Some(true));
        // The exchange is collective: every rank rebuilds when one must.
        self.comm.any(due)
    }

    /// Forces on the owned particles, then the second half of a step of `closing` if
    /// given (velocity Verlet's closing half kick, or PCVV's corrector). The ghosts first
    /// take the states `advance` packed, unless a rebuild since gave them fresh copies
    /// ([`Forward`]). The world's arrays are not touched: `gathered` brings the owned
    /// particles when they are read. Returns the deepest overlaps, finiteness and body
    /// loads over all subdomains of all ranks.
    pub(crate) fn forces<L: PairLaw<History = H>, W: WallLaw<History = WH>>(
        &mut self,
        physics: &Physics<'_, L, W>,
        closing: Option<Integrator>,
    ) -> ForceSums {
        self.bytes_sent += self.forward.route(&self.subdomains, &self.comm);
        let sums = self.pass(physics, closing);
        self.forward.unpacked();
        sums
    }

    /// One pass per owned subdomain: the ghosts' states unpacked (if packed), forces, the
    /// second half of the step (if `closing`); the guard's values and the body loads over
    /// all ranks, summed in subdomain order.
    fn pass<L: PairLaw<History = H>, W: WallLaw<History = WH>>(
        &mut self,
        physics: &Physics<'_, L, W>,
        closing: Option<Integrator>,
    ) -> ForceSums {
        let count = self.subdomains.len();
        let (comm, forward, skin) = (&self.comm, &self.forward, self.skin);
        let mine: Vec<Option<ForceSums>> = comm.each_owned(&mut self.subdomains, |sub| {
            forward.unpack(sub);
            forces_and_closing(sub, physics, closing, skin)
        });
        let in_order = |all: Vec<ForceSums>| {
            all.into_iter()
                .reduce(ForceSums::then)
                .expect("at least one subdomain")
        };
        if !comm.is_distributed() {
            return in_order(mine.into_iter().flatten().collect());
        }
        if physics.surroundings.bodies.is_empty() && physics.kinematic.is_empty() {
            let here = in_order(mine.into_iter().flatten().collect());
            // One reduction for the three (max is exact in any order).
            let finite = if here.finite { 0.0 } else { 1.0 };
            let mut v = [here.deepest_pair, here.deepest_wall, finite];
            comm.max_each(&mut v);
            return ForceSums {
                deepest_pair: v[0],
                deepest_wall: v[1],
                finite: v[2] == 0.0,
                ..here
            };
        }
        // Loads are sums: every rank adds all subdomains' in subdomain order, as one
        // process does (one all-gather instead of the max reduction).
        let per_sub = comm.gather_by_subdomain(count, |s, out| {
            mine[s].as_ref().expect("owned here").write(out)
        });
        let bodies = physics.surroundings.bodies.len();
        in_order(per_sub.iter().map(|w| ForceSums::read(w, bodies)).collect())
    }

    /// Kinetic plus gravitational energy (from `origin`) and mobile mass of the owned
    /// particles, summed per subdomain and then over the subdomains in order: the same
    /// numbers on any number of threads or ranks.
    pub fn energy_and_mobile_mass(&self, gravity: Vec3, origin: Vec3) -> (Real, Real) {
        let per_sub = self
            .comm
            .gather_by_subdomain(self.subdomains.len(), |s, out| {
                let sub = &self.subdomains[s];
                let p = &sub.particles;
                let (mut energy, mut mass) = (0.0, 0.0);
                for k in 0..sub.n_owned {
                    energy += 0.5 * p.mass[k] * p.velocity[k].length_squared() + p.spin_energy(k)
                        - p.mass[k] * gravity.dot(p.position[k] - origin);
                    if p.inv_mass[k] > 0.0 {
                        mass += p.mass[k];
                    }
                }
                out.extend_from_slice(&[energy, mass]);
            });
        per_sub
            .iter()
            .fold((0.0, 0.0), |(e, m), w| (e + w[0], m + w[1]))
    }

    /// Elastic energy of the listed pairs, each counted once: owned pairs, and pairs with a
    /// ghost from the side of the lower id.
    pub fn pair_elastic_energy<L: PairLaw>(&self, law: &L, n_species: usize) -> Real {
        let per_sub = self
            .comm
            .gather_by_subdomain(self.subdomains.len(), |s, out| {
                let sub = &self.subdomains[s];
                out.push({
                    let p = &sub.particles;
                    sub.list
                        .each()
                        .filter(|&([a, _], _, _)| (a as usize) < sub.n_owned)
                        .map(|([i, j], shift, _)| {
                            let (i, j) = (i as usize, j as usize);
                            let distance = (p.position[i] - (p.position[j] + shift)).length();
                            let species_pair =
                                p.species[i] as usize * n_species + p.species[j] as usize;
                            law.elastic_energy(species_pair, p.radius[i], p.radius[j], distance)
                        })
                        .sum::<Real>()
                })
            });
        per_sub.iter().map(|w| w[0]).sum()
    }

    /// Every listed pair once, by id (lower first), with its contact history: owned pairs,
    /// and pairs with a ghost from the side of the lower id; gathered from every rank, in
    /// subdomain and list order (for tests and diagnostics).
    pub fn pair_histories(&self) -> Vec<(u32, u32, H)> {
        let per_sub = self
            .comm
            .gather_by_subdomain(self.subdomains.len(), |s, out| {
                let sub = &self.subdomains[s];
                let id = &sub.particles.id;
                let (mut ids, mut histories) = (Vec::new(), Vec::new());
                for ([a, b], _, &h) in sub.list.each() {
                    if (a as usize) < sub.n_owned {
                        ids.extend_from_slice(&[id[a as usize] as Real, id[b as usize] as Real]);
                        histories.push(h);
                    }
                }
                out.push(histories.len() as Real);
                out.extend_from_slice(&ids);
                write_histories(&histories, out);
            });
        let mut all = Vec::new();
        for words in per_sub {
            let n = words[0] as usize;
            let ids = &words[1..1 + 2 * n];
            let mut rest = &words[1 + 2 * n..];
            let histories: Vec<H> = read_histories(&mut rest);
            for (pair, h) in ids.chunks_exact(2).zip(histories) {
                all.push((pair[0] as u32, pair[1] as u32, h));
            }
        }
        all
    }

    /// The arrays of the subdomains this rank steps: particles (owned and ghosts), wall
    /// histories, send lists, forward buffers and list references as per-particle bytes;
    /// pairs and their histories as per-pair bytes (a pair across a boundary is listed, and
    /// counted, on both sides).
    pub fn memory_use(&self) -> MemoryUse {
        fn bytes<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let mut m = MemoryUse {
            particles: 0,
            particle_bytes: 0,
            pairs: 0,
            pair_bytes: 0,
            history_entries: 0,
        };
        for sub in self.owned() {
            m.particles += sub.n_owned;
            m.particle_bytes += sub.particles.array_bytes()
                + bytes(&sub.wall_history)
                + bytes(&sub.body_clearances)
                + bytes(&sub.near_triangles)
                + bytes(&sub.list.reference)
                + sub.sends.iter().map(|l| bytes(&l.indices)).sum::<usize>()
                + bytes(&sub.receives);
            let l = &sub.list;
            m.pairs += l.len();
            m.pair_bytes += bytes(&l.pairs)
                + bytes(&l.constants)
                + bytes(&l.history)
                + bytes(&l.image_pairs)
                + bytes(&l.image_history)
                // The force pass's scratch for laws with history, as it will be sized
                // (counted from the list, so a resumed run reports what the
                // uninterrupted one does).
                + if force_pass::compacts_touching_pairs::<H>() {
                    l.pairs.len() * std::mem::size_of::<u32>()
                } else {
                    0
                };
            m.history_entries += l.len();
        }
        m.particle_bytes += self.forward.bytes();
        m
    }

    /// Pairs listed over all subdomains (a pair across a boundary twice).
    pub fn listed_pairs(&self) -> usize {
        let here: usize = self.owned().map(|s| s.list.len()).sum();
        self.comm.sum(here as u64) as usize
    }

    /// Ghosts over all subdomains.
    pub fn ghosts(&self) -> usize {
        let here: usize = self.owned().map(|s| s.ghosts()).sum();
        self.comm.sum(here as u64) as usize
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

// Run-time dispatch, in this one place: the two halves of a subdomain's step below (83%
// of the heap bench's time) are each compiled three times, for AVX-512 (x86-64-v4), AVX2
// (x86-64-v3) and any x86-64, and the first call picks the best the CPU has. So the build
// needs no `target-cpu`: one binary runs on every node of a cluster, and on the heap bench
// it is as fast as a `target-cpu=native` build. The clones give the same bits (Rust never
// fuses a multiply and an add unless asked), so ranks on different CPUs agree. What they
// call on the hot path (force pass, laws, integrator kernels) is `#[inline(always)]`: a
// function not inlined into them runs as plain x86-64 code. Dispatching lower down instead
// (around the pair loop and each kernel) cost the inlining across each boundary: the heap
// bench ran 7% slower so.

/// The first half of a step of `integrator` for `sub`'s owned particles (velocity Verlet's
/// half kick and drift, or PCVV's predictor), then the particles of bodies built of
/// particles moved to their bodies' pose; whether one moved farther than
/// `sqrt(limit_sq)` from its position at the last build.
#[multiversion(targets(
    "x86_64+avx512f+avx512bw+avx512cd+avx512dq+avx512vl+avx2+fma+bmi1+bmi2+f16c+lzcnt+movbe+popcnt",
    "x86_64+avx2+fma+bmi1+bmi2+f16c+lzcnt+movbe+popcnt",
))]
fn first_half<H: PairHistory, WH: PairHistory>(
    sub: &mut Subdomain<H, WH>,
    dt: Real,
    integrator: Integrator,
    drive: &Drive<'_>,
    limit_sq: Real,
) -> bool {
    let n = sub.n_owned;
    let p = &mut sub.particles;
    let reference = &sub.list.reference;
    let (position, velocity) = (&mut p.position[..n], &mut p.velocity[..n]);
    let mut moved = match integrator {
        Integrator::VelocityVerlet => kick_then_drift(
            position,
            velocity,
            &p.force,
            &p.inv_mass,
            reference,
            limit_sq,
            dt,
        ),
        Integrator::Pcvv => {
            pcvv::predict(position, velocity, &p.force[..n], &p.inv_mass[..n], dt);
            false
        }
    };
    if let Some(a) = p.angular.as_mut().filter(|_| drive.rotates) {
        let (omega, torque, inv_inertia) = (&mut a.omega[..n], &a.torque[..n], &a.inv_inertia);
        match integrator {
            Integrator::VelocityVerlet => {
                kick(omega, torque, inv_inertia, 0.5 * dt);
            }
            Integrator::Pcvv => pcvv::predict_rate(omega, torque, &inv_inertia[..n], dt),
        }
    }
    // The body particles move after the drift, and PCVV's predictor has no displacement
    // test of its own: the test runs (again) on the final positions.
    if integrator == Integrator::Pcvv || !drive.kinematic.is_empty() {
        for group in drive.kinematic {
            group.drive(&drive.bodies[group.body], p, n);
        }
        moved = p.position[..n]
            .iter()
            .zip(reference)
            .any(|(&x, &r)| (x - r).length_squared() > limit_sq);
    }
    moved
}

/// Forces on `sub`'s owned particles, the load on the particles of bodies built of
/// particles, then the second half of a step of `closing` (velocity Verlet's closing half
/// kick, or PCVV's corrector from the forces before this step's).
#[multiversion(targets(
    "x86_64+avx512f+avx512bw+avx512cd+avx512dq+avx512vl+avx2+fma+bmi1+bmi2+f16c+lzcnt+movbe+popcnt",
    "x86_64+avx2+fma+bmi1+bmi2+f16c+lzcnt+movbe+popcnt",
))]
fn forces_and_closing<L: PairLaw, W: WallLaw>(
    sub: &mut Subdomain<L::History, W::History>,
    physics: &Physics<'_, L, W>,
    closing: Option<Integrator>,
    skin: Real,
) -> ForceSums {
    let n = sub.n_owned;
    // PCVV's F0 and T0: the forces of the last step, which travel with their particles in
    // an exchange.
    let old = (closing == Some(Integrator::Pcvv)).then(|| {
        let p = &sub.particles;
        let torque = p.angular.as_ref().map(|a| a.torque[..n].to_vec());
        (p.force[..n].to_vec(), torque)
    });
    let mut sums = force_pass::forces(sub, physics, skin);
    let (p, gravity) = (&sub.particles, physics.surroundings.gravity);
    sums.kinematic_loads = physics
        .kinematic
        .iter()
        .map(|group| {
            let center = physics.surroundings.bodies[group.body].center();
            group.load(p, n, gravity, center)
        })
        .collect();
    sums.finite = match closing {
        None => true,
        Some(integrator) => second_half(sub, physics, integrator, old),
    };
    sums
}

/// The second half of a step of `integrator` for `sub`'s owned particles, from the forces
/// just evaluated (`old`: PCVV's forces and torques of the step before); whether every
/// velocity and spin stayed finite.
#[inline(always)]
fn second_half<L: PairLaw, W: WallLaw>(
    sub: &mut Subdomain<L::History, W::History>,
    physics: &Physics<'_, L, W>,
    integrator: Integrator,
    old: Option<OldLoads>,
) -> bool {
    let (n, dt) = (sub.n_owned, physics.surroundings.dt);
    let p = &mut sub.particles;
    let spins = p.angular.as_mut().filter(|_| physics.rotates);
    match integrator {
        Integrator::VelocityVerlet => {
            let mut finite = closing_kick(&mut p.velocity[..n], &p.force, &p.inv_mass, dt);
            if let Some(a) = spins {
                finite &= closing_kick(&mut a.omega[..n], &a.torque, &a.inv_inertia, dt);
            }
            finite
        }
        Integrator::Pcvv => {
            let (force, torque) = old.expect("kept for PCVV");
            let mut finite = pcvv::correct(
                &mut p.velocity[..n],
                &p.force[..n],
                &force,
                &p.inv_mass[..n],
                dt,
            );
            if let (Some(a), Some(torque)) = (spins, torque) {
                let (omega, new) = (&mut a.omega[..n], &a.torque[..n]);
                finite &= pcvv::correct(omega, new, &torque, &a.inv_inertia[..n], dt);
            }
            finite
        }
    }
}

/// PCVV's forces and torques (none without spin) of the step before, per owned particle.
type OldLoads = (Vec<Vec3>, Option<Vec<Vec3>>);
