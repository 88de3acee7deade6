//! A heap poured or collapsed about a vertical axis: its height and the slope of its flank,
//! from the particles alone (the same function for cgdem's state and the reference codes'
//! dumps).
//!
//! The surface is the highest particle top (`z + r`) in rings of equal width about the axis.
//! The height is the surface in the central ring above the floor; the heap's edge is the
//! outermost ring whose surface stands at least two diameters above the floor; the slope is
//! the least-squares line through the ring surfaces between 20% and 80% of the edge radius
//! (the rounded top and the toe excluded, as for the repose angle of the collapse).

use crate::math::{Real, Vec3};

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ConicalHeap {
    /// Surface height at the axis above the floor, m.
    pub height_m: Real,
    /// Radius of the outermost ring at least two diameters high, m.
    pub edge_radius_m: Real,
    /// Angle of the fitted flank, degrees.
    pub slope_deg: Real,
    /// Rings in the fit.
    pub fit_rings: usize,
}

/// The heap of the particles for which `counted` is true (e.g. not frozen), about the
/// vertical axis through `axis`, standing on the floor at height `floor_z`, measured in rings
/// `ring_width` wide. None when there are too few rings for a fit.
pub fn conical_heap(
    positions: &[Vec3],
    radii: &[Real],
    counted: impl Fn(usize) -> bool,
    axis: Vec3,
    floor_z: Real,
    ring_width: Real,
) -> Option<ConicalHeap> {
    let mut surface: Vec<Real> = Vec::new();
    let mut max_diameter: Real = 0.0;
    for (k, (p, &r)) in positions.iter().zip(radii).enumerate() {
        if !counted(k) {
            continue;
        }
        max_diameter = max_diameter.max(2.0 * r);
        let ring = ((p.x - axis.x).hypot(p.y - axis.y) / ring_width) as usize;
        if ring >= surface.len() {
            surface.resize(ring + 1, floor_z);
        }
        surface[ring] = surface[ring].max(p.z + r);
    }
    let height_m = surface.first()? - floor_z;
    let edge = surface
        .iter()
        .rposition(|&top| top - floor_z >= 2.0 * max_diameter)?;
    let edge_radius_m = (edge as Real + 1.0) * ring_width;
    let (lo, hi) = (0.2 * edge_radius_m, 0.8 * edge_radius_m);
    let points: Vec<(Real, Real)> = surface
        .iter()
        .enumerate()
        .map(|(ring, &top)| ((ring as Real + 0.5) * ring_width, top))
        .filter(|&(r, _)| r >= lo && r <= hi)
        .collect();
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as Real;
    let (mean_r, mean_z) = (
        points.iter().map(|p| p.0).sum::<Real>() / n,
        points.iter().map(|p| p.1).sum::<Real>() / n,
    );
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for &(r, z) in &points {
        sxy += (r - mean_r) * (z - mean_z);
        sxx += (r - mean_r) * (r - mean_r);
    }
    Some(ConicalHeap {
        height_m,
        edge_radius_m,
        slope_deg: (-sxy / sxx).atan().to_degrees(),
        fit_rings: points.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cone_of_spheres_has_its_slope_and_height() {
        // Spheres of radius 1 mm filling a 30 degree cone of radius 50 mm, on a 2 mm grid.
        let (r, tan) = (1e-3, 30f64.to_radians().tan());
        let (mut positions, mut radii) = (Vec::new(), Vec::new());
        for i in -25..=25 {
            for j in -25..=25 {
                let (x, y) = (i as Real * 2e-3, j as Real * 2e-3);
                let top = (0.05 - x.hypot(y)) * tan;
                let mut z = r;
                while z + r <= top {
                    positions.push(Vec3::new(x, y, z));
                    radii.push(r);
                    z += 2e-3;
                }
            }
        }
        let heap = conical_heap(&positions, &radii, |_| true, Vec3::ZERO, 0.0, 2e-3).unwrap();
        assert!((heap.slope_deg - 30.0).abs() < 2.0, "{heap:?}");
        assert!((heap.height_m - 0.05 * tan).abs() < 3e-3, "{heap:?}");
        // Nothing counted: no heap.
        assert!(conical_heap(&positions, &radii, |_| false, Vec3::ZERO, 0.0, 2e-3).is_none());
    }
}
