//! Heap profile, run-out and repose angle of a collapsed column.
//!
//! **Profile.** The heap runs out along +x from the remaining wall at `wall_x`. x is cut into
//! bins one `bin_width` wide; a bin's height is the highest particle top `z + r` in it,
//! measured from the floor (0 for an empty bin). Periodic depth (y) is folded in.
//!
//! **Front (run-out).** The centre of the furthest bin whose height is at least
//! `min_depth` (two particle diameters): a lone particle rolling away does not count.
//!
//! **Repose angle.** A least-squares line through the bin heights between
//! `wall_x + exclude_wall * L` and `x_front - exclude_toe * L`, `L = x_front - wall_x`: the
//! region next to the wall (where the column may still stand) and the toe (where the
//! surface curves into the floor) are left out. The angle is `atan(-slope)`; R^2 of the fit
//! is reported beside it.

use crate::math::{Real, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct HeapProfile {
    pub wall_x: Real,
    pub bin_width: Real,
    /// Height of the free surface above the floor, per bin.
    pub heights: Vec<Real>,
}

impl HeapProfile {
    pub fn bin_centre(&self, k: usize) -> Real {
        self.wall_x + (k as Real + 0.5) * self.bin_width
    }

    /// Surface height next to the remaining wall (first bin).
    pub fn wall_height(&self) -> Real {
        self.heights.first().copied().unwrap_or(0.0)
    }

    /// Furthest bin centre with a deposit at least `min_depth` deep, or `wall_x` if none.
    pub fn front(&self, min_depth: Real) -> Real {
        self.heights
            .iter()
            .rposition(|&h| h >= min_depth)
            .map_or(self.wall_x, |k| self.bin_centre(k))
    }
}

/// Profile of the particles between `wall_x` and `x_end`, heights above `floor_z`.
pub fn profile(
    positions: &[Vec3],
    radii: &[Real],
    wall_x: Real,
    x_end: Real,
    floor_z: Real,
    bin_width: Real,
) -> HeapProfile {
    let n_bins = ((x_end - wall_x) / bin_width).ceil().max(1.0) as usize;
    let mut heights = vec![0.0; n_bins];
    for (p, &r) in positions.iter().zip(radii) {
        let k = ((p.x - wall_x) / bin_width).floor();
        if k >= 0.0 && (k as usize) < n_bins {
            let h = &mut heights[k as usize];
            *h = Real::max(*h, p.z + r - floor_z);
        }
    }
    HeapProfile {
        wall_x,
        bin_width,
        heights,
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct ReposeFit {
    pub angle_deg: Real,
    pub r_squared: Real,
    pub runout: Real,
    pub fit_from_x: Real,
    pub fit_to_x: Real,
    pub bins_used: usize,
}

/// Repose angle by the rule in the module doc; why it cannot be measured otherwise (fewer
/// than 3 bins in the window, no slope to fit, or a fit that is not a finite number).
pub fn repose_angle(
    profile: &HeapProfile,
    min_depth: Real,
    exclude_wall: Real,
    exclude_toe: Real,
) -> Result<ReposeFit, String> {
    let front = profile.front(min_depth);
    let runout = front - profile.wall_x;
    let from = profile.wall_x + exclude_wall * runout;
    let to = front - exclude_toe * runout;
    let points: Vec<(Real, Real)> = (0..profile.heights.len())
        .map(|k| (profile.bin_centre(k), profile.heights[k]))
        .filter(|&(x, _)| x >= from && x <= to)
        .collect();
    if points.len() < 3 {
        return Err(format!(
            "no heap to fit: {} profile bins between the wall and the front after the exclusions (at least 3 needed)",
            points.len()
        ));
    }
    let (slope, r_squared) =
        least_squares(&points).ok_or("the profile's bins share one x: no slope to fit")?;
    if !(slope.is_finite() && r_squared.is_finite() && runout.is_finite()) {
        return Err(format!(
            "the fit is not a finite number (slope {slope}, R^2 {r_squared}, run-out {runout} m): the heap's heights or the box overflow"
        ));
    }
    Ok(ReposeFit {
        angle_deg: (-slope).atan().to_degrees(),
        r_squared,
        runout,
        fit_from_x: from,
        fit_to_x: to,
        bins_used: points.len(),
    })
}

/// Slope and R^2 of the least-squares line through `points` (at least 3, not all at one x);
/// a line through points all at one height fits them exactly: R^2 = 1.
pub fn least_squares(points: &[(Real, Real)]) -> Option<(Real, Real)> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as Real;
    let mean_x = points.iter().map(|p| p.0).sum::<Real>() / n;
    let mean_y = points.iter().map(|p| p.1).sum::<Real>() / n;
    let sxx: Real = points.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    let sxy: Real = points.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    let syy: Real = points.iter().map(|p| (p.1 - mean_y).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let r_squared = if syy == 0.0 {
        1.0
    } else {
        sxy * sxy / (sxx * syy)
    };
    Some((slope, r_squared))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangular_heap_gives_its_angle_with_unit_r2() {
        // Spheres stacked on a 30 degree slope from x = 0 (height 0.1) down to the toe.
        let (r, slope_deg) = (0.001, 30.0f64);
        let tan = slope_deg.to_radians().tan();
        let mut positions = Vec::new();
        let mut x = 0.0005;
        while 0.1 - tan * x > 0.0 {
            positions.push(Vec3::new(x, 0.0, 0.1 - tan * x - r));
            x += 0.0005;
        }
        let radii = vec![r; positions.len()];
        let p = profile(&positions, &radii, 0.0, 0.3, 0.0, 0.002);
        let fit = repose_angle(&p, 0.004, 0.15, 0.15).unwrap();
        assert!((fit.angle_deg - 30.0).abs() < 0.5, "{fit:?}");
        assert!(fit.r_squared > 0.99);
        assert!((p.wall_height() - 0.1).abs() < 0.002);
    }
}
