//! The bench's runs: each code (each build of a reference code) on each prepared case at
//! each worker count, in alternation, timed by its own step loop; cgdem's MPI ranks under
//! `mpirun`; the untimed runs to the scene's end that measure the heap each code leaves.

use std::path::{Path, PathBuf};

use super::builds::{self, Build, Launch};
use super::measurement::mobile_centroid;
use super::suite::PreparedCase;
use super::{BenchError, BenchMemory, BenchOptions, BenchOutcome, BenchRun};
use crate::decks::postprocess::log_timing;
use crate::decks::{self, lammps, liggghts, read_dump, runner, RunStatus, RunnerOptions};
use crate::suite::Code;
use cgdem_core::analysis::conical_heap::conical_heap;
use cgdem_core::math::{Real, Vec3};
use cgdem_core::run::{run, RunOptions};
use cgdem_core::scene::{Scene, StageEnd};

/// Who makes one run: cgdem on threads, cgdem as MPI ranks (`--np`), or a reference build
/// launched one way.
#[derive(Clone, Copy, Debug)]
pub(super) enum Runner<'b> {
    Cgdem,
    CgdemRanks(usize),
    Reference(&'b Build, Launch),
}

impl Runner<'_> {
    pub(super) fn code(&self) -> Code {
        match self {
            Runner::Cgdem | Runner::CgdemRanks(_) => Code::Cgdem,
            Runner::Reference(b, _) => b.code,
        }
    }

    fn build(&self) -> Option<String> {
        match self {
            Runner::Reference(b, _) => Some(b.label.clone()),
            _ => None,
        }
    }
}

/// The run's directory below the case's: `cgdem-t2-r0`, `cgdem-np2-r0`,
/// `lammps-LABEL-np2-r0`, `lammps-LABEL-omp2-r0`.
pub(super) fn run_dir(runner: Runner, threads: usize, repetition: usize) -> String {
    let how = match runner {
        Runner::Cgdem => format!("cgdem-t{threads}"),
        Runner::CgdemRanks(n) => format!("cgdem-np{n}"),
        Runner::Reference(b, launch) => {
            let how = match launch {
                Launch::Ranks(1) => "t1".to_string(),
                Launch::Ranks(n) => format!("np{n}"),
                Launch::OpenMp(n) => format!("omp{n}"),
            };
            format!("{}-{}-{how}", b.code.name(), b.label)
        }
    };
    format!("{how}-r{repetition}")
}

/// One run of `runner` on `scene` from the case's state in `dir`, plus cgdem's summary (with
/// its final particles).
fn run_code(
    case: &PreparedCase,
    scene: &Scene,
    runner: Runner,
    threads: usize,
    dir: &Path,
    options: &BenchOptions,
) -> (RunResult, Option<cgdem_core::run::RunSummary>) {
    let mut result = RunResult::default();
    let launch = match runner {
        Runner::Reference(_, launch) => launch,
        _ => Launch::Ranks(threads),
    };
    match runner.code() {
        Code::Cgdem => {
            let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
                Ok(pool) => pool,
                Err(e) => return (RunResult::failed(e.to_string()), None),
            };
            let run_options = RunOptions {
                out_dir: dir.to_path_buf(),
                initial_state: Some(case.state.clone()),
                keep_final_state: true,
                grid: case.grid,
                ..Default::default()
            };
            match pool.install(|| run(scene, &run_options)) {
                Ok(summary) => {
                    result.status = "completed".into();
                    result.n_particles = summary.n_particles;
                    result.steps = summary.steps;
                    result.loop_s = Some(summary.wall_s);
                    result.particle_steps = Some(summary.particle_steps);
                    result.memory = summary.memory;
                    return (result, Some(summary));
                }
                Err(e) => return (RunResult::failed(e.to_string()), None),
            }
        }
        Code::Liggghts | Code::Lammps if case.grid.is_some() => {
            result.status = "skipped".into();
            result.reason = Some(format!(
                "`{}` is cgdem's decomposed run; the reference codes run the undecomposed case",
                case.name
            ));
            return (result, None);
        }
        Code::Liggghts | Code::Lammps if !case.reference_codes => {
            result.status = "skipped".into();
            result.reason = Some(format!(
                "the reference decks are written for Hertz scenes; `{}` uses the WCA model of Hirose (cgdem alone)",
                case.name
            ));
            return (result, None);
        }
        code => {
            let Runner::Reference(build, _) = runner else {
                return (RunResult::failed("no build to run".into()), None);
            };
            let (deck, log_file) = match code {
                Code::Liggghts => (
                    liggghts::write_deck(scene, &case.state, case.dt),
                    liggghts::LOG_FILE,
                ),
                _ => (
                    lammps::write_hertz_deck_for(scene, &case.state, case.dt, build.wall_modulus()),
                    lammps::LOG_FILE,
                ),
            };
            let run = |dir: &Path| run_build(build, launch, dir, log_file, options);
            finish_reference(deck, dir, run, log_file, &mut result);
        }
    }
    (result, None)
}

/// Runs the deck in `dir` with `build`, launched as `launch`; a build that is not installed
/// is a skipped run.
fn run_build(
    build: &Build,
    launch: Launch,
    dir: &Path,
    log_file: &str,
    options: &BenchOptions,
) -> RunStatus {
    let found = match &build.found {
        Ok(found) => found,
        Err(reason) => {
            return RunStatus::Skipped {
                reason: reason.clone(),
                install_hint: decks::INSTALL_HINT.into(),
            }
        }
    };
    let argv = builds::command(found, launch, decks::DECK_FILE, log_file, runner::cores());
    let runner = RunnerOptions {
        stop: None,
        // The CPU-time limit is per worker, rank or thread.
        np: Some(launch.workers() as u32),
        timeout: options.timeout,
    };
    runner::run_command(&argv, dir, log_file, &runner)
}

#[derive(Clone, Debug, Default)]
struct RunResult {
    status: String,
    reason: Option<String>,
    n_particles: usize,
    steps: u64,
    loop_s: Option<Real>,
    particle_steps: Option<u64>,
    memory: Option<cgdem_core::memory_use::MemoryUse>,
    memory_mb: Option<Real>,
}

impl RunResult {
    fn failed(reason: String) -> RunResult {
        RunResult {
            status: "failed".into(),
            reason: Some(reason),
            ..Default::default()
        }
    }
}

fn finish_reference(
    deck: Result<decks::Deck, decks::DeckError>,
    dir: &Path,
    run_deck: impl Fn(&Path) -> RunStatus,
    log_file: &str,
    result: &mut RunResult,
) {
    let deck = match deck {
        Ok(deck) => deck,
        Err(e) => {
            *result = RunResult::failed(e.to_string());
            return;
        }
    };
    if let Err(e) = deck.write_to(dir) {
        *result = RunResult::failed(format!("cannot write the deck into {}: {e}", dir.display()));
        return;
    }
    match run_deck(dir) {
        RunStatus::Completed { .. } => {
            let log = std::fs::read_to_string(dir.join(log_file)).unwrap_or_default();
            let timing = log_timing(&log);
            match timing {
                Some(t) => {
                    result.status = "completed".into();
                    result.n_particles = t.atoms;
                    result.steps = t.steps;
                    result.loop_s = Some(t.loop_s);
                    result.particle_steps = Some(t.particle_steps);
                    result.memory_mb = t.memory_mb;
                }
                None => {
                    *result = RunResult::failed(format!(
                        "{}: no `Loop time of ...` line",
                        dir.join(log_file).display()
                    ))
                }
            }
        }
        other => *result = not_completed(other),
    }
}

/// The result of a run that did not complete: skipped (with how to install what is
/// missing), failed (with the log's tail) or timed out.
fn not_completed(status: RunStatus) -> RunResult {
    let mut result = RunResult::default();
    match status {
        RunStatus::Completed { .. } => result.status = "completed".into(),
        RunStatus::Skipped {
            reason,
            install_hint,
        } => {
            result.status = "skipped".into();
            result.reason = Some(format!("{reason}; install with `{install_hint}`"));
        }
        RunStatus::Failed {
            exit_code,
            log_tail,
        } => {
            result = RunResult::failed(format!("exit code {exit_code:?}; log tail:\n{log_tail}"));
        }
        RunStatus::TimedOut {
            after_s,
            cpu_s,
            log_tail,
        } => {
            result.status = "timed out".into();
            result.reason = Some(format!(
                "killed after {cpu_s:.0} s of CPU per rank ({after_s:.0} s of wall clock); log tail:\n{log_tail}"
            ));
        }
    }
    result
}

pub(super) fn timed_run(
    case: &PreparedCase,
    runner: Runner,
    threads: usize,
    repetition: usize,
    dir: &Path,
    options: &BenchOptions,
) -> (BenchRun, Option<BenchMemory>) {
    let (result, _) = run_code(case, &case.timed, runner, threads, dir, options);
    let per_s = match (result.particle_steps, result.loop_s) {
        (Some(ps), Some(s)) if s > 0.0 => Some(ps as Real / s),
        _ => None,
    };
    let memory = result.memory.map(|m| BenchMemory {
        case: case.name.clone(),
        bytes_per_particle: m.particle_bytes as Real / m.particles.max(1) as Real,
        bytes_per_listed_pair: m.pair_bytes as Real / m.pairs.max(1) as Real,
        listed_pairs: m.pairs,
        history_entries: m.history_entries,
    });
    let memory_mb = result
        .memory
        .map(|m| (m.particle_bytes + m.pair_bytes) as Real / 1e6)
        .or(result.memory_mb);
    (
        BenchRun {
            case: case.name.clone(),
            code: runner.code(),
            build: runner.build(),
            threads,
            ranks: match runner {
                Runner::Reference(_, launch) => launch.ranks(),
                _ => None,
            },
            openmp_threads: match runner {
                Runner::Reference(_, launch) => launch.openmp_threads(),
                _ => None,
            },
            repetition,
            status: result.status,
            reason: result.reason,
            n_particles: result.n_particles,
            steps: result.steps,
            loop_s: result.loop_s,
            particle_steps_per_s: per_s,
            memory_mb,
            dir: dir.to_path_buf(),
        },
        memory,
    )
}

/// The runs at `threads` workers in alternation order: each case with each code on threads
/// (when `threads` is one of `--threads`), a reference code as each of its builds, each
/// build as ranks and (with OPENMP) as threads; after cgdem's threaded run of a decomposed
/// case, its run as that many MPI ranks (when `threads` is one of `--np`).
pub(super) fn run_order<'c, 'b>(
    cases: &'c [PreparedCase],
    builds: &'b [Build],
    options: &BenchOptions,
    threads: usize,
) -> Vec<(&'c PreparedCase, Runner<'b>)> {
    let threaded = options.threads.contains(&threads);
    let ranks = options.np.contains(&threads);
    let mut order = Vec::new();
    for case in cases {
        for &code in &options.codes {
            if code == Code::Cgdem {
                if threaded {
                    order.push((case, Runner::Cgdem));
                }
                if ranks && case.grid.is_some() {
                    order.push((case, Runner::CgdemRanks(threads)));
                }
                continue;
            }
            for build in builds.iter().filter(|b| b.code == code && threaded) {
                for launch in build.launches(threads) {
                    order.push((case, Runner::Reference(build, launch)));
                }
            }
        }
    }
    order
}

/// With `--np`: the cgdem binary the ranks run, after checking what they need (a grid of at
/// least as many subdomains, cgdem in the codes, `mpirun`, a binary built with MPI); None
/// without `--np`.
pub(super) fn check_ranks(options: &BenchOptions) -> Result<Option<PathBuf>, BenchError> {
    let Some(&most) = options.np.iter().max() else {
        return Ok(None);
    };
    if !options.codes.contains(&Code::Cgdem) {
        return Err(BenchError::Ranks(
            "the ranks are cgdem's: add cgdem to --codes".into(),
        ));
    }
    // A zero among the counts is refused as such, whatever the largest.
    let np = if options.np.contains(&0) { 0 } else { most };
    crate::ranks::Ranks::checked(np, options.grid, options.cgdem_bin.as_deref())
        .map(|r| Some(r.bin))
        .map_err(BenchError::Ranks)
}

/// The scene overrides that make a case file's scene the bench's timed scene (as
/// `with_duration` makes it): one stage of `duration`, one output row at its end, no VTK.
fn timed_overrides(duration: Real) -> Vec<String> {
    // `{:?}` keeps every digit (and a `.` or exponent, so TOML reads a float).
    vec![
        format!("stage[0].duration={duration:?}"),
        format!("output.timeseries_interval={duration:?}"),
        "output.vtk_interval=0.0".into(),
    ]
}

/// `mpirun -np N BIN run CASE --set ... --initial-state STATE --grid G --threads 1 --out DIR`:
/// the ranks run of a decomposed case from its prepared state (one thread per rank).
pub(super) fn ranks_command(
    case: &PreparedCase,
    bin: &Path,
    np: usize,
    cores: usize,
    dir: &Path,
) -> Vec<String> {
    let duration = match case.timed.stages[0].end {
        StageEnd::Duration(d) => d,
        StageEnd::Settled { max_duration, .. } => max_duration,
    };
    let mut argv = runner::mpirun_argv(np as u32, cores);
    argv.extend([
        bin.display().to_string(),
        "run".into(),
        case.source.display().to_string(),
    ]);
    for o in timed_overrides(duration) {
        argv.extend(["--set".into(), o]);
    }
    let state = case.state_file.as_deref().unwrap_or(Path::new(""));
    argv.extend([
        "--initial-state".into(),
        state.display().to_string(),
        "--grid".into(),
        case.grid.map_or(String::new(), |g| g.to_string()),
        "--threads".into(),
        "1".into(),
        "--out".into(),
        dir.display().to_string(),
        "--quiet".into(),
    ]);
    argv
}

/// One timed run of a decomposed case as `np` MPI ranks of `bin`; the figures are rank 0's
/// summary.json (its step loop, as the threaded runs'). Memory is not reported: each rank
/// counts only its own subdomains.
pub(super) fn ranks_run(
    case: &PreparedCase,
    bin: &Path,
    np: usize,
    repetition: usize,
    dir: &Path,
    options: &BenchOptions,
) -> BenchRun {
    let dir = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
    let result = match std::fs::create_dir_all(&dir) {
        Err(e) => RunResult::failed(format!("cannot create {}: {e}", dir.display())),
        Ok(()) => {
            let argv = ranks_command(case, bin, np, runner::cores(), &dir);
            let runner = RunnerOptions {
                np: None,
                timeout: options.timeout,
                stop: None,
            };
            match runner::run_command(&argv, &dir, "stdout.txt", &runner) {
                RunStatus::Completed { .. } => read_cgdem_summary(&dir),
                other => not_completed(other),
            }
        }
    };
    let per_s = match (result.particle_steps, result.loop_s) {
        (Some(ps), Some(s)) if s > 0.0 => Some(ps as Real / s),
        _ => None,
    };
    BenchRun {
        case: case.name.clone(),
        code: Code::Cgdem,
        build: None,
        threads: np,
        ranks: Some(np),
        openmp_threads: None,
        repetition,
        status: result.status,
        reason: result.reason,
        n_particles: result.n_particles,
        steps: result.steps,
        loop_s: result.loop_s,
        particle_steps_per_s: per_s,
        memory_mb: None,
        dir,
    }
}

/// A completed cgdem run's figures from its `summary.json`.
fn read_cgdem_summary(dir: &Path) -> RunResult {
    let path = dir.join("summary.json");
    let summary: Result<cgdem_core::run::RunSummary, String> = std::fs::read_to_string(&path)
        .map_err(|e| e.to_string())
        .and_then(|text| serde_json::from_str(&text).map_err(|e| e.to_string()));
    match summary {
        Ok(s) => RunResult {
            status: "completed".into(),
            n_particles: s.n_particles,
            steps: s.steps,
            loop_s: Some(s.wall_s),
            particle_steps: Some(s.particle_steps),
            ..Default::default()
        },
        Err(e) => RunResult::failed(format!("{}: {e}", path.display())),
    }
}

pub(super) fn outcome_run(
    case: &PreparedCase,
    runner: Runner,
    threads: usize,
    options: &BenchOptions,
) -> BenchOutcome {
    let (code, build) = (runner.code(), runner.build());
    let Some(full) = &case.full else {
        return BenchOutcome {
            case: case.name.clone(),
            code,
            build,
            status: "skipped: the timed window already reaches the scene's end".into(),
            simulated_s: 0.0,
            heap: None,
        };
    };
    let name = match &build {
        Some(b) => format!("{}-{b}-outcome", code.name()),
        None => format!("{}-outcome", code.name()),
    };
    let dir = options.out.join(&case.name).join(name);
    let (result, summary) = run_code(case, full, runner, threads, &dir, options);
    let simulated_s = match full.stages[0].end {
        StageEnd::Duration(d) => d,
        _ => 0.0,
    };
    let frozen: Vec<bool> = full.species.iter().map(|s| s.frozen).collect();
    let axis = mobile_centroid(&case.state);
    let floor_z = full.domain.lo.z;
    let ring = full.max_diameter();
    let heap = match (code, &summary) {
        (Code::Cgdem, Some(s)) => s.final_state.as_ref().and_then(|p| {
            conical_heap(
                &p.position,
                &p.radius,
                |k| !p.is_frozen(k),
                axis,
                floor_z,
                ring,
            )
        }),
        (Code::Liggghts | Code::Lammps, _) if result.status == "completed" => {
            let path = dir.join(decks::TRAJECTORY_FILE);
            match read_dump(&path) {
                Ok(frames) => frames.last().and_then(|f| {
                    let (x, y, z, r, t) = (
                        f.column("x")?,
                        f.column("y")?,
                        f.column("z")?,
                        f.column("radius")?,
                        f.column("type")?,
                    );
                    let positions: Vec<Vec3> =
                        (0..f.len()).map(|k| Vec3::new(x[k], y[k], z[k])).collect();
                    conical_heap(
                        &positions,
                        r,
                        |k| !frozen.get(t[k] as usize - 1).copied().unwrap_or(false),
                        axis,
                        floor_z,
                        ring,
                    )
                }),
                Err(e) => {
                    return BenchOutcome {
                        case: case.name.clone(),
                        code,
                        build,
                        status: format!("failed: {e}"),
                        simulated_s,
                        heap: None,
                    }
                }
            }
        }
        _ => None,
    };
    BenchOutcome {
        case: case.name.clone(),
        code,
        build,
        status: match &result.reason {
            Some(reason) => format!("{}: {reason}", result.status),
            None => result.status.clone(),
        },
        simulated_s,
        heap,
    }
}
