//! Which grid a run steps on, and where its cut planes start. Every run is a grid of
//! subdomains: `--grid` gives it; otherwise it follows from the scene alone (its particle
//! count, box and periodic axes), never from the threads or ranks it runs on, so a scene,
//! seed and grid give bitwise the same outputs on any number of them.

use super::balance::clamp_to_width;
use super::grid::{choose_counts, Grid, GridSpec};
use crate::domain::Domain;
use crate::math::{Real, Vec3};

/// How `summary.json` says a grid was chosen from the scene (its `grid_reason` begins so).
pub const FROM_THE_SCENE: &str = "chosen from the scene";

/// Particles a subdomain holds at least when the grid is chosen from the scene: below
/// twice this a scene runs as one subdomain. Measured (reports/PERFORMANCE.md): with fewer,
/// the ghost layers and the phases' synchronisation cost more than a second thread gains.
pub const PARTICLES_PER_SUBDOMAIN: usize = 4096;
/// Subdomains at most when the grid is chosen from the scene: enough for a workstation's
/// threads; clusters give `--grid` for their ranks.
pub const MAX_SUBDOMAINS: usize = 64;

/// The grid chosen from the scene: the largest power of two of subdomains, at most
/// [`MAX_SUBDOMAINS`], that leaves each at least [`PARTICLES_PER_SUBDOMAIN`] particles, cut
/// across the axes that give the least ghost surface; with why, for `summary.json`.
pub fn scene_grid(particles: usize, extent: Vec3, periodic: [bool; 3]) -> (GridSpec, String) {
    let mut count = 1;
    while count * 2 <= MAX_SUBDOMAINS && particles >= count * 2 * PARTICLES_PER_SUBDOMAIN {
        count *= 2;
    }
    let counts = choose_counts(count, extent, periodic);
    let reason = if count == 1 {
        format!(
            "{FROM_THE_SCENE}: {particles} particles, one subdomain (a grid needs at least {PARTICLES_PER_SUBDOMAIN} particles per subdomain)"
        )
    } else {
        format!(
            "{FROM_THE_SCENE}: {particles} particles, {count} subdomains of at least {PARTICLES_PER_SUBDOMAIN} (at most {MAX_SUBDOMAINS}), cut where the ghost surface is least"
        )
    };
    (GridSpec::Given(counts), reason)
}

/// The extent the particles span along each bounded axis (the box's along periodic ones,
/// and where the particles span nothing).
pub fn particle_extent(domain: &Domain, positions: &[Vec3]) -> Vec3 {
    let mut extent = domain.length();
    for a in 0..3 {
        let (lo, hi) = positions
            .iter()
            .fold((Real::MAX, Real::MIN), |(lo, hi), x| {
                (lo.min(x[a]), hi.max(x[a]))
            });
        if !domain.periodic[a] && hi > lo {
            extent[a] = hi - lo;
        }
    }
    extent
}

/// The grid of `spec` over `positions`, its planes by count and at least `width` (the ghost
/// layer) apart; an error, for the user, when no placement is thick enough, a periodic axis
/// is shorter than twice `contact` (the contact distance), or `ranks` outnumber its
/// subdomains.
pub fn place(
    spec: GridSpec,
    domain: &Domain,
    positions: &[Vec3],
    width: Real,
    contact: Real,
    ranks: usize,
) -> Result<Grid, String> {
    let counts = match spec {
        GridSpec::Given(counts) => counts,
        GridSpec::Auto(count) => {
            choose_counts(count, particle_extent(domain, positions), domain.periodic)
        }
    };
    let mut grid = Grid::balanced(counts, domain, positions);
    if grid.check_width(width).is_err() {
        // By count the planes crowd where the particles do: moved apart to a ghost layer
        // (as a balance shift would be); refused only if no placement is thick enough.
        clamp_to_width(&mut grid, width);
    }
    grid.check_width(width)?;
    grid.check_periodic_images(contact)?;
    if ranks > grid.len() {
        return Err(format!(
            "{ranks} MPI ranks need at least as many subdomains, and the grid {}x{}x{} has {}; give a grid of at least {ranks} subdomains (--grid)",
            counts[0],
            counts[1],
            counts[2],
            grid.len(),
        ));
    }
    Ok(grid)
}

/// The scene's grid placed over `positions`: the count of [`scene_grid`], halved while its
/// subdomains would be thinner than the ghost layer (a small box holds few layers).
pub fn place_scene_grid(
    domain: &Domain,
    positions: &[Vec3],
    width: Real,
    contact: Real,
    ranks: usize,
) -> Result<(Grid, String), String> {
    let extent = particle_extent(domain, positions);
    let (mut spec, mut reason) = scene_grid(positions.len(), extent, domain.periodic);
    loop {
        let GridSpec::Given(counts) = spec else {
            unreachable!("scene_grid gives counts")
        };
        let count: usize = counts.iter().product();
        match place(spec, domain, positions, width, contact, ranks) {
            Ok(grid) => return Ok((grid, reason)),
            // Too thin: fewer subdomains (ranks beyond the count are the caller's error).
            Err(_) if count > 1 && ranks <= count / 2 => {
                spec = GridSpec::Given(choose_counts(count / 2, extent, domain.periodic));
                reason = format!(
                    "{reason}; {} subdomains would be thinner than the ghost layer ({width:.3e} m), so {}",
                    count,
                    count / 2
                );
            }
            Err(e) if ranks > 1 && !e.contains("MPI ranks") => {
                return Err(format!(
                    "{e}; with {ranks} MPI ranks the grid needs at least {ranks} subdomains thick enough for the ghost layer: give fewer ranks, or a grid with --grid"
                ))
            }
            Err(e) => return Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_grid_depends_on_the_particle_count_only_by_powers_of_two() {
        let extent = Vec3::new(0.4, 0.2, 0.1);
        let count = |n| {
            let (GridSpec::Given(c), _) = scene_grid(n, extent, [false; 3]) else {
                panic!()
            };
            c.iter().product::<usize>()
        };
        assert_eq!(count(10), 1);
        assert_eq!(count(2 * PARTICLES_PER_SUBDOMAIN - 1), 1);
        assert_eq!(count(2 * PARTICLES_PER_SUBDOMAIN), 2);
        assert_eq!(count(5 * PARTICLES_PER_SUBDOMAIN), 4);
        assert_eq!(count(1 << 30), MAX_SUBDOMAINS);
        // The longest axis is cut first.
        assert_eq!(
            scene_grid(2 * PARTICLES_PER_SUBDOMAIN, extent, [false; 3]).0,
            GridSpec::Given([2, 1, 1])
        );
    }

    #[test]
    fn a_box_too_small_for_the_ghost_layers_gets_fewer_subdomains() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::ONE,
            periodic: [true; 3],
        };
        // 16 subdomains' worth, spread over the box: 4x2x2 would give slabs of 0.25, thinner
        // than the layer of 0.4; 2x2x2 gives 0.5.
        let n = 16 * PARTICLES_PER_SUBDOMAIN;
        let positions: Vec<Vec3> = (0..n)
            .map(|k| {
                let u = |m: usize| ((k * m) % 9973) as Real / 9973.0;
                Vec3::new(u(7919), u(104729), u(1299709))
            })
            .collect();
        let (grid, reason) = place_scene_grid(&domain, &positions, 0.4, 0.1, 1).unwrap();
        assert_eq!(grid.counts, [2, 2, 2], "{reason}");
        assert!(reason.contains("thinner than the ghost layer"), "{reason}");
        // More ranks than any thick enough grid has subdomains: refused, naming the ranks.
        let error = place_scene_grid(&domain, &positions, 0.4, 0.1, 16).unwrap_err();
        assert!(error.contains("16 MPI ranks"), "{error}");
    }
}
