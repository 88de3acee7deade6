//! Moving the cut planes (`--balance`, LAMMPS `fix balance ... shift`): the planes are found
//! by bisection on counts, as LAMMPS's `Balance::shift` does: each iteration counts the owned
//! particles below every candidate plane and sums those counts over the ranks, so what
//! travels is a few words per plane per iteration, whatever the particle count (gathering the
//! coordinates would send every particle's to every rank). The counts are integers, summed
//! exactly in any order, so every rank and every thread count finds the same planes bit for
//! bit. When to move them, and what a run saw, is `super::balance`.

use super::balance::{clamp_to_width, imbalance};
use super::step::Decomposition;
use super::Grid;
use crate::contact::PairHistory;
use crate::domain::Domain;
use crate::math::{Real, Vec3};

/// Bisection steps at most per balance: the bracket is then the box over 2^48.
const MAX_ITERATIONS: usize = 48;
/// A plane is placed when the particles below it are within this fraction of a slab's
/// mean count of its target: each slab then within twice that of the mean.
const COUNT_TOLERANCE: Real = 0.01;

impl<H: PairHistory, WH: PairHistory> Decomposition<H, WH> {
    /// Per subdomain, how many owned particles it holds now (all ranks, in index order).
    pub fn owned_counts(&self) -> Vec<u64> {
        let mut words = vec![0.0; self.subdomains.len()];
        for sub in self.owned() {
            words[sub.index] = sub.n_owned as Real;
        }
        self.comm.sum_each(&mut words);
        words.into_iter().map(|w| w as u64).collect()
    }

    /// Per grid of `grids`, how many of the owned particles `keep` accepts each of its
    /// subdomains would own (by their wrapped positions): what an exchange over it would
    /// leave. Summed over the subdomains and the ranks (integers: any order).
    pub fn counts_over(
        &self,
        grids: &[&Grid],
        domain: &Domain,
        keep: &(impl Fn(Vec3) -> bool + Sync),
    ) -> Vec<Vec<u64>> {
        let lengths: Vec<usize> = grids.iter().map(|g| g.len()).collect();
        let words = self.summed(
            lengths.iter().sum(),
            |x, counts| {
                let mut at = 0;
                for (g, n) in grids.iter().zip(&lengths) {
                    counts[at + g.owner(x)] += 1;
                    at += n;
                }
            },
            domain,
            keep,
        );
        let mut at = 0;
        lengths
            .iter()
            .map(|&n| {
                let c = words[at..at + n].to_vec();
                at += n;
                c
            })
            .collect()
    }

    /// `count(x, counts)` over every owned particle `keep` accepts (wrapped), into `len`
    /// counters per subdomain, summed over subdomains and ranks.
    fn summed(
        &self,
        len: usize,
        count: impl Fn(Vec3, &mut [u64]) + Sync,
        domain: &Domain,
        keep: &(impl Fn(Vec3) -> bool + Sync),
    ) -> Vec<u64> {
        let mut subs: Vec<_> = self.subdomains.iter().collect();
        let mut here = vec![0u64; len];
        let per_sub = self.comm.each_owned(&mut subs, |sub| {
            let mut counts = vec![0u64; len];
            for &x in &sub.particles.position[..sub.n_owned] {
                if keep(x) {
                    count(domain.wrap(x), &mut counts);
                }
            }
            counts
        });
        for counts in per_sub.into_iter().flatten() {
            here.iter_mut().zip(&counts).for_each(|(a, b)| *a += b);
        }
        // Counts below 2^53 are exact as f64, summed in any order.
        let mut words: Vec<Real> = here.iter().map(|&c| c as Real).collect();
        self.comm.sum_each(&mut words);
        words.into_iter().map(|w| w as u64).collect()
    }

    /// At a rebuild, before the exchange: measures the imbalance the exchange would leave
    /// and, past the threshold, moves the cut planes (see the module's comment). Collective.
    pub fn rebalance(&mut self, domain: &Domain, keep: &(impl Fn(Vec3) -> bool + Sync)) {
        let Some(threshold) = self.balance.threshold else {
            return;
        };
        let start = self.balance.start.clone();
        let counts = self.counts_over(&[&self.grid, &start], domain, keep);
        let b = &mut self.balance;
        b.static_worst = b.static_worst.max(imbalance(&counts[1]));
        if imbalance(&counts[0]) <= threshold {
            return;
        }
        let total: u64 = counts[0].iter().sum();
        let planes = self.planes_by_count(total, domain, keep);
        let mut grid = self.grid.clone();
        grid.planes = planes;
        clamp_to_width(&mut grid, self.width);
        // The clamp keeps each subdomain a ghost layer thick up to rounding; should rounding
        // still leave one thinner, the planes stay where they were (the ghosts would miss
        // pairs otherwise).
        if grid.check_width(self.width).is_err() || grid.planes == self.grid.planes {
            return;
        }
        self.grid = grid;
        for sub in &mut self.subdomains {
            (sub.lo, sub.hi) = self.grid.bounds(sub.index);
        }
        self.balance.shifts += 1;
    }

    /// Per axis cut into several slabs, the planes below which `c / n` of the `total`
    /// particles lie (`n` slabs), by simultaneous bisection of every plane's bracket; the
    /// other axes keep their planes.
    fn planes_by_count(
        &self,
        total: u64,
        domain: &Domain,
        keep: &(impl Fn(Vec3) -> bool + Sync),
    ) -> [Vec<Real>; 3] {
        let counts = self.grid.counts;
        let targets: [Vec<u64>; 3] = std::array::from_fn(|a| {
            (1..counts[a])
                .map(|c| c as u64 * total / counts[a] as u64)
                .collect()
        });
        let tolerance: [u64; 3] =
            std::array::from_fn(|a| (COUNT_TOLERANCE * total as Real / counts[a] as Real) as u64);
        let mut bracket: [Vec<(Real, Real)>; 3] =
            std::array::from_fn(|a| vec![(domain.lo[a], domain.hi[a]); targets[a].len()]);
        // Per plane: the smallest miss so far and where.
        let mut best: [Vec<(u64, Real)>; 3] =
            std::array::from_fn(|a| self.grid.planes[a].iter().map(|&p| (u64::MAX, p)).collect());
        for _ in 0..MAX_ITERATIONS {
            let mids: [Vec<Real>; 3] = std::array::from_fn(|a| {
                bracket[a].iter().map(|&(lo, hi)| 0.5 * (lo + hi)).collect()
            });
            let offsets = [0, mids[0].len(), mids[0].len() + mids[1].len()];
            let len = offsets[2] + mids[2].len();
            if len == 0 {
                break;
            }
            let below = self.summed(
                len,
                |x, counts| {
                    for a in 0..3 {
                        for (c, &m) in mids[a].iter().enumerate() {
                            if x[a] < m {
                                counts[offsets[a] + c] += 1;
                            }
                        }
                    }
                },
                domain,
                keep,
            );
            let mut placed = true;
            for a in 0..3 {
                for (c, &target) in targets[a].iter().enumerate() {
                    let n = below[offsets[a] + c];
                    let miss = n.abs_diff(target);
                    if miss < best[a][c].0 {
                        best[a][c] = (miss, mids[a][c]);
                    }
                    placed &= best[a][c].0 <= tolerance[a];
                    let (lo, hi) = &mut bracket[a][c];
                    if n < target {
                        *lo = mids[a][c];
                    } else {
                        *hi = mids[a][c];
                    }
                }
            }
            if placed {
                break;
            }
        }
        best.map(|planes| planes.into_iter().map(|b| b.1).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decomposition::{Comm, HistoryRows};
    use crate::particles::Particles;
    use rand::{Rng, SeedableRng};

    fn domain() -> Domain {
        Domain {
            lo: Vec3::ZERO,
            hi: Vec3::new(1.0, 0.5, 1.0),
            periodic: [false, true, false],
        }
    }

    /// `n` particles crowded into the corner x, z < 0.2 (y spread), in a decomposition over
    /// `counts` whose planes were placed for particles spread over the whole box.
    fn crowded(counts: [usize; 3], n: usize) -> Decomposition<Real, Real> {
        let domain = domain();
        let mut spread = Particles::new(false);
        for k in 0..1000 {
            let u = Vec3::new(
                (k % 10) as Real + 0.5,
                (k / 10 % 10) as Real + 0.5,
                (k / 100) as Real + 0.5,
            ) / 10.0;
            spread.push(0, domain.lo + u * domain.length(), 0.001, 1.0);
        }
        let grid = Grid::balanced(counts, &domain, &spread.position);
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut p = Particles::new(false);
        for k in 0..n {
            // Denser towards the corner itself along x.
            let (u, v, w): (Real, Real, Real) = (rng.gen(), rng.gen(), rng.gen());
            p.push(0, Vec3::new(0.2 * u * u, 0.5 * v, 0.2 * w), 0.001, 1.0);
            *p.id.last_mut().unwrap() = k as u32;
        }
        let rows = HistoryRows::from_entries(n, Vec::new());
        let mut d = Decomposition::new(
            grid,
            &p,
            &vec![0.0; n],
            &rows,
            &domain,
            1,
            0.01,
            0.0,
            0.001,
            Comm::local(),
        );
        d.balance.threshold = Some(1.1);
        d
    }

    #[test]
    fn a_shift_gives_each_subdomain_about_the_same_count() {
        for counts in [[2, 1, 1], [4, 1, 1], [2, 1, 2], [3, 2, 1]] {
            let mut d = crowded(counts, 3000);
            let keep = |_: Vec3| true;
            let before = imbalance(&d.owned_counts());
            assert!(before > 1.5, "{counts:?}: crowded start {before}");
            d.rebalance(&domain(), &keep);
            assert_eq!(d.balance.shifts, 1, "{counts:?}");
            let the_box = domain();
            let rule = crate::decomposition::removal::RemovalRule {
                domain: &the_box,
                delete_regions: &[],
                stop_on_lost: false,
                tripped: false,
                gravity: Vec3::ZERO,
                origin: Vec3::ZERO,
            };
            d.rebuild(&rule, 1, false);
            let after = d.owned_counts();
            assert_eq!(after.iter().sum::<u64>(), 3000);
            // Per axis the slabs are balanced to 2%; a grid cut along two axes multiplies
            // two such errors (and the corner's fill is not exactly a product).
            let limit = if counts.iter().filter(|&&n| n > 1).count() > 1 {
                1.1
            } else {
                1.021
            };
            assert!(
                imbalance(&after) <= limit,
                "{counts:?}: {after:?} ({})",
                imbalance(&after)
            );
            for sub in &d.subdomains {
                assert_eq!((sub.lo, sub.hi), d.grid.bounds(sub.index));
                for k in 0..sub.n_owned {
                    assert_eq!(d.grid.owner(sub.particles.position[k]), sub.index);
                }
            }
            // Balanced now: below the threshold nothing moves.
            let planes = d.grid.planes.clone();
            d.rebalance(&domain(), &keep);
            assert_eq!((d.grid.planes.clone(), d.balance.shifts), (planes, 1));
        }
    }

    #[test]
    fn a_shift_keeps_every_subdomain_a_ghost_layer_thick() {
        // Four slabs along x for particles within x < 0.2 and a ghost layer of 0.1: by count
        // the middle slabs would be 0.05 wide; clamped they are 0.1.
        let mut d = crowded([4, 1, 1], 3000);
        d.width = 0.1;
        let keep = |_: Vec3| true;
        d.rebalance(&domain(), &keep);
        assert_eq!(d.balance.shifts, 1);
        assert!(d.grid.check_width(0.1).is_ok(), "{:?}", d.grid.planes);
        let p = &d.grid.planes[0];
        assert!(p[0] > 0.0 && p[2] < 1.0, "{p:?}");
        assert!((p[1] - p[0] - 0.1).abs() < 1e-6 && (p[2] - p[1] - 0.1).abs() < 1e-6);
    }
}
