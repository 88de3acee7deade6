//! Porosity of a sphere packing inside an axis-aligned measurement region.
//!
//! Porosity = 1 - (solid volume inside the region) / (region volume), as in the packing case
//! (paper B, sec. 3: void volume over the volume of the region holding the particles).
//!
//! **Overlaps.** Spheres are counted as if they did not overlap: the lens shared by two spheres
//! is counted twice. For equal spheres of radius `r` overlapping by `delta` the lens is
//! `pi delta^2 (3 r - delta/2) / 6 ~ (3/8) (delta/r)^2` sphere volumes, second order in the
//! overlap; with `Z` contacts per sphere the solid volume is over-counted by about
//! `(3 Z / 16) (delta/r)^2` of itself, e.g. 1.1e-4 for `Z = 6`, `delta/d = 0.5%` (porosity low by
//! under 1e-4). The test `overlap_error_is_second_order` pins this.

use crate::math::{Real, Vec3};
use crate::scene::BedRegionRule;
use std::f64::consts::PI;
use std::fmt;

/// Axis-aligned box `[lo, hi]`. On a periodic axis the box is exactly one period: a sphere
/// (its centre anywhere, any image) that crosses a face counts on the other side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasurementRegion {
    pub lo: Vec3,
    pub hi: Vec3,
    pub periodic: [bool; 3],
}

impl MeasurementRegion {
    /// Volume of the box.
    pub fn volume(&self) -> Real {
        let e = self.hi - self.lo;
        e.x * e.y * e.z
    }
}

/// Result of a porosity measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Porosity {
    /// Void fraction, `1 - solid_volume / region_volume`.
    pub porosity: Real,
    /// Sphere volume inside the region (overlaps counted twice).
    pub solid_volume: Real,
    pub region_volume: Real,
}

/// Errors of the porosity measurement.
#[derive(Clone, Debug, PartialEq)]
pub enum PorosityError {
    /// `centres` and `radii` have different lengths.
    LengthMismatch { centres: usize, radii: usize },
    /// `hi <= lo` on some axis (or not finite).
    EmptyRegion { lo: Vec3, hi: Vec3 },
    /// The z-slab method needs every sphere inside the region laterally on non-periodic axes.
    SphereCutByLateralFace { particle: usize, axis: usize },
    /// The bed is too thin (or too few particles) for the margins of the rule.
    BedTooThin { bottom: Real, top: Real },
    /// A rule parameter is out of range.
    InvalidRule { reason: &'static str },
}

impl fmt::Display for PorosityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::LengthMismatch { centres, radii } => {
                write!(f, "{centres} centres but {radii} radii")
            }
            Self::EmptyRegion { lo, hi } => {
                write!(f, "measurement region is empty: lo {lo} must be below hi {hi} on every axis")
            }
            Self::SphereCutByLateralFace { particle, axis } => write!(
                f,
                "particle {particle} is cut by a non-periodic face on axis {axis}; the z-slab \
                 method needs periodic x and y or spheres inside laterally (use porosity_voxel)"
            ),
            Self::BedTooThin { bottom, top } => write!(
                f,
                "bed too thin for the margins: measurement region would span z = {bottom} .. {top}; \
                 reduce the margins or pack more particles"
            ),
            Self::InvalidRule { reason } => write!(f, "invalid region rule: {reason}"),
        }
    }
}

impl std::error::Error for PorosityError {}

/// Exact volume of the part of a sphere (centre height `centre_z`, radius `radius`) between the
/// planes `z = z_lo` and `z = z_hi`: a difference of two spherical caps.
pub fn sphere_slab_volume(centre_z: Real, radius: Real, z_lo: Real, z_hi: Real) -> Real {
    // Volume of the sphere below height t (relative to the centre), t clamped to [-r, r].
    let below = |t: Real| {
        let t = t.clamp(-radius, radius);
        PI * (radius + t) * (radius + t) * (2.0 * radius - t) / 3.0
    };
    (below(z_hi - centre_z) - below(z_lo - centre_z)).max(0.0)
}

fn check_inputs(
    region: &MeasurementRegion,
    centres: &[Vec3],
    radii: &[Real],
) -> Result<(), PorosityError> {
    if centres.len() != radii.len() {
        return Err(PorosityError::LengthMismatch {
            centres: centres.len(),
            radii: radii.len(),
        });
    }
    let e = region.hi - region.lo;
    if !(e.x > 0.0 && e.y > 0.0 && e.z > 0.0 && e.is_finite()) {
        return Err(PorosityError::EmptyRegion {
            lo: region.lo,
            hi: region.hi,
        });
    }
    Ok(())
}

/// Exact porosity when the region is bounded only in z: the sphere volumes are clipped by the
/// planes `z = lo.z`, `z = hi.z` (spherical caps, [`sphere_slab_volume`]).
///
/// Exact when x and y are periodic (the packing case: lateral period 10 d, the region spanning
/// it) or when, on a non-periodic lateral axis, every sphere reaching into the slab lies inside
/// `[lo, hi]` on that axis. A sphere may poke through such a face by up to 1% of its radius (a
/// DEM wall overlap; its cap is then counted inside, a second-order error); beyond that the
/// result would not be exact and [`PorosityError::SphereCutByLateralFace`] is returned. If z is
/// periodic too, every sphere counts whole. For a general box use [`porosity_voxel`].
pub fn porosity_z_slab(
    region: &MeasurementRegion,
    centres: &[Vec3],
    radii: &[Real],
) -> Result<Porosity, PorosityError> {
    check_inputs(region, centres, radii)?;
    let mut solid = 0.0;
    for (i, (c, &r)) in centres.iter().zip(radii).enumerate() {
        let v = if region.periodic[2] {
            4.0 / 3.0 * PI * r * r * r
        } else {
            sphere_slab_volume(c.z, r, region.lo.z, region.hi.z)
        };
        if v <= 0.0 {
            continue;
        }
        for axis in 0..2 {
            let tolerance = 0.01 * r;
            if !region.periodic[axis]
                && (c[axis] - r < region.lo[axis] - tolerance
                    || c[axis] + r > region.hi[axis] + tolerance)
            {
                return Err(PorosityError::SphereCutByLateralFace { particle: i, axis });
            }
        }
        solid += v;
    }
    let region_volume = region.volume();
    Ok(Porosity {
        porosity: 1.0 - solid / region_volume,
        solid_volume: solid,
        region_volume,
    })
}

/// Porosity of any box by sampling: the region is cut into about `(L / voxel_size)^3` cells
/// (cell edges adjusted per axis to divide the box) and a cell counts as solid if its centre is
/// in some sphere. Periodic axes wrap; other faces clip. Error about `voxel_size / d` of the
/// solid fraction for a single sphere, much less for many (errors of opposite sign cancel).
pub fn porosity_voxel(
    region: &MeasurementRegion,
    centres: &[Vec3],
    radii: &[Real],
    voxel_size: Real,
) -> Result<Porosity, PorosityError> {
    check_inputs(region, centres, radii)?;
    if !(voxel_size > 0.0 && voxel_size.is_finite()) {
        return Err(PorosityError::InvalidRule {
            reason: "voxel size must be positive",
        });
    }
    let extent = region.hi - region.lo;
    let dims: [i64; 3] = std::array::from_fn(|a| (extent[a] / voxel_size).ceil().max(1.0) as i64);
    let h: [Real; 3] = std::array::from_fn(|a| extent[a] / dims[a] as Real);
    let mut solid = vec![false; (dims[0] * dims[1] * dims[2]) as usize];
    for (c, &r) in centres.iter().zip(radii) {
        let u: [Real; 3] = std::array::from_fn(|a| (c[a] - region.lo[a]) / h[a]);
        let range: [(i64, i64); 3] = std::array::from_fn(|a| {
            let lo = ((c[a] - r - region.lo[a]) / h[a] - 0.5).ceil() as i64;
            let hi = ((c[a] + r - region.lo[a]) / h[a] - 0.5).floor() as i64;
            if region.periodic[a] {
                (lo, hi)
            } else {
                (lo.max(0), hi.min(dims[a] - 1))
            }
        });
        for k in range[2].0..=range[2].1 {
            let dz = (k as Real + 0.5 - u[2]) * h[2];
            for j in range[1].0..=range[1].1 {
                let dy = (j as Real + 0.5 - u[1]) * h[1];
                let rem = r * r - dz * dz - dy * dy;
                if rem < 0.0 {
                    continue;
                }
                let row = dims[0] * (j.rem_euclid(dims[1]) + dims[1] * k.rem_euclid(dims[2]));
                for i in range[0].0..=range[0].1 {
                    let dx = (i as Real + 0.5 - u[0]) * h[0];
                    if dx * dx <= rem {
                        solid[(row + i.rem_euclid(dims[0])) as usize] = true;
                    }
                }
            }
        }
    }
    let fraction = solid.iter().filter(|&&s| s).count() as Real / solid.len() as Real;
    let region_volume = region.volume();
    Ok(Porosity {
        porosity: 1.0 - fraction,
        solid_volume: fraction * region_volume,
        region_volume,
    })
}

/// Measurement region of a bed by `rule`: lateral extent `[lateral_lo, lateral_hi]` (x, y,
/// periodic), z from the rule. Errors if the result is thinner than one diameter.
pub fn bed_measurement_region(
    centres: &[Vec3],
    radii: &[Real],
    lateral_lo: [Real; 2],
    lateral_hi: [Real; 2],
    floor_z: Real,
    rule: &BedRegionRule,
) -> Result<MeasurementRegion, PorosityError> {
    if centres.len() != radii.len() {
        return Err(PorosityError::LengthMismatch {
            centres: centres.len(),
            radii: radii.len(),
        });
    }
    if !(rule.top_quantile > 0.0 && rule.top_quantile <= 1.0) {
        return Err(PorosityError::InvalidRule {
            reason: "top_quantile must be in (0, 1]",
        });
    }
    if !(rule.floor_margin >= 0.0 && rule.top_margin >= 0.0) {
        return Err(PorosityError::InvalidRule {
            reason: "margins must be non-negative",
        });
    }
    if centres.is_empty() {
        return Err(PorosityError::BedTooThin {
            bottom: floor_z,
            top: floor_z,
        });
    }
    let d = 2.0 * radii.iter().sum::<Real>() / radii.len() as Real;
    let mut z: Vec<Real> = centres.iter().map(|c| c.z).collect();
    z.sort_by(Real::total_cmp);
    let rank = ((rule.top_quantile * z.len() as Real).ceil() as usize).clamp(1, z.len());
    let bed_height = z[rank - 1];
    let bottom = floor_z + rule.floor_margin * d;
    let top = bed_height - rule.top_margin * d;
    if top - bottom < d {
        return Err(PorosityError::BedTooThin { bottom, top });
    }
    Ok(MeasurementRegion {
        lo: Vec3::new(lateral_lo[0], lateral_lo[1], bottom),
        hi: Vec3::new(lateral_hi[0], lateral_hi[1], top),
        periodic: [true, true, false],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Simple cubic lattice of touching spheres (d = 1), n x n laterally, layers k_lo..=k_hi.
    fn simple_cubic(n: usize, k_lo: i64, k_hi: i64, shift: Vec3) -> (Vec<Vec3>, Vec<Real>) {
        let mut c = Vec::new();
        for k in k_lo..=k_hi {
            for j in 0..n {
                for i in 0..n {
                    c.push(Vec3::new(i as Real, j as Real, k as Real) + shift);
                }
            }
        }
        let r = vec![0.5; c.len()];
        (c, r)
    }

    #[test]
    fn slab_volume_of_caps() {
        let full = 4.0 / 3.0 * PI;
        assert!((sphere_slab_volume(0.0, 1.0, -5.0, 5.0) - full).abs() < 1e-14);
        assert!((sphere_slab_volume(0.0, 1.0, 0.0, 5.0) - full / 2.0).abs() < 1e-14);
        assert_eq!(sphere_slab_volume(0.0, 1.0, 2.0, 5.0), 0.0);
        // Cap of height 0.3: pi h^2 (3 r - h) / 3.
        let cap = PI * 0.09 * (3.0 - 0.3) / 3.0;
        assert!((sphere_slab_volume(0.0, 1.0, 0.7, 9.0) - cap).abs() < 1e-14);
        // Midpoint-rule integral of the disc area over a thin slab.
        let (lo, hi, m) = (-0.37, 0.81, 100_000);
        let dz = (hi - lo) / m as Real;
        let num: Real = (0..m)
            .map(|i| {
                let z: Real = lo + (i as Real + 0.5) * dz;
                PI * (1.0 - z * z) * dz
            })
            .sum();
        assert!((sphere_slab_volume(0.0, 1.0, lo, hi) - num).abs() < 1e-9);
    }

    #[test]
    fn simple_cubic_lattice_porosity_is_one_minus_pi_over_six() {
        let expected = 1.0 - PI / 6.0;
        // Spheres cross the periodic x and y faces (centres on them) and the z planes.
        for (shift, z_lo, layers) in [
            (Vec3::ZERO, 0.3, 3.0),
            (Vec3::new(0.25, 0.5, 0.1), 0.37, 4.0),
            (Vec3::new(-0.4, 3.9, 0.0), 1.0, 2.0),
        ] {
            let (c, r) = simple_cubic(4, -2, 8, shift);
            let region = MeasurementRegion {
                lo: Vec3::new(0.0, 0.0, z_lo),
                hi: Vec3::new(4.0, 4.0, z_lo + layers),
                periodic: [true, true, false],
            };
            let p = porosity_z_slab(&region, &c, &r).unwrap();
            assert!((p.porosity - expected).abs() < 1e-9, "{p:?}");
        }
    }

    #[test]
    fn voxel_porosity_agrees_with_exact() {
        let (c, r) = simple_cubic(4, -2, 8, Vec3::new(0.13, 0.71, 0.05));
        let region = MeasurementRegion {
            lo: Vec3::new(0.0, 0.0, 0.3),
            hi: Vec3::new(4.0, 4.0, 3.3),
            periodic: [true, true, false],
        };
        let exact = porosity_z_slab(&region, &c, &r).unwrap().porosity;
        // Voxels commensurate with the lattice: every sphere has the same sampling error.
        let voxel = porosity_voxel(&region, &c, &r, 0.02).unwrap().porosity;
        assert!((exact - voxel).abs() < 3e-3, "exact {exact} voxel {voxel}");
    }

    #[test]
    fn sphere_cut_by_non_periodic_lateral_face_is_an_error() {
        let region = MeasurementRegion {
            lo: Vec3::ZERO,
            hi: Vec3::splat(4.0),
            periodic: [false, true, false],
        };
        let err = porosity_z_slab(&region, &[Vec3::new(0.2, 2.0, 2.0)], &[0.5]).unwrap_err();
        assert_eq!(
            err,
            PorosityError::SphereCutByLateralFace {
                particle: 0,
                axis: 0
            }
        );
        // Inside laterally: fine, and exact.
        let p = porosity_z_slab(&region, &[Vec3::new(1.0, 2.0, 2.0)], &[0.5]).unwrap();
        assert!((p.solid_volume - PI / 6.0).abs() < 1e-14);
    }

    #[test]
    fn overlap_error_is_second_order() {
        let r = 0.5;
        let region = MeasurementRegion {
            lo: Vec3::ZERO,
            hi: Vec3::splat(4.0),
            periodic: [true, true, false],
        };
        // Exact union volume of two equal spheres at distance s: 2 V - lens.
        let error = |delta: Real| {
            let c = [Vec3::splat(2.0), Vec3::new(2.0 + 2.0 * r - delta, 2.0, 2.0)];
            let p = porosity_z_slab(&region, &c, &[r, r]).unwrap();
            let cap_h = delta / 2.0;
            let lens = 2.0 * PI * cap_h * cap_h * (3.0 * r - cap_h) / 3.0;
            let exact = 1.0 - (2.0 * 4.0 / 3.0 * PI * r.powi(3) - lens) / region.volume();
            exact - p.porosity
        };
        let (e1, e2) = (error(0.01), error(0.005));
        assert!(e1 > 0.0 && e2 > 0.0);
        let order = (e1 / e2).log2();
        assert!((order - 2.0).abs() < 0.01, "order {order}");
        // Relative to one sphere volume: (3/8) (delta/r)^2.
        let rel = e1 * region.volume() / (4.0 / 3.0 * PI * r.powi(3));
        assert!((rel / (0.375 * (0.01 / r).powi(2)) - 1.0).abs() < 0.01);
    }

    #[test]
    fn bed_region_rule_excludes_floor_and_top() {
        // Layers at z = 0.5 .. 19.5 (d = 1) over a floor at z = 0.
        let (c, r) = simple_cubic(10, 0, 19, Vec3::new(0.0, 0.0, 0.5));
        let rule = BedRegionRule::default();
        let region = bed_measurement_region(&c, &r, [0.0; 2], [10.0; 2], 0.0, &rule).unwrap();
        assert_eq!(region.lo.z, 2.0);
        assert_eq!(region.hi.z, 19.5 - 2.0);
        // One particle far above the bed does not move the top.
        let mut c2 = c.clone();
        c2.push(Vec3::new(5.0, 5.0, 60.0));
        let mut r2 = r.clone();
        r2.push(0.5);
        let region2 = bed_measurement_region(&c2, &r2, [0.0; 2], [10.0; 2], 0.0, &rule).unwrap();
        assert_eq!(region2.hi.z, region.hi.z);
        let thin = simple_cubic(10, 0, 3, Vec3::new(0.0, 0.0, 0.5));
        assert!(matches!(
            bed_measurement_region(&thin.0, &thin.1, [0.0; 2], [10.0; 2], 0.0, &rule),
            Err(PorosityError::BedTooThin { .. })
        ));
    }
}
