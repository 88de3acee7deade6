//! The pair list of a set of owned particles and their ghosts (a subdomain): a half list,
//! built from a cell grid when a particle has moved more than half the skin, with the
//! contact history of each pair. Pairs of two owned particles appear once, pairs of an owned
//! particle and a ghost once here and once in the ghost's own subdomain (newton off); the
//! ghosts are the periodic images, so the list has none of its own. Across a rebuild the
//! histories travel as rows keyed by the partner's id ([`HistoryRows`]), with their
//! particles.

use super::CellGrid;
use crate::contact::PairHistory;
use crate::domain::Domain;
use crate::math::{Real, Vec3};
use crate::particles::Particles;

/// Per owned particle, the contact histories of its pairs keyed by the partner's id (LAMMPS
/// `fix neigh/history`'s partner lists, kept with both particles of a pair when newton is
/// off): they travel with the particle in an exchange and seed the new list's histories.
/// Histories are in the pair's canonical orientation (lower id first), so both copies are
/// equal and never mirrored.
#[derive(Clone, Debug)]
pub struct HistoryRows<H> {
    /// Rows of particle `k` are `rows[start[k]..start[k + 1]]`, sorted by partner id.
    pub start: Vec<u32>,
    pub rows: Vec<(u32, H)>,
}

impl<H> Default for HistoryRows<H> {
    fn default() -> Self {
        HistoryRows {
            start: vec![0],
            rows: Vec::new(),
        }
    }
}

impl<H: PairHistory> HistoryRows<H> {
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn of(&self, k: usize) -> &[(u32, H)] {
        &self.rows[self.start[k] as usize..self.start[k + 1] as usize]
    }

    /// Rows for `n` particles without history.
    pub fn none(n: usize) -> Self {
        HistoryRows {
            start: vec![0; n + 1],
            rows: Vec::new(),
        }
    }

    /// Appends a particle with `rows` (sorted by partner id).
    pub fn push(&mut self, rows: &[(u32, H)]) {
        self.rows.extend_from_slice(rows);
        self.start.push(self.rows.len() as u32);
    }

    /// The history of the pair with `partner`, if the particle has one.
    pub fn find(&self, k: usize, partner: u32) -> Option<H> {
        let rows = self.of(k);
        rows.binary_search_by_key(&partner, |r| r.0)
            .ok()
            .map(|at| rows[at].1)
    }

    /// Rows from per-particle lists of `(particle, partner, history)`, `n` particles.
    pub fn from_entries(n: usize, mut entries: Vec<(u32, u32, H)>) -> Self {
        entries.sort_unstable_by_key(|e| (e.0, e.1));
        let mut start = vec![0u32; n + 1];
        for e in &entries {
            start[e.0 as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        HistoryRows {
            start,
            rows: entries.into_iter().map(|e| (e.1, e.2)).collect(),
        }
    }
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct PairList<H> {
    /// Per pair its two particles in canonical orientation, the lower id first, so that
    /// every subdomain that lists a pair evaluates it the same way round with no look-up;
    /// grouped by the owned particle `i` that found it (with `j > i`, owned or ghost), `j`
    /// increasing within a group.
    pub pairs: Vec<[u32; 2]>,
    /// Pairs found by owned particle `i` are `pairs[out_start[i]..out_start[i + 1]]`.
    pub out_start: Vec<u32>,
    /// Contact history per pair, in the pair's canonical orientation (lower id first).
    pub history: Vec<H>,
    /// Owned positions at the build, for the displacement test.
    pub reference: Vec<Vec3>,
}

impl<H: PairHistory> PairList<H> {
    /// The pairs of the first `n_owned` of `p` (owned) with every later particle (owned or
    /// ghost) within `r_i + r_j + extra` (except two frozen particles), found in cells at
    /// least `cell_size` wide, with each pair's history from its first particle's `rows`.
    pub fn build(
        p: &Particles,
        n_owned: usize,
        rows: &HistoryRows<H>,
        extra: Real,
        cell_size: Real,
    ) -> Self {
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
            .map(|&[i, j]| rows.find(i as usize, p.id[j as usize]).unwrap_or_default())
            .collect();
        for pair in &mut pairs {
            if p.id[pair[0] as usize] > p.id[pair[1] as usize] {
                pair.swap(0, 1);
            }
        }
        PairList {
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
        for (&[a, b], &h) in self.pairs.iter().zip(&self.history) {
            if h == H::default() {
                continue;
            }
            if (a as usize) < n_owned {
                entries.push((a, ids[b as usize], h));
            }
            if (b as usize) < n_owned {
                entries.push((b, ids[a as usize], h));
            }
        }
        HistoryRows::from_entries(n_owned, entries)
    }
}
