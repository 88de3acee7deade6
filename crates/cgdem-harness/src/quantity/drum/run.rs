//! One run's drum measurement, from the frames cgdem writes with `[output] write_data`
//! (`vtk/particles_*.data`, LAMMPS data files with the frame's time in the title line) or,
//! for a reference code, from its trajectory dump (every `timeseries_interval`; the frames
//! at cgdem's frame period are kept), or why there is none.

use std::path::{Path, PathBuf};

use super::measurement::{
    lacey_index, surface_angle, zone_counts, Grain, Lacey, SurfaceLine, ZoneCounts,
};
use super::oscillation::{oscillation, Oscillation};
use super::DrumSettings;
use crate::code::Code;
use crate::runs::{Outcome, RunRecord};
use cgdem_core::output_format::RunSummary;
use cgdem_core::scene::Scene;

/// The measures of one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameMeasure {
    /// s after the drum started turning (negative: the settle before it).
    pub time_s: f64,
    pub counts: ZoneCounts,
    pub surface: Option<SurfaceLine>,
    pub lacey: Option<Lacey>,
}

/// One run's frames measured (or why they are not).
#[derive(Clone, Debug)]
pub struct DrumRun {
    pub code: Code,
    pub lambda: u32,
    pub seed: u64,
    pub dir: PathBuf,
    pub frames: Vec<FrameMeasure>,
    pub problem: Option<String>,
}

/// Means over the steady frames of one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyMeans {
    pub frames: usize,
    /// Zone 1 M1, zone 1 M2, zone 2 M1, zone 2 M2.
    pub counts: [f64; 4],
    pub angle_deg: Option<f64>,
    pub lacey: Option<f64>,
}

impl DrumRun {
    /// The frames from `steady_from_s` of rotation on, to the nearest frame: a frame within
    /// half a frame interval before it counts. cgdem writes a frame one time step after
    /// each multiple of the frame period, the reference codes' dumps at the multiple itself;
    /// both must give the same frames.
    fn steady_frames(&self, steady_from_s: f64) -> Vec<&FrameMeasure> {
        let rotating: Vec<f64> = (self.frames.iter())
            .map(|f| f.time_s)
            .filter(|&t| t >= 0.0)
            .collect();
        let interval = (rotating.windows(2))
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let slack = if interval.is_finite() {
            0.5 * interval
        } else {
            1e-9
        };
        (self.frames.iter())
            .filter(|f| f.time_s >= steady_from_s - slack)
            .collect()
    }

    /// Means over the frames at or after `steady_from_s` of the rotation; None without any.
    pub fn steady_means(&self, steady_from_s: f64) -> Option<SteadyMeans> {
        let steady = self.steady_frames(steady_from_s);
        if steady.is_empty() {
            return None;
        }
        let n = steady.len() as f64;
        let mut counts = [0.0; 4];
        for f in &steady {
            for (c, v) in counts.iter_mut().zip(f.counts.as_array()) {
                *c += v as f64 / n;
            }
        }
        let mean = |v: Vec<f64>| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
        Some(SteadyMeans {
            frames: steady.len(),
            counts,
            angle_deg: mean(
                steady
                    .iter()
                    .filter_map(|f| f.surface.map(|s| s.angle_deg))
                    .collect(),
            ),
            lacey: mean(
                steady
                    .iter()
                    .filter_map(|f| f.lacey.map(|l| l.index))
                    .collect(),
            ),
        })
    }
}

impl DrumRun {
    /// The swing of the zone counts over the frames at or after `steady_from_s` of the
    /// rotation (`oscillation`); None where it is not resolved.
    pub fn oscillation(&self, steady_from_s: f64) -> Option<Oscillation> {
        let steady = self.steady_frames(steady_from_s);
        let times: Vec<f64> = steady.iter().map(|f| f.time_s).collect();
        let counts: Vec<[f64; 4]> = (steady.iter())
            .map(|f| f.counts.as_array().map(|c| c as f64))
            .collect();
        oscillation(&times, &counts)
    }
}

/// The time in a cgdem frame's title line (`... at t = 3.0e-1 s`).
pub(crate) fn parse_frame_time(title: &str) -> Option<f64> {
    let rest = &title[title.rfind("at t = ")? + "at t = ".len()..];
    rest.strip_suffix(" s")?.trim().parse().ok()
}

/// A frame's time and grains; atom type `large_type` is the large species.
pub(crate) fn read_frame(path: &Path, large_type: u64) -> Result<(f64, Vec<Grain>), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let title = text.lines().next().unwrap_or_default();
    let time = parse_frame_time(title)
        .ok_or_else(|| format!("{}: no `at t = ... s` in the title line", path.display()))?;
    let data = cgdem_core::lammps_data::parse_data(&text, path).map_err(|e| e.to_string())?;
    let grains = (data.atoms.iter())
        .map(|a| Grain {
            position: [a.position.x, a.position.y, a.position.z],
            diameter: a.diameter,
            large: a.atom_type == large_type,
        })
        .collect();
    Ok((time, grains))
}

/// The frames of a cgdem run directory, in time order.
fn frame_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let vtk = dir.join("vtk");
    let entries = std::fs::read_dir(&vtk).map_err(|e| format!("{}: {e}", vtk.display()))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("particles_") && n.ends_with(".data"))
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(format!(
            "{}: no particles_*.data frames (the scene needs `[output] write_data = true` and a vtk_interval)",
            vtk.display()
        ));
    }
    Ok(files)
}

/// The atom type of the large species (the benchmark's M2): the scene's two species, the
/// larger diameter's.
fn large_type(scene: &Scene) -> Result<u64, String> {
    match scene.species.as_slice() {
        [a, b] if a.diameter != b.diameter => Ok(if a.diameter > b.diameter { 1 } else { 2 }),
        _ => Err(format!(
            "{}: the drum is measured with two species of different sizes; it has {}",
            scene.source.display(),
            scene.species.len()
        )),
    }
}

/// The scene's smallest and largest species diameters (the drum's M1 and M2), m.
pub(crate) fn species_diameters(scene: &Scene) -> (f64, f64) {
    let d = scene.species.iter().map(|s| s.diameter);
    (
        d.clone().fold(f64::INFINITY, f64::min),
        d.fold(0.0, f64::max),
    )
}

/// Every frame of one finished run measured: the surface in bins of two small-grain
/// diameters, Lacey's index in cells of 2.5 large-grain diameters with at least 10 grains
/// (4 mm and 10 mm in the benchmark; at lambda > 1 the parcels').
pub(crate) fn measure_one(
    scene: &Scene,
    settings: &DrumSettings,
    r: &RunRecord,
) -> Result<Vec<FrameMeasure>, String> {
    let path = r.dir.join("summary.json");
    let summary: RunSummary = std::fs::read_to_string(&path)
        .map_err(|e| format!("{}: {e}", path.display()))
        .and_then(|t| serde_json::from_str(&t).map_err(|e| format!("{}: {e}", path.display())))?;
    let start = (summary.stages.iter())
        .find(|s| s.name == settings.stage)
        .ok_or_else(|| {
            format!(
                "{}: no stage `{}` (the suite's drum.stage)",
                path.display(),
                settings.stage
            )
        })?
        .start_s;
    let large = large_type(scene)?;
    let lambda = f64::from(r.lambda);
    let (small_d, large_d) = species_diameters(scene);
    let (small_d, large_d) = (lambda * small_d, lambda * large_d);
    let measure = |time: f64, grains: Vec<Grain>| FrameMeasure {
        time_s: time - start,
        counts: zone_counts(&grains),
        surface: surface_angle(&grains, 2.0 * small_d),
        lacey: lacey_index(&grains, 2.5 * large_d, 10),
    };
    if r.code != Code::Cgdem {
        let every = (scene.output.vtk_interval / summary.dt_s).round().max(1.0) as u64;
        let frames = dump_frames(&r.dir.join(crate::decks::TRAJECTORY_FILE), large, every)?;
        return Ok(frames
            .into_iter()
            .map(|(step, grains)| measure(step as f64 * summary.dt_s, grains))
            .collect());
    }
    frame_files(&r.dir)?
        .iter()
        .map(|f| read_frame(f, large).map(|(time, grains)| measure(time, grains)))
        .collect()
}

/// The frames of a reference code's trajectory dump at steps that are multiples of
/// `every`, with their grains (`type`, `x`, `y`, `z`, `radius` columns).
pub(crate) fn dump_frames(
    path: &Path,
    large_type: u64,
    every: u64,
) -> Result<Vec<(u64, Vec<Grain>)>, String> {
    let frames = crate::decks::read_dump(path).map_err(|e| e.to_string())?;
    frames
        .iter()
        .filter(|f| f.step % every == 0)
        .map(|f| {
            let column = |name: &str| {
                f.column(name).ok_or_else(|| {
                    format!("{}: step {}: no `{name}` column", path.display(), f.step)
                })
            };
            let (t, x, y, z, radius) = (
                column("type")?,
                column("x")?,
                column("y")?,
                column("z")?,
                column("radius")?,
            );
            let grains = (0..f.len())
                .map(|k| Grain {
                    position: [x[k], y[k], z[k]],
                    diameter: 2.0 * radius[k],
                    large: t[k].round() as u64 == large_type,
                })
                .collect();
            Ok((f.step, grains))
        })
        .collect()
}

/// Every run of a drum case measured, or why not.
pub fn measure_runs(scene: &Scene, settings: &DrumSettings, runs: &[RunRecord]) -> Vec<DrumRun> {
    runs.iter()
        .map(|r| {
            let measured = if r.status != Outcome::Ok {
                Err(r.reason.clone().unwrap_or_else(|| "not run".into()))
            } else {
                measure_one(scene, settings, r)
            };
            let (frames, problem) = match measured {
                Ok(frames) => (frames, None),
                Err(p) => (Vec::new(), Some(p)),
            };
            DrumRun {
                code: r.code,
                lambda: r.lambda,
                seed: r.seed,
                dir: r.dir.clone(),
                frames,
                problem,
            }
        })
        .collect()
}
