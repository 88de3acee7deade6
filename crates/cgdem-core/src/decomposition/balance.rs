//! Load balance (LAMMPS `fix balance Nfreq thresh shift`): at a list rebuild, before the
//! exchange, the imbalance (most particles in one subdomain over the mean, over all ranks)
//! the exchange would leave is measured; past the threshold the cut planes move so that
//! each slab along each axis holds the same number of particles, and the exchange then
//! moves the particles to their new owners with their histories.
//!
//! The planes are found by bisection on counts, as LAMMPS's `Balance::shift` does: each
//! iteration counts the owned particles below every candidate plane and sums those counts
//! over the ranks, so what travels is a few words per plane per iteration, whatever the
//! particle count (gathering the coordinates would send every particle's to every rank).
//! The counts are integers, summed exactly in any order, so every rank and every thread
//! count finds the same planes bit for bit.

use std::str::FromStr;

use super::step::Decomposition;
use super::Grid;
use crate::contact::PairHistory;
use crate::domain::Domain;
use crate::math::{Real, Vec3};

/// `--balance`: move the cut planes when the imbalance passes `threshold`, or never.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BalanceSpec {
    Off,
    Shift(Real),
}

impl Default for BalanceSpec {
    /// On with `--grid`: a split that follows the particles costs a counting pass per
    /// rebuild, a split that does not can leave one subdomain with most of the work.
    fn default() -> Self {
        BalanceSpec::Shift(1.1)
    }
}

impl BalanceSpec {
    pub fn threshold(self) -> Option<Real> {
        match self {
            BalanceSpec::Off => None,
            BalanceSpec::Shift(t) => Some(t),
        }
    }
}

impl FromStr for BalanceSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        if s.eq_ignore_ascii_case("off") {
            return Ok(BalanceSpec::Off);
        }
        match s.parse::<Real>() {
            Ok(t) if t.is_finite() && t >= 1.0 => Ok(BalanceSpec::Shift(t)),
            _ => Err(format!(
                "--balance `{s}`: expected a threshold of at least 1.0 (most particles in one subdomain over the mean, e.g. 1.1), or `off`"
            )),
        }
    }
}

impl std::fmt::Display for BalanceSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BalanceSpec::Off => write!(f, "off"),
            BalanceSpec::Shift(t) => write!(f, "{t}"),
        }
    }
}

/// The balancing of a decomposed run and what it saw.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Balance {
    /// Rebalance at a rebuild when the imbalance passes this; None: the planes stay.
    pub threshold: Option<Real>,
    /// The planes of the start (by count), for what a static split would give.
    pub start: Grid,
    /// Rebuilds at which the planes moved.
    pub shifts: u64,
    /// Largest imbalance of the owned particles after a rebuild, from the first shift on.
    pub worst_after_first_shift: Option<Real>,
    /// Largest imbalance the start's planes gave (or would have given) at a rebuild.
    pub static_worst: Real,
}

impl Balance {
    pub fn new(start: Grid, threshold: Option<Real>) -> Self {
        Balance {
            threshold,
            start,
            shifts: 0,
            worst_after_first_shift: None,
            static_worst: 0.0,
        }
    }
}

/// Most over mean (1 is perfect balance; 1 with no particles).
pub fn imbalance(counts: &[u64]) -> Real {
    let total: u64 = counts.iter().sum();
    if total == 0 {
        return 1.0;
    }
    let most = counts.iter().copied().max().unwrap_or(0);
    most as Real * counts.len() as Real / total as Real
}

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

/// Moves `grid`'s planes as little as needed for every subdomain that has neighbours on
/// both sides along an axis (all of them on a periodic axis) to be at least `width` thick
/// (`Grid::check_width`), and every plane to stay inside the box: a pass up the axis pushes
/// planes up, a pass down pulls them back. Planes balanced by count crowd where the
/// particles crowd; the ghost layer must come from adjacent subdomains only, so the balance
/// there is given up rather than that.
pub fn clamp_to_width(grid: &mut Grid, width: Real) {
    // A hair more than the width, so that rounding in the sums does not undo it.
    let width = width * (1.0 + 1e-9);
    for a in 0..3 {
        let n = grid.counts[a];
        if n < 2 {
            continue;
        }
        let need = |slab: usize| {
            if grid.periodic[a] || (slab > 0 && slab + 1 < n) {
                width
            } else {
                0.0
            }
        };
        let needs: Vec<Real> = (0..n).map(need).collect();
        let mut p = Vec::with_capacity(n + 1);
        p.push(grid.lo[a]);
        p.extend_from_slice(&grid.planes[a]);
        p.push(grid.hi[a]);
        for s in 1..n {
            p[s] = p[s].max(p[s - 1] + needs[s - 1]);
        }
        for s in (1..n).rev() {
            p[s] = p[s].min(p[s + 1] - needs[s]);
        }
        grid.planes[a] = p[1..n].to_vec();
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
            d.rebuild(&domain(), 1, &keep, false);
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

    #[test]
    fn the_clamp_works_on_periodic_axes_and_leaves_thick_slabs_alone() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::splat(1.0),
            periodic: [true, false, false],
        };
        let mut grid = Grid::balanced([4, 1, 1], &domain, &[]);
        grid.planes[0] = vec![0.01, 0.02, 0.99];
        clamp_to_width(&mut grid, 0.2);
        assert!(grid.check_width(0.2).is_ok(), "{:?}", grid.planes[0]);
        let thick = vec![0.25, 0.5, 0.75];
        grid.planes[0] = thick.clone();
        clamp_to_width(&mut grid, 0.2);
        assert_eq!(grid.planes[0], thick);
    }

    #[test]
    fn balance_values_are_checked() {
        assert_eq!("1.25".parse(), Ok(BalanceSpec::Shift(1.25)));
        assert_eq!("1".parse(), Ok(BalanceSpec::Shift(1.0)));
        assert_eq!("off".parse(), Ok(BalanceSpec::Off));
        for bad in ["0.9", "-1", "inf", "NaN", "", "x"] {
            let e = bad.parse::<BalanceSpec>().unwrap_err();
            assert!(e.contains("at least 1.0"), "{bad}: {e}");
        }
        assert_eq!(imbalance(&[3, 1]), 1.5);
        assert_eq!(imbalance(&[0, 0]), 1.0);
    }
}
