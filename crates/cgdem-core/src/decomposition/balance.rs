//! Load balance (LAMMPS `fix balance Nfreq thresh shift`): at a list rebuild, before the
//! exchange, the imbalance (most particles in one subdomain over the mean, over all ranks)
//! the exchange would leave is measured; past the threshold the cut planes move so that
//! each slab along each axis holds the same number of particles, and the exchange then
//! moves the particles to their new owners with their histories.
//!
//! Here: the setting, the record of what a run saw, the imbalance measure and the ghost
//! layer's limit on how close planes may come. Finding the planes is `super::rebalance`.

use std::str::FromStr;

use super::Grid;
use crate::math::Real;

/// `--balance`: move the cut planes when the imbalance passes `threshold`, or never.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BalanceSpec {
    Off,
    Shift(Real),
}

impl Default for BalanceSpec {
    /// On with `--grid`: a split that follows the particles costs a counting pass per
    /// rebuild, a split that does not can leave one subdomain with most of the work.
    fn default() -> Self {
        BalanceSpec::Shift(1.1)
    }
}

impl BalanceSpec {
    pub fn threshold(self) -> Option<Real> {
        match self {
            BalanceSpec::Off => None,
            BalanceSpec::Shift(t) => Some(t),
        }
    }
}

impl FromStr for BalanceSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        if s.eq_ignore_ascii_case("off") {
            return Ok(BalanceSpec::Off);
        }
        match s.parse::<Real>() {
            Ok(t) if t.is_finite() && t >= 1.0 => Ok(BalanceSpec::Shift(t)),
            _ => Err(format!(
                "--balance `{s}`: expected a threshold of at least 1.0 (most particles in one subdomain over the mean, e.g. 1.1), or `off`"
            )),
        }
    }
}

impl std::fmt::Display for BalanceSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BalanceSpec::Off => write!(f, "off"),
            BalanceSpec::Shift(t) => write!(f, "{t}"),
        }
    }
}

/// The balancing of a decomposed run and what it saw.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Balance {
    /// Rebalance at a rebuild when the imbalance passes this; None: the planes stay.
    pub threshold: Option<Real>,
    /// The planes of the start (by count), for what a static split would give.
    pub start: Grid,
    /// Rebuilds at which the planes moved.
    pub shifts: u64,
    /// Largest imbalance of the owned particles after a rebuild, from the first shift on.
    pub worst_after_first_shift: Option<Real>,
    /// Largest imbalance the start's planes gave (or would have given) at a rebuild.
    pub static_worst: Real,
}

impl Balance {
    pub fn new(start: Grid, threshold: Option<Real>) -> Self {
        Balance {
            threshold,
            start,
            shifts: 0,
            worst_after_first_shift: None,
            static_worst: 0.0,
        }
    }
}

/// Most over mean (1 is perfect balance; 1 with no particles).
pub fn imbalance(counts: &[u64]) -> Real {
    let total: u64 = counts.iter().sum();
    if total == 0 {
        return 1.0;
    }
    let most = counts.iter().copied().max().unwrap_or(0);
    most as Real * counts.len() as Real / total as Real
}

/// Moves `grid`'s planes as little as needed for every subdomain that has neighbours on
/// both sides along an axis (all of them on a periodic axis) to be at least `width` thick
/// (`Grid::check_width`), and every plane to stay inside the box: a pass up the axis pushes
/// planes up, a pass down pulls them back. Planes balanced by count crowd where the
/// particles crowd; the ghost layer must come from adjacent subdomains only, so the balance
/// there is given up rather than that.
pub fn clamp_to_width(grid: &mut Grid, width: Real) {
    // A hair more than the width, so that rounding in the sums does not undo it.
    let width = width * (1.0 + 1e-9);
    for a in 0..3 {
        let n = grid.counts[a];
        if n < 2 {
            continue;
        }
        let need = |slab: usize| {
            if grid.periodic[a] || (slab > 0 && slab + 1 < n) {
                width
            } else {
                0.0
            }
        };
        let needs: Vec<Real> = (0..n).map(need).collect();
        let mut p = Vec::with_capacity(n + 1);
        p.push(grid.lo[a]);
        p.extend_from_slice(&grid.planes[a]);
        p.push(grid.hi[a]);
        for s in 1..n {
            p[s] = p[s].max(p[s - 1] + needs[s - 1]);
        }
        for s in (1..n).rev() {
            p[s] = p[s].min(p[s + 1] - needs[s]);
        }
        grid.planes[a] = p[1..n].to_vec();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Domain;
    use crate::math::Vec3;

    #[test]
    fn the_clamp_works_on_periodic_axes_and_leaves_thick_slabs_alone() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::splat(1.0),
            periodic: [true, false, false],
        };
        let mut grid = Grid::balanced([4, 1, 1], &domain, &[]);
        grid.planes[0] = vec![0.01, 0.02, 0.99];
        clamp_to_width(&mut grid, 0.2);
        assert!(grid.check_width(0.2).is_ok(), "{:?}", grid.planes[0]);
        let thick = vec![0.25, 0.5, 0.75];
        grid.planes[0] = thick.clone();
        clamp_to_width(&mut grid, 0.2);
        assert_eq!(grid.planes[0], thick);
    }

    #[test]
    fn balance_values_are_checked() {
        assert_eq!("1.25".parse(), Ok(BalanceSpec::Shift(1.25)));
        assert_eq!("1".parse(), Ok(BalanceSpec::Shift(1.0)));
        assert_eq!("off".parse(), Ok(BalanceSpec::Off));
        for bad in ["0.9", "-1", "inf", "NaN", "", "x"] {
            let e = bad.parse::<BalanceSpec>().unwrap_err();
            assert!(e.contains("at least 1.0"), "{bad}: {e}");
        }
        assert_eq!(imbalance(&[3, 1]), 1.5);
        assert_eq!(imbalance(&[0, 0]), 1.0);
    }
}
