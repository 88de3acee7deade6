//! Van der Waals attraction between two spheres (Hamaker), paper B Eq. (7)-(8):
//! `F = (H_a/6) 64 R_i^3 R_j^3 (h + R_i + R_j) /
//!      [(h^2 + 2 R_i h + 2 R_j h)^2 (h^2 + 2 R_i h + 2 R_j h + 4 R_i R_j)^2]`,
//! `h = max(gap, h_min)`: the force saturates at `h_min` (touching or overlapping pairs feel
//! `F(h_min)`). It is cut off at `reach` beyond touching, where it has fallen to a stated
//! fraction of `F(h_min)` (or at an explicit distance from the scene).

use super::super::{CohesionModel, Contact};
use crate::math::Real;

/// Paper B Eq. (7): attraction magnitude at surface gap `h` (> 0).
pub fn vdw_force(hamaker: Real, r_i: Real, r_j: Real, h: Real) -> Real {
    let a = h * h + 2.0 * r_i * h + 2.0 * r_j * h;
    let b = a + 4.0 * r_i * r_j;
    hamaker / 6.0 * 64.0 * r_i.powi(3) * r_j.powi(3) * (h + r_i + r_j) / (a * a * b * b)
}

/// The gap beyond which `vdw_force` is below `fraction` of its value at `h_min`.
pub fn vdw_reach(r_i: Real, r_j: Real, h_min: Real, fraction: Real) -> Real {
    let target = fraction * vdw_force(1.0, r_i, r_j, h_min);
    let (mut lo, mut hi) = (h_min, h_min);
    while vdw_force(1.0, r_i, r_j, hi) > target {
        hi *= 2.0;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if vdw_force(1.0, r_i, r_j, mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

#[derive(Clone, Debug)]
pub struct VanDerWaals {
    /// `H_a` (J) per species pair.
    pub hamaker_constant: Vec<Real>,
    /// Saturation gap, m.
    pub h_min: Real,
    /// Cut-off gap beyond touching, m.
    pub reach: Real,
}

impl CohesionModel for VanDerWaals {
    fn reach(&self) -> Real {
        self.reach
    }

    #[inline(always)]
    fn force(&self, contact: &Contact) -> Real {
        let h = (-contact.overlap).max(self.h_min);
        vdw_force(
            self.hamaker_constant[contact.species_pair],
            contact.radius_i,
            contact.radius_j,
            h,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vdw_force_matches_eq7_and_the_near_field_limit_at_three_gaps() {
        // Equal spheres: Eq. (7) tends to H R_eff / (6 h^2) (Derjaguin) for h << R.
        let (h_a, r) = (6.5e-20, 25e-6);
        for (h, tol) in [(4e-10, 1e-4), (4e-9, 1e-3), (4e-8, 1e-2)] {
            let f = vdw_force(h_a, r, r, h);
            // Eq. (7) written out independently for R_i = R_j = R.
            let a = h * h + 4.0 * r * h;
            let exact =
                h_a / 6.0 * 64.0 * r.powi(6) * (h + 2.0 * r) / (a * a * (a + 4.0 * r * r).powi(2));
            assert!((f - exact).abs() < 1e-12 * exact);
            let derjaguin = h_a * 0.5 * r / (6.0 * h * h);
            assert!(
                (f / derjaguin - 1.0).abs() < tol,
                "h = {h}: {f} vs {derjaguin}"
            );
        }
    }

    #[test]
    fn reach_is_where_the_force_falls_to_the_stated_fraction() {
        let (r, h_min) = (25e-6, 4e-10);
        let reach = vdw_reach(r, r, h_min, 1e-3);
        let ratio = vdw_force(1.0, r, r, reach) / vdw_force(1.0, r, r, h_min);
        assert!((ratio / 1e-3 - 1.0).abs() < 1e-6);
        // Near field ~ 1/h^2: about sqrt(1000) h_min.
        assert!(
            (reach / (1000f64.sqrt() * h_min) - 1.0).abs() < 0.01,
            "{reach}"
        );
    }
}
