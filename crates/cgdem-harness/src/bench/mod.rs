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
//!
//! Each reference code may be timed in several builds (`--build lammps=LABEL:PATH`), each in
//! the same alternation, with rows of its own; at more than one worker a LAMMPS build with
//! the OPENMP package also runs as one process of OpenMP threads. The report names the
//! fastest build of each code at each worker count, with cgdem's ratio to it.

//!
//! Its phases, one file each: `suite` (the cases prepared to time), `builds` (the reference
//! builds found and probed), `runs` (every code, build, case and worker count in
//! alternation, and the outcome runs), `measurement` (medians and ratios) and `report`
//! (`bench.json`, the CSV, the figure and the printed text).

pub mod builds;
mod measurement;
mod report;
mod runs;
mod suite;
#[cfg(test)]
mod tests;

pub use report::format_report;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;

use serde::Serialize;

use crate::suite::Code;
use builds::{Build, BuildSpec};
use cgdem_core::analysis::conical_heap::ConicalHeap;
use cgdem_core::decomposition::GridSpec;
use cgdem_core::math::Real;
use measurement::{fastest, medians, rank_ratios, ratios};
use report::write_report;
use runs::{check_ranks, outcome_run, ranks_run, run_dir, run_order, timed_run, Runner};
use suite::{prepare, PreparedCase};

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
    /// The reference builds to time (`--build`); a code none is given for runs its default
    /// build.
    pub builds: Vec<BuildSpec>,
}

#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("{0}")]
    Case(String),
    #[error("{path}: {message}")]
    Output { path: PathBuf, message: String },
    #[error("--np: {0}")]
    Ranks(String),
    #[error("{0}")]
    Build(String),
}

/// One timed run.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRun {
    pub case: String,
    pub code: Code,
    /// The reference code's build (its label); none for cgdem.
    pub build: Option<String>,
    /// Workers: cgdem's threads, or the MPI ranks of a reference code or of cgdem (`--np`).
    pub threads: usize,
    /// MPI ranks when the run was started by `mpirun` (the reference codes beyond one
    /// worker, cgdem under `--np`); none for one process.
    pub ranks: Option<usize>,
    /// OpenMP threads of a reference run as one process (`-sf omp`).
    pub openmp_threads: Option<usize>,
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
    pub build: Option<String>,
    pub threads: usize,
    pub ranks: Option<usize>,
    pub openmp_threads: Option<usize>,
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

/// The fastest build of a reference code at one worker count (over its builds, ranks and
/// OpenMP runs), and cgdem over it.
#[derive(Clone, Debug, Serialize)]
pub struct BenchFastest {
    pub case: String,
    pub code: Code,
    pub threads: usize,
    /// The fastest row, as the tables name it.
    pub row: String,
    pub median_particle_steps_per_s: Real,
    /// cgdem on threads over that row, median of the per-repetition ratios.
    pub cgdem_over_fastest: Option<Real>,
}

#[derive(Clone, Debug, Serialize)]
pub struct BenchOutcome {
    pub case: String,
    pub code: Code,
    pub build: Option<String>,
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
    pub fastest: Vec<BenchFastest>,
    pub outcomes: Vec<BenchOutcome>,
    pub memory: Vec<BenchMemory>,
}

pub fn bench(options: &BenchOptions) -> Result<BenchReport, BenchError> {
    let ranks_bin = check_ranks(options)?;
    let builds = builds::resolve(&options.codes, &options.builds)?;
    let cases = prepare_cases(options, ranks_bin.is_some())?;
    let mut runs: Vec<BenchRun> = Vec::new();
    let mut memory = Vec::new();
    // Worker counts: threads (and the reference codes' ranks), and cgdem's ranks.
    let mut workers: Vec<usize> = options.threads.iter().chain(&options.np).copied().collect();
    workers.sort_unstable();
    workers.dedup();
    for &threads in &workers {
        for repetition in 0..options.pairs {
            // Every (case, code, build) in turn, the whole sequence reversed on odd
            // repetitions (A B C, C B A), so adjacent runs make each ratio.
            let mut order = run_order(&cases, &builds, options, threads);
            if repetition % 2 == 1 {
                order.reverse();
            }
            for (case, runner) in order {
                let dir = out_dir(options, case, runner, threads, repetition);
                let (run, mem) = match (runner, &ranks_bin) {
                    (Runner::CgdemRanks(n), Some(bin)) => {
                        (ranks_run(case, bin, n, repetition, &dir, options), None)
                    }
                    _ => timed_run(case, runner, threads, repetition, &dir, options),
                };
                eprintln!(
                    "bench {} {} threads={threads} rep={repetition}: {}",
                    case.name,
                    run.label(),
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
    let report = BenchReport {
        provenance: provenance(&builds),
        steps: options.steps,
        prepare_s: options.prepare_s,
        medians: medians(&runs),
        ratios: all_ratios(&runs, &cases),
        fastest: fastest(&runs),
        outcomes: outcomes(&cases, &builds, options),
        runs,
        memory,
    };
    write_report(&report, &options.out)?;
    Ok(report)
}

fn out_dir(
    options: &BenchOptions,
    case: &PreparedCase,
    runner: Runner,
    threads: usize,
    repetition: usize,
) -> PathBuf {
    options
        .out
        .join(&case.name)
        .join(run_dir(runner, threads, repetition))
}

/// Each case prepared, and after it its decomposed copy with `--grid` (with the state file
/// its ranks start from when they run).
fn prepare_cases(options: &BenchOptions, ranks: bool) -> Result<Vec<PreparedCase>, BenchError> {
    let out = &options.out;
    let mut cases = Vec::new();
    for path in &options.cases {
        let case = prepare(path, options)?;
        let Some(grid) = options.grid else {
            cases.push(case);
            continue;
        };
        let mut decomposed = case.clone();
        decomposed.name = format!("{}-grid{grid}", case.name);
        decomposed.grid = Some(grid);
        if ranks {
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
    }
    Ok(cases)
}

fn all_ratios(runs: &[BenchRun], cases: &[PreparedCase]) -> Vec<BenchRatio> {
    let names: Vec<String> = cases.iter().map(|c| c.name.clone()).collect();
    let mut out = ratios(runs, &names);
    out.extend(rank_ratios(
        runs,
        &cases
            .iter()
            .filter(|c| c.grid.is_some())
            .map(|c| (c.name.clone(), c.base.clone()))
            .collect::<Vec<_>>(),
    ));
    out
}

/// With `options.outcome`, each case run to the scene's end by cgdem and by every build.
fn outcomes(cases: &[PreparedCase], builds: &[Build], options: &BenchOptions) -> Vec<BenchOutcome> {
    let mut out = Vec::new();
    if !options.outcome {
        return out;
    }
    let threads = options.threads.iter().copied().max().unwrap_or(1);
    for case in cases {
        if options.codes.contains(&Code::Cgdem) {
            out.push(outcome_run(case, Runner::Cgdem, threads, options));
        }
        for build in builds {
            let runner = Runner::Reference(build, builds::Launch::Ranks(threads));
            out.push(outcome_run(case, runner, threads, options));
        }
    }
    out
}

/// The machine, and each build: its banner and binary (or why it is missing).
fn provenance(builds: &[Build]) -> BTreeMap<String, String> {
    let mut p = crate::validation::machine_provenance();
    for b in builds {
        let what = match &b.found {
            Ok(f) => format!(
                "{}{}",
                f.version.describe(),
                if f.openmp { "; OPENMP" } else { "" }
            ),
            Err(reason) => format!("not available: {reason}"),
        };
        p.insert(format!("{} build {}", b.code.label(), b.label), what);
    }
    p
}

/// How a run is named in the tables and plots: the code, a reference build's label, and how
/// it used its workers (cgdem's MPI ranks, a reference code's ranks or OpenMP threads).
pub fn label(
    code: Code,
    build: Option<&str>,
    ranks: Option<usize>,
    openmp_threads: Option<usize>,
) -> String {
    let mut s = code.name().to_string();
    if let Some(b) = build {
        s = format!("{s} {b}");
    }
    match (code, ranks, openmp_threads) {
        (_, _, Some(t)) => format!("{s} (1 rank x {t} OpenMP threads)"),
        (Code::Cgdem, Some(1), _) => format!("{s} (1 rank)"),
        (_, Some(n), _) => format!("{s} ({n} ranks)"),
        _ => s,
    }
}

impl BenchRun {
    pub fn label(&self) -> String {
        label(
            self.code,
            self.build.as_deref(),
            self.ranks,
            self.openmp_threads,
        )
    }
}

impl BenchMedian {
    pub fn label(&self) -> String {
        label(
            self.code,
            self.build.as_deref(),
            self.ranks,
            self.openmp_threads,
        )
    }
}
