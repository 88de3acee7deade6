//! Screw-conveyor measurements (paper A sec. 4 and 6, Eq. 7): mass flow through a plane
//! across the screw section (or at the outlet) with block-average standard error, fill ratio in the screw section, bulk
//! density, drive torque, and the theoretical rate `Q = a (pi/4)(Ds^2 - ds^2) ps ns rho_b`.

use serde::Serialize;

use crate::math::{Real, Vec3};
use crate::scene::ConveyingSettings;

/// Fill ratio: solid volume of the particles whose centres lie inside the bore between
/// `fill_x` (axial coordinate along the screw axis through `point`) over the swept volume
/// `(pi/4)(Ds^2 - ds^2) (x1 - x0)` of that length.
pub fn fill_ratio(
    c: &ConveyingSettings,
    axis: Vec3,
    point: Vec3,
    position: &[Vec3],
    radius: &[Real],
) -> Real {
    let mut solid = 0.0;
    for (&p, &r) in position.iter().zip(radius) {
        let v = p - point;
        let s = v.dot(axis);
        if s >= c.fill_x[0] && s < c.fill_x[1] && (v - s * axis).length() < c.bore_radius {
            solid += 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        }
    }
    solid / (swept_area(c) * (c.fill_x[1] - c.fill_x[0]))
}

/// `(pi/4)(Ds^2 - ds^2)`.
pub fn swept_area(c: &ConveyingSettings) -> Real {
    0.25 * std::f64::consts::PI * (c.outer_diameter.powi(2) - c.shaft_diameter.powi(2))
}

/// Mass that has passed the flow plane: the deleted mass plus the mass of the grains whose
/// centres lie beyond the plane `flow_x` along the axis (without a plane, the deleted mass).
/// Its slope is the flow through the plane. Counting the grains beyond the plane, rather than
/// only those deleted below the outlet, takes out the outlet's once-per-turn discharge pulse:
/// the grains between the plane and the outlet are counted as they cross the plane.
pub fn passed_mass(
    c: &ConveyingSettings,
    axis: Vec3,
    point: Vec3,
    position: &[Vec3],
    mass: &[Real],
    deleted_mass: Real,
) -> Real {
    let Some(plane) = c.flow_x else {
        return deleted_mass;
    };
    let beyond: Real = position
        .iter()
        .zip(mass)
        .filter(|(&p, _)| (p - point).dot(axis) > plane)
        .map(|(_, m)| m)
        .sum();
    deleted_mass + beyond
}

/// Where the flow is measured, in words for the summary.
pub fn flow_rule(c: &ConveyingSettings) -> String {
    match c.flow_x {
        Some(x) => format!("through the plane at {x} m along the screw axis: slope of the deleted mass plus the mass of the grains with centres beyond the plane"),
        None => "at the outlet: slope of the mass deleted below it".into(),
    }
}

/// Mass of the particles whose centres lie in the bulk box over its volume.
pub fn bulk_density(c: &ConveyingSettings, position: &[Vec3], mass: &[Real]) -> Real {
    let inside: Real = position
        .iter()
        .zip(mass)
        .filter(|(p, _)| p.cmpge(c.bulk_lo).all() && p.cmplt(c.bulk_hi).all())
        .map(|(_, m)| m)
        .sum();
    inside / (c.bulk_hi - c.bulk_lo).element_product()
}

/// One time-series sample during the conveying stage.
#[derive(Clone, Copy, Debug, Serialize, serde::Deserialize)]
pub struct ConveyingSample {
    pub time: Real,
    /// See [`passed_mass`].
    pub passed_mass: Real,
    pub fill_ratio: Real,
    pub bulk_density: Real,
}

#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct ConveyingSummary {
    pub stage: String,
    pub rpm: Real,
    pub window_s: [Real; 2],
    pub blocks: u32,
    pub block_mass_flow_kg_s: Vec<Real>,
    pub mass_flow_kg_s: Real,
    pub mass_flow_std_error_kg_s: Real,
    #[serde(default)]
    pub flow_rule: String,
    /// Solid volume in the screw section over the swept volume (mean over the window).
    pub fill_ratio: Real,
    pub fill_rule: String,
    /// Eq. (7)'s `a`: bulk volume in the section over the swept volume,
    /// `fill_ratio * rho_particle / bulk_density`.
    pub fill_ratio_bulk: Real,
    /// Bulk density at the hopper bottom at the start of the stage (the settled, full
    /// hopper; the box may drain later).
    pub bulk_density_kg_m3: Real,
    /// Mean over the window, for reference (lower if the hopper drains below the box).
    pub bulk_density_window_kg_m3: Real,
    pub bulk_rule: String,
    pub drive_torque_nm: Real,
    pub drive_power_w: Real,
    pub swept_volume_per_turn_m3: Real,
    /// Eq. (7) with the measured `a` and bulk density: `fill_ratio * V * ns * rho_particle`.
    pub eq7_mass_flow_kg_s: Real,
    /// Eq. (7) with a = 1 and the measured bulk density.
    pub eq7_full_mass_flow_kg_s: Real,
    pub ratio_to_eq7: Real,
}

/// Summarizes the samples in the window `[t0, t1]` (the stage after the discarded start-up).
#[allow(clippy::too_many_arguments)]
pub fn summarize(
    c: &ConveyingSettings,
    rpm: Real,
    particle_density: Real,
    samples: &[ConveyingSample],
    t0: Real,
    t1: Real,
    drive_torque: Real,
    drive_power: Real,
) -> Option<ConveyingSummary> {
    let window: Vec<&ConveyingSample> = samples
        .iter()
        .filter(|s| s.time >= t0 - 1e-12 && s.time <= t1 + 1e-12)
        .collect();
    let blocks = c.blocks as usize;
    if window.len() < blocks + 1 {
        return None;
    }
    // Block edges on sample indices: equal numbers of sample intervals per block.
    let intervals = window.len() - 1;
    let edges: Vec<usize> = (0..=blocks).map(|b| b * intervals / blocks).collect();
    let flows: Vec<Real> = edges
        .windows(2)
        .map(|e| {
            let (a, b) = (window[e[0]], window[e[1]]);
            (b.passed_mass - a.passed_mass) / (b.time - a.time)
        })
        .collect();
    let mean = flows.iter().sum::<Real>() / blocks as Real;
    let var = flows.iter().map(|f| (f - mean).powi(2)).sum::<Real>() / (blocks - 1) as Real;
    let n = window.len() as Real;
    let fill = window.iter().map(|s| s.fill_ratio).sum::<Real>() / n;
    let bulk_window = window.iter().map(|s| s.bulk_density).sum::<Real>() / n;
    let bulk = samples[0].bulk_density;
    let per_turn = swept_area(c) * c.pitch;
    let ns = rpm.abs() / 60.0;
    let full = per_turn * ns * bulk;
    Some(ConveyingSummary {
        stage: c.stage.clone(),
        rpm,
        window_s: [window[0].time, window[window.len() - 1].time],
        blocks: c.blocks,
        block_mass_flow_kg_s: flows,
        mass_flow_kg_s: mean,
        mass_flow_std_error_kg_s: (var / blocks as Real).sqrt(),
        flow_rule: flow_rule(c),
        fill_ratio: fill,
        fill_rule: format!(
            "solid volume of particles with centres in the bore (r < {} m) for {} <= x < {} m along the screw axis, over (pi/4)(Ds^2 - ds^2) times that length; mean of the samples in the window",
            c.bore_radius, c.fill_x[0], c.fill_x[1]
        ),
        fill_ratio_bulk: fill * particle_density / bulk,
        bulk_density_kg_m3: bulk,
        bulk_density_window_kg_m3: bulk_window,
        bulk_rule: format!(
            "mass of particles with centres in the box {:?} .. {:?} over its volume, at the first sample of the stage",
            c.bulk_lo.to_array(),
            c.bulk_hi.to_array()
        ),
        drive_torque_nm: drive_torque,
        drive_power_w: drive_power,
        swept_volume_per_turn_m3: per_turn,
        eq7_mass_flow_kg_s: fill * per_turn * ns * particle_density,
        eq7_full_mass_flow_kg_s: full,
        ratio_to_eq7: mean / (fill * per_turn * ns * particle_density),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_average_of_a_steady_flow_has_zero_error_and_eq7_uses_the_measured_fill() {
        let c = ConveyingSettings {
            stage: "convey".into(),
            body: "screw".into(),
            discard: 0.0,
            blocks: 4,
            outer_diameter: 0.205,
            shaft_diameter: 0.055,
            pitch: 0.15,
            bore_radius: 0.1148,
            fill_x: [0.0, 0.1],
            flow_x: None,
            bulk_lo: Vec3::ZERO,
            bulk_hi: Vec3::ONE,
        };
        let samples: Vec<ConveyingSample> = (0..=40)
            .map(|k| ConveyingSample {
                time: k as Real * 0.05,
                passed_mass: 2.0 * k as Real * 0.05,
                fill_ratio: 0.5,
                bulk_density: 800.0,
            })
            .collect();
        let s = summarize(&c, 60.0, 1600.0, &samples, 0.0, 2.0, 1.0, 1.0).unwrap();
        assert!((s.mass_flow_kg_s - 2.0).abs() < 1e-12);
        assert!(s.mass_flow_std_error_kg_s < 1e-12);
        // Seed: (pi/4)(Ds^2 - ds^2) ps = 4.595e-3 m^3 per turn.
        assert!((s.swept_volume_per_turn_m3 - 4.595e-3).abs() < 1e-6);
        // a = 0.5 solid fraction of the swept volume = 1.0 in bulk volume at 800 / 1600.
        assert!((s.fill_ratio_bulk - 1.0).abs() < 1e-12);
        assert!((s.eq7_mass_flow_kg_s - 0.5 * 4.595e-3 * 1600.0).abs() < 1e-2);
        assert!((s.eq7_full_mass_flow_kg_s - 4.595e-3 * 800.0).abs() < 1e-2);
    }

    #[test]
    fn passed_mass_counts_a_grain_once_whether_beyond_the_plane_or_deleted() {
        let mut c = settings_for_plane(Some(0.5));
        let axis = Vec3::X;
        let point = Vec3::new(0.1, 0.0, 0.0);
        let mass = [1.0, 2.0];
        // Grain 1 upstream, grain 2 at axial 0.45 (x = 0.55): not yet past the plane.
        let before = [Vec3::new(0.2, 0.0, 0.0), Vec3::new(0.55, 0.0, 0.0)];
        assert_eq!(passed_mass(&c, axis, point, &before, &mass, 0.0), 0.0);
        // Grain 2 crosses the plane (axial 0.7).
        let crossed = [Vec3::new(0.2, 0.0, 0.0), Vec3::new(0.8, 0.0, 0.0)];
        assert_eq!(passed_mass(&c, axis, point, &crossed, &mass, 0.0), 2.0);
        // Grain 2 is deleted below the outlet: still counted once.
        assert_eq!(
            passed_mass(&c, axis, point, &crossed[..1], &mass[..1], 2.0),
            2.0
        );
        // Without a plane only the deleted mass counts.
        c.flow_x = None;
        assert_eq!(passed_mass(&c, axis, point, &crossed, &mass, 0.5), 0.5);
    }

    fn settings_for_plane(flow_x: Option<Real>) -> ConveyingSettings {
        ConveyingSettings {
            stage: "convey".into(),
            body: "screw".into(),
            discard: 0.0,
            blocks: 2,
            outer_diameter: 0.205,
            shaft_diameter: 0.055,
            pitch: 0.15,
            bore_radius: 0.1148,
            fill_x: [0.0, 0.1],
            flow_x,
            bulk_lo: Vec3::ZERO,
            bulk_hi: Vec3::ONE,
        }
    }
}
