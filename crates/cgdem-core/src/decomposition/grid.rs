//! The subdomain grid (LAMMPS `processors`): how many subdomains along each axis, and the cut
//! planes between them, placed by particle count (LAMMPS `balance shift`'s start).

use std::str::FromStr;

use crate::domain::Domain;
use crate::math::{Real, Vec3};

/// What the user asked for: a grid given axis by axis (`2x1x1`), or a number of subdomains
/// whose grid is chosen to minimise the ghost surface (`4`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridSpec {
    Given([usize; 3]),
    Auto(usize),
}

impl FromStr for GridSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "--grid `{s}`: expected three counts of at least 1 as NXxNYxNZ (e.g. 2x1x1), or one count of subdomains (e.g. 2) for a grid chosen to minimise the ghost surface"
            )
        };
        let parts: Vec<&str> = s.trim().split(['x', 'X']).collect();
        let counts: Vec<usize> = parts
            .iter()
            .map(|p| p.trim().parse::<usize>().ok().filter(|&n| n >= 1))
            .collect::<Option<_>>()
            .ok_or_else(bad)?;
        match counts.as_slice() {
            [n] => Ok(GridSpec::Auto(*n)),
            [x, y, z] => Ok(GridSpec::Given([*x, *y, *z])),
            _ => Err(bad()),
        }
    }
}

impl std::fmt::Display for GridSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GridSpec::Given([x, y, z]) => write!(f, "{x}x{y}x{z}"),
            GridSpec::Auto(n) => write!(f, "{n}"),
        }
    }
}

/// The grid of `count` subdomains whose cut faces have the least area over `extent`: the
/// ghost layer's volume, so what forward communication moves each step. On a periodic axis
/// every subdomain face is a cut (the images cross it), on a bounded one the outer faces are
/// not. Ties go to more cuts across x, then across y.
pub fn choose_counts(count: usize, extent: Vec3, periodic: [bool; 3]) -> [usize; 3] {
    choose_counts_uncut(count, extent, periodic, None)
}

/// [`choose_counts`] among the grids that do not cut axis `uncut` (if given).
pub fn choose_counts_uncut(
    count: usize,
    extent: Vec3,
    periodic: [bool; 3],
    uncut: Option<usize>,
) -> [usize; 3] {
    let mut best = ([count, 1, 1], Real::INFINITY);
    for nx in (1..=count).rev() {
        if !count.is_multiple_of(nx) {
            continue;
        }
        for ny in (1..=count / nx).rev() {
            if !(count / nx).is_multiple_of(ny) {
                continue;
            }
            let n = [nx, ny, count / nx / ny];
            if uncut.is_some_and(|a| n[a] > 1) {
                continue;
            }
            let surface: Real = (0..3)
                .map(|a| {
                    let cuts = if periodic[a] { n[a] } else { n[a] - 1 };
                    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                    cuts as Real * extent[b] * extent[c]
                })
                .sum();
            if surface < best.1 {
                best = (n, surface);
            }
        }
    }
    best.0
}

/// The subdomain grid: per axis the counts and the interior cut planes.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Grid {
    pub counts: [usize; 3],
    /// Per axis, `counts[a] - 1` increasing planes; subdomain `c` along `a` holds
    /// `planes[a][c - 1] <= x < planes[a][c]` (open-ended at the box on bounded axes, the box
    /// faces on periodic ones).
    pub planes: [Vec<Real>; 3],
    pub lo: Vec3,
    pub hi: Vec3,
    pub periodic: [bool; 3],
}

impl Grid {
    /// Cut planes that give each slab along each axis the same number of `positions`
    /// (wrapped into the box on periodic axes), each halfway between two particles.
    pub fn balanced(counts: [usize; 3], domain: &Domain, positions: &[Vec3]) -> Grid {
        let planes = std::array::from_fn(|a| {
            let mut x: Vec<Real> = positions
                .iter()
                .map(|&p| domain.wrap(p)[a])
                .filter(|x| x.is_finite())
                .collect();
            x.sort_unstable_by(Real::total_cmp);
            let (lo, hi) = (domain.lo[a], domain.hi[a]);
            (1..counts[a])
                .map(|c| {
                    if x.is_empty() {
                        return lo + (hi - lo) * c as Real / counts[a] as Real;
                    }
                    let k = (c * x.len() / counts[a]).clamp(1, x.len() - 1);
                    0.5 * (x[k - 1] + x[k])
                })
                .collect()
        });
        Grid {
            counts,
            planes,
            lo: domain.lo,
            hi: domain.hi,
            periodic: domain.periodic,
        }
    }

    pub fn len(&self) -> usize {
        self.counts.iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Subdomain index of grid coordinates (x fastest).
    pub fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.counts[1] + c[1]) * self.counts[0] + c[0]
    }

    pub fn coords(&self, index: usize) -> [usize; 3] {
        let (nx, ny) = (self.counts[0], self.counts[1]);
        [index % nx, (index / nx) % ny, index / nx / ny]
    }

    /// The subdomain owning a (wrapped) position; positions beyond a bounded face belong to
    /// the outermost subdomain.
    pub fn owner(&self, p: Vec3) -> usize {
        let c = std::array::from_fn(|a| self.planes[a].partition_point(|&plane| plane <= p[a]));
        self.index(c)
    }

    /// The bounds of subdomain `index` (infinite on the outer side of bounded axes).
    pub fn bounds(&self, index: usize) -> (Vec3, Vec3) {
        let c = self.coords(index);
        let (mut lo, mut hi) = (Vec3::ZERO, Vec3::ZERO);
        for a in 0..3 {
            let planes = &self.planes[a];
            lo[a] = match c[a] {
                0 if self.periodic[a] => self.lo[a],
                0 => Real::NEG_INFINITY,
                k => planes[k - 1],
            };
            hi[a] = if c[a] + 1 < self.counts[a] {
                planes[c[a]]
            } else if self.periodic[a] {
                self.hi[a]
            } else {
                Real::INFINITY
            };
        }
        (lo, hi)
    }

    /// Checks that ghosts of width `width` come from the adjacent subdomains only: each
    /// subdomain at least `width` thick where it has neighbours on both sides (a cut periodic
    /// axis is then at least two layers long). Returns what is wrong, for the user. A
    /// periodic axis that is not cut has no ghosts (its pairs meet through images), and may
    /// be as short as [`Grid::check_periodic_images`] allows.
    pub fn check_width(&self, width: Real) -> Result<(), String> {
        for a in 0..3 {
            let axis = ["x", "y", "z"][a];
            for c in 0..self.counts[a] {
                let cut = self.counts[a] > 1;
                let interior = (self.periodic[a] && cut) || (c > 0 && c + 1 < self.counts[a]);
                if !interior {
                    continue;
                }
                let mut coords = [0; 3];
                coords[a] = c;
                let (lo, hi) = self.bounds(self.index(coords));
                if hi[a] - lo[a] < width {
                    return Err(format!(
                        "subdomain {} along {axis} is {:.4e} m thick, thinner than the ghost layer ({width:.4e} m); use fewer subdomains along {axis}",
                        c + 1,
                        hi[a] - lo[a]
                    ));
                }
            }
        }
        Ok(())
    }

    /// Whether axis `a` is periodic and not cut: each subdomain spans it alone, and its pairs
    /// across it meet through images, not ghosts.
    pub fn spans_periodic(&self, a: usize) -> bool {
        self.periodic[a] && self.counts[a] == 1
    }

    /// The box a subdomain's list searches: periodic where the subdomain spans a periodic
    /// axis alone, bounded (spanning the particles) elsewhere.
    pub fn list_box(&self) -> Domain {
        Domain {
            lo: self.lo,
            hi: self.hi,
            periodic: std::array::from_fn(|a| self.spans_periodic(a)),
        }
    }

    /// The subdomains adjacent to `index` (a subdomain can be its own neighbour across a
    /// cut periodic axis of two), each with the shift that takes a position from `index`'s
    /// frame into the neighbour's: one entry per offset in {-1, 0, 1}^3 that stays inside
    /// bounded axes and is 0 along the periodic axes not cut (no ghosts there), except
    /// `(index, 0)`. Fixed order (z, y, x offsets increasing).
    /// Checks that a particle touches a partner through one periodic image at most: every
    /// periodic axis at least twice `contact` (the largest contact distance) long, as a
    /// minimum image needs. On an axis shorter than two ghost layers a
    /// subdomain then lists a partner through both images, but the farther one never comes
    /// within contact: its pair gives no force and its history stays at rest.
    pub fn check_periodic_images(&self, contact: Real) -> Result<(), String> {
        for a in 0..3 {
            let length = self.hi[a] - self.lo[a];
            if self.periodic[a] && length < 2.0 * contact {
                return Err(format!(
                    "the periodic {} axis ({length:.4e} m) is shorter than twice the contact distance ({contact:.4e} m: the largest diameter plus the contact reach); use a longer box",
                    ["x", "y", "z"][a]
                ));
            }
        }
        Ok(())
    }

    pub fn neighbours(&self, index: usize) -> Vec<(usize, Vec3)> {
        let c = self.coords(index);
        let length = self.hi - self.lo;
        let mut found = Vec::new();
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let offset = [dx, dy, dz];
                    let mut t = [0usize; 3];
                    let mut shift = Vec3::ZERO;
                    let mut inside = true;
                    for a in 0..3 {
                        let n = self.counts[a] as i64;
                        let v = c[a] as i64 + offset[a];
                        if self.spans_periodic(a) {
                            inside &= offset[a] == 0;
                            t[a] = 0;
                        } else if self.periodic[a] {
                            t[a] = v.rem_euclid(n) as usize;
                            shift[a] = -(v.div_euclid(n) as Real) * length[a];
                        } else if v < 0 || v >= n {
                            inside = false;
                        } else {
                            t[a] = v as usize;
                        }
                    }
                    let t = self.index(t);
                    if inside && !(t == index && shift == Vec3::ZERO) {
                        found.push((t, shift));
                    }
                }
            }
        }
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_spec_parses_counts_and_names_the_allowed_forms() {
        assert_eq!("2x1x1".parse(), Ok(GridSpec::Given([2, 1, 1])));
        assert_eq!("4".parse(), Ok(GridSpec::Auto(4)));
        for bad in ["", "0x1x1", "2x1", "2x1x1x1", "ax1x1", "-1"] {
            let e = bad.parse::<GridSpec>().unwrap_err();
            assert!(e.contains("NXxNYxNZ"), "{bad}: {e}");
        }
    }

    #[test]
    fn automatic_grid_cuts_across_the_longest_axes() {
        // A flat, wide box: cut across x and y, never z.
        let flat = Vec3::new(0.3, 0.3, 0.08);
        assert_eq!(choose_counts(2, flat, [false; 3]), [2, 1, 1]);
        assert_eq!(choose_counts(4, flat, [false; 3]), [2, 2, 1]);
        assert_eq!(choose_counts(1, flat, [false; 3]), [1, 1, 1]);
        // A tall column: cut across z.
        assert_eq!(
            choose_counts(4, Vec3::new(0.1, 0.1, 1.0), [false; 3]),
            [1, 1, 4]
        );
        // Brute force over all factorisations of 12 in a 1 x 2 x 3 box.
        let extent = Vec3::new(1.0, 2.0, 3.0);
        let area = |n: [usize; 3]| {
            (n[0] - 1) as Real * 6.0 + (n[1] - 1) as Real * 3.0 + (n[2] - 1) as Real * 2.0
        };
        let chosen = choose_counts(12, extent, [false; 3]);
        assert_eq!(chosen.iter().product::<usize>(), 12);
        for nx in 1..=12 {
            for ny in 1..=12 {
                for nz in 1..=12 {
                    if nx * ny * nz == 12 {
                        assert!(area(chosen) <= area([nx, ny, nz]));
                    }
                }
            }
        }
    }

    #[test]
    fn planes_split_the_particles_by_count_and_owners_cover_every_position() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::new(1.0, 1.0, 1.0),
            periodic: [true, false, false],
        };
        // Crowded at low x: equal counts need planes there, not at the box's thirds.
        let positions: Vec<Vec3> = (0..300)
            .map(|k| {
                let u = k as Real / 300.0;
                Vec3::new(u * u * u, (k % 7) as Real / 7.0, 0.5)
            })
            .collect();
        let grid = Grid::balanced([3, 1, 1], &domain, &positions);
        let mut per = vec![0; 3];
        for &p in &positions {
            per[grid.owner(p)] += 1;
        }
        assert_eq!(per, vec![100, 100, 100]);
        // Outside a bounded face: the outermost subdomain.
        assert_eq!(grid.owner(Vec3::new(0.9, -5.0, 9.0)), 2);
        let (lo, hi) = grid.bounds(0);
        assert_eq!(
            (lo.x, lo.y, hi.y),
            (0.0, Real::NEG_INFINITY, Real::INFINITY)
        );
    }

    #[test]
    fn neighbours_cross_cut_periodic_axes_and_not_uncut_ones_nor_bounded_faces() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::splat(1.0),
            periodic: [true, false, false],
        };
        // x periodic and not cut: no neighbours across it (pairs meet through images); y:
        // the other subdomain; z: none.
        let grid = Grid::balanced([1, 2, 1], &domain, &[]);
        assert_eq!(grid.neighbours(0), vec![(1, Vec3::ZERO)]);
        assert!(grid.spans_periodic(0) && !grid.spans_periodic(1));
        // x periodic and cut in two: the other subdomain on both sides, through an image on
        // one of them.
        let cut = Grid::balanced([2, 1, 1], &domain, &[]);
        let n = cut.neighbours(0);
        assert_eq!(n.len(), 2);
        assert!(n.contains(&(1, Vec3::ZERO)));
        assert!(n.contains(&(1, Vec3::new(1.0, 0.0, 0.0))));
    }

    #[test]
    fn too_thin_subdomains_and_short_periodic_axes_are_refused() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::splat(1.0),
            periodic: [false, true, false],
        };
        let grid = Grid::balanced([3, 1, 1], &domain, &[]);
        assert!(grid.check_width(0.3).is_ok());
        assert!(grid
            .check_width(0.34)
            .unwrap_err()
            .contains("subdomain 2 along x"));
        // An uncut periodic axis has no ghost layer; it needs two contact distances.
        let one = Grid::balanced([1, 1, 1], &domain, &[]);
        assert!(one.check_width(1.1).is_ok());
        assert!(one.check_periodic_images(0.5).is_ok());
        let e = one.check_periodic_images(0.55).unwrap_err();
        assert!(
            e.contains("periodic y") && e.contains("contact distance"),
            "{e}"
        );
    }
}
