//! `cgdem bench`: throughput of cgdem, LIGGGHTS and LAMMPS on the same case, measured side
//! by side.
//!
//! Every code starts from one prepared state (cgdem runs the case for `prepare_s` first, so
//! the timed window is a heap that is forming, not particles in free fall), with identical
//! particles, physics, time step and step count. The codes alternate within each repetition
//! (forward order on even repetitions, reverse on odd ones), so machine drift hits all alike,
//! and each repetition gives one ratio cgdem / other from adjacent runs; the report quotes
//! medians. Throughput is particles times steps over the loop time (LAMMPS and LIGGGHTS:
//! their `Loop time` line; cgdem: its step loop), so start-up and file reading are excluded
//! from every code alike.
//!
//! A separate, untimed run of each code from the same state to the scene's end measures the
//! outcome (height and flank slope of the heap), so that the speed is compared on the same
//! physics.
//!
//! cgdem's MPI ranks (`np`) run the decomposed case as the reference codes run: a process
//! tree under `mpirun`, `cgdem run` on the case file with the timed scene's overrides, the
//! prepared state from a state file and `--grid`, its figures from rank 0's summary.json.
//! Their outcome is not run again: the ranks write bitwise the threaded grid's outputs.

use cgdem_core::io::CsvBuffer;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

use serde::Serialize;

use crate::decks::postprocess::log_timing;
use crate::decks::{self, lammps, liggghts, read_dump, runner, RunStatus, RunnerOptions};
use crate::report::plot::write_bar_chart;
use crate::suite::Code;
use cgdem_core::analysis::conical_heap::{conical_heap, ConicalHeap};
use cgdem_core::decomposition::GridSpec;
use cgdem_core::math::{Real, Vec3};
use cgdem_core::particles::Particles;
use cgdem_core::run::{run, RunOptions};
use cgdem_core::scene::{ContactSettings, Scene, StageEnd};
use cgdem_core::timestep::TimeStepRequest;

#[derive(Clone, Debug)]
pub struct BenchOptions {
    pub cases: Vec<PathBuf>,
    pub out: PathBuf,
    pub codes: Vec<Code>,
    /// Threads for cgdem, MPI ranks for the reference codes.
    pub threads: Vec<usize>,
    /// Repetitions of the alternating sequence.
    pub pairs: usize,
    /// Steps in each timed run.
    pub steps: u64,
    /// Simulated seconds cgdem runs the case before the timed window (0: start from the
    /// scene's insertions).
    pub prepare_s: Real,
    /// Also run each code once from the prepared state to the scene's end and compare the
    /// heap it leaves.
    pub outcome: bool,
    pub timeout: Duration,
    /// Also time cgdem decomposed into these subdomains (`--grid`), as a case of its own
    /// (`<case>-grid<G>`) run in the same alternation, so that each repetition gives the
    /// ratio decomposed / undecomposed from adjacent runs. The reference codes run the
    /// undecomposed case only.
    pub grid: Option<GridSpec>,
    /// Also time cgdem on the decomposed case as this many MPI ranks of one thread each
    /// (`mpirun -np N cgdem run --grid G --initial-state ...`, started from the prepared
    /// state), in the same alternation as the other runs at N workers.
    pub np: Vec<usize>,
    /// The cgdem the ranks run: a build with `--features mpi`.
    pub cgdem_bin: Option<PathBuf>,
}

#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("{0}")]
    Case(String),
    #[error("{path}: {message}")]
    Output { path: PathBuf, message: String },
    #[error("--np: {0}")]
    Ranks(String),
}

/// One timed run.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRun {
    pub case: String,
    pub code: Code,
    /// Workers: cgdem's threads, or the MPI ranks of a reference code or of cgdem (`--np`).
    pub threads: usize,
    /// MPI ranks when the run was started by `mpirun` (the reference codes beyond one
    /// worker, cgdem under `--np`); none for one process.
    pub ranks: Option<usize>,
    pub repetition: usize,
    /// `completed`, `skipped`, `failed` or `timed out`.
    pub status: String,
    pub reason: Option<String>,
    pub n_particles: usize,
    pub steps: u64,
    pub loop_s: Option<Real>,
    pub particle_steps_per_s: Option<Real>,
    /// Memory the code reports for its data (LAMMPS/LIGGGHTS: `Per MPI rank memory
    /// allocation`, average times ranks; cgdem: its particle, pair and history arrays), MB.
    pub memory_mb: Option<Real>,
    pub dir: PathBuf,
}

/// Medians over the repetitions of one case, code and thread count.
#[derive(Clone, Debug, Serialize)]
pub struct BenchMedian {
    pub case: String,
    pub code: Code,
    pub threads: usize,
    pub ranks: Option<usize>,
    pub runs: usize,
    pub median_particle_steps_per_s: Real,
    pub min_particle_steps_per_s: Real,
    pub max_particle_steps_per_s: Real,
    /// Median throughput at this worker count over `threads` times the median of the same
    /// case and code at one worker (in one process for cgdem's ranks).
    pub parallel_efficiency: Option<Real>,
}

/// cgdem over another code (or over itself on another case), per repetition and median.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRatio {
    pub numerator: String,
    pub denominator: String,
    pub threads: usize,
    pub per_repetition: Vec<Real>,
    pub median: Real,
}

#[derive(Clone, Debug, Serialize)]
pub struct BenchOutcome {
    pub case: String,
    pub code: Code,
    pub status: String,
    pub simulated_s: Real,
    pub heap: Option<ConicalHeap>,
}

/// cgdem's memory for one case (arrays at their capacity at the end of the timed run).
#[derive(Clone, Debug, Serialize)]
pub struct BenchMemory {
    pub case: String,
    pub bytes_per_particle: Real,
    pub bytes_per_listed_pair: Real,
    pub listed_pairs: usize,
    pub history_entries: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    pub provenance: BTreeMap<String, String>,
    pub steps: u64,
    pub prepare_s: Real,
    pub runs: Vec<BenchRun>,
    pub medians: Vec<BenchMedian>,
    pub ratios: Vec<BenchRatio>,
    pub outcomes: Vec<BenchOutcome>,
    pub memory: Vec<BenchMemory>,
}

/// A case ready to time: the scene cut to `steps`, its step and the prepared state.
#[derive(Clone)]
struct PreparedCase {
    name: String,
    /// The case file, absolute (the ranks' command line reads it).
    source: PathBuf,
    /// The undecomposed case this one was derived from (itself if it is).
    base: String,
    timed: Scene,
    full: Option<Scene>,
    state: Particles,
    dt: Real,
    reference_codes: bool,
    /// cgdem runs decomposed into this grid (the reference codes skip the case).
    grid: Option<GridSpec>,
    /// `state` written for the ranks (`--np`).
    state_file: Option<PathBuf>,
}

pub fn bench(options: &BenchOptions) -> Result<BenchReport, BenchError> {
    let out = &options.out;
    let ranks_bin = check_ranks(options)?;
    let mut cases = Vec::new();
    for path in &options.cases {
        let case = prepare(path, options)?;
        if let Some(grid) = options.grid {
            let mut decomposed = case.clone();
            decomposed.name = format!("{}-grid{grid}", case.name);
            decomposed.grid = Some(grid);
            if ranks_bin.is_some() {
                let path = out.join(&decomposed.name).join("state.cgs");
                std::fs::create_dir_all(out.join(&decomposed.name))
                    .and_then(|_| cgdem_core::run::state_file::write(&path, &case.state))
                    .map_err(|e| BenchError::Output {
                        path: path.clone(),
                        message: e.to_string(),
                    })?;
                decomposed.state_file = Some(path);
            }
            cases.push(case);
            cases.push(decomposed);
        } else {
            cases.push(case);
        }
    }
    let mut runs: Vec<BenchRun> = Vec::new();
    let mut memory = Vec::new();
    // Worker counts: threads (and the reference codes' ranks), and cgdem's ranks.
    let mut workers: Vec<usize> = options.threads.iter().chain(&options.np).copied().collect();
    workers.sort_unstable();
    workers.dedup();
    for &threads in &workers {
        for repetition in 0..options.pairs {
            // Every (case, code) in turn, the whole sequence reversed on odd repetitions
            // (A B C, C B A), so adjacent runs make each ratio.
            let mut order = run_order(&cases, options, threads);
            if repetition % 2 == 1 {
                order.reverse();
            }
            for (case, code, ranks) in order {
                let dir = out.join(&case.name).join(match ranks {
                    Some(n) => format!("{}-np{n}-r{repetition}", code.name()),
                    None => format!("{}-t{threads}-r{repetition}", code.name()),
                });
                let (run, mem) = match (ranks, &ranks_bin) {
                    (Some(n), Some(bin)) => {
                        (ranks_run(case, bin, n, repetition, &dir, options), None)
                    }
                    _ => timed_run(case, code, threads, repetition, &dir, options),
                };
                eprintln!(
                    "bench {} {} threads={threads} rep={repetition}: {}",
                    case.name,
                    label(code, run.ranks),
                    run.particle_steps_per_s
                        .map_or(run.status.clone(), |v| format!("{v:.3e} particle-steps/s"))
                );
                if let Some(m) = mem {
                    if memory.iter().all(|x: &BenchMemory| x.case != m.case) {
                        memory.push(m);
                    }
                }
                runs.push(run);
            }
        }
    }
    let medians = medians(&runs);
    let mut ratios = ratios(
        &runs,
        &cases.iter().map(|c| c.name.clone()).collect::<Vec<_>>(),
    );
    ratios.extend(rank_ratios(
        &runs,
        &cases
            .iter()
            .filter(|c| c.grid.is_some())
            .map(|c| (c.name.clone(), c.base.clone()))
            .collect::<Vec<_>>(),
    ));
    let mut outcomes = Vec::new();
    if options.outcome {
        let threads = options.threads.iter().copied().max().unwrap_or(1);
        for case in &cases {
            for &code in &options.codes {
                outcomes.push(outcome_run(case, code, threads, options));
            }
        }
    }
    let report = BenchReport {
        provenance: crate::validate::machine_provenance(),
        steps: options.steps,
        prepare_s: options.prepare_s,
        runs,
        medians,
        ratios,
        outcomes,
        memory,
    };
    write_report(&report, out)?;
    Ok(report)
}

fn prepare(path: &Path, options: &BenchOptions) -> Result<PreparedCase, BenchError> {
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
fn with_duration(scene: &Scene, duration: Real) -> Scene {
    let mut s = scene.clone();
    s.stages[0].end = StageEnd::Duration(duration);
    s.output.timeseries_interval = duration;
    s.output.vtk_interval = 0.0;
    s
}

fn runner(threads: usize, options: &BenchOptions) -> RunnerOptions {
    RunnerOptions {
        stop: None,
        np: (threads > 1).then_some(threads as u32),
        timeout: options.timeout,
    }
}

/// One run of `code` on `scene` from the case's state in `dir`, plus cgdem's summary (with
/// its final particles).
fn run_code(
    case: &PreparedCase,
    scene: &Scene,
    code: Code,
    threads: usize,
    dir: &Path,
    options: &BenchOptions,
) -> (RunResult, Option<cgdem_core::run::RunSummary>) {
    let mut result = RunResult::default();
    match code {
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
                "the reference decks are written for Hertz scenes; `{}` uses the seed's WCA model (cgdem alone)",
                case.name
            ));
            return (result, None);
        }
        Code::Liggghts => {
            let deck = liggghts::write_deck(scene, &case.state, case.dt);
            finish_reference(
                deck,
                dir,
                |dir| liggghts::run_deck(dir, &runner(threads, options)),
                liggghts::LOG_FILE,
                &mut result,
            );
        }
        Code::Lammps => {
            let deck = lammps::write_hertz_deck(scene, &case.state, case.dt);
            finish_reference(
                deck,
                dir,
                |dir| lammps::run_deck(dir, &runner(threads, options)),
                lammps::LOG_FILE,
                &mut result,
            );
        }
    }
    (result, None)
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
        RunStatus::TimedOut { after_s, log_tail } => {
            result.status = "timed out".into();
            result.reason = Some(format!(
                "killed after {after_s:.0} s; log tail:\n{log_tail}"
            ));
        }
    }
    result
}

fn timed_run(
    case: &PreparedCase,
    code: Code,
    threads: usize,
    repetition: usize,
    dir: &Path,
    options: &BenchOptions,
) -> (BenchRun, Option<BenchMemory>) {
    let (result, _) = run_code(case, &case.timed, code, threads, dir, options);
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
            code,
            threads,
            // The reference runner starts them under mpirun beyond one worker.
            ranks: (code != Code::Cgdem && threads > 1).then_some(threads),
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
/// (when `threads` is one of `--threads`), and after cgdem's threaded run of a decomposed
/// case, its run as that many MPI ranks (when `threads` is one of `--np`).
fn run_order<'c>(
    cases: &'c [PreparedCase],
    options: &BenchOptions,
    threads: usize,
) -> Vec<(&'c PreparedCase, Code, Option<usize>)> {
    let threaded = options.threads.contains(&threads);
    let ranks = options.np.contains(&threads);
    let mut order = Vec::new();
    for case in cases {
        for &code in &options.codes {
            if threaded {
                order.push((case, code, None));
            }
            if ranks && code == Code::Cgdem && case.grid.is_some() {
                order.push((case, code, Some(threads)));
            }
        }
    }
    order
}

/// How a code is named in the tables and plots: cgdem's MPI runs with their rank count.
pub fn label(code: Code, ranks: Option<usize>) -> String {
    match (code, ranks) {
        (Code::Cgdem, Some(1)) => "cgdem (1 rank)".into(),
        (Code::Cgdem, Some(n)) => format!("cgdem ({n} ranks)"),
        _ => code.name().into(),
    }
}

/// With `--np`: the cgdem binary the ranks run, after checking what they need (a grid of at
/// least as many subdomains, cgdem in the codes, `mpirun`, a binary built with MPI); None
/// without `--np`.
fn check_ranks(options: &BenchOptions) -> Result<Option<PathBuf>, BenchError> {
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
fn ranks_command(
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
fn ranks_run(
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
        threads: np,
        ranks: Some(np),
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

fn outcome_run(
    case: &PreparedCase,
    code: Code,
    threads: usize,
    options: &BenchOptions,
) -> BenchOutcome {
    let Some(full) = &case.full else {
        return BenchOutcome {
            case: case.name.clone(),
            code,
            status: "skipped: the timed window already reaches the scene's end".into(),
            simulated_s: 0.0,
            heap: None,
        };
    };
    let dir = options
        .out
        .join(&case.name)
        .join(format!("{}-outcome", code.name()));
    let (result, summary) = run_code(case, full, code, threads, &dir, options);
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
        status: match &result.reason {
            Some(reason) => format!("{}: {reason}", result.status),
            None => result.status.clone(),
        },
        simulated_s,
        heap,
    }
}

/// Centre (x, y) of the mobile particles: the heap's axis.
fn mobile_centroid(p: &Particles) -> Vec3 {
    let (mut sum, mut n) = (Vec3::ZERO, 0usize);
    for k in (0..p.len()).filter(|&k| !p.is_frozen(k)) {
        sum += p.position[k];
        n += 1;
    }
    if n == 0 {
        Vec3::ZERO
    } else {
        Vec3::new(sum.x / n as Real, sum.y / n as Real, 0.0)
    }
}

fn median(values: &mut [Real]) -> Real {
    values.sort_by(|a, b| a.total_cmp(b));
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

fn medians(runs: &[BenchRun]) -> Vec<BenchMedian> {
    let mut groups: BTreeMap<(String, Code, usize, Option<usize>), Vec<Real>> = BTreeMap::new();
    for r in runs {
        if let Some(v) = r.particle_steps_per_s {
            groups
                .entry((r.case.clone(), r.code, r.threads, r.ranks))
                .or_default()
                .push(v);
        }
    }
    let mut out: Vec<BenchMedian> = groups
        .iter()
        .map(|((case, code, threads, ranks), values)| {
            let mut v = values.clone();
            BenchMedian {
                case: case.clone(),
                code: *code,
                threads: *threads,
                ranks: *ranks,
                runs: v.len(),
                median_particle_steps_per_s: median(&mut v),
                min_particle_steps_per_s: v[0],
                max_particle_steps_per_s: v[v.len() - 1],
                parallel_efficiency: None,
            }
        })
        .collect();
    // One worker: cgdem in one process (its ranks are measured against it too), a
    // reference code serial; cgdem's single rank when it ran no single thread.
    let mut singles: Vec<(String, Code, Real)> = Vec::new();
    for m in out.iter().filter(|m| m.threads == 1) {
        let base = m.code != Code::Cgdem || m.ranks.is_none();
        let known = singles.iter().position(|s| s.0 == m.case && s.1 == m.code);
        match known {
            Some(k) if base => singles[k].2 = m.median_particle_steps_per_s,
            Some(_) => {}
            None => singles.push((m.case.clone(), m.code, m.median_particle_steps_per_s)),
        }
    }
    for m in &mut out {
        if let Some((_, _, one)) = singles.iter().find(|s| s.0 == m.case && s.1 == m.code) {
            m.parallel_efficiency = Some(m.median_particle_steps_per_s / (m.threads as Real * one));
        }
    }
    out
}

/// The throughput of one run: `case`, `code` and workers in repetition `rep`, cgdem's
/// threaded run unless `cgdem_ranks`.
fn speed_of(
    runs: &[BenchRun],
    (case, code, threads, rep): (&str, Code, usize, usize),
    cgdem_ranks: bool,
) -> Option<Real> {
    runs.iter()
        .find(|r| {
            r.case == case
                && r.code == code
                && r.threads == threads
                && r.repetition == rep
                && (code != Code::Cgdem || r.ranks.is_some() == cgdem_ranks)
        })
        .and_then(|r| r.particle_steps_per_s)
}

/// The worker counts among the runs `include` accepts, each with its repetitions, in order.
fn repetitions_by_workers(
    runs: &[BenchRun],
    include: impl Fn(&BenchRun) -> bool,
) -> Vec<(usize, Vec<usize>)> {
    let mut keys: Vec<(usize, usize)> = runs
        .iter()
        .filter(|r| include(r))
        .map(|r| (r.threads, r.repetition))
        .collect();
    keys.sort();
    keys.dedup();
    let mut out: Vec<(usize, Vec<usize>)> = Vec::new();
    for (workers, rep) in keys {
        match out.last_mut() {
            Some((w, reps)) if *w == workers => reps.push(rep),
            _ => out.push((workers, vec![rep])),
        }
    }
    out
}

/// The row `numerator / denominator` at `workers`: `ratio(rep)` for every repetition that
/// measured both, with their median; None when none did.
fn ratio_row(
    numerator: String,
    denominator: String,
    workers: usize,
    reps: &[usize],
    ratio: impl Fn(usize) -> Option<Real>,
) -> Option<BenchRatio> {
    let per_repetition: Vec<Real> = reps.iter().filter_map(|&rep| ratio(rep)).collect();
    if per_repetition.is_empty() {
        return None;
    }
    let mut sorted = per_repetition.clone();
    Some(BenchRatio {
        numerator,
        denominator,
        threads: workers,
        median: median(&mut sorted),
        per_repetition,
    })
}

/// Per repetition, cgdem over each other code on the same case, and cgdem on each case over
/// cgdem on the first case (cgdem on threads).
fn ratios(runs: &[BenchRun], cases: &[String]) -> Vec<BenchRatio> {
    let speed = |case: &str, code: Code, threads: usize, rep: usize| {
        speed_of(runs, (case, code, threads, rep), false)
    };
    let mut out = Vec::new();
    for (threads, reps) in repetitions_by_workers(runs, |_| true) {
        for case in cases {
            for other in [Code::Liggghts, Code::Lammps] {
                out.extend(ratio_row(
                    format!("{case} cgdem"),
                    format!("{case} {}", other.name()),
                    threads,
                    &reps,
                    |rep| {
                        Some(
                            speed(case, Code::Cgdem, threads, rep)?
                                / speed(case, other, threads, rep)?,
                        )
                    },
                ));
            }
        }
        for case in cases.iter().skip(1) {
            out.extend(ratio_row(
                format!("{case} cgdem"),
                format!("{} cgdem", cases[0]),
                threads,
                &reps,
                |rep| {
                    Some(
                        speed(case, Code::Cgdem, threads, rep)?
                            / speed(&cases[0], Code::Cgdem, threads, rep)?,
                    )
                },
            ));
        }
    }
    out
}

/// Per repetition, cgdem's ranks on each decomposed case (`(case, base)`) over: cgdem on
/// the same case on as many threads, cgdem on the undecomposed base case, and each
/// reference code on the base case, at the same worker count.
fn rank_ratios(runs: &[BenchRun], cases: &[(String, String)]) -> Vec<BenchRatio> {
    let mut out = Vec::new();
    let with_ranks = |r: &BenchRun| r.code == Code::Cgdem && r.ranks.is_some();
    for (n, reps) in repetitions_by_workers(runs, with_ranks) {
        for (case, base) in cases {
            let ranks = |rep| speed_of(runs, (case.as_str(), Code::Cgdem, n, rep), true);
            let others = [
                (case.as_str(), Code::Cgdem),
                (base.as_str(), Code::Cgdem),
                (base.as_str(), Code::Liggghts),
                (base.as_str(), Code::Lammps),
            ];
            for (other_case, other) in others {
                out.extend(ratio_row(
                    format!("{case} {}", label(Code::Cgdem, Some(n))),
                    format!("{other_case} {}", other.name()),
                    n,
                    &reps,
                    |rep| Some(ranks(rep)? / speed_of(runs, (other_case, other, n, rep), false)?),
                ));
            }
        }
    }
    out
}

fn write_report(report: &BenchReport, out: &Path) -> Result<(), BenchError> {
    let io = |path: &Path, e: &dyn std::fmt::Display| BenchError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(out).map_err(|e| io(out, &e))?;
    let json_path = out.join("bench.json");
    let json = serde_json::to_string_pretty(report).map_err(|e| io(&json_path, &e))?;
    cgdem_core::io::write_atomic(&json_path, json.as_bytes()).map_err(|e| io(&json_path, &e))?;
    let mut csv = CsvBuffer::new([
        "case",
        "code",
        "threads",
        "ranks",
        "repetition",
        "status",
        "n_particles",
        "steps",
        "loop_s",
        "particle_steps_per_s",
        "memory_mb",
    ]);
    let opt = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    for r in &report.runs {
        csv.row([
            r.case.to_string(),
            r.code.name().to_string(),
            r.threads.to_string(),
            r.ranks.map_or(String::new(), |n| n.to_string()),
            r.repetition.to_string(),
            r.status.to_string(),
            r.n_particles.to_string(),
            r.steps.to_string(),
            opt(r.loop_s),
            opt(r.particle_steps_per_s),
            opt(r.memory_mb),
        ]);
    }
    let csv_path = out.join("bench_runs.csv");
    csv.bytes()
        .and_then(|bytes| cgdem_core::io::write_atomic(&csv_path, bytes))
        .map_err(|e| io(&csv_path, &e))?;
    let bars: Vec<(String, String, f64, Option<f64>)> = report
        .medians
        .iter()
        .map(|m| {
            (
                format!("{}, {} worker(s)", m.case, m.threads),
                label(m.code, m.ranks),
                m.median_particle_steps_per_s / 1e6,
                Some(0.5 * (m.max_particle_steps_per_s - m.min_particle_steps_per_s) / 1e6),
            )
        })
        .collect();
    if !bars.is_empty() {
        write_bar_chart(
            out,
            "throughput",
            &format!(
                "Throughput, median of {} alternating runs of {} steps (error bar: half the range)",
                report
                    .runs
                    .iter()
                    .map(|r| r.repetition + 1)
                    .max()
                    .unwrap_or(0),
                report.steps
            ),
            "million particle-steps per second",
            &bars,
        )
        .map_err(|e| io(&out.join("throughput.png"), &e))?;
    }
    Ok(())
}

/// The report as text: medians, ratios, outcomes and memory.
pub fn format_report(report: &BenchReport) -> String {
    let mut s = String::new();
    s += "case | code | workers | runs | median particle-steps/s | range | parallel efficiency\n";
    for m in &report.medians {
        s += &format!(
            "{} | {} | {} | {} | {:.3e} | {:.3e} .. {:.3e} | {}\n",
            m.case,
            label(m.code, m.ranks),
            m.threads,
            m.runs,
            m.median_particle_steps_per_s,
            m.min_particle_steps_per_s,
            m.max_particle_steps_per_s,
            m.parallel_efficiency
                .map_or("-".into(), |e| format!("{:.0}%", 100.0 * e))
        );
    }
    s += "\nratio | workers | median | per repetition\n";
    for r in &report.ratios {
        s += &format!(
            "{} / {} | {} | {:.2} | {}\n",
            r.numerator,
            r.denominator,
            r.threads,
            r.median,
            r.per_repetition
                .iter()
                .map(|v| format!("{v:.2}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    if !report.outcomes.is_empty() {
        s += "\noutcome | code | simulated s | heap height mm | edge radius mm | flank slope deg | status\n";
        for o in &report.outcomes {
            let (h, e, a) = o.heap.map_or(("-".into(), "-".into(), "-".into()), |h| {
                (
                    format!("{:.2}", 1e3 * h.height_m),
                    format!("{:.1}", 1e3 * h.edge_radius_m),
                    format!("{:.2}", h.slope_deg),
                )
            });
            s += &format!(
                "{} | {} | {:.3} | {h} | {e} | {a} | {}\n",
                o.case,
                o.code.name(),
                o.simulated_s,
                o.status.lines().next().unwrap_or("")
            );
        }
    }
    for m in &report.memory {
        s += &format!(
            "\nmemory ({}): {:.0} bytes per particle, {:.0} bytes per listed pair ({} pairs, {} history entries)\n",
            m.case, m.bytes_per_particle, m.bytes_per_listed_pair, m.listed_pairs, m.history_entries
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A completed run of `case` by `code` at `v` particle-steps per second.
    fn completed_run(
        case: &str,
        code: Code,
        threads: usize,
        ranks: Option<usize>,
        repetition: usize,
        v: Real,
    ) -> BenchRun {
        BenchRun {
            case: case.into(),
            code,
            threads,
            ranks,
            repetition,
            status: "completed".into(),
            reason: None,
            n_particles: 1,
            steps: 1,
            loop_s: Some(1.0),
            particle_steps_per_s: Some(v),
            memory_mb: None,
            dir: PathBuf::new(),
        }
    }

    #[test]
    fn ratios_pair_adjacent_runs_and_take_the_median() {
        let run = |code, rep, v| completed_run("heap", code, 1, None, rep, v);
        let runs = vec![
            run(Code::Cgdem, 0, 10.0),
            run(Code::Lammps, 0, 5.0),
            run(Code::Cgdem, 1, 9.0),
            run(Code::Lammps, 1, 3.0),
            run(Code::Cgdem, 2, 12.0),
            run(Code::Lammps, 2, 5.0),
        ];
        let r = ratios(&runs, &["heap".into()]);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].per_repetition, vec![2.0, 3.0, 2.4]);
        assert_eq!(r[0].median, 2.4);
        let m = medians(&runs);
        assert_eq!(m[0].median_particle_steps_per_s, 10.0);
        assert_eq!(m[0].parallel_efficiency, Some(1.0));
    }

    fn heap_case(grid: Option<GridSpec>) -> PreparedCase {
        let path = Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../validation/bench/heap.toml"
        ));
        let scene = Scene::load(path).unwrap();
        PreparedCase {
            name: if grid.is_some() {
                "bench_heap-grid2x1x1".into()
            } else {
                scene.name.clone()
            },
            source: path.to_path_buf(),
            base: scene.name.clone(),
            timed: with_duration(&scene, 1234.0 * 1e-5),
            full: None,
            state: Particles::new(true),
            dt: 1e-5,
            reference_codes: true,
            grid,
            state_file: Some(PathBuf::from("/tmp/bench/state.cgs")),
        }
    }

    #[test]
    fn the_ranks_run_the_timed_scene_from_the_state_on_the_grid() {
        let case = heap_case(Some(GridSpec::Given([2, 1, 1])));
        let argv = ranks_command(&case, Path::new("/opt/cgdem"), 2, 2, Path::new("/tmp/out"));
        assert_eq!(
            argv[..6],
            [
                "mpirun",
                "--allow-run-as-root",
                "-np",
                "2",
                "/opt/cgdem",
                "run"
            ]
        );
        let after = |flag: &str| {
            let k = argv.iter().position(|a| a == flag).unwrap();
            argv[k + 1].clone()
        };
        assert_eq!(after("--grid"), "2x1x1");
        assert_eq!(after("--threads"), "1");
        assert_eq!(after("--initial-state"), "/tmp/bench/state.cgs");
        assert_eq!(after("--out"), "/tmp/out");
        // The overrides turn the case file's scene into exactly the timed scene.
        let overrides: Vec<_> = argv
            .windows(2)
            .filter(|w| w[0] == "--set")
            .map(|w| cgdem_core::scene::Override::parse(&w[1], Path::new("--set")).unwrap())
            .collect();
        assert_eq!(overrides.len(), 3);
        let scene = Scene::load_with_overrides(Path::new(&argv[6]), &overrides).unwrap();
        assert!(scene == case.timed, "the ranks would run another scene");
        // More ranks than cores: OpenMPI needs --oversubscribe.
        let argv = ranks_command(&case, Path::new("/opt/cgdem"), 4, 2, Path::new("/tmp/out"));
        assert_eq!(argv[2], "--oversubscribe");
    }

    #[test]
    fn ranks_follow_the_threaded_run_of_the_decomposed_case() {
        let cases = vec![heap_case(None), heap_case(Some(GridSpec::Given([2, 1, 1])))];
        let options = BenchOptions {
            cases: Vec::new(),
            out: PathBuf::new(),
            codes: vec![Code::Cgdem, Code::Lammps],
            threads: vec![1, 2],
            pairs: 1,
            steps: 1,
            prepare_s: 0.0,
            outcome: false,
            timeout: Duration::from_secs(1),
            grid: Some(GridSpec::Given([2, 1, 1])),
            np: vec![2],
            cgdem_bin: None,
        };
        let names = |w| -> Vec<(String, Code, Option<usize>)> {
            run_order(&cases, &options, w)
                .into_iter()
                .map(|(c, code, r)| (c.name.clone(), code, r))
                .collect()
        };
        assert!(names(1).iter().all(|e| e.2.is_none()));
        assert_eq!(names(1).len(), 4);
        let two = names(2);
        assert_eq!(two.len(), 5);
        assert_eq!(two[2], ("bench_heap-grid2x1x1".into(), Code::Cgdem, None));
        assert_eq!(
            two[3],
            ("bench_heap-grid2x1x1".into(), Code::Cgdem, Some(2))
        );
    }

    #[test]
    fn bad_rank_requests_are_refused_before_anything_runs() {
        let mut options = BenchOptions {
            cases: Vec::new(),
            out: PathBuf::new(),
            codes: vec![Code::Cgdem],
            threads: vec![1],
            pairs: 1,
            steps: 1,
            prepare_s: 0.0,
            outcome: false,
            timeout: Duration::from_secs(1),
            grid: None,
            np: vec![2],
            cgdem_bin: None,
        };
        let err = |o: &BenchOptions| check_ranks(o).unwrap_err().to_string();
        assert!(err(&options).contains("--grid"), "{}", err(&options));
        options.grid = Some(GridSpec::Given([2, 1, 1]));
        options.np = vec![4];
        assert!(err(&options).contains("at least 4 subdomains"));
        options.np = vec![2];
        options.codes = vec![Code::Lammps];
        assert!(err(&options).contains("--codes"));
        options.codes = vec![Code::Cgdem];
        // A binary without MPI (echo's --version does not say "with MPI").
        if Path::new("/bin/echo").is_file() {
            options.cgdem_bin = Some(PathBuf::from("/bin/echo"));
            let e = err(&options);
            assert!(e.contains("cargo build --release --features mpi"), "{e}");
        }
        options.np = Vec::new();
        assert!(check_ranks(&options).unwrap().is_none());
    }

    #[test]
    fn ranks_get_rows_efficiency_and_ratios_of_their_own() {
        let run =
            |case: &str, code, threads, ranks, v| completed_run(case, code, threads, ranks, 0, v);
        let g = "heap-grid2x1x1";
        let runs = vec![
            run("heap", Code::Cgdem, 1, None, 10.0),
            run(g, Code::Cgdem, 1, None, 10.0),
            run("heap", Code::Cgdem, 2, None, 17.0),
            run(g, Code::Cgdem, 2, None, 18.0),
            run(g, Code::Cgdem, 2, Some(2), 19.0),
            run("heap", Code::Lammps, 2, Some(2), 12.5),
        ];
        let m = medians(&runs);
        let ranks = m
            .iter()
            .find(|m| m.ranks == Some(2) && m.code == Code::Cgdem);
        assert_eq!(ranks.unwrap().parallel_efficiency, Some(19.0 / 20.0));
        let threads = m
            .iter()
            .find(|m| m.case == g && m.threads == 2 && m.ranks.is_none());
        assert_eq!(threads.unwrap().parallel_efficiency, Some(0.9));
        // The threaded ratios ignore the ranks' runs.
        let r = ratios(&runs, &["heap".into(), g.into()]);
        let grid = r
            .iter()
            .find(|r| r.threads == 2 && r.numerator.starts_with(g));
        assert_eq!(grid.unwrap().median, 18.0 / 17.0);
        let r = rank_ratios(&runs, &[(g.into(), "heap".into())]);
        let values: Vec<(String, Real)> = r
            .iter()
            .map(|r| (r.denominator.clone(), r.median))
            .collect();
        assert_eq!(
            values,
            vec![
                (format!("{g} cgdem"), 19.0 / 18.0),
                ("heap cgdem".into(), 19.0 / 17.0),
                ("heap lammps".into(), 19.0 / 12.5),
            ]
        );
        assert_eq!(r[0].numerator, format!("{g} cgdem (2 ranks)"));
    }
}
