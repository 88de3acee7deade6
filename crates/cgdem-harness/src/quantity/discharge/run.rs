//! One run's discharge measurement, from the files every code leaves (`summary.json`, its
//! `timeseries.csv`, and for the bulk density cgdem's data file at the fill's end or a
//! reference code's trajectory), or why there is none.

use std::path::{Path, PathBuf};

use super::measurement::{
    beverloo_c, data_bulk_density, discharge_rate, discharge_series, dump_bulk_density,
    flow_stopped_at, DischargeRate, DischargeSeries, PUBLISHED_K,
};
use super::DischargeSettings;
use crate::code::Code;
use crate::runs::{Outcome, RunRecord};
use cgdem_core::coarse_graining::coarse_grain_by;
use cgdem_core::output_format::RunSummary;
use cgdem_core::scene::Scene;

/// One run's discharge measurement (or why there is none).
#[derive(Clone, Debug)]
pub struct SiloRun {
    pub code: Code,
    pub lambda: u32,
    pub seed: u64,
    pub dir: PathBuf,
    /// The grain's (at lambda > 1 the parcel's) diameter, m.
    pub grain_diameter_m: f64,
    pub series: Option<DischargeSeries>,
    pub rate: Option<DischargeRate>,
    /// kg/m3, and the code whose fill it was measured in (cgdem's own from the data file it
    /// writes at the fill's end when the scene asks for it, else a reference code's of the
    /// same seed).
    pub bulk_density: Option<(f64, Code)>,
    /// Beverloo's C with k = 1.5 and its standard error.
    pub c_fixed_k: Option<(f64, f64)>,
    /// Why there is no measurement.
    pub problem: Option<String>,
    /// Why a measured run has no bulk density of its own (a reference run's trajectory was
    /// deleted, as the nightly does after its report): the rate stands without it.
    pub bulk_density_problem: Option<String>,
}

impl SiloRun {
    /// The bulk density as the runs table shows it: kg/m3, and whose fill when not its own.
    pub(super) fn bulk_density_text(&self) -> String {
        match self.bulk_density {
            Some((rho, code)) if code == self.code => format!("{rho:.0}"),
            Some((rho, code)) => format!("{rho:.0} ({}'s fill)", code.name()),
            None if self.bulk_density_problem.is_some() => "- (see the CSV's problem)".into(),
            None => "-".into(),
        }
    }

    /// Why the run has no measurement, or no bulk density, for the CSV's quoted column.
    pub(super) fn csv_problem(&self) -> String {
        let problem = self.problem.as_ref().or(self.bulk_density_problem.as_ref());
        problem.map_or(String::new(), |p| p.replace('"', "'"))
    }

    /// The rate and its block-average standard error, kg/s, when measured.
    pub fn rate_with_error(&self) -> Option<(f64, f64)> {
        self.rate.as_ref().map(|r| (r.rate_kg_s, r.std_error_kg_s))
    }

    /// When the flow stopped (s after the gate opened): no grain out over the window's last
    /// two blocks of `blocks`, a clog rather than a gap between grains; None while grains
    /// still leave or without a measurement.
    pub fn clogged_at(&self, blocks: usize) -> Option<f64> {
        let (rate, series) = (self.rate.as_ref()?, self.series.as_ref()?);
        let block = (rate.window_s[1] - rate.window_s[0]) / blocks as f64;
        flow_stopped_at(series, 2.0 * block)
    }
}

/// Reads a run's summary and measures it (the mass of the run's own particles: a parcel at
/// lambda carries lambda^3 grains' mass); `Err` says why it cannot be. Also returns the
/// step at which the gate opened.
pub(crate) fn measure_one(
    scene: &Scene,
    settings: &DischargeSettings,
    r: &RunRecord,
) -> Result<(SiloRun, Option<u64>), String> {
    let coarse = coarse_grain_by(&scene.with_insertion_seed(r.seed), r.lambda, r.cg_rule)
        .map_err(|e| e.to_string())?;
    let [species] = coarse.species.as_slice() else {
        return Err(format!(
            "{}: {} species; the discharge counts grains of one species",
            scene.source.display(),
            coarse.species.len()
        ));
    };
    // A built-in silo's orifice is the scene's; the suite's value must be the same.
    for b in &scene.bodies {
        if let cgdem_core::scene::MeshSource::Silo(_, spec) = &b.mesh {
            if (spec.orifice_diameter - settings.orifice_diameter_m).abs() > 1e-9 {
                return Err(format!(
                    "{}: the silo's orifice_diameter is {} m, the suite's discharge.orifice_diameter {} m",
                    scene.source.display(),
                    spec.orifice_diameter,
                    settings.orifice_diameter_m
                ));
            }
        }
    }
    let path = r.dir.join("summary.json");
    let summary: RunSummary = std::fs::read_to_string(&path)
        .map_err(|e| format!("{}: {e}", path.display()))
        .and_then(|t| serde_json::from_str(&t).map_err(|e| format!("{}: {e}", path.display())))?;
    let stage = summary
        .stages
        .iter()
        .find(|s| s.name == settings.stage)
        .ok_or_else(|| {
            format!(
                "{}: no stage `{}` (the suite's discharge.stage)",
                path.display(),
                settings.stage
            )
        })?;
    let series = discharge_series(&r.dir, &settings.stage, stage.start_s, species.mass())?;
    let rate = discharge_rate(&series, settings.discard_s, settings.blocks)?;
    let gate_step = (stage.start_s / summary.dt_s).round() as u64;
    let (bulk_density, bulk_density_problem) = match r.code {
        Code::Cgdem => (cgdem_bulk_density(&coarse, settings, &r.dir)?, None),
        _ => match dump_bulk_density(
            &r.dir,
            &coarse,
            gate_step,
            settings.bulk_lo,
            settings.bulk_hi,
        ) {
            Ok(rho) => (Some((rho, r.code)), None),
            Err(e) => (None, Some(format!("no bulk density: {e}"))),
        },
    };
    Ok((
        SiloRun {
            code: r.code,
            lambda: r.lambda,
            seed: r.seed,
            dir: r.dir.clone(),
            grain_diameter_m: species.diameter,
            series: Some(series),
            rate: Some(rate),
            bulk_density,
            c_fixed_k: None,
            problem: None,
            bulk_density_problem,
        },
        Some(gate_step),
    ))
}

/// cgdem's bulk density at the gate's opening, from the particles it wrote at the end of the
/// stage before the discharge (`[output] data_at_stage_ends`); None when the scene does not
/// write them.
fn cgdem_bulk_density(
    scene: &Scene,
    settings: &DischargeSettings,
    dir: &Path,
) -> Result<Option<(f64, Code)>, String> {
    let k = scene
        .stages
        .iter()
        .position(|s| s.name == settings.stage)
        .ok_or_else(|| format!("{}: no stage `{}`", scene.source.display(), settings.stage))?;
    let Some(before) = k.checked_sub(1).map(|j| &scene.stages[j].name) else {
        return Ok(None);
    };
    if !scene.output.data_at_stage_ends.contains(before) {
        return Ok(None);
    }
    let path = cgdem_core::run::stage_end_data_path(dir, before);
    data_bulk_density(&path, settings.bulk_lo, settings.bulk_hi).map(|rho| Some((rho, Code::Cgdem)))
}

/// Every finished run of a discharge case measured; cgdem's runs whose scene writes no data
/// file at the fill's end take the bulk density of a reference code's run of the same level
/// and seed (LIGGGHTS first).
pub fn measure_runs(
    scene: &Scene,
    settings: &DischargeSettings,
    runs: &[RunRecord],
) -> Vec<SiloRun> {
    let mut out: Vec<SiloRun> = runs
        .iter()
        .map(|r| {
            let failed = |problem: String| SiloRun {
                code: r.code,
                lambda: r.lambda,
                seed: r.seed,
                dir: r.dir.clone(),
                grain_diameter_m: f64::NAN,
                series: None,
                rate: None,
                bulk_density: None,
                c_fixed_k: None,
                problem: Some(problem),
                bulk_density_problem: None,
            };
            if r.status != Outcome::Ok {
                return failed(r.reason.clone().unwrap_or_else(|| "not run".into()));
            }
            match measure_one(scene, settings, r) {
                Ok((run, _)) => run,
                Err(problem) => failed(problem),
            }
        })
        .collect();
    let measured: Vec<(u32, u64, Code, f64)> = out
        .iter()
        .filter_map(|s| s.bulk_density.map(|(rho, c)| (s.lambda, s.seed, c, rho)))
        .collect();
    for s in &mut out {
        if s.bulk_density.is_none() && s.rate.is_some() {
            s.bulk_density = [Code::Liggghts, Code::Lammps].iter().find_map(|&code| {
                measured
                    .iter()
                    .find(|m| (m.0, m.1, m.2) == (s.lambda, s.seed, code))
                    .map(|m| (m.3, code))
            });
        }
        if let (Some(rate), Some((rho, _))) = (&s.rate, s.bulk_density) {
            s.c_fixed_k = beverloo_c(
                rate.rate_kg_s,
                rate.std_error_kg_s,
                rho,
                settings.orifice_diameter_m,
                s.grain_diameter_m,
                PUBLISHED_K,
            );
        }
    }
    out
}
