//! LAMMPS and LIGGGHTS dumps turned into cgdem's outputs with cgdem's own analysis
//! (`analysis::heap`): `timeseries.csv` (same columns), `repose.csv`, `profile.csv` and
//! `summary.json` with `code` from the deck's plan. Particle-steps per second come from the
//! `Loop time` lines of the log (the same in both codes).

use std::path::{Path, PathBuf};

use super::dump::{read_dump, DumpError, Frame};
use super::{DeckPlan, TRAJECTORY_FILE};
use cgdem_core::analysis::conveying::{self, ConveyingSample, ConveyingSummary};
use cgdem_core::analysis::heap::HeapProfile;
use cgdem_core::io::{write_atomic, CsvBuffer};
use cgdem_core::math::{Real, Vec3};
use cgdem_core::output_format::{
    headline_sample, heap_profile, potential_origin, profile_csv, repose_csv, ReposeSample,
    RunSummary, SampleTrigger, StageRecord, TIMESERIES_COLUMNS,
};
use cgdem_core::scene::{ConveyingSettings, Scene};
use cgdem_core::timestep::Timescales;

#[derive(Debug, thiserror::Error)]
pub enum PostprocessError {
    #[error(transparent)]
    Dump(#[from] DumpError),
    #[error("{file}: {message}")]
    Content { file: PathBuf, message: String },
    #[error("cannot write {path}: {message}")]
    Output { path: PathBuf, message: String },
}

/// Positions, radii (the species' own, not LAMMPS's contact radius), masses, velocities and,
/// when the dump has spins, the rotational kinetic energy of one frame.
pub struct FrameParticles {
    pub position: Vec<Vec3>,
    pub velocity: Vec<Vec3>,
    pub radius: Vec<Real>,
    pub mass: Vec<Real>,
    /// Sum of `I omega^2 / 2` with `I = 2/5 m r^2` (0 without `omegax` columns), as cgdem's
    /// kinetic energy counts it.
    pub rotational_energy: Real,
}

/// Reads the per-atom state of a frame by column name, species from `type`.
pub fn frame_particles(
    frame: &Frame,
    scene: &Scene,
    file: &Path,
) -> Result<FrameParticles, PostprocessError> {
    let column = |name: &str| {
        frame.column(name).ok_or_else(|| PostprocessError::Content {
            file: file.to_path_buf(),
            message: format!(
                "step {}: no column `{name}` (columns: {})",
                frame.step,
                frame.columns.join(" ")
            ),
        })
    };
    let (x, y, z) = (column("x")?, column("y")?, column("z")?);
    let (vx, vy, vz) = (column("vx")?, column("vy")?, column("vz")?);
    let types = column("type")?;
    let spins = match (
        frame.column("omegax"),
        frame.column("omegay"),
        frame.column("omegaz"),
    ) {
        (Some(wx), Some(wy), Some(wz)) => Some((wx, wy, wz)),
        _ => None,
    };
    let mut out = FrameParticles {
        position: Vec::new(),
        velocity: Vec::new(),
        radius: Vec::new(),
        mass: Vec::new(),
        rotational_energy: 0.0,
    };
    for k in 0..frame.len() {
        let t = types[k] as usize;
        let species =
            scene
                .species
                .get(t.wrapping_sub(1))
                .ok_or_else(|| PostprocessError::Content {
                    file: file.to_path_buf(),
                    message: format!(
                        "step {}: atom type {t} has no species (the scene has {})",
                        frame.step,
                        scene.species.len()
                    ),
                })?;
        out.position.push(Vec3::new(x[k], y[k], z[k]));
        out.velocity.push(Vec3::new(vx[k], vy[k], vz[k]));
        out.radius.push(species.radius());
        out.mass.push(species.mass());
        if let Some((wx, wy, wz)) = spins {
            let w2 = wx[k] * wx[k] + wy[k] * wy[k] + wz[k] * wz[k];
            out.rotational_energy += 0.2 * species.mass() * species.radius().powi(2) * w2;
        }
    }
    Ok(out)
}

/// One `CGDEM_STAGE` boundary printed by the deck.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct StageMark {
    name: String,
    start: u64,
    end: Option<(u64, String)>,
}

fn stage_marks(log: &str) -> Vec<StageMark> {
    let mut marks: Vec<StageMark> = Vec::new();
    for line in log.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() < 4 || f[0] != "CGDEM_STAGE" {
            continue;
        }
        let Ok(step) = f[3].parse::<u64>() else {
            continue;
        };
        match f[2] {
            "start" => marks.push(StageMark {
                name: f[1].into(),
                start: step,
                end: None,
            }),
            "end" => {
                if let Some(m) = marks.iter_mut().rev().find(|m| m.name == f[1]) {
                    m.end = Some((step, f.get(4).copied().unwrap_or("").to_string()));
                }
            }
            _ => {}
        }
    }
    marks
}

/// The timing a LAMMPS or LIGGGHTS log reports, summed over its runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogTiming {
    pub loop_s: Real,
    pub ranks: usize,
    pub steps: u64,
    /// Atoms in the last run.
    pub atoms: usize,
    /// Steps times atoms, run by run (the count changes when particles are deleted).
    pub particle_steps: u64,
    /// `Per MPI rank memory allocation (min/avg/max)`: average times ranks, MB.
    pub memory_mb: Option<Real>,
}

/// Sums the `Loop time of T on P procs for N steps with M atoms` lines (a deck sets up with
/// `run 0` and may run its stage in pieces) and reads the memory line; None if the log has
/// no loop line with steps.
pub fn log_timing(log: &str) -> Option<LogTiming> {
    let mut memory_per_rank: Option<Real> = None;
    let mut timing: Option<LogTiming> = None;
    for line in log.lines() {
        if line.starts_with("Memory usage per processor") || line.starts_with("Per MPI rank memory")
        {
            // LAMMPS: `... (min/avg/max) = a | b | c Mbytes`; LIGGGHTS: `Memory usage per
            // processor = a Mbytes`.
            let numbers: Vec<Real> = line
                .split(['=', '|'])
                .skip(1)
                .filter_map(|f| f.split_whitespace().next()?.parse().ok())
                .collect();
            memory_per_rank = match numbers.as_slice() {
                [one] => Some(*one),
                [_, avg, _] => Some(*avg),
                _ => memory_per_rank,
            };
        }
        if let Some(rest) = line.strip_prefix("Loop time of ") {
            let f: Vec<&str> = rest.split_whitespace().collect();
            // T on P procs for N steps with M atoms
            if let (Some(t), Some(p), Some(n), Some(m)) = (f.first(), f.get(2), f.get(5), f.get(8))
            {
                if let (Ok(t), Ok(p), Ok(n), Ok(m)) = (
                    t.parse::<Real>(),
                    p.parse::<usize>(),
                    n.parse::<u64>(),
                    m.parse::<usize>(),
                ) {
                    if n == 0 {
                        continue;
                    }
                    let before =
                        timing.map_or((0.0, 0, 0), |t| (t.loop_s, t.steps, t.particle_steps));
                    timing = Some(LogTiming {
                        loop_s: before.0 + t,
                        ranks: p,
                        steps: before.1 + n,
                        atoms: m,
                        particle_steps: before.2 + n * m as u64,
                        memory_mb: memory_per_rank.map(|mb| mb * p as Real),
                    });
                }
            }
        }
    }
    timing
}

fn output_error(path: &Path, e: impl std::fmt::Display) -> PostprocessError {
    PostprocessError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Post-processes a finished LAMMPS or LIGGGHTS run in `dir` (the code and its log named by
/// `plan`) into cgdem's output files and summary.
pub fn postprocess(
    scene: &Scene,
    dir: &Path,
    plan: &DeckPlan,
    scales: &Timescales,
    wall_s: Real,
    ranks: usize,
) -> Result<RunSummary, PostprocessError> {
    let log_path = dir.join(plan.log_file);
    // Lossy: LIGGGHTS's "Lost atoms" error writes stray bytes after its message.
    let log = std::fs::read(&log_path)
        .map(|b| String::from_utf8_lossy(&b).into_owned())
        .map_err(|e| PostprocessError::Content {
            file: log_path.clone(),
            message: format!("cannot read: {e}"),
        })?;
    let marks = stage_marks(&log);
    let dt = plan.dt;
    let traj_path = dir.join(TRAJECTORY_FILE);
    let frames = read_dump(&traj_path)?;
    let last_state = write_timeseries(scene, dir, &marks, &frames, &traj_path, dt)?;
    let mut warnings = plan.notes.clone();
    warnings.extend(super::scene_notes(scene, plan.code));
    let samples = write_repose(
        scene,
        dir,
        plan,
        &marks,
        &frames,
        last_state.as_ref().map(|(_, p)| p),
        &mut warnings,
    )?;
    // An unfinished stage (stopped run) ends at the last frame written.
    let last_step = frames.last().map_or(0, |f| f.step);
    let stages = stage_records(&marks, last_step, plan, &mut warnings);
    let steps = marks.last().map_or(0, |m| {
        m.end
            .as_ref()
            .map_or(last_step.max(m.start), |(end, _)| *end)
    });
    let n_inserted = frames.first().map_or(0, Frame::len);
    let n_final = last_state.as_ref().map_or(0, |(_, p)| p.position.len());
    let count = atom_count(scene, &frames);
    if !scene.deletions.is_empty() {
        warnings.push(format!("{}: deleted grains are those that vanished from the trajectory dump (deleted in a [[delete]] box or lost from the domain, not told apart)", plan.code));
    }
    let (particle_steps, loop_s) =
        log_timing(&log).map_or((0, 0.0), |t| (t.particle_steps, t.loop_s));
    let headline = headline_sample(&samples);
    let conveying = conveying_summary(scene, &marks, &frames, dt, &traj_path, &mut warnings)?;
    Ok(RunSummary {
        case: scene.name.clone(),
        code: plan.code.into(),
        lambda: scene.lambda,
        cg_rule: scene.cg_rule,
        deleted_particles: count.vanished,
        deleted_mass_kg: count.vanished_mass_kg,
        conveying,
        stopped_by: None,
        guard_peaks: None,
        packing: None,
        n_particles: n_final,
        n_particles_inserted: n_inserted,
        n_particles_refilled: count.added,
        n_body_particles: count.frozen,
        lost_particles: if scene.deletions.is_empty() {
            (n_inserted - n_final.min(n_inserted)) as u64
        } else {
            0
        },
        steps,
        dt_s: dt,
        contact_period_s: scales.shortest_period,
        stable_dt_s: scales.stable_limit,
        simulated_s: steps as Real * dt,
        wall_s: if wall_s.is_finite() { wall_s } else { loop_s },
        particle_steps,
        particle_steps_per_s: particle_steps as Real / loop_s.max(1e-9),
        threads: ranks,
        repose_angle_deg: headline.and_then(|s| s.repose_angle_deg),
        repose_fit_r2: headline.and_then(|s| s.repose_fit_r2),
        repose_not_measured: scene.repose.as_ref().and_then(|_| match headline {
            Some(s) => s.not_measured.clone(),
            None => Some("the run left no heap profile at the repose times".into()),
        }),
        repose_rule: scene.repose.as_ref().map(|r| format!("as cgdem's (analysis::heap), on the {} write_dump at {:?} s after stage `{}` began", plan.code, r.at_times, r.stage)),
        runout_m: headline.map(|s| s.runout_m),
        repose_samples: samples,
        stages,
        warnings,
        scene_file: scene.source.display().to_string(),
        scene_digest: scene.digest(),
        cgdem_version: env!("CARGO_PKG_VERSION").into(),
        final_state: None,
        memory: None,
        decomposition: None,
    })
}

/// The heap surface of one frame, measured as cgdem measures it (None without `[repose]`).
fn frame_heap_profile(scene: &Scene, p: &FrameParticles) -> Option<HeapProfile> {
    heap_profile(scene, &p.position, &p.radius)
}

/// Writes `timeseries.csv`, one row per trajectory frame after step 0 (cgdem's columns);
/// returns the last frame's step and particles.
fn write_timeseries(
    scene: &Scene,
    dir: &Path,
    marks: &[StageMark],
    frames: &[Frame],
    traj_path: &Path,
    dt: Real,
) -> Result<Option<(u64, FrameParticles)>, PostprocessError> {
    let max_diameter = scene.max_diameter();
    let mut csv = CsvBuffer::new(TIMESERIES_COLUMNS.iter().chain(&["mechanical_energy_j"]));
    let origin = potential_origin(scene.gravity, scene.domain.lo, scene.domain.hi);
    let mut last_state = None;
    for frame in frames.iter().filter(|f| f.step > 0) {
        let p = frame_particles(frame, scene, traj_path)?;
        let stage = marks
            .iter()
            .find(|m| {
                frame.step > m.start && m.end.as_ref().is_none_or(|(end, _)| frame.step <= *end)
            })
            .map_or("", |m| m.name.as_str());
        let ke: Real = p
            .velocity
            .iter()
            .zip(&p.mass)
            .map(|(v, m)| 0.5 * m * v.length_squared())
            .sum::<Real>()
            + p.rotational_energy;
        let mass: Real = p.mass.iter().sum();
        // Kinetic plus gravitational energy, as cgdem's `World::mechanical_energy`.
        let potential: Real = p
            .position
            .iter()
            .zip(&p.mass)
            .map(|(&x, &m)| -m * scene.gravity.dot(x - origin))
            .sum();
        let profile = frame_heap_profile(scene, &p);
        let opt = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6e}"));
        csv.row([
            format!("{:.9e}", frame.step as Real * dt),
            stage.to_string(),
            format!("{ke:.9e}"),
            format!("{:.9e}", ke / mass.max(Real::MIN_POSITIVE)),
            p.position.len().to_string(),
            opt(profile.as_ref().map(|p| p.front(2.0 * max_diameter))),
            opt(profile.as_ref().map(|p| p.wall_height())),
            format!("{:.9e}", ke + potential),
        ]);
        last_state = Some((frame.step, p));
    }
    let path = dir.join("timeseries.csv");
    csv.bytes()
        .and_then(|bytes| write_atomic(&path, bytes))
        .map_err(|e| output_error(&path, e))?;
    Ok(last_state)
}

/// The repose samples: at the fixed times of `plan`'s dumps, then (when the scene asks) at
/// the last trajectory frame of the repose stage; writes `profile.csv` (the latest profile,
/// else the last frame's) and `repose.csv`.
fn write_repose(
    scene: &Scene,
    dir: &Path,
    plan: &DeckPlan,
    marks: &[StageMark],
    frames: &[Frame],
    last_particles: Option<&FrameParticles>,
    warnings: &mut Vec<String>,
) -> Result<Vec<ReposeSample>, PostprocessError> {
    let max_diameter = scene.max_diameter();
    let dt = plan.dt;
    let mut samples = Vec::new();
    let mut final_profile = None;
    for (_, t, file) in &plan.repose_dumps {
        let path = dir.join(file);
        if !path.exists() {
            // A run stopped early (time limit) has only the samples it reached.
            warnings.push(format!(
                "no {file}: the run ended before {t} s into the stage"
            ));
            continue;
        }
        let frames = read_dump(&path)?;
        let Some(frame) = frames.last() else {
            return Err(PostprocessError::Content {
                file: path,
                message: "no frame".into(),
            });
        };
        let p = frame_particles(frame, scene, &path)?;
        if let (Some(profile), Some(r)) = (frame_heap_profile(scene, &p), scene.repose.as_ref()) {
            samples.push(ReposeSample::measure(
                &profile,
                r,
                max_diameter,
                *t,
                SampleTrigger::FixedTime,
            ));
            final_profile = Some(profile);
        }
    }
    let mut final_profile =
        final_profile.or_else(|| last_particles.and_then(|p| frame_heap_profile(scene, p)));
    // The stage-end measurement: the last trajectory frame of the repose stage.
    if let Some(r) = scene.repose.as_ref().filter(|r| r.at_stage_end) {
        if let Some(mark) = marks.iter().find(|m| m.name == r.stage) {
            let end = mark.end.as_ref().map_or(u64::MAX, |(end, _)| *end);
            if let Some(frame) = frames
                .iter()
                .rev()
                .find(|f| f.step > mark.start && f.step <= end)
            {
                let p = frame_particles(frame, scene, &dir.join(TRAJECTORY_FILE))?;
                if let Some(profile) = frame_heap_profile(scene, &p) {
                    let t = (frame.step - mark.start) as Real * dt;
                    samples.push(ReposeSample::measure(
                        &profile,
                        r,
                        max_diameter,
                        t,
                        SampleTrigger::StageEnd,
                    ));
                    final_profile = Some(profile);
                }
            }
        }
    }
    if let Some(profile) = &final_profile {
        let path = dir.join("profile.csv");
        profile_csv(profile)
            .and_then(|csv| write_atomic(&path, &csv))
            .map_err(|e| output_error(&path, e))?;
    }
    if !samples.is_empty() {
        let path = dir.join("repose.csv");
        repose_csv(&samples)
            .and_then(|csv| write_atomic(&path, &csv))
            .map_err(|e| output_error(&path, e))?;
    }
    Ok(samples)
}

/// The stages as the log marks them; an unfinished one (a stopped run) ends at `last_step`.
fn stage_records(
    marks: &[StageMark],
    last_step: u64,
    plan: &DeckPlan,
    warnings: &mut Vec<String>,
) -> Vec<StageRecord> {
    let dt = plan.dt;
    marks
        .iter()
        .map(|m| {
            let (end, how) = m
                .end
                .clone()
                .unwrap_or((last_step.max(m.start), "did not finish".into()));
            if how == "did not finish" {
                warnings.push(format!(
                    "partial run: {} stopped during stage `{}`, {:.3} s after it began",
                    plan.code,
                    m.name,
                    (end - m.start) as Real * dt
                ));
            }
            if how == "max_duration" {
                warnings.push(format!(
                    "stage `{}` did not settle within max_duration",
                    m.name
                ));
            }
            StageRecord {
                name: m.name.clone(),
                start_s: m.start as Real * dt,
                end_s: end as Real * dt,
                steps: end - m.start,
                ended_by: how,
            }
        })
        .collect()
}

/// How the atoms of a trajectory came and went, counted by id from frame to frame.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct AtomCount {
    /// Atoms of frozen species (a particle-built body) in the last frame.
    pub frozen: usize,
    /// Atoms that appeared after the first frame (top-ups).
    pub added: u64,
    /// Mobile atoms present in one frame and missing from a later one, and their mass.
    pub vanished: u64,
    pub vanished_mass_kg: Real,
}

/// Counts atoms by id across `frames`: an atom deposited and deleted between two frames is
/// not seen (the dumps are written as often as LAMMPS deletes, `fix evaporate`).
pub(crate) fn atom_count(scene: &Scene, frames: &[Frame]) -> AtomCount {
    let mut count = AtomCount::default();
    let mut previous: std::collections::HashMap<i64, Real> = Default::default();
    for (n, frame) in frames.iter().enumerate() {
        let ids = frame.column("id").unwrap_or_default();
        let types = frame.column("type").unwrap_or_default();
        let mut current = std::collections::HashMap::with_capacity(ids.len());
        let mut frozen = 0;
        for (k, &id) in ids.iter().enumerate() {
            let species = types
                .get(k)
                .and_then(|&t| scene.species.get((t as usize).wrapping_sub(1)));
            if species.is_some_and(|s| s.frozen) {
                frozen += 1;
                continue;
            }
            current.insert(id as i64, species.map_or(Real::NAN, |s| s.mass()));
            if n > 0 && !previous.contains_key(&(id as i64)) {
                count.added += 1;
            }
        }
        for (id, mass) in &previous {
            if !current.contains_key(id) {
                count.vanished += 1;
                count.vanished_mass_kg += mass;
            }
        }
        count.frozen = frozen;
        previous = current;
    }
    count
}

/// The conveying measurement of `analysis::conveying` from the trajectory frames of the
/// conveying stage, as cgdem measures it from its state: per frame the passed mass (the mass
/// of the grains that have vanished so far, each with the mass it had, plus the mass beyond
/// the flow plane), the fill ratio and the bulk density; then the same block average. Grains
/// of frozen species (a particle-built screw) do not count. The drive torque is not in the
/// dumps (NaN).
pub(crate) fn conveying_summary(
    scene: &Scene,
    marks: &[StageMark],
    frames: &[Frame],
    dt: Real,
    file: &Path,
    warnings: &mut Vec<String>,
) -> Result<Option<ConveyingSummary>, PostprocessError> {
    let Some(c) = scene.conveying.as_ref() else {
        return Ok(None);
    };
    let Some(body) = scene.bodies.iter().find(|b| b.name == c.body) else {
        return Ok(None);
    };
    let Some(mark) = marks.iter().find(|m| m.name == c.stage) else {
        warnings.push(format!(
            "conveying: stage `{}` never started; no mass flow",
            c.stage
        ));
        return Ok(None);
    };
    let end = mark.end.as_ref().map_or(u64::MAX, |(end, _)| *end);
    let samples = conveying_samples(
        scene, c, body.axis, body.point, frames, dt, mark.start, end, file,
    )?;
    let (t0, t1) = (
        mark.start as Real * dt + c.discard,
        samples.last().map_or(0.0, |s| s.time),
    );
    let summary = conveying::summarize(
        c,
        body.rpm,
        scene.species[0].density,
        &samples,
        t0,
        t1,
        Real::NAN,
        Real::NAN,
    );
    if summary.is_none() {
        warnings.push(format!("conveying: too few frames after the discarded {} s for {} blocks; shorten output.timeseries_interval or run longer", c.discard, c.blocks));
    }
    Ok(summary)
}

/// One `ConveyingSample` per frame in `(start, end]` (steps). A grain that was in an earlier
/// frame (from the first frame of the run on) and is missing now counts as deleted, with its
/// mass.
#[allow(clippy::too_many_arguments)]
pub(crate) fn conveying_samples(
    scene: &Scene,
    c: &ConveyingSettings,
    axis: Vec3,
    point: Vec3,
    frames: &[Frame],
    dt: Real,
    start: u64,
    end: u64,
    file: &Path,
) -> Result<Vec<ConveyingSample>, PostprocessError> {
    let mut seen: std::collections::HashMap<i64, Real> = std::collections::HashMap::new();
    let mut samples = Vec::new();
    for frame in frames.iter().filter(|f| f.step <= end) {
        let p = frame_particles(frame, scene, file)?;
        let ids = frame
            .column("id")
            .ok_or_else(|| PostprocessError::Content {
                file: file.to_path_buf(),
                message: format!("step {}: no column `id`", frame.step),
            })?;
        let types = frame.column("type").unwrap_or_default();
        let mut present = std::collections::HashSet::new();
        let (mut position, mut radius, mut mass) = (Vec::new(), Vec::new(), Vec::new());
        for (k, &id) in ids.iter().enumerate() {
            let frozen = types
                .get(k)
                .and_then(|&t| scene.species.get((t as usize).wrapping_sub(1)))
                .is_some_and(|s| s.frozen);
            if frozen {
                continue;
            }
            let id = id as i64;
            seen.insert(id, p.mass[k]);
            present.insert(id);
            position.push(p.position[k]);
            radius.push(p.radius[k]);
            mass.push(p.mass[k]);
        }
        if frame.step < start {
            continue;
        }
        let deleted: Real = seen
            .iter()
            .filter(|(id, _)| !present.contains(id))
            .map(|(_, m)| m)
            .sum();
        samples.push(ConveyingSample {
            time: frame.step as Real * dt,
            passed_mass: conveying::passed_mass(c, axis, point, &position, &mass, deleted),
            fill_ratio: conveying::fill_ratio(c, axis, point, &position, &radius),
            bulk_density: conveying::bulk_density(c, &position, &mass),
        });
    }
    Ok(samples)
}

/// Writes the summary as `summary.json` in `dir`.
pub fn write_summary(summary: &RunSummary, dir: &Path) -> Result<(), PostprocessError> {
    let path = dir.join("summary.json");
    let json = serde_json::to_string_pretty(summary).map_err(|e| output_error(&path, e))?;
    write_atomic(&path, json.as_bytes()).map_err(|e| output_error(&path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line of grains moving along the screw axis at `v`, one every `spacing`: the passed
    /// mass through the plane grows by one grain mass per `spacing / v`, and grains that
    /// reach x = 0.9 m vanish from the dump (deleted): the flow is `m v / spacing` whichever
    /// way a grain is counted.
    #[test]
    fn dump_frames_of_a_steady_stream_give_its_mass_flow() {
        crate::at_repo_root();
        let scene = Scene::load(Path::new("validation/cases/screw_feeder_hertz.toml")).unwrap();
        let c = scene.conveying.clone().unwrap();
        let (v, spacing, dt, every) = (0.1, 0.01, 1e-3, 50);
        let m = scene.species[0].mass();
        let mut frames = Vec::new();
        for k in 0..=60u64 {
            let t = (k * every) as Real * dt;
            let mut values = vec![Vec::new(); 9];
            // Grain i starts at x = 0.005 + i spacing - 0.6 (half a spacing off the frames).
            for i in 0..150 {
                let x = 0.005 + i as Real * spacing - 0.6 + v * t;
                if x >= 0.9 {
                    continue;
                }
                let row = [i as Real + 1.0, 1.0, x, 0.0, 0.0, v, 0.0, 0.0, 0.0108];
                for (col, value) in values.iter_mut().zip(row) {
                    col.push(value);
                }
            }
            frames.push(Frame {
                step: k * every,
                boundary: "ff ff ff".into(),
                bounds: [[-0.1, 1.0], [-0.3, 0.3], [-0.45, 1.0]],
                columns: "id type x y z vx vy vz radius"
                    .split(' ')
                    .map(String::from)
                    .collect(),
                values,
            });
        }
        let samples = conveying_samples(
            &scene,
            &c,
            Vec3::X,
            Vec3::ZERO,
            &frames,
            dt,
            1000,
            u64::MAX,
            Path::new("traj.dump"),
        )
        .unwrap();
        assert_eq!(samples.len(), 41); // frames from step 1000 (t = 1 s) on
        let summary =
            conveying::summarize(&c, -100.0, 1370.0, &samples, 1.0, 3.0, 0.0, 0.0).unwrap();
        let flow = m * v / spacing;
        assert!(
            (summary.mass_flow_kg_s - flow).abs() < 1e-9 * flow,
            "{} vs {flow}",
            summary.mass_flow_kg_s
        );
        assert!(summary.mass_flow_std_error_kg_s < 1e-9 * flow);
        // Grains were deleted during the window: their mass kept counting.
        assert!(frames.last().unwrap().len() < frames[20].len());
    }

    /// Frames of the particle-screw case: two screw atoms (frozen type 2) throughout, grain 1
    /// throughout, grain 2 deleted after the first frame, grain 3 deposited in the second.
    #[test]
    fn atoms_are_counted_as_frozen_added_and_vanished_by_id() {
        crate::at_repo_root();
        let scene = Scene::load(Path::new(
            "validation/cases/screw_feeder_hertz_particles.toml",
        ))
        .unwrap();
        let frame = |step: u64, atoms: &[(Real, Real)]| Frame {
            step,
            boundary: "ff ff ff".into(),
            bounds: [[-0.1, 1.0], [-0.3, 0.3], [-0.45, 1.0]],
            columns: vec!["id".into(), "type".into()],
            values: vec![
                atoms.iter().map(|a| a.0).collect(),
                atoms.iter().map(|a| a.1).collect(),
            ],
        };
        let frames = [
            frame(0, &[(1.0, 1.0), (2.0, 1.0), (10.0, 2.0), (11.0, 2.0)]),
            frame(100, &[(1.0, 1.0), (10.0, 2.0), (11.0, 2.0), (3.0, 1.0)]),
            frame(200, &[(1.0, 1.0), (3.0, 1.0), (10.0, 2.0), (11.0, 2.0)]),
        ];
        let count = atom_count(&scene, &frames);
        assert_eq!((count.frozen, count.added, count.vanished), (2, 1, 1));
        assert_eq!(count.vanished_mass_kg, scene.species[0].mass());
    }

    #[test]
    fn stage_marks_and_loop_times_are_read_from_the_log() {
        let log = "print \"CGDEM_STAGE settle start $(step)\"\nCGDEM_STAGE settle start 0\nLoop time of 2.5 on 1 procs for 100 steps with 10 atoms\nCGDEM_STAGE settle end 400 settled\nCGDEM_STAGE collapse start 400\nLoop time of 1.5 on 1 procs for 100 steps with 8 atoms\nCGDEM_STAGE collapse end 900 duration\n";
        let marks = stage_marks(log);
        assert_eq!(marks.len(), 2);
        assert_eq!(marks[0].end, Some((400, "settled".into())));
        assert_eq!(marks[1].start, 400);
        let t = log_timing(log).unwrap();
        assert_eq!((t.particle_steps, t.loop_s), (1800, 4.0));
    }

    #[test]
    fn reads_loop_time_and_memory_from_lammps_and_liggghts_logs() {
        let lammps = "Per MPI rank memory allocation (min/avg/max) = 12.5 | 13.0 | 13.5 Mbytes\nLoop time of 1e-6 on 2 procs for 0 steps with 11103 atoms\nStep Atoms\nLoop time of 20.5 on 2 procs for 6000 steps with 11103 atoms\nLoop time of 10.5 on 2 procs for 4000 steps with 11103 atoms\n";
        let t = log_timing(lammps).unwrap();
        // The set-up `run 0` is left out; the pieces of the stage add up.
        assert_eq!(
            (t.loop_s, t.ranks, t.steps, t.atoms),
            (31.0, 2, 10000, 11103)
        );
        assert_eq!(t.memory_mb, Some(26.0));
        let liggghts = "Memory usage per processor = 9.5 Mbytes\nLoop time of 41 on 1 procs for 10000 steps with 11103 atoms\n";
        let t = log_timing(liggghts).unwrap();
        assert_eq!((t.loop_s, t.ranks, t.memory_mb), (41.0, 1, Some(9.5)));
        // A truncated log (killed before the loop ended) has no timing.
        assert!(
            log_timing("Memory usage per processor = 9.5 Mbytes\nStep Atoms\n100 11103\n")
                .is_none()
        );
    }
}
