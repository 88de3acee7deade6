//! The Verlet pair list: half list with periodic images, rebuilt from the cell grid when a
//! particle has moved more than half the skin since the last build.

use rayon::prelude::*;

use super::cell_grid::CellGrid;
use crate::contact::PairHistory;
use crate::domain::Domain;
use crate::math::{Real, Vec3};
use crate::particles::Particles;

/// One pair within cut-off plus skin: particle `i < j`, with `j` seen through periodic
/// image `image` (see [`Domain::image_shift`]).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub struct Pair {
    pub i: u32,
    pub j: u32,
    pub image: u8,
}

/// The list's rebuild criterion, for the integrator to test as it moves the particles:
/// has some particle moved farther than `sqrt(limit_sq)` from its `reference` position?
#[derive(Clone, Copy, Debug)]
pub struct DisplacementCheck<'a> {
    pub reference: &'a [Vec3],
    pub limit_sq: Real,
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct VerletList {
    pub pairs: Vec<Pair>,
    /// Pairs whose first particle is `i`: `pairs[out_start[i]..out_start[i + 1]]`.
    pub out_start: Vec<u32>,
    /// Pairs whose second particle is `j`: `in_pairs[in_start[j]..in_start[j + 1]]`.
    pub in_start: Vec<u32>,
    pub in_pairs: Vec<u32>,
    /// Positions at the last build, for the displacement criterion.
    pub(crate) reference: Vec<Vec3>,
    pub skin: Real,
    pub builds: u64,
}

impl VerletList {
    pub fn new(skin: Real) -> Self {
        VerletList {
            skin,
            ..Default::default()
        }
    }

    /// True when some particle moved more than half the skin since the last build, or the
    /// particle count changed.
    pub fn needs_rebuild(&self, positions: &[Vec3]) -> bool {
        let Some(check) = self.displacement_check(positions.len()) else {
            return true;
        };
        positions
            .par_iter()
            .zip(check.reference)
            .any(|(p, r)| (*p - *r).length_squared() > check.limit_sq)
    }

    /// The displacement test for `n` particles (half the skin from the positions at the
    /// last build), for the integrator to apply as it moves them; None when the list must
    /// be rebuilt anyway (never built, or the particle count changed).
    pub fn displacement_check(&self, n: usize) -> Option<DisplacementCheck<'_>> {
        (n == self.reference.len() && self.builds > 0).then_some(DisplacementCheck {
            reference: &self.reference,
            limit_sq: 0.25 * self.skin * self.skin,
        })
    }

    /// Rebuilds the list. Wraps periodic positions into the box first. When `resort` is set
    /// the particles are reordered by cell so memory order follows space; the permutation
    /// applied (new index -> old index) is returned so callers can carry per-pair data over.
    ///
    /// `reach` is how far beyond touching (`r_i + r_j`) the contact law acts.
    pub fn build(
        &mut self,
        particles: &mut Particles,
        domain: &Domain,
        reach: Real,
        resort: bool,
    ) -> Option<Vec<u32>> {
        for p in particles.position.iter_mut() {
            *p = domain.wrap(*p);
        }
        let max_radius = particles.radius.iter().cloned().fold(0.0, Real::max);
        let cell_size = 2.0 * max_radius + reach + self.skin;
        let mut grid = CellGrid::build(domain, &particles.position, cell_size);
        let mut permutation = None;
        if resort {
            let order = grid.items.clone();
            particles.permute(&order);
            grid = CellGrid::build(domain, &particles.position, cell_size);
            permutation = Some(order);
        }
        self.pairs = find_pairs(&grid, domain, particles, reach + self.skin);
        self.index_pairs(particles.len());
        self.reference = particles.position.clone();
        self.builds += 1;
        permutation
    }

    /// Bytes of the per-particle arrays (offsets, reference positions).
    pub fn particle_bytes(&self) -> usize {
        (self.out_start.capacity() + self.in_start.capacity()) * std::mem::size_of::<u32>()
            + self.reference.capacity() * std::mem::size_of::<Vec3>()
    }

    /// Bytes of the per-pair arrays (pairs and the reverse index).
    pub fn pair_bytes(&self) -> usize {
        self.pairs.capacity() * std::mem::size_of::<Pair>()
            + self.in_pairs.capacity() * std::mem::size_of::<u32>()
    }

    fn index_pairs(&mut self, n: usize) {
        let mut out_start = vec![0u32; n + 1];
        let mut in_start = vec![0u32; n + 1];
        for pair in &self.pairs {
            out_start[pair.i as usize + 1] += 1;
            in_start[pair.j as usize + 1] += 1;
        }
        for k in 0..n {
            out_start[k + 1] += out_start[k];
            in_start[k + 1] += in_start[k];
        }
        let mut fill = in_start.clone();
        let mut in_pairs = vec![0u32; self.pairs.len()];
        for (k, pair) in self.pairs.iter().enumerate() {
            let slot = &mut fill[pair.j as usize];
            in_pairs[*slot as usize] = k as u32;
            *slot += 1;
        }
        self.out_start = out_start;
        self.in_start = in_start;
        self.in_pairs = in_pairs;
    }

    /// Carries per-pair history from the previous list to this one. `old_pairs` and
    /// `old_history` are the list before the rebuild; `wraps[k]` is how many box lengths the
    /// build's wrap moved old particle `k` on each periodic axis (a pair's image changes when
    /// one of its particles crosses a periodic face); `remap` maps old particle indices to new
    /// ones (`u32::MAX` for a removed particle) when particles were reordered or removed.
    /// Pairs that are new start from the default history.
    pub fn carry_history<H: PairHistory>(
        &self,
        old_pairs: &[Pair],
        old_history: &[H],
        wraps: Option<&[[i32; 3]]>,
        remap: Option<&[u32]>,
    ) -> Vec<H> {
        if std::mem::size_of::<H>() == 0 {
            return vec![H::default(); self.pairs.len()];
        }
        let wraps = wraps.filter(|w| w.iter().any(|&k| k != [0; 3]));
        if remap.is_none() && wraps.is_none() {
            // The old list as it is: sorted by pair, each pair once.
            return self.merge_history(old_pairs, old_history);
        }
        let mut remapped: Vec<(Pair, H)> = old_pairs
            .iter()
            .zip(old_history)
            .filter_map(|(pair, &h)| {
                let mut image = pair.image;
                if let Some(w) = wraps {
                    // d = x_i - (x_j + o L); after wrapping x -> x - W L:
                    // o' = o + W_j - W_i.
                    let o = Domain::image_offset(image);
                    let (wi, wj) = (w[pair.i as usize], w[pair.j as usize]);
                    let moved: [i32; 3] = std::array::from_fn(|a| o[a] + wj[a] - wi[a]);
                    if moved.iter().any(|x| x.abs() > 1) {
                        return None;
                    }
                    image = Domain::image_index(moved);
                }
                let (i, j) = match remap {
                    Some(new_index) => (new_index[pair.i as usize], new_index[pair.j as usize]),
                    None => (pair.i, pair.j),
                };
                if i == u32::MAX || j == u32::MAX {
                    None
                } else if i < j {
                    Some((Pair { i, j, image }, h))
                } else {
                    let image = 26 - image; // the opposite image
                    Some((Pair { i: j, j: i, image }, h.mirrored()))
                }
            })
            .collect();
        remapped.sort_unstable_by_key(|(pair, _)| *pair);
        remapped.dedup_by_key(|(pair, _)| *pair);
        let (pairs, history): (Vec<Pair>, Vec<H>) = remapped.into_iter().unzip();
        self.merge_history(&pairs, &history)
    }

    /// The history of each listed pair from `old_pairs` (sorted, each pair once) and their
    /// `old_history`; the default for pairs not in it. Merged in parallel blocks, each
    /// finding its start in the old list by bisection.
    fn merge_history<H: PairHistory>(&self, old_pairs: &[Pair], old_history: &[H]) -> Vec<H> {
        const BLOCK: usize = 4096;
        let mut history = vec![H::default(); self.pairs.len()];
        history
            .par_chunks_mut(BLOCK)
            .zip(self.pairs.par_chunks(BLOCK))
            .for_each(|(history, pairs)| {
                let mut cursor = old_pairs.partition_point(|old| *old < pairs[0]);
                for (pair, entry) in pairs.iter().zip(history) {
                    while cursor < old_pairs.len() && old_pairs[cursor] < *pair {
                        cursor += 1;
                    }
                    if cursor < old_pairs.len() && old_pairs[cursor] == *pair {
                        *entry = old_history[cursor];
                    }
                }
            });
        history
    }
}

/// All pairs `i < j` (with image) closer than `r_i + r_j + extra`, sorted by `(i, j, image)`,
/// except pairs of two frozen particles.
fn find_pairs(grid: &CellGrid, domain: &Domain, particles: &Particles, extra: Real) -> Vec<Pair> {
    // One vector per block of particles (not per particle): few allocations per build.
    const BLOCK: usize = 256;
    let n = particles.len();
    let per_block: Vec<Vec<Pair>> = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        .map(|block| {
            let mut found = Vec::new();
            for i in block * BLOCK..((block + 1) * BLOCK).min(n) {
                let first = found.len();
                pairs_of(grid, domain, particles, extra, i, &mut found);
                found[first..].sort_unstable();
            }
            found
        })
        .collect();
    per_block.concat()
}

/// Appends the pairs `(i, j > i)` of particle `i` within `r_i + r_j + extra`.
fn pairs_of(
    grid: &CellGrid,
    domain: &Domain,
    particles: &Particles,
    extra: Real,
    i: usize,
    found: &mut Vec<Pair>,
) {
    let positions = &particles.position;
    let radii = &particles.radius;
    let frozen_i = particles.is_frozen(i);
    let home = grid.cell_coords(positions[i]);
    for dz in -1i32..=1 {
        for dy in -1i32..=1 {
            for dx in -1i32..=1 {
                let Some((cell, image)) = neighbour_cell(grid, domain, home, [dx, dy, dz]) else {
                    continue;
                };
                let shift = domain.image_shift(image);
                for &j in grid.particles_in(cell) {
                    // Two frozen particles never interact (neither moves).
                    if (j as usize) <= i || (frozen_i && particles.is_frozen(j as usize)) {
                        continue;
                    }
                    let reach = radii[i] + radii[j as usize] + extra;
                    let d = positions[j as usize] + shift - positions[i];
                    if d.length_squared() < reach * reach {
                        found.push(Pair {
                            i: i as u32,
                            j,
                            image,
                        });
                    }
                }
            }
        }
    }
}

/// The cell at `home + offset` and the periodic image it is seen through, or None when the
/// offset leaves a bounded axis. On a periodic axis with fewer than three cells the same cell
/// is reached through different images, which is what a short box needs.
fn neighbour_cell(
    grid: &CellGrid,
    domain: &Domain,
    home: [usize; 3],
    offset: [i32; 3],
) -> Option<(u32, u8)> {
    let mut cell = [0usize; 3];
    let mut image = [0i32; 3];
    for axis in 0..3 {
        let n = grid.counts[axis] as i32;
        let c = home[axis] as i32 + offset[axis];
        if domain.periodic[axis] {
            image[axis] = c.div_euclid(n);
            cell[axis] = c.rem_euclid(n) as usize;
        } else if c < 0 || c >= n {
            return None;
        } else {
            cell[axis] = c as usize;
        }
    }
    Some((grid.linear(cell), Domain::image_index(image)))
}

/// Reference answer for tests: every pair `i < j` over all images within `r_i + r_j + extra`,
/// except pairs of two frozen particles.
pub fn brute_force_pairs(particles: &Particles, domain: &Domain, extra: Real) -> Vec<Pair> {
    let mut pairs = Vec::new();
    let range = |axis: usize| if domain.periodic[axis] { -1..=1 } else { 0..=0 };
    let n = particles.len();
    let positions: Vec<Vec3> = particles.position.iter().map(|&p| domain.wrap(p)).collect();
    for i in 0..n {
        for j in i + 1..n {
            if particles.is_frozen(i) && particles.is_frozen(j) {
                continue;
            }
            for a in range(0) {
                for b in range(1) {
                    for c in range(2) {
                        let image = Domain::image_index([a, b, c]);
                        let d = positions[j] + domain.image_shift(image) - positions[i];
                        let reach = particles.radius[i] + particles.radius[j] + extra;
                        if d.length_squared() < reach * reach {
                            pairs.push(Pair {
                                i: i as u32,
                                j: j as u32,
                                image,
                            });
                        }
                    }
                }
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn random_particles(
        n: usize,
        domain: &Domain,
        radius_range: (Real, Real),
        seed: u64,
    ) -> Particles {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let mut particles = Particles::new(false);
        for _ in 0..n {
            let u = Vec3::new(rng.gen(), rng.gen(), rng.gen());
            // Some particles slightly outside bounded faces: clamping must still find them.
            let p = domain.lo + (u * 1.02 - Vec3::splat(0.01)) * domain.length();
            let r = rng.gen_range(radius_range.0..=radius_range.1);
            particles.push(0, p, r, 1.0);
        }
        particles
    }

    fn check(domain: Domain, n: usize, radii: (Real, Real), skin: Real) {
        for seed in 0..3 {
            let mut particles = random_particles(n, &domain, radii, seed);
            let mut list = VerletList::new(skin);
            list.build(&mut particles, &domain, 0.0, false);
            assert_eq!(
                list.pairs,
                brute_force_pairs(&particles, &domain, skin),
                "seed {seed}"
            );
            // Re-sorted by cell: the same set of pairs in the new numbering.
            list.build(&mut particles, &domain, 0.0, true);
            assert_eq!(
                list.pairs,
                brute_force_pairs(&particles, &domain, skin),
                "seed {seed}, re-sorted"
            );
            // Incidence: every pair appears once as outgoing of i and once as incoming of j.
            for (k, pair) in list.pairs.iter().enumerate() {
                let out = list.out_start[pair.i as usize]..list.out_start[pair.i as usize + 1];
                assert!(out.contains(&(k as u32)));
                let incoming = &list.in_pairs[list.in_start[pair.j as usize] as usize
                    ..list.in_start[pair.j as usize + 1] as usize];
                assert!(incoming.contains(&(k as u32)));
            }
        }
    }

    fn unit_box(periodic: [bool; 3], size: Vec3) -> Domain {
        Domain {
            lo: Vec3::new(-0.3, 0.1, 2.0),
            hi: Vec3::new(-0.3, 0.1, 2.0) + size,
            periodic,
        }
    }

    #[test]
    fn cell_list_equals_brute_force_monodisperse() {
        check(
            unit_box([false; 3], Vec3::splat(1.0)),
            600,
            (0.03, 0.03),
            0.01,
        );
    }

    #[test]
    fn cell_list_equals_brute_force_polydisperse_one_to_five() {
        check(
            unit_box([false; 3], Vec3::new(1.0, 0.7, 1.3)),
            500,
            (0.01, 0.05),
            0.01,
        );
    }

    #[test]
    fn cell_list_equals_brute_force_with_periodic_boundaries() {
        check(
            unit_box([true, false, true], Vec3::splat(1.0)),
            600,
            (0.02, 0.05),
            0.02,
        );
        check(
            unit_box([true; 3], Vec3::splat(1.0)),
            600,
            (0.02, 0.05),
            0.02,
        );
    }

    #[test]
    fn short_periodic_box_finds_every_image_pair() {
        // One or two cells across a periodic axis: a pair can interact through two images.
        check(
            unit_box([false, true, false], Vec3::new(1.0, 0.25, 1.0)),
            200,
            (0.04, 0.05),
            0.02,
        );
        check(
            unit_box([false, true, true], Vec3::new(1.0, 0.13, 0.2)),
            100,
            (0.03, 0.05),
            0.02,
        );
    }

    #[test]
    fn a_runaway_particle_leaves_the_pairs_unchanged() {
        // It stretches the grid over the bounded axes until the cap on cells widens them.
        let domain = unit_box([false; 3], Vec3::splat(1.0));
        let mut particles = random_particles(400, &domain, (0.02, 0.03), 7);
        particles.position[5] = Vec3::new(5e3, -2e3, 7e3);
        let mut list = VerletList::new(0.01);
        list.build(&mut particles, &domain, 0.0, true);
        assert_eq!(list.pairs, brute_force_pairs(&particles, &domain, 0.01));
    }

    #[test]
    fn rebuild_is_needed_only_after_half_the_skin() {
        let domain = unit_box([false; 3], Vec3::splat(1.0));
        let mut particles = random_particles(50, &domain, (0.02, 0.02), 1);
        let mut list = VerletList::new(0.01);
        list.build(&mut particles, &domain, 0.0, false);
        particles.position[7].x += 0.0049;
        assert!(!list.needs_rebuild(&particles.position));
        particles.position[7].x += 0.0002;
        assert!(list.needs_rebuild(&particles.position));
    }

    #[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Spring(Vec3);
    impl PairHistory for Spring {
        fn mirrored(self) -> Self {
            Spring(-self.0)
        }
        const WORDS: usize = 3;
        fn write_words(&self, out: &mut Vec<Real>) {
            self.0.write_words(out);
        }
        fn read_words(w: &[Real]) -> Self {
            Spring(Vec3::read_words(w))
        }
    }

    #[test]
    fn history_follows_its_pair_through_a_resort_and_is_mirrored_when_the_order_flips() {
        let domain = unit_box([true; 3], Vec3::splat(1.0));
        let mut particles = random_particles(300, &domain, (0.03, 0.05), 4);
        let mut list = VerletList::new(0.02);
        list.build(&mut particles, &domain, 0.0, false);
        // Tag each pair's history with the ids of its particles, from i's side.
        let ids = particles.id.clone();
        let tag = |a: u32, b: u32| Vec3::new(a as Real, b as Real, 1.0);
        let history: Vec<Spring> = list
            .pairs
            .iter()
            .map(|p| Spring(tag(ids[p.i as usize], ids[p.j as usize])))
            .collect();
        let old_pairs = list.pairs.clone();
        let order = list.build(&mut particles, &domain, 0.0, true).unwrap();
        let mut remap = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            remap[old as usize] = new as u32;
        }
        let carried = list.carry_history(&old_pairs, &history, None, Some(&remap));
        for (pair, h) in list.pairs.iter().zip(&carried) {
            let (a, b) = (particles.id[pair.i as usize], particles.id[pair.j as usize]);
            if h.0 == tag(a, b) {
                continue;
            }
            assert_eq!(h.0, -tag(b, a), "pair {pair:?} carried {h:?}");
        }
        assert!(
            carried.iter().all(|h| h.0.z.abs() == 1.0),
            "a pair lost its history"
        );
    }
}
