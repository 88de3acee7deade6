//! Insertion. Random: particles placed one by one at uniformly random positions inside a
//! box region, rejecting any that would overlap a particle already there (random sequential
//! addition); a hash grid keeps each check local. Lattice: every site of a cubic or
//! hexagonal lattice inside the region.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::HashMap;

use crate::math::{Real, Vec3};
use crate::particles::Particles;
use crate::scene::{Lattice, LatticeKind};

/// The sites of `lattice` where a sphere of `radius` lies inside `lo..hi` (and, with
/// `lattice.radius`, whose x-y distance from the origin is at most that radius), in
/// z-major, then y, then x order.
pub fn lattice_sites(lattice: &Lattice, lo: Vec3, hi: Vec3, radius: Real) -> Vec<Vec3> {
    let s = lattice.spacing;
    let origin = lattice.origin.unwrap_or(lo + Vec3::splat(radius));
    let (row, layer) = match lattice.kind {
        LatticeKind::Cubic => (s, s),
        LatticeKind::Hexagonal => (s * 3.0_f64.sqrt() / 2.0, s),
    };
    // Sites within `tolerance` of a face still count: `lo + r + 19 s` must not be lost to
    // rounding.
    let tolerance = 1e-9 * s;
    let (inner_lo, inner_hi) = (
        lo + Vec3::splat(radius - tolerance),
        hi - Vec3::splat(radius - tolerance),
    );
    let index_range = |from: Real, to: Real, step: Real| {
        ((from / step).floor() as i64 - 1)..=((to / step).ceil() as i64 + 1)
    };
    let rel_lo = inner_lo - origin;
    let rel_hi = inner_hi - origin;
    let mut sites = Vec::new();
    for k in index_range(rel_lo.z, rel_hi.z, layer) {
        for j in index_range(rel_lo.y, rel_hi.y, row) {
            let shift = match lattice.kind {
                LatticeKind::Hexagonal if j.rem_euclid(2) == 1 => 0.5 * s,
                _ => 0.0,
            };
            for i in index_range(rel_lo.x - shift, rel_hi.x - shift, s) {
                let offset = Vec3::new(i as Real * s + shift, j as Real * row, k as Real * layer);
                let p = origin + offset;
                let inside = p.cmpge(inner_lo).all() && p.cmple(inner_hi).all();
                let in_disk = lattice
                    .radius
                    .is_none_or(|r| offset.x.hypot(offset.y) <= r + tolerance);
                if inside && in_disk {
                    sites.push(p);
                }
            }
        }
    }
    sites
}

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

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(
        kind: LatticeKind,
        spacing: Real,
        origin: Option<Vec3>,
        radius: Option<Real>,
    ) -> Lattice {
        Lattice {
            kind,
            spacing,
            origin,
            radius,
        }
    }

    #[test]
    fn cubic_lattice_fills_the_box_corner_to_corner() {
        // 20 sites of 2.2 mm per axis in 2 * 1 mm + 19 * 2.2 mm.
        let l = lattice(LatticeKind::Cubic, 2.2e-3, None, None);
        let side = 2e-3 + 19.0 * 2.2e-3;
        let sites = lattice_sites(&l, Vec3::ZERO, Vec3::splat(side), 1e-3);
        assert_eq!(sites.len(), 8000);
        assert!((sites[0] - Vec3::splat(1e-3)).length() < 1e-15);
    }

    #[test]
    fn hexagonal_disk_centred_on_a_site_has_sixfold_symmetric_count() {
        // The benchmark's base: every site of a 2 mm hexagonal layer within 58.5 mm.
        let l = lattice(
            LatticeKind::Hexagonal,
            2e-3,
            Some(Vec3::new(0.0, 0.0, 1e-3)),
            Some(0.0585),
        );
        let sites = lattice_sites(
            &l,
            Vec3::new(-0.06, -0.06, 0.0),
            Vec3::new(0.06, 0.06, 0.002),
            1e-3,
        );
        assert_eq!(sites.len(), 3103);
        assert_eq!((sites.len() - 1) % 6, 0);
        // Nearest neighbours touch: six at one spacing from the centre site.
        let near = sites
            .iter()
            .filter(|p| ((p.x.hypot(p.y)) - 2e-3).abs() < 1e-12)
            .count();
        assert_eq!(near, 6);
        assert!(sites.iter().all(|p| p.z == 1e-3));
    }
}
