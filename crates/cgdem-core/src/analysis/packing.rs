//! The packed bed of paper B sec. 3: porosity in a region that leaves out the floor layers and
//! the loose top ([`bed_measurement_region`]), and the Gelb-Gubbins pore-size distribution in
//! the same region ([`pore_size_field_of_spheres`]).
//!
//! The pore-size grid spans the lateral period (periodic) and, in z, the measurement region
//! grown by two diameters each way (clipped to the floor and the highest sphere top), so the
//! balls that cover voxels near the region's faces see the solid beyond them. Beyond the grid
//! in z nothing is assumed (`Boundary::Open`); only voxels inside the region are counted.

use serde::Serialize;

use super::pore_size::{pore_size_field_of_spheres, Boundary, PoreSizeDistribution, VoxelGrid};
use super::porosity::{bed_measurement_region, porosity_z_slab};
use crate::math::{Real, Vec3};
use crate::scene::BedRegionRule;

/// What was measured, for `summary.json`.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct PackingSummary {
    pub diameter_m: Real,
    pub porosity: Real,
    /// Measurement region in z, m.
    pub region_z_m: [Real; 2],
    /// Its height, in diameters.
    pub region_height_diameters: Real,
    /// The bed height by the rule's quantile (centre height), in diameters above the floor.
    pub bed_height_diameters: Real,
    pub solid_volume_m3: Real,
    pub region_volume_m3: Real,
    pub rule: String,
    pub pore_voxel_m: Real,
    /// Volume-weighted mean and median pore diameter in the region, m.
    pub mean_pore_diameter_m: Real,
    pub median_pore_diameter_m: Real,
    /// Pore diameter of the fullest histogram bin (its centre), m.
    pub modal_pore_diameter_m: Real,
}

/// The measurement of one bed: summary and histogram.
#[derive(Clone, Debug)]
pub struct PackingMeasurement {
    pub summary: PackingSummary,
    pub pore_sizes: PoreSizeDistribution,
}

/// Porosity and pore sizes of a monodisperse bed of spheres (`diameter`) on a floor at
/// `floor_z`, periodic in x and y over `[lateral_lo, lateral_hi]`.
#[allow(clippy::too_many_arguments)]
pub fn measure_packing(
    centres: &[Vec3],
    radii: &[Real],
    lateral_lo: [Real; 2],
    lateral_hi: [Real; 2],
    floor_z: Real,
    rule: &BedRegionRule,
    voxels_per_diameter: u32,
    bin_width_diameters: Real,
) -> Result<PackingMeasurement, String> {
    let region = bed_measurement_region(centres, radii, lateral_lo, lateral_hi, floor_z, rule)
        .map_err(|e| e.to_string())?;
    let porosity = porosity_z_slab(&region, centres, radii).map_err(|e| e.to_string())?;
    let d = 2.0 * radii.iter().sum::<Real>() / radii.len() as Real;
    let top = centres
        .iter()
        .zip(radii)
        .map(|(c, r)| c.z + r)
        .fold(Real::NEG_INFINITY, Real::max);
    let h = d / voxels_per_diameter as Real;
    let lo = Vec3::new(
        lateral_lo[0],
        lateral_lo[1],
        (region.lo.z - 2.0 * d).max(floor_z),
    );
    let hi = Vec3::new(
        lateral_hi[0],
        lateral_hi[1],
        (region.hi.z + 2.0 * d).min(top),
    );
    let grid = VoxelGrid::covering(
        lo,
        hi,
        h,
        [Boundary::Periodic, Boundary::Periodic, Boundary::Open],
    )
    .map_err(|e| e.to_string())?;
    let field = pore_size_field_of_spheres(&grid, centres, radii).map_err(|e| e.to_string())?;
    let pore_sizes = field.distribution(bin_width_diameters * d, Some((region.lo.z, region.hi.z)));
    let edges = &pore_sizes.bin_edges;
    let median = pore_sizes
        .cumulative
        .iter()
        .position(|&c| c >= 0.5)
        .map_or(Real::NAN, |k| edges[k + 1]);
    let modal = pore_sizes
        .fraction
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(Real::NAN, |(k, _)| 0.5 * (edges[k] + edges[k + 1]));
    let mut z: Vec<Real> = centres.iter().map(|c| c.z).collect();
    z.sort_by(Real::total_cmp);
    let rank = ((rule.top_quantile * z.len() as Real).ceil() as usize).clamp(1, z.len());
    Ok(PackingMeasurement {
        summary: PackingSummary {
            diameter_m: d,
            porosity: porosity.porosity,
            region_z_m: [region.lo.z, region.hi.z],
            region_height_diameters: (region.hi.z - region.lo.z) / d,
            bed_height_diameters: (z[rank - 1] - floor_z) / d,
            solid_volume_m3: porosity.solid_volume,
            region_volume_m3: porosity.region_volume,
            rule: describe_rule(rule),
            pore_voxel_m: h,
            mean_pore_diameter_m: pore_sizes.mean_diameter,
            median_pore_diameter_m: median,
            modal_pore_diameter_m: modal,
        },
        pore_sizes,
    })
}

/// The region rule in words, for the summary.
pub fn describe_rule(rule: &BedRegionRule) -> String {
    format!(
        "porosity = 1 - (sphere volume inside the region, spherical caps cut exactly at its z faces) / (region volume); region: the whole lateral period, from {} d above the floor to {} d below the bed height, the bed height being the {} quantile of the particle-centre heights; pore sizes (Gelb & Gubbins) of the void voxels in the same region",
        rule.floor_margin, rule.top_margin, rule.top_quantile
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Simple cubic lattice of touching spheres (d = 1) on a floor at z = 0, 10 x 10 x layers.
    fn simple_cubic(layers: usize) -> (Vec<Vec3>, Vec<Real>) {
        let mut c = Vec::new();
        for k in 0..layers {
            for j in 0..10 {
                for i in 0..10 {
                    c.push(Vec3::new(i as Real + 0.5, j as Real + 0.5, k as Real + 0.5));
                }
            }
        }
        let r = vec![0.5; c.len()];
        (c, r)
    }

    #[test]
    fn simple_cubic_bed_has_its_porosity_and_pores_in_the_rule_region() {
        let (c, r) = simple_cubic(12);
        let m = measure_packing(
            &c,
            &r,
            [0.0; 2],
            [10.0; 2],
            0.0,
            &BedRegionRule::default(),
            10,
            0.1,
        )
        .unwrap();
        let s = &m.summary;
        // Bed height = top centre 11.5; region 2 .. 9.5.
        assert_eq!(s.region_z_m, [2.0, 9.5]);
        assert!((s.bed_height_diameters - 11.5).abs() < 1e-12);
        assert!(
            (s.porosity - (1.0 - PI / 6.0)).abs() < 1e-9,
            "{}",
            s.porosity
        );
        // The largest empty ball of a simple cubic lattice sits at the cube centre, diameter
        // (sqrt(3) - 1) d = 0.732 d; every pore voxel sees at most that (plus the voxel bias).
        let total: Real = m.pore_sizes.fraction.iter().sum();
        assert!((total - 1.0).abs() < 1e-9);
        assert!(s.modal_pore_diameter_m > 0.5 && s.modal_pore_diameter_m < 0.85);
        let beyond: Real = m
            .pore_sizes
            .fraction
            .iter()
            .zip(m.pore_sizes.bin_edges.windows(2))
            .filter(|(_, e)| e[0] >= 0.732 + 0.1 + 1e-9)
            .map(|(f, _)| f)
            .sum();
        assert_eq!(beyond, 0.0);
    }

    #[test]
    fn a_bed_too_thin_for_the_margins_is_an_error_naming_the_region() {
        let (c, r) = simple_cubic(4);
        let message = measure_packing(
            &c,
            &r,
            [0.0; 2],
            [10.0; 2],
            0.0,
            &BedRegionRule::default(),
            10,
            0.1,
        )
        .unwrap_err();
        assert!(message.contains("bed too thin"), "{message}");
    }
}
