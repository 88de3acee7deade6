//! `borders` (LAMMPS `Comm::borders`): at a list rebuild, after the exchange, each subdomain
//! lists the owned particles its neighbours need as ghosts (those within `width` of the
//! neighbour's bounds, through the periodic image that brings them there), and each
//! subdomain appends its ghosts: full copies of the particles, positions shifted by the
//! image. The lists stay until the next rebuild; `forward` refreshes the ghosts' state.

use super::transport::{Comm, Wire};
use super::{Grid, Subdomain};
use crate::contact::PairHistory;
use crate::math::{Real, Vec3};
use crate::particles::Particles;

/// Owned particles (by index) that subdomain `to` keeps as ghosts, seen with `shift` added.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SendList {
    pub to: usize,
    pub shift: Vec3,
    pub indices: Vec<u32>,
}

/// First half: `sub`'s send lists for ghost layers of `width`, and the ghosts packed per list.
pub fn pack<H: PairHistory, WH: PairHistory>(
    sub: &mut Subdomain<H, WH>,
    grid: &Grid,
    width: Real,
) -> Vec<(usize, Particles)> {
    let rotation = sub.particles.angular.is_some();
    let p = &sub.particles;
    let mut sends = Vec::new();
    let mut packed = Vec::new();
    for (to, shift) in grid.neighbours(sub.index) {
        let (lo, hi) = grid.bounds(to);
        let (lo, hi) = (lo - Vec3::splat(width), hi + Vec3::splat(width));
        let mut ghosts = Particles::new(rotation);
        let indices: Vec<u32> = (0..sub.n_owned)
            .filter(|&k| {
                let x = p.position[k] + shift;
                x.cmpge(lo).all() && x.cmple(hi).all()
            })
            .map(|k| {
                ghosts.push_copy(p, k);
                *ghosts.position.last_mut().expect("just pushed") += shift;
                k as u32
            })
            .collect();
        if !indices.is_empty() {
            sends.push(SendList { to, shift, indices });
            packed.push((to, ghosts));
        }
    }
    sub.sends = sends;
    packed
}

/// Second half: appends to `sub` the ghosts every subdomain packed for it, in subdomain
/// then list order, and records where they came from for `forward`.
pub fn unpack<H: PairHistory, WH: PairHistory>(sub: &mut Subdomain<H, WH>, packed: &[Vec<Ghosts>]) {
    sub.particles.truncate(sub.n_owned);
    sub.receives.clear();
    for (from, lists) in packed.iter().enumerate() {
        for (list, Ghosts(to, ghosts)) in lists.iter().enumerate() {
            if *to != sub.index {
                continue;
            }
            for k in 0..ghosts.len() {
                sub.particles.push_copy(ghosts, k);
            }
            sub.receives.push((from, list));
        }
    }
}

/// Ghosts for one subdomain: its index and the particles, as they travel.
#[derive(Clone, Debug)]
pub struct Ghosts(pub usize, pub Particles);

impl Default for Ghosts {
    /// A slot meant for another rank's subdomain.
    fn default() -> Self {
        Ghosts(usize::MAX, Particles::default())
    }
}

impl Wire for Ghosts {
    fn write(&self, out: &mut Vec<Real>) {
        out.push(self.0 as Real);
        self.1.write(out);
    }

    fn read(input: &mut &[Real]) -> Self {
        let to = input[0] as usize;
        *input = &input[1..];
        Ghosts(to, Particles::read(input))
    }
}

/// Both halves over the subdomains `comm` owns here, the ghosts of other ranks' subdomains
/// sent there. Returns the bytes sent to other ranks.
pub fn borders<H: PairHistory, WH: PairHistory>(
    subs: &mut [Subdomain<H, WH>],
    grid: &Grid,
    width: Real,
    comm: &Comm,
) -> u64 {
    let mut packed: Vec<Vec<Ghosts>> = comm
        .each_owned(subs, |sub| {
            pack(sub, grid, width)
                .into_iter()
                .map(|(to, p)| Ghosts(to, p))
                .collect()
        })
        .into_iter()
        .map(Option::unwrap_or_default)
        .collect();
    let sent = comm.route(&mut packed, |_, _, g| g.0, &mut None);
    comm.each_owned(subs, |sub| unpack(sub, &packed));
    sent
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::decomposition::exchange::exchange;
    use crate::domain::Domain;
    use crate::neighbor::{brute_force_pairs, PairList};
    use rand::{Rng, SeedableRng};

    /// `n` particles spread over `domain`, dealt into the subdomains of `counts` by exchange.
    pub(crate) fn decomposed(
        domain: &Domain,
        counts: [usize; 3],
        n: usize,
        seed: u64,
    ) -> (Particles, Grid, Vec<Subdomain<(), ()>>) {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let mut p = Particles::new(false);
        for _ in 0..n {
            let u = Vec3::new(rng.gen(), rng.gen(), rng.gen());
            let r = rng.gen_range(0.01..=0.03);
            p.push(0, domain.lo + u * domain.length(), r, 1.0);
        }
        let grid = Grid::balanced(counts, domain, &p.position);
        let mut subs: Vec<Subdomain<(), ()>> = (0..grid.len())
            .map(|s| Subdomain::new(s, &grid, false))
            .collect();
        for k in 0..p.len() {
            subs[0].particles.push_copy(&p, k);
            subs[0].wall_history.push(());
            subs[0].rows.push(&[]);
        }
        subs[0].n_owned = p.len();
        exchange(&mut subs, &grid, domain, 1, &|_| true, &Comm::local());
        (p, grid, subs)
    }

    /// Every (id, image position) within `width` of subdomain `t`'s bounds, over the images
    /// -1, 0, 1 of every cut periodic axis (an uncut one has no ghosts: its pairs meet
    /// through images), except `t`'s own particles unshifted.
    fn brute_force_ghosts(
        p: &Particles,
        domain: &Domain,
        grid: &Grid,
        t: usize,
        width: Real,
    ) -> Vec<(u32, [u64; 3])> {
        let (lo, hi) = grid.bounds(t);
        let (lo, hi) = (lo - Vec3::splat(width), hi + Vec3::splat(width));
        let mut found = Vec::new();
        let range = |a: usize| {
            if domain.periodic[a] && !grid.spans_periodic(a) {
                -1..=1
            } else {
                0..=0
            }
        };
        for k in 0..p.len() {
            let x0 = domain.wrap(p.position[k]);
            for a in range(0) {
                for b in range(1) {
                    for c in range(2) {
                        let shift = Vec3::new(a as Real, b as Real, c as Real) * domain.length();
                        let x = x0 + shift;
                        let own = shift == Vec3::ZERO && grid.owner(x0) == t;
                        if !own && x.cmpge(lo).all() && x.cmple(hi).all() {
                            found.push((p.id[k], x.to_array().map(Real::to_bits)));
                        }
                    }
                }
            }
        }
        found.sort_unstable();
        found
    }

    #[test]
    fn ghosts_equal_the_brute_force_layer_with_periodic_images() {
        let cases = [
            ([true, false, true], [2, 2, 1]),
            ([true; 3], [1, 2, 3]),
            ([false; 3], [3, 1, 1]),
            ([true, true, false], [2, 1, 1]),
        ];
        for (periodic, counts) in cases {
            let domain = Domain {
                lo: Vec3::new(-0.2, 0.1, 0.0),
                hi: Vec3::new(0.8, 0.9, 0.9),
                periodic,
            };
            let width = 0.1;
            let (p, grid, mut subs) = decomposed(&domain, counts, 600, 3);
            grid.check_width(width).unwrap();
            borders(&mut subs, &grid, width, &Comm::local());
            for sub in &subs {
                let mut ghosts: Vec<(u32, [u64; 3])> = (sub.n_owned..sub.particles.len())
                    .map(|k| {
                        let x = sub.particles.position[k];
                        (sub.particles.id[k], x.to_array().map(Real::to_bits))
                    })
                    .collect();
                ghosts.sort_unstable();
                let expected = brute_force_ghosts(&p, &domain, &grid, sub.index, width);
                assert!(!expected.is_empty() || grid.len() == 1);
                assert_eq!(
                    ghosts, expected,
                    "{periodic:?} {counts:?} sub {}",
                    sub.index
                );
            }
        }
    }

    /// Every pair of the whole system is found by the subdomains' lists: once where both
    /// particles are owned by one subdomain, on both sides (newton off) where one is a ghost.
    #[test]
    fn owned_and_ghost_pairs_of_all_subdomains_equal_the_global_pair_list() {
        let cases = [
            ([true, false, true], [2, 2, 1]),
            ([true; 3], [1, 2, 2]),
            ([false; 3], [3, 1, 1]),
            ([false, true, false], [2, 1, 1]),
        ];
        for (periodic, counts) in cases {
            let domain = Domain {
                lo: Vec3::new(-0.2, 0.1, 0.0),
                hi: Vec3::new(0.8, 0.9, 0.9),
                periodic,
            };
            let skin = 0.01;
            let (mut p, grid, mut subs) = decomposed(&domain, counts, 700, 9);
            // A few frozen particles: two frozen ones are never a pair.
            for k in (0..p.len()).step_by(5) {
                p.freeze(k);
            }
            for sub in subs.iter_mut() {
                for k in 0..sub.n_owned {
                    if sub.particles.id[k] % 5 == 0 {
                        sub.particles.freeze(k);
                    }
                }
            }
            let width = 2.0 * 0.03 + skin;
            borders(
                &mut subs,
                &grid,
                width,
                &crate::decomposition::Comm::local(),
            );
            // Global pairs by id: (lower id, higher id, image offset of the higher seen from
            // the lower), found once when both are owned by one subdomain, twice otherwise.
            let key = |a: u32, b: u32, xa: Vec3, xb: Vec3| {
                let d = xb - xa;
                let image = ((d - (domain.wrap(xb) - domain.wrap(xa))) / domain.length())
                    .round()
                    .to_array()
                    .map(|v| v as i32);
                if a < b {
                    (a, b, image)
                } else {
                    (b, a, image.map(|v| -v))
                }
            };
            let mut expected: Vec<_> = brute_force_pairs(&p, &domain, skin)
                .iter()
                .map(|pair| {
                    let (i, j) = (pair.i as usize, pair.j as usize);
                    let xi = domain.wrap(p.position[i]);
                    let xj = domain.wrap(p.position[j]) + domain.image_shift(pair.image);
                    key(p.id[i], p.id[j], xi, xj)
                })
                .collect();
            expected.sort_unstable();
            let mut found = Vec::new();
            for sub in &subs {
                let (p, n) = (&sub.particles, sub.n_owned);
                let list = PairList::<()>::build(p, n, &sub.rows, skin, width, &grid.list_box());
                for ([i, j], shift, _) in list.each() {
                    let (i, j) = (i as usize, j as usize);
                    // Stored lower id first: either may be the ghost.
                    assert!(p.id[i] < p.id[j]);
                    // Listed once when both are owned here.
                    let once = i.max(j) < n;
                    let (xi, xj) = (p.position[i], p.position[j] + shift);
                    found.push((key(p.id[i], p.id[j], xi, xj), once));
                }
            }
            found.sort_unstable();
            let mut counted = Vec::new();
            let mut k = 0;
            while k < found.len() {
                let (pair, once) = found[k];
                let copies = found[k..].iter().take_while(|f| f.0 == pair).count();
                let wanted = if once { 1 } else { 2 };
                assert_eq!(copies, wanted, "{periodic:?} {counts:?} pair {pair:?}");
                assert!(found[k..k + copies].iter().all(|f| f.1 == once));
                counted.push(pair);
                k += copies;
            }
            assert_eq!(counted, expected, "{periodic:?} {counts:?}");
        }
    }
}
