//! The bench's cases: each case file cut to the timed window and started from one state
//! that cgdem prepares, so that every code times the same particles and physics.

use std::path::{Path, PathBuf};

use super::{BenchError, BenchOptions};
use cgdem_core::decomposition::GridSpec;
use cgdem_core::math::Real;
use cgdem_core::particles::Particles;
use cgdem_core::run::{run, RunOptions};
use cgdem_core::scene::{ContactSettings, Scene, StageEnd};
use cgdem_core::timestep::TimeStepRequest;

/// A case ready to time: the scene cut to `steps`, its step and the prepared state.
#[derive(Clone)]
pub(super) struct PreparedCase {
    pub(super) name: String,
    /// The case file, absolute (the ranks' command line reads it).
    pub(super) source: PathBuf,
    /// The undecomposed case this one was derived from (itself if it is).
    pub(super) base: String,
    pub(super) timed: Scene,
    pub(super) full: Option<Scene>,
    pub(super) state: Particles,
    pub(super) dt: Real,
    pub(super) reference_codes: bool,
    /// cgdem runs decomposed into this grid (the reference codes skip the case).
    pub(super) grid: Option<GridSpec>,
    /// `state` written for the ranks (`--np`).
    pub(super) state_file: Option<PathBuf>,
}

pub(super) fn prepare(path: &Path, options: &BenchOptions) -> Result<PreparedCase, BenchError> {
    let scene = Scene::load(path).map_err(|e| BenchError::Case(e.to_string()))?;
    let file = path.display().to_string();
    let [stage] = scene.stages.as_slice() else {
        return Err(BenchError::Case(format!(
            "{file}: the bench takes scenes of one stage with a duration; this one has {}",
            scene.stages.len()
        )));
    };
    let StageEnd::Duration(duration) = stage.end else {
        return Err(BenchError::Case(format!(
            "{file}: stage[0]: the bench needs a fixed duration (stage.duration), not a settling condition"
        )));
    };
    if options.prepare_s >= duration {
        return Err(BenchError::Case(format!(
            "{file}: --prepare {} s is not shorter than the scene's {duration} s",
            options.prepare_s
        )));
    }
    let rotation = matches!(scene.contact, ContactSettings::Hertz(_));
    // The step every code takes: the scene's explicit one, else cgdem's choice.
    let mut dt = match (&scene.contact, scene.time_step) {
        (_, TimeStepRequest::Explicit(dt)) => Some(dt),
        (ContactSettings::Wca(_), _) => Some(
            cgdem_core::run::time_step(&scene, false)
                .map_err(|e| BenchError::Case(e.to_string()))?
                .0,
        ),
        _ => None,
    };
    let state = if options.prepare_s > 0.0 {
        let dir = options.out.join(&scene.name).join("prepare");
        let threads = options.threads.iter().copied().max().unwrap_or(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| BenchError::Case(e.to_string()))?;
        // In a pool of its own: rayon calls from outside any pool would each be handed over
        // to the global pool and waited for.
        let summary = pool
            .install(|| {
                run(
                    &with_duration(&scene, options.prepare_s),
                    &RunOptions {
                        out_dir: dir,
                        keep_final_state: true,
                        ..Default::default()
                    },
                )
            })
            .map_err(|e| BenchError::Case(format!("preparing the state: {e}")))?;
        dt = dt.or(Some(summary.dt_s));
        summary.final_state.expect("asked for the final state")
    } else {
        cgdem_core::run::initial_particles(&scene, rotation, &[])
            .map_err(|e| BenchError::Case(e.to_string()))?
    };
    let Some(dt) = dt else {
        return Err(BenchError::Case(format!(
            "{file}: give the time step ([time] dt) or --prepare > 0: a Hertz scene's step is chosen when cgdem runs it"
        )));
    };
    let window = options.steps as Real * dt;
    let remaining = duration - options.prepare_s;
    Ok(PreparedCase {
        name: scene.name.clone(),
        source: std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()),
        base: scene.name.clone(),
        state_file: None,
        timed: with_duration(&scene, window),
        full: (options.outcome && remaining > window).then(|| with_duration(&scene, remaining)),
        state,
        dt,
        reference_codes: rotation,
        grid: None,
    })
}

/// The scene cut to one stage of `duration`, with one output row (or dump frame) at its end
/// and no VTK, so that output costs every code the same (nothing).
pub(super) fn with_duration(scene: &Scene, duration: Real) -> Scene {
    let mut s = scene.clone();
    s.stages[0].end = StageEnd::Duration(duration);
    s.output.timeseries_interval = duration;
    s.output.vtk_interval = 0.0;
    s
}
