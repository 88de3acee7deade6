//! `exchange` (LAMMPS `Comm::exchange`): at a list rebuild, owned particles that left their
//! subdomain move to the subdomain that now holds them, with their wall history and their
//! contact-history rows. Particles the world removes (left the box through a bounded face,
//! non-finite) are dropped here.

use super::transport::{read_histories, write_histories, Comm, Wire};
use super::{Grid, HistoryRows, Subdomain};
use crate::contact::PairHistory;
use crate::domain::Domain;
use crate::math::{Real, Vec3};
use crate::particles::Particles;

/// Particles on their way to one subdomain, with everything that travels with them.
#[derive(Clone, Debug)]
pub struct Migrants<H, WH> {
    pub particles: Particles,
    /// `wall_slots` entries per particle.
    pub wall_history: Vec<WH>,
    pub rows: HistoryRows<H>,
}

impl<H: PairHistory, WH: PairHistory> Default for Migrants<H, WH> {
    fn default() -> Self {
        Migrants::new(false)
    }
}

impl<H: PairHistory, WH: PairHistory> Wire for Migrants<H, WH> {
    fn write(&self, out: &mut Vec<Real>) {
        self.particles.write(out);
        write_histories(&self.wall_history, out);
        out.extend(self.rows.start.iter().map(|&s| s as Real));
        let (partners, histories): (Vec<u32>, Vec<H>) = self.rows.rows.iter().copied().unzip();
        out.extend(partners.iter().map(|&p| p as Real));
        write_histories(&histories, out);
    }

    fn read(input: &mut &[Real]) -> Self {
        let particles = Particles::read(input);
        let wall_history = read_histories(input);
        let n = particles.len() + 1;
        let start: Vec<u32> = input[..n].iter().map(|&s| s as u32).collect();
        *input = &input[n..];
        let m = *start.last().expect("at least one start") as usize;
        let partners: Vec<u32> = input[..m].iter().map(|&p| p as u32).collect();
        *input = &input[m..];
        let histories: Vec<H> = read_histories(input);
        Migrants {
            particles,
            wall_history,
            rows: HistoryRows {
                start,
                rows: partners.into_iter().zip(histories).collect(),
            },
        }
    }
}

impl<H: PairHistory, WH: PairHistory> Migrants<H, WH> {
    fn new(with_rotation: bool) -> Self {
        Migrants {
            particles: Particles::new(with_rotation),
            wall_history: Vec::new(),
            rows: HistoryRows::default(),
        }
    }

    /// Appends owned particle `k` of `sub`.
    fn push_from(&mut self, sub: &Subdomain<H, WH>, k: usize, wall_slots: usize) {
        self.particles.push_copy(&sub.particles, k);
        self.wall_history
            .extend_from_slice(&sub.wall_history[k * wall_slots..(k + 1) * wall_slots]);
        self.rows.push(sub.rows.of(k));
    }
}

/// First half: drops `sub`'s ghosts, wraps its owned particles into the periodic box, drops
/// those `keep` refuses, keeps those still inside and packs the others per destination
/// (one buffer per subdomain; its own stays empty). Order is kept, so the result does not
/// depend on the thread count.
pub fn pack<H: PairHistory, WH: PairHistory>(
    sub: &mut Subdomain<H, WH>,
    grid: &Grid,
    domain: &Domain,
    wall_slots: usize,
    keep: &(impl Fn(Vec3) -> bool + Sync),
) -> Vec<Migrants<H, WH>> {
    let rotation = sub.particles.angular.is_some();
    sub.particles.truncate(sub.n_owned);
    let mut out: Vec<Migrants<H, WH>> = (0..grid.len()).map(|_| Migrants::new(rotation)).collect();
    let mut stay = Migrants::new(rotation);
    for k in 0..sub.n_owned {
        if !keep(sub.particles.position[k]) {
            continue;
        }
        let x = domain.wrap(sub.particles.position[k]);
        sub.particles.position[k] = x;
        let owner = grid.owner(x);
        let to = if owner == sub.index {
            &mut stay
        } else {
            &mut out[owner]
        };
        to.push_from(sub, k, wall_slots);
    }
    sub.particles = stay.particles;
    sub.wall_history = stay.wall_history;
    sub.rows = stay.rows;
    sub.n_owned = sub.particles.len();
    out
}

/// Second half: appends what every subdomain packed for `sub`, in subdomain order.
pub fn unpack<H: PairHistory, WH: PairHistory>(
    sub: &mut Subdomain<H, WH>,
    packed: &[Vec<Migrants<H, WH>>],
) {
    for from in packed {
        // Under MPI a subdomain of another rank that sent nothing here has no buffer.
        let Some(m) = from.get(sub.index) else {
            continue;
        };
        for k in 0..m.particles.len() {
            sub.particles.push_copy(&m.particles, k);
            sub.rows.push(m.rows.of(k));
        }
        sub.wall_history.extend_from_slice(&m.wall_history);
    }
    sub.n_owned = sub.particles.len();
}

/// Both halves over the subdomains `comm` owns here, each subdomain on its own task, with
/// the buffers for other ranks' subdomains sent there. Returns the bytes sent to other ranks.
pub fn exchange<H: PairHistory, WH: PairHistory>(
    subs: &mut [Subdomain<H, WH>],
    grid: &Grid,
    domain: &Domain,
    wall_slots: usize,
    keep: &(impl Fn(Vec3) -> bool + Sync),
    comm: &Comm,
) -> u64 {
    let mut packed: Vec<Vec<Migrants<H, WH>>> = comm
        .each_owned(subs, |sub| pack(sub, grid, domain, wall_slots, keep))
        .into_iter()
        .map(Option::unwrap_or_default)
        .collect();
    let sent = comm.route(&mut packed, |_, to, _| to, &mut None);
    comm.each_owned(subs, |sub| unpack(sub, &packed));
    sent
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Particles spread over a box, each with a recognisable wall history (its id) and a
    /// history row per "partner" id + 1000.
    fn scattered(n: usize, domain: &Domain, seed: u64) -> (Particles, Vec<Real>, Vec<u32>) {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let mut p = Particles::new(true);
        for _ in 0..n {
            let u = Vec3::new(rng.gen(), rng.gen(), rng.gen());
            p.push(0, domain.lo + u * domain.length(), 0.01, 1.0);
        }
        let wall: Vec<Real> =
            p.id.iter()
                .flat_map(|&id| [id as Real, -(id as Real)])
                .collect();
        (p, wall, (0..n as u32).collect())
    }

    #[test]
    fn after_exchange_every_particle_is_owned_once_by_the_subdomain_holding_it() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::new(1.0, 0.8, 0.6),
            periodic: [true, false, true],
        };
        for seed in 0..3 {
            let (p, wall, _) = scattered(500, &domain, seed);
            let grid = Grid::balanced([2, 3, 2], &domain, &p.position);
            // Deal the particles out round-robin: most start in the wrong subdomain.
            let mut subs: Vec<Subdomain<Real, Real>> = (0..grid.len())
                .map(|s| Subdomain::new(s, &grid, true))
                .collect();
            for k in 0..p.len() {
                let sub = &mut subs[k % grid.len()];
                sub.particles.push_copy(&p, k);
                sub.wall_history.extend_from_slice(&wall[2 * k..2 * k + 2]);
                let id = p.id[k];
                sub.rows.push(&[(id + 1000, id as Real), (id + 2000, 0.5)]);
                sub.n_owned += 1;
            }
            // Move every particle a bit, some across periodic faces and one out of the box.
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed + 10);
            let lost_id = 17;
            for sub in subs.iter_mut() {
                for k in 0..sub.n_owned {
                    let d = Vec3::new(rng.gen(), rng.gen(), rng.gen()) - Vec3::splat(0.5);
                    let x = &mut sub.particles.position[k];
                    *x += 0.2 * d;
                    x.y = x.y.clamp(0.0, 0.8);
                    if sub.particles.id[k] == lost_id {
                        sub.particles.position[k].y = -1.0;
                    }
                }
            }
            let keep = |x: Vec3| domain.contains_bounded(x);
            exchange(&mut subs, &grid, &domain, 2, &keep, &Comm::local());
            let mut seen = vec![0; p.len()];
            for sub in &subs {
                assert_eq!(sub.particles.len(), sub.n_owned);
                assert_eq!(sub.rows.len(), sub.n_owned);
                assert_eq!(sub.wall_history.len(), 2 * sub.n_owned);
                for k in 0..sub.n_owned {
                    let id = sub.particles.id[k];
                    seen[id as usize] += 1;
                    let x = sub.particles.position[k];
                    assert_eq!(grid.owner(x), sub.index, "id {id} at {x}");
                    assert!(
                        x.x >= 0.0 && x.x < 1.0 && x.z >= 0.0 && x.z < 0.6,
                        "wrapped"
                    );
                    // What travels travels with its particle.
                    assert_eq!(sub.wall_history[2 * k], id as Real);
                    assert_eq!(sub.wall_history[2 * k + 1], -(id as Real));
                    assert_eq!(sub.rows.find(k, id + 1000), Some(id as Real));
                    assert_eq!(sub.rows.find(k, id + 2000), Some(0.5));
                    assert_eq!(sub.rows.find(k, id + 3000), None);
                }
            }
            for (id, &count) in seen.iter().enumerate() {
                let expected = if id as u32 == lost_id { 0 } else { 1 };
                assert_eq!(count, expected, "id {id}");
            }
        }
    }
}
