//! Which grid a run steps on, and where its cut planes start. Every run is a grid of
//! subdomains: `--grid` gives it; otherwise it follows from the scene alone (its particle
//! count, box and periodic axes), never from the threads or ranks it runs on, so a scene,
//! seed and grid give bitwise the same outputs on any number of them.

use super::balance::clamp_to_width;
use super::grid::{choose_counts, choose_counts_uncut, Grid, GridSpec};
use crate::domain::Domain;
use crate::math::{Real, Vec3};

/// How `summary.json` says a grid was chosen from the scene (its `grid_reason` begins so).
pub const FROM_THE_SCENE: &str = "chosen from the scene";

/// Particles a subdomain holds at least when the grid is chosen from the scene: below twice
/// this a scene runs as one subdomain. Measured on the main job (819 particles; alternating
/// runs, reports/PERFORMANCE.md): two subdomains of about 410 cost one thread 6% and give
/// two threads about 1.5x; four of about 205 cost one thread 19%.
pub const PARTICLES_PER_SUBDOMAIN: usize = 400;
/// Subdomains at most when the grid is chosen from the scene. Threads and ranks take whole
/// subdomains, so up to this many keep busy; on fewer threads each extra subdomain costs its
/// ghost layers (the heap bench, 11,103 particles: four cost 2% against two on one or two
/// threads, eight 5%). Machines with more cores and clusters give `--grid`.
pub const MAX_SUBDOMAINS: usize = 4;

/// The grid chosen from the scene: the largest power of two of subdomains, at most
/// [`MAX_SUBDOMAINS`], that leaves each at least [`PARTICLES_PER_SUBDOMAIN`] particles, cut
/// where the ghost surface is least among the grids whose planes contain `gravity` (a bed
/// settles and flows across horizontal planes, emptying the slabs above; LAMMPS users write
/// `processors * * 1` for the same reason); with why, for `summary.json`.
pub fn scene_grid(
    particles: usize,
    extent: Vec3,
    periodic: [bool; 3],
    gravity: Vec3,
) -> (GridSpec, String) {
    let mut count = 1;
    while count * 2 <= MAX_SUBDOMAINS && particles >= count * 2 * PARTICLES_PER_SUBDOMAIN {
        count *= 2;
    }
    let counts = choose_counts_uncut(count, extent, periodic, vertical(gravity));
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

/// The axis gravity acts along, if it acts along one.
fn vertical(gravity: Vec3) -> Option<usize> {
    let g = gravity.abs().to_array();
    let along = (0..3).filter(|&a| g[a] > 0.0).count();
    (along == 1).then(|| (0..3).find(|&a| g[a] > 0.0).expect("one axis"))
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

/// The scene's grid placed over `positions`: the grid of [`scene_grid`]; if its subdomains
/// would be thinner than the ghost layer (a small box holds few layers), the same count cut
/// along gravity too, then half as many, and so on.
pub fn place_scene_grid(
    domain: &Domain,
    positions: &[Vec3],
    gravity: Vec3,
    width: Real,
    contact: Real,
    ranks: usize,
) -> Result<(Grid, String), String> {
    let extent = particle_extent(domain, positions);
    let (spec, mut reason) = scene_grid(positions.len(), extent, domain.periodic, gravity);
    let GridSpec::Given(counts) = spec else {
        unreachable!("scene_grid gives counts")
    };
    let mut count: usize = counts.iter().product();
    if ranks > count {
        let [x, y, z] = counts;
        return Err(format!(
            "{ranks} MPI ranks need at least as many subdomains, and the grid chosen from the scene is {x}x{y}x{z} ({reason}): give a grid of at least {ranks} subdomains with --grid"
        ));
    }
    let mut last_error = String::new();
    while count >= ranks.max(1) {
        let across = choose_counts_uncut(count, extent, domain.periodic, vertical(gravity));
        let any = choose_counts(count, extent, domain.periodic);
        for counts in [across, any] {
            match place(
                GridSpec::Given(counts),
                domain,
                positions,
                width,
                contact,
                ranks,
            ) {
                Ok(grid) => {
                    if grid.counts != across {
                        let [x, y, z] = counts;
                        reason = format!("{reason}; cut along gravity too ({x}x{y}x{z}): across it the subdomains would be thinner than the ghost layer ({width:.3e} m)");
                    }
                    return Ok((grid, reason));
                }
                Err(e) => last_error = e,
            }
        }
        if count == 1 {
            break;
        }
        reason = format!(
            "{reason}; {count} subdomains would be thinner than the ghost layer ({width:.3e} m), so {}",
            count / 2
        );
        count /= 2;
    }
    if ranks > 1 {
        return Err(format!(
            "{ranks} MPI ranks need at least as many subdomains, and fewer are thick enough for the ghost layer ({last_error}): give fewer ranks"
        ));
    }
    Err(last_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_grid_depends_on_the_particle_count_only_by_powers_of_two() {
        let extent = Vec3::new(0.4, 0.2, 0.1);
        let g = Vec3::new(0.0, 0.0, -9.81);
        let count = |n| {
            let (GridSpec::Given(c), _) = scene_grid(n, extent, [false; 3], g) else {
                panic!()
            };
            c.iter().product::<usize>()
        };
        assert_eq!(count(10), 1);
        assert_eq!(count(2 * PARTICLES_PER_SUBDOMAIN - 1), 1);
        assert_eq!(count(2 * PARTICLES_PER_SUBDOMAIN), 2);
        assert_eq!(count(4 * PARTICLES_PER_SUBDOMAIN), 4);
        assert_eq!(count(1 << 30), MAX_SUBDOMAINS);
        // The longest axis is cut first, but not along gravity: a column 1 m tall on a
        // base of 0.3 by 0.3 m is cut across x and y.
        let two = 2 * PARTICLES_PER_SUBDOMAIN;
        assert_eq!(
            scene_grid(two, extent, [false; 3], g).0,
            GridSpec::Given([2, 1, 1])
        );
        let column = Vec3::new(0.3, 0.3, 1.0);
        assert_eq!(
            scene_grid(two, column, [false; 3], g).0,
            GridSpec::Given([2, 1, 1])
        );
        let four = 4 * PARTICLES_PER_SUBDOMAIN;
        assert_eq!(
            scene_grid(four, column, [false; 3], g).0,
            GridSpec::Given([2, 2, 1])
        );
        // Without gravity the column is cut across z.
        let none = Vec3::ZERO;
        assert_eq!(
            scene_grid(two, column, [false; 3], none).0,
            GridSpec::Given([1, 1, 2])
        );
    }

    #[test]
    fn a_box_too_small_for_the_ghost_layers_gets_fewer_subdomains() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::new(1.0, 0.1, 0.1),
            periodic: [true, false, false],
        };
        // Four subdomains' worth along x, the only long axis: 4x1x1 would give slabs of 0.25,
        // thinner than the layer of 0.4; 2x1x1 gives 0.5.
        let n = 4 * PARTICLES_PER_SUBDOMAIN;
        let positions: Vec<Vec3> = (0..n)
            .map(|k| {
                let u = |m: usize| ((k * m) % 9973) as Real / 9973.0;
                Vec3::new(u(7919), 0.1 * u(104729), 0.1 * u(1299709))
            })
            .collect();
        let g = Vec3::new(0.0, 0.0, -9.81);
        let (grid, reason) = place_scene_grid(&domain, &positions, g, 0.4, 0.1, 1).unwrap();
        assert_eq!(grid.counts, [2, 1, 1], "{reason}");
        assert!(reason.contains("thinner than the ghost layer"), "{reason}");
        // More ranks than any thick enough grid has subdomains: refused, naming the ranks.
        let error = place_scene_grid(&domain, &positions, g, 0.4, 0.1, 4).unwrap_err();
        assert!(error.contains("4 MPI ranks"), "{error}");
    }
}
