//! A subdomain's pair list: a half list over its owned particles and its ghosts. Pairs of two
//! owned particles appear once, pairs of an owned particle and a ghost once here and once in
//! the ghost's own subdomain (newton off). Built from a cell grid over the subdomain and its
//! ghost layer; no periodic images (the ghosts are the images).

use super::{HistoryRows, Subdomain};
use crate::contact::PairHistory;
use crate::domain::Domain;
use crate::math::{Real, Vec3};
use crate::neighbor::CellGrid;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct LocalList<H> {
    /// `[i, j]` with `i` owned and `j > i` (owned or ghost), grouped by `i`, `j` increasing.
    pub pairs: Vec<[u32; 2]>,
    /// Pairs of `i` are `pairs[out_start[i]..out_start[i + 1]]`.
    pub out_start: Vec<u32>,
    /// Contact history per pair, in the pair's canonical orientation (lower id first).
    pub history: Vec<H>,
    /// Owned positions at the build, for the displacement test.
    pub reference: Vec<Vec3>,
}

impl<H: PairHistory> LocalList<H> {
    /// Every pair within `r_i + r_j + extra` (except two frozen particles), in cells at least
    /// `cell_size` wide, with each pair's history from its first particle's rows.
    pub fn build<WH: PairHistory>(sub: &Subdomain<H, WH>, extra: Real, cell_size: Real) -> Self {
        let p = &sub.particles;
        let n_owned = sub.n_owned;
        let bounded = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::ONE,
            periodic: [false; 3],
        };
        let grid = CellGrid::build(&bounded, &p.position, cell_size);
        let mut pairs = Vec::new();
        let mut out_start = Vec::with_capacity(n_owned + 1);
        out_start.push(0u32);
        for i in 0..n_owned {
            let first = pairs.len();
            let home = grid.cell_coords(p.position[i]);
            let frozen_i = p.is_frozen(i);
            for dz in -1i64..=1 {
                for dy in -1i64..=1 {
                    for dx in -1i64..=1 {
                        let mut cell = [0usize; 3];
                        let mut inside = true;
                        for (a, d) in [dx, dy, dz].into_iter().enumerate() {
                            let c = home[a] as i64 + d;
                            inside &= c >= 0 && c < grid.counts[a] as i64;
                            cell[a] = c.max(0) as usize;
                        }
                        if !inside {
                            continue;
                        }
                        for &j in grid.particles_in(grid.linear(cell)) {
                            let j = j as usize;
                            if j <= i || (frozen_i && p.is_frozen(j)) {
                                continue;
                            }
                            let reach = p.radius[i] + p.radius[j] + extra;
                            if (p.position[j] - p.position[i]).length_squared() < reach * reach {
                                pairs.push([i as u32, j as u32]);
                            }
                        }
                    }
                }
            }
            pairs[first..].sort_unstable();
            out_start.push(pairs.len() as u32);
        }
        let history = pairs
            .iter()
            .map(|&[i, j]| {
                sub.rows
                    .find(i as usize, p.id[j as usize])
                    .unwrap_or_default()
            })
            .collect();
        LocalList {
            pairs,
            out_start,
            history,
            reference: p.position[..n_owned].to_vec(),
        }
    }

    /// The histories as rows of the owned particles (both particles of an owned pair keep a
    /// copy, as LAMMPS's `fix neigh/history` with newton off), for the exchange; pairs at
    /// rest (default history) are left out.
    pub fn rows(&self, ids: &[u32], n_owned: usize) -> HistoryRows<H> {
        if std::mem::size_of::<H>() == 0 {
            return HistoryRows::from_entries(n_owned, Vec::new());
        }
        let mut entries = Vec::new();
        for (&[i, j], &h) in self.pairs.iter().zip(&self.history) {
            if h == H::default() {
                continue;
            }
            entries.push((i, ids[j as usize], h));
            if (j as usize) < n_owned {
                entries.push((j, ids[i as usize], h));
            }
        }
        HistoryRows::from_entries(n_owned, entries)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decomposition::borders::{borders, tests::decomposed};
    use crate::neighbor::brute_force_pairs;

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
                let list = LocalList::<()>::build(sub, skin, width);
                let q = &sub.particles;
                for &[i, j] in &list.pairs {
                    let (i, j) = (i as usize, j as usize);
                    let both_owned = j < sub.n_owned;
                    found.push((
                        key(q.id[i], q.id[j], q.position[i], q.position[j]),
                        both_owned,
                    ));
                }
            }
            found.sort_unstable();
            let mut counted = Vec::new();
            let mut k = 0;
            while k < found.len() {
                let (pair, both_owned) = found[k];
                let copies = found[k..].iter().take_while(|f| f.0 == pair).count();
                let wanted = if both_owned { 1 } else { 2 };
                assert_eq!(copies, wanted, "{periodic:?} {counts:?} pair {pair:?}");
                assert!(found[k..k + copies].iter().all(|f| f.1 == both_owned));
                counted.push(pair);
                k += copies;
            }
            assert_eq!(counted, expected, "{periodic:?} {counts:?}");
        }
    }
}
