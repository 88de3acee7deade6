//! Pair search over a whole set of particles with periodic images: every pair within reach
//! of each other, found through a cell grid. The step keeps its own lists (one per
//! subdomain, [`super::PairList`]); this search serves what reads the gathered particles (the
//! contact network of an output, the guard's diagnosis of an overlap).

use rayon::prelude::*;

use super::cell_grid::CellGrid;
use crate::domain::Domain;
use crate::math::{Real, Vec3};
use crate::particles::Particles;

/// One pair within reach: particle `i < j`, with `j` seen through periodic image `image`
/// (see [`Domain::image_shift`]).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub struct Pair {
    pub i: u32,
    pub j: u32,
    pub image: u8,
}

/// Every pair `i < j` (with image) of `particles`, their positions wrapped into the box,
/// closer than `r_i + r_j + extra`, except pairs of two frozen particles; sorted by
/// `(i, j, image)`.
pub fn pairs_within(particles: &Particles, domain: &Domain, extra: Real) -> Vec<Pair> {
    let mut wrapped = particles.clone();
    for x in wrapped.position.iter_mut() {
        *x = domain.wrap(*x);
    }
    let max_radius = wrapped.radius.iter().cloned().fold(0.0, Real::max);
    let grid = CellGrid::build(domain, &wrapped.position, 2.0 * max_radius + extra);
    find_pairs(&grid, domain, &wrapped, extra)
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

/// The 27 offsets from a cell to itself and its neighbours, z slowest.
pub(super) const NEIGHBOUR_OFFSETS: [[i32; 3]; 27] = {
    let mut offsets = [[0; 3]; 27];
    let mut k = 0;
    while k < 27 {
        offsets[k] = [
            (k % 3) as i32 - 1,
            ((k / 3) % 3) as i32 - 1,
            (k / 9) as i32 - 1,
        ];
        k += 1;
    }
    offsets
};

/// The cell at `home + offset` and the periodic image it is seen through, or None when the
/// offset leaves a bounded axis. On a periodic axis with fewer than three cells the same cell
/// is reached through different images, which is what a short box needs.
pub(super) fn neighbour_cell(
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
            let particles = random_particles(n, &domain, radii, seed);
            assert_eq!(
                pairs_within(&particles, &domain, skin),
                brute_force_pairs(&particles, &domain, skin),
                "seed {seed}"
            );
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
        assert_eq!(
            pairs_within(&particles, &domain, 0.01),
            brute_force_pairs(&particles, &domain, 0.01)
        );
    }
}
