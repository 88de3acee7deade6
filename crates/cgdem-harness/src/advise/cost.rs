//! What a scene's matrix will cost before it runs: particle-steps of every run (particles
//! and steps counted from the scene at each level, as the run builds it), which runs are
//! already made (`--reuse`: the same scene digest, finished), and the machine's throughput,
//! from the runs already made or from a short probe run.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use super::scene::SceneMatrix;
use super::AdviseError;
use crate::accuracy::planned_runs;
use crate::runs::ValidateOptions;
use cgdem_core::coarse_graining::{coarse_grain_by, CoarseGrainRule};
use cgdem_core::run::{RunOptions, StageEnding};
use cgdem_core::scene::{Scene, Stage, StageEnd};

/// Steps of the probe run: enough to time the force loop past its first list builds, short
/// enough to take seconds.
pub const PROBE_STEPS: u64 = 300;

/// One run of the matrix and its cost.
#[derive(Clone, Debug, PartialEq)]
pub struct RunCost {
    pub lambda: u32,
    pub rule: CoarseGrainRule,
    pub seed: u64,
    /// Particles the insertions make at this level (for a lattice or a mesh region, at
    /// most this many).
    pub particles: f64,
    /// Steps if every stage that ends when the flow settles ends at its shortest, and at
    /// its longest (equal when every stage has a fixed duration).
    pub steps: (f64, f64),
    /// A finished run of this very scene is already in its directory: it is taken, not made.
    pub done: bool,
    /// The particle-steps and wall seconds a finished run took.
    pub measured: Option<(f64, f64)>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct MatrixCost {
    pub runs: Vec<RunCost>,
}

impl MatrixCost {
    /// Particle-steps of the runs selected, (shortest, longest).
    fn sum(&self, keep: impl Fn(&RunCost) -> bool) -> (f64, f64) {
        self.runs
            .iter()
            .filter(|r| keep(r))
            .fold((0.0, 0.0), |a, r| {
                (a.0 + r.particles * r.steps.0, a.1 + r.particles * r.steps.1)
            })
    }

    /// Every run's particle-steps.
    pub fn total(&self) -> (f64, f64) {
        self.sum(|_| true)
    }

    /// The particle-steps still to make.
    pub fn remaining(&self) -> (f64, f64) {
        self.sum(|r| !r.done)
    }

    pub fn done(&self) -> usize {
        self.runs.iter().filter(|r| r.done).count()
    }

    /// Particle-steps per wall second of the runs already made, and how many: None when none.
    pub fn measured_throughput(&self) -> Option<(f64, usize)> {
        let made: Vec<(f64, f64)> = self.runs.iter().filter_map(|r| r.measured).collect();
        let wall: f64 = made.iter().map(|m| m.1).sum();
        (wall > 0.0).then(|| (made.iter().map(|m| m.0).sum::<f64>() / wall, made.len()))
    }
}

/// Steps of `scene`'s stages at time step `dt`: (shortest, longest).
fn stage_steps(stages: &[Stage], dt: f64) -> (f64, f64) {
    stages.iter().fold((0.0, 0.0), |(lo, hi), s| {
        let (a, b) = match s.end {
            StageEnd::Duration(d) => (d, d),
            StageEnd::Settled {
                min_duration,
                max_duration,
                ..
            } => (min_duration, max_duration),
        };
        (lo + (a / dt).ceil(), hi + (b / dt).ceil())
    })
}

/// The cost of every run of `matrix` made with `options` (its runs' directory).
pub fn matrix_cost(
    matrix: &SceneMatrix,
    options: &ValidateOptions,
) -> Result<MatrixCost, AdviseError> {
    let (_, planned) = planned_runs(&matrix.sweep, &matrix.sweep.file, options)?;
    let mut runs = Vec::new();
    for run in planned {
        let fail = |reason: String| AdviseError::NoMatrix {
            file: matrix.sweep.file.clone(),
            reason: format!(
                "lambda = {} under the {} rule: {reason}",
                run.lambda,
                run.rule.name()
            ),
        };
        let coarse = coarse_grain_by(
            &run.scene.with_insertion_seed(run.seed),
            run.lambda,
            run.rule,
        )
        .map_err(|e| fail(e.to_string()))?;
        let (dt, _, _) =
            cgdem_core::run::time_step(&coarse, false).map_err(|e| fail(e.to_string()))?;
        let summary: Option<serde_json::Value> =
            std::fs::read_to_string(run.dir.join("summary.json"))
                .ok()
                .and_then(|t| serde_json::from_str(&t).ok())
                .filter(|s| !StageEnding::interrupted_summary(s))
                .filter(|s| s["scene_digest"].as_str() == Some(coarse.digest().as_str()))
                .filter(|s| options.decomposition.made(s));
        runs.push(RunCost {
            lambda: run.lambda,
            rule: run.rule,
            seed: run.seed,
            particles: cgdem_core::run::memory::estimate(&coarse, None).particles,
            steps: stage_steps(&coarse.stages, dt),
            done: summary.is_some(),
            measured: summary
                .as_ref()
                .and_then(|s| Some((s["particle_steps"].as_f64()?, s["wall_s"].as_f64()?))),
        });
    }
    Ok(MatrixCost { runs })
}

/// A probe run's throughput.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    pub lambda: u32,
    pub particles: usize,
    pub steps: u64,
    pub wall_s: f64,
    pub particle_steps_per_s: f64,
    /// Seconds before the first step (SDF grids, insertion): each run of the matrix spends
    /// about as much again (at most: coarser levels insert fewer particles).
    pub setup_s: f64,
}

/// The scene of the probe: the matrix's finest level, first rule and seed, running its first
/// stage (its walls removed as it removes them) for `steps` steps, measuring and writing
/// nothing but its summary.
fn probe_scene(matrix: &SceneMatrix, steps: u64) -> Result<Scene, String> {
    let (lambda, rule, seed) = (matrix.levels[0].lambda, matrix.rules[0], matrix.seeds[0]);
    let mut scene = coarse_grain_by(&matrix.scene.with_insertion_seed(seed), lambda, rule)
        .map_err(|e| e.to_string())?;
    let (dt, _, _) = cgdem_core::run::time_step(&scene, false).map_err(|e| e.to_string())?;
    let first = scene
        .stages
        .first()
        .ok_or("the scene has no stage")?
        .clone();
    let duration = steps as f64 * dt;
    scene.stages = vec![Stage {
        end: StageEnd::Duration(duration),
        ..first
    }];
    scene.repose = None;
    scene.conveying = None;
    scene.packing = None;
    scene.output.vtk_interval = 0.0;
    scene.output.write_data = false;
    scene.output.data_at_stage_ends.clear();
    scene.output.timeseries_interval = duration;
    Ok(scene)
}

/// Runs the probe in `dir` (removed afterwards) and times its steps (the insertion before
/// them not counted).
pub fn probe(
    matrix: &SceneMatrix,
    dir: &Path,
    steps: u64,
    stop: Option<Arc<AtomicBool>>,
) -> Result<Probe, String> {
    let scene = probe_scene(matrix, steps)?;
    let options = RunOptions {
        out_dir: dir.to_path_buf(),
        stop,
        ..Default::default()
    };
    let started = std::time::Instant::now();
    let summary = cgdem_core::run::run(&scene, &options).map_err(|e| e.to_string());
    let elapsed = started.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(dir);
    let summary = summary?;
    Ok(Probe {
        lambda: matrix.levels[0].lambda,
        particles: summary.n_particles,
        steps: summary.steps,
        wall_s: summary.wall_s,
        particle_steps_per_s: summary.particle_steps_per_s,
        setup_s: (elapsed - summary.wall_s).max(0.0),
    })
}
