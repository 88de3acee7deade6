//! `cgdem run --sweep`: the chosen sweep run on a prepared scene, with the lines the command
//! prints for it.

use std::path::Path;

use super::{diameter_sweep, rpm_sweep, screw_ratio_sweep, Sweep};
use cgdem_core::math::Real;
use cgdem_core::run::{Progress, RunSummary};

/// What every run of a sweep is given (`cgdem run`'s options).
#[derive(Clone, Default)]
pub struct SweepSettings {
    pub progress: Option<Progress>,
    pub force_dt: bool,
    pub keep_going: bool,
    /// Runs whose directory already holds the same scene are not made again (the screw
    /// sweeps; `--reuse`).
    pub reuse: bool,
}

/// A finished sweep: the summary of its last run and what the command prints, one line per
/// run (and where the tables are).
#[derive(Clone, Debug)]
pub struct SweepOutcome {
    pub last: RunSummary,
    pub lines: Vec<String>,
}

impl Sweep {
    /// Runs the sweep on `scene` (coarse-grained already) into `out`.
    pub fn run(
        &self,
        scene: &cgdem_core::scene::Scene,
        out: &Path,
        settings: SweepSettings,
    ) -> Result<SweepOutcome, String> {
        let SweepSettings {
            progress,
            force_dt,
            keep_going,
            reuse,
        } = settings;
        match self {
            Sweep::Diameter(diameters) => {
                let results =
                    diameter_sweep(scene, diameters, out, progress, force_dt, keep_going)?;
                let mut lines: Vec<String> = results.iter().map(diameter_line).collect();
                lines.push(format!(
                    "porosity_vs_diameter.csv, pore_size_vs_diameter.csv and plots in {}",
                    out.display()
                ));
                finished(results, lines)
            }
            Sweep::ScrewRatio(ratios) => {
                let results =
                    screw_ratio_sweep(scene, ratios, out, progress, force_dt, keep_going, reuse)?;
                let lines = results.iter().filter_map(screw_ratio_line).collect();
                finished(results, lines)
            }
            Sweep::Rpm(speeds) => {
                let results = rpm_sweep(scene, speeds, out, progress, force_dt, keep_going, reuse)?;
                let lines = results.iter().filter_map(rpm_line).collect();
                finished(results, lines)
            }
        }
    }
}

fn finished(results: Vec<(Real, RunSummary)>, lines: Vec<String>) -> Result<SweepOutcome, String> {
    let last = results
        .into_iter()
        .last()
        .map(|r| r.1)
        .ok_or("empty sweep")?;
    Ok(SweepOutcome { last, lines })
}

fn diameter_line((d, s): &(Real, RunSummary)) -> String {
    let porosity = s
        .packing
        .as_ref()
        .map_or("not measured".into(), |p| format!("{:.4}", p.porosity));
    format!(
        "d = {:.3e} m: {} particles, {} steps of {:.3e} s, porosity {porosity}, wall {:.1} s",
        d, s.n_particles, s.steps, s.dt_s, s.wall_s
    )
}

fn screw_ratio_line((r, s): &(Real, RunSummary)) -> Option<String> {
    let c = s.conveying.as_ref()?;
    Some(format!(
        "r_s/r_p = {r}: {} screw particles, {:.4} +- {:.4} kg/s, Eq. (7) {:.4} kg/s (ratio {:.3}), wall {:.1} s",
        s.n_body_particles,
        c.mass_flow_kg_s,
        c.mass_flow_std_error_kg_s,
        c.eq7_mass_flow_kg_s,
        c.ratio_to_eq7,
        s.wall_s
    ))
}

fn rpm_line((rpm, s): &(Real, RunSummary)) -> Option<String> {
    let c = s.conveying.as_ref()?;
    Some(format!(
        "{rpm} rpm: {:.4} +- {:.4} kg/s, Eq. (7) {:.4} kg/s (a = {:.3}), wall {:.1} s",
        c.mass_flow_kg_s, c.mass_flow_std_error_kg_s, c.eq7_mass_flow_kg_s, c.fill_ratio, s.wall_s
    ))
}
