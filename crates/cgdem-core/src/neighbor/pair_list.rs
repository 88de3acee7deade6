//! The pair list of a set of owned particles and their ghosts (a subdomain): a half list,
//! built from a cell grid when a particle has moved more than half the skin, with the
//! contact history of each pair. Pairs of two owned particles appear once, pairs of an owned
//! particle and a ghost once here and once in the ghost's own subdomain (newton off). Along
//! a periodic axis the subdomain spans alone there are no ghosts: the cell grid wraps there,
//! and a pair that meets across it is listed once with the shift of the image it meets
//! (image pairs). Across a rebuild the histories travel as rows keyed by the partner's id
//! ([`HistoryRows`]), with their particles.

use super::pair_search::{neighbour_cell, NEIGHBOUR_OFFSETS};
use super::CellGrid;
use crate::contact::PairHistory;
use crate::domain::{Domain, NO_IMAGE};
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

/// A pair that meets across a periodic axis its subdomain spans alone: its particles in
/// canonical orientation (the lower id first), the second seen at its position plus `shift`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ImagePair {
    pub pair: [u32; 2],
    pub shift: Vec3,
    pub constants: PairConstants,
}

/// What a pair's law reads of its two particles that stays the same between list builds (a
/// particle's radius and mass change only where the list is rebuilt: insertion, removal,
/// freezing), computed once per pair at the build instead of at every step: two divisions
/// per contact fewer. The same expressions as the step used (and `+`, `*` commute), so the
/// same bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PairConstants {
    /// Effective radius `r_i r_j / (r_i + r_j)`.
    pub r_eff: Real,
    /// Effective mass `1 / (1/m_i + 1/m_j)`: a frozen particle (inverse mass 0) acts with
    /// infinite mass, as in LIGGGHTS and LAMMPS with `fix freeze`; two frozen particles are
    /// never listed.
    pub m_eff: Real,
}

impl PairConstants {
    /// Of particles `i` and `j` of `p`.
    #[inline(always)]
    pub fn of(p: &Particles, i: usize, j: usize) -> Self {
        let (radius_i, radius_j) = (p.radius[i], p.radius[j]);
        PairConstants {
            r_eff: radius_i * radius_j / (radius_i + radius_j),
            m_eff: 1.0 / (p.inv_mass[i] + p.inv_mass[j]),
        }
    }
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct PairList<H> {
    /// Per pair its two particles in canonical orientation, the lower id first, so that
    /// every subdomain that lists a pair evaluates it the same way round with no look-up;
    /// in the order the owned particles found them (each with the later particles, owned or
    /// ghost, in index order).
    pub pairs: Vec<[u32; 2]>,
    /// Per pair, its effective radius and mass.
    pub constants: Vec<PairConstants>,
    /// Contact history per pair, in the pair's canonical orientation (lower id first).
    pub history: Vec<H>,
    /// Pairs that meet through a periodic image, and their histories.
    pub image_pairs: Vec<ImagePair>,
    pub image_history: Vec<H>,
    /// Owned positions at the build, for the displacement test.
    pub reference: Vec<Vec3>,
}

impl<H> PairList<H> {
    /// Listed pairs, direct and through an image.
    pub fn len(&self) -> usize {
        self.pairs.len() + self.image_pairs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every pair with the shift its second particle is seen through (zero for a direct
    /// pair) and its history.
    pub fn each(&self) -> impl Iterator<Item = ([u32; 2], Vec3, &H)> {
        let direct = self.pairs.iter().zip(&self.history);
        let through = self.image_pairs.iter().zip(&self.image_history);
        direct
            .map(|(&pair, h)| (pair, Vec3::ZERO, h))
            .chain(through.map(|(p, h)| (p.pair, p.shift, h)))
    }
}

impl<H: PairHistory> PairList<H> {
    /// The pairs of the first `n_owned` of `p` (owned) with every later particle (owned or
    /// ghost) within `r_i + r_j + extra` (except two frozen particles), found in cells at
    /// least `cell_size` wide, through the periodic images of `box_` along its periodic axes
    /// (those the subdomain spans alone, where it has no ghosts; positions there lie in the
    /// box), with each pair's history from its first particle's `rows`.
    pub fn build(
        p: &Particles,
        n_owned: usize,
        rows: &HistoryRows<H>,
        extra: Real,
        cell_size: Real,
        box_: &Domain,
    ) -> Self {
        let grid = CellGrid::build(box_, &p.position, cell_size);
        let mut found: Vec<(u32, u32, u8)> = Vec::new();
        let (mut pairs, mut images) = (Vec::new(), Vec::new());
        for i in 0..n_owned {
            let home = grid.cell_coords(p.position[i]);
            let frozen_i = p.is_frozen(i);
            found.clear();
            for offset in NEIGHBOUR_OFFSETS {
                let Some((cell, image)) = neighbour_cell(&grid, box_, home, offset) else {
                    continue;
                };
                let shift = box_.image_shift(image);
                for &j in grid.particles_in(cell) {
                    let j = j as usize;
                    if j <= i || (frozen_i && p.is_frozen(j)) {
                        continue;
                    }
                    let reach = p.radius[i] + p.radius[j] + extra;
                    let d = p.position[j] + shift - p.position[i];
                    if d.length_squared() < reach * reach {
                        found.push((i as u32, j as u32, image));
                    }
                }
            }
            found.sort_unstable();
            for &(i, j, image) in &found {
                if image == NO_IMAGE {
                    pairs.push([i, j]);
                } else {
                    images.push((i, j, image));
                }
            }
        }
        let history_of =
            |i: u32, j: u32| rows.find(i as usize, p.id[j as usize]).unwrap_or_default();
        let history = pairs.iter().map(|&[i, j]| history_of(i, j)).collect();
        let image_history = images.iter().map(|&(i, j, _)| history_of(i, j)).collect();
        let lower_first = |i: u32, j: u32| p.id[i as usize] < p.id[j as usize];
        for pair in &mut pairs {
            if !lower_first(pair[0], pair[1]) {
                pair.swap(0, 1);
            }
        }
        let image_pairs = images
            .into_iter()
            .map(|(i, j, image)| {
                let shift = box_.image_shift(image);
                // Seen from the other side, the partner is behind the opposite image.
                let constants = PairConstants::of(p, i as usize, j as usize);
                if lower_first(i, j) {
                    ImagePair {
                        pair: [i, j],
                        shift,
                        constants,
                    }
                } else {
                    ImagePair {
                        pair: [j, i],
                        shift: -shift,
                        constants,
                    }
                }
            })
            .collect();
        let constants = pairs
            .iter()
            .map(|&[i, j]| PairConstants::of(p, i as usize, j as usize))
            .collect();
        PairList {
            pairs,
            constants,
            history,
            image_pairs,
            image_history,
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
        for ([a, b], _, &h) in self.each() {
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
