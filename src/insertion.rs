//! Random insertion: particles placed one by one at uniformly random positions inside a box
//! region, rejecting any that would overlap a particle already there (random sequential
//! addition). A hash grid keeps each check local.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::HashMap;

use crate::math::{Real, Vec3};
use crate::particles::Particles;

#[derive(Debug, thiserror::Error, PartialEq)]
#[error("could place only {placed} of {requested} particles without overlap in the region {lo:?} .. {hi:?}; enlarge the region or insert fewer")]
pub struct InsertionFailed {
    pub placed: u64,
    pub requested: u64,
    pub lo: [Real; 3],
    pub hi: [Real; 3],
}

/// Adds `count` particles of one species (radius, mass) inside `lo..hi` (centres kept one
/// radius from the region faces), not overlapping each other or existing particles.
#[allow(clippy::too_many_arguments)]
pub fn insert_random(
    particles: &mut Particles,
    species: u16,
    radius: Real,
    mass: Real,
    lo: Vec3,
    hi: Vec3,
    count: u64,
    seed: u64,
) -> Result<(), InsertionFailed> {
    insert_random_where(
        particles,
        species,
        radius,
        mass,
        lo,
        hi,
        count,
        seed,
        0.0,
        |_| true,
    )
}

/// As [`insert_random`], keeping only positions that `accept` (e.g. inside a mesh region and
/// clear of bodies), and allowing centres as close as `(1 - overlap)` times the sum of radii.
#[allow(clippy::too_many_arguments)]
pub fn insert_random_where(
    particles: &mut Particles,
    species: u16,
    radius: Real,
    mass: Real,
    lo: Vec3,
    hi: Vec3,
    count: u64,
    seed: u64,
    overlap: Real,
    accept: impl Fn(Vec3) -> bool,
) -> Result<(), InsertionFailed> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let max_radius = particles.radius.iter().cloned().fold(radius, Real::max);
    let cell = 2.0 * max_radius;
    let key = |p: Vec3| ((p / cell).floor()).as_ivec3().to_array();
    let mut grid: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
    for (k, &p) in particles.position.iter().enumerate() {
        grid.entry(key(p)).or_default().push(k as u32);
    }
    let (inner_lo, inner_hi) = (lo + Vec3::splat(radius), hi - Vec3::splat(radius));
    let failed = |placed| InsertionFailed {
        placed,
        requested: count,
        lo: lo.to_array(),
        hi: hi.to_array(),
    };
    if inner_lo.cmpgt(inner_hi).any() {
        return Err(failed(0));
    }
    let max_attempts = 1000 * count + 10_000;
    let (mut placed, mut attempts) = (0u64, 0u64);
    while placed < count {
        attempts += 1;
        if attempts > max_attempts {
            return Err(failed(placed));
        }
        let p = Vec3::new(
            rng.gen_range(inner_lo.x..=inner_hi.x),
            rng.gen_range(inner_lo.y..=inner_hi.y),
            rng.gen_range(inner_lo.z..=inner_hi.z),
        );
        if !accept(p) {
            continue;
        }
        let [cx, cy, cz] = key(p);
        let overlaps = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                (-1..=1).any(|dz| {
                    grid.get(&[cx + dx, cy + dy, cz + dz])
                        .is_some_and(|members| {
                            members.iter().any(|&k| {
                                let reach =
                                    (radius + particles.radius[k as usize]) * (1.0 - overlap);
                                (particles.position[k as usize] - p).length_squared()
                                    < reach * reach
                            })
                        })
                })
            })
        });
        if !overlaps {
            grid.entry(key(p)).or_default().push(particles.len() as u32);
            particles.push(species, p, radius, mass);
            placed += 1;
        }
    }
    Ok(())
}
