//! The `cgdem` command: a thin layer that turns arguments into validated settings, calls the
//! library and reports errors as messages with a non-zero exit code.

mod interrupt;
mod progress_bar;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};

use cgdem_core::coarse_graining::{
    coarse_grain_by, coarse_grain_checks, CgSeverity, CoarseGrainRule,
};
use cgdem_core::geometry::accuracy::format_accuracy_table;
use cgdem_core::geometry::screw_feeder::{self, ScrewFeederSpec};
use cgdem_core::run::restart::{self, RestartLoaded};
use cgdem_core::run::{run, CheckpointOptions, RunOptions};
use cgdem_core::scene::{Override, Scene};
use cgdem_harness::report::sdf_study::write_sdf_accuracy_study;
use cgdem_harness::sweep::Sweep;

/// The command line of `cgdem run` that a restart file stores, to rebuild the same scene
/// on `--resume` (the scene's digest is checked against the stored one).
#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct RunInvocation {
    /// Absolute, so a resume from another directory finds it.
    case: PathBuf,
    lambda: u32,
    cg_rule: CoarseGrainRule,
    seed: Option<u64>,
    set: Vec<String>,
    variant: Option<String>,
    force_dt: bool,
    keep_going: bool,
    /// `--grid` and `--balance` as given (absent in files of runs without them).
    #[serde(default)]
    grid: Option<String>,
    #[serde(default)]
    balance: Option<String>,
}

impl RunInvocation {
    /// The newest usable restart file of `dir` and the command line it stored.
    fn resumed(
        dir: &std::path::Path,
    ) -> Result<(RunInvocation, std::sync::Arc<RestartLoaded>), String> {
        let loaded = restart::read_latest(dir)?;
        let invocation = serde_json::from_str(&loaded.restart.invocation).map_err(|e| {
            format!(
                "{}: the stored command line does not decode: {e}",
                loaded.path.display()
            )
        })?;
        eprintln!("resuming from {}", loaded.path.display());
        Ok((invocation, std::sync::Arc::new(loaded)))
    }
}

/// The coarse-graining rules as command-line values (`seed`, `bulk-viscosity`,
/// `scaled-particle`, `liggghts-pfm`).
#[derive(Clone, Copy, ValueEnum)]
enum CgRule {
    Seed,
    BulkViscosity,
    ScaledParticle,
    LiggghtsPfm,
}

impl From<CgRule> for CoarseGrainRule {
    fn from(rule: CgRule) -> Self {
        match rule {
            CgRule::Seed => CoarseGrainRule::Seed,
            CgRule::BulkViscosity => CoarseGrainRule::BulkViscosity,
            CgRule::ScaledParticle => CoarseGrainRule::ScaledParticle,
            CgRule::LiggghtsPfm => CoarseGrainRule::LiggghtsPfm,
        }
    }
}

/// `cgdem --version`; a build with MPI says so (`bench --np` and `validate --np` look for
/// `cgdem_harness::ranks::MPI_MARK` in it).
#[cfg(feature = "mpi")]
const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (built with MPI: --features mpi)"
);
#[cfg(not(feature = "mpi"))]
const VERSION: &str = env!("CARGO_PKG_VERSION");

#[derive(Parser)]
#[command(
    name = "cgdem",
    version = VERSION,
    about = "Discrete-element solver for powders and granular flow, with coarse-graining"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (a TOML case file) and write its outputs.
    Run {
        /// The scene file, e.g. validation/cases/aor_collapse.toml, or the `scene.json` a
        /// harness run wrote (`validate --np`), run as written. With --resume it names the
        /// scene to continue instead of the command line the run stored (the digests must
        /// match): how `validate --np` resumes the runs it started.
        #[arg(required_unless_present = "resume")]
        case: Option<PathBuf>,
        /// Coarse-graining level: a power of two (1 = the original, uncoarsened system).
        /// Diameters grow by lambda, the particle count falls by lambda^3 (paper A Eq. 3-6).
        #[arg(long, default_value_t = 1)]
        lambda: u32,
        /// Coarse-graining rule. WCA: `seed` (paper A: eps' = lambda^3 eps, gamma' = lambda^2
        /// gamma) or `bulk-viscosity` (eps' = lambda eps, gamma' = lambda gamma: keeps gamma/d,
        /// so viscous flows keep their speed). Hertz: `seed` (every contact force x lambda^2),
        /// `scaled-particle` (the same material in larger particles) or `liggghts-pfm`
        /// (LIGGGHTS-PFM's coarsegraining, cohesion scaled like the weight). What each keeps:
        /// reference/COARSE_GRAINING.md.
        #[arg(long, value_enum, default_value_t = CgRule::Seed)]
        cg_rule: CgRule,
        /// Insertion seed: insertion k uses seed + k (default: the seeds in the case file).
        #[arg(long)]
        seed: Option<u64>,
        /// Output directory (default: runs/CASE-lambdaN).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads for the force loop (default: all cores). Results are bitwise
        /// identical for any thread count.
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar (it is also hidden when stderr is not a terminal).
        #[arg(long)]
        quiet: bool,
        /// Run even if the time step exceeds the stable limit (prints a warning).
        #[arg(long)]
        force_dt: bool,
        /// Do not stop when a guard fires (non-finite state, overlap beyond a quarter of the
        /// radius, energy growing without work): warn once per guard and go on.
        #[arg(long)]
        keep_going: bool,
        /// Refuse to coarse-grain where the rule cannot keep what it states for a parameter of
        /// the scene (e.g. the seed rule with van der Waals cohesion under gravity: the Bond
        /// number), naming the rule and the parameter, instead of warning.
        #[arg(long)]
        strict: bool,
        /// The grid of subdomains the box is cut into (domain decomposition; each subdomain
        /// owns its particles and keeps ghost layers of its neighbours'): `2x1x1` subdomains
        /// along x, y, z, or a count (`2`) for the grid with the least ghost surface. Without
        /// it, every run still is a grid, chosen from the scene alone (its particle count,
        /// box, periodic axes and gravity: at most 4 subdomains of at least 400 particles,
        /// with planes along gravity), so the outputs are bitwise the same on any number of
        /// threads or ranks; summary.json says which grid and why. Threads and MPI ranks
        /// (`mpirun -np N`, a build with `--features mpi`) take whole subdomains. Not with
        /// --sweep (its runs take their scenes' grids).
        #[arg(long, conflicts_with = "sweep")]
        grid: Option<cgdem_core::decomposition::GridSpec>,
        /// At each list rebuild, when the imbalance (most particles in one subdomain over
        /// the mean) passes this threshold, move the cut planes so that each slab along each
        /// axis holds the same number of particles (LAMMPS `fix balance ... shift`), never
        /// thinner than the ghost layer; `off` keeps the start's planes. At least 1.0.
        /// summary.json's `decomposition` gives the shifts and the imbalance the start's
        /// planes would give.
        #[arg(long, value_name = "THRESH|off", default_value_t)]
        balance: cgdem_core::decomposition::BalanceSpec,
        /// With `--sweep rpm=` or `screw_ratio=`: a run directory whose summary.json holds
        /// the same scene (digest) is not run again, so a sweep can be resumed or extended.
        #[arg(long)]
        reuse: bool,
        /// Override a scene field before validation, e.g. `--set wall_contact.friction=0.0`
        /// or `--set 'wall[2].point=[0.1, 0.0, 0.0]'` (TOML value; repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Name the variant the overrides make: appended to the scene's name
        /// (`aor_collapse-smooth-walls`), as a suite's `variant` does, so `validate --reuse`
        /// recognises the run.
        #[arg(long, requires = "set")]
        variant: Option<String>,
        /// A sweep, one run per value: `rpm=20,40,60` (screw speed of the `[conveying]` body;
        /// OUT/rpmN/, OUT/mass_flow_vs_rpm.csv and a plot with Eq. (7)) or
        /// `diameter=1e-6,1e-5,1e-4` (m; a `[packing]` scene rescaled to each diameter with the
        /// material held; OUT/dUMum/, OUT/porosity_vs_diameter.csv, pore_size_vs_diameter.csv
        /// and plots with the published points).
        #[arg(long)]
        sweep: Option<String>,
        /// Write a restart file (OUT/restart.cgr, the one before kept as restart.prev.cgr)
        /// every this many simulated seconds, at the start, at every stage end and when
        /// SIGINT/SIGTERM stops the run. Not with --sweep. With --grid it holds the
        /// subdomains (gathered from every rank; rank 0 writes it). With --resume: the
        /// interval from the resumed checkpoint on (default: the stored one).
        #[arg(long, value_name = "SECONDS")]
        checkpoint_every: Option<f64>,
        /// Continue the run in DIR from its newest usable restart file: the case file and
        /// options (--lambda, --set, --grid, ...) are the ones the run stored, unless a scene
        /// file is given, and the scene's digest must match the stored one. Outputs come out
        /// as those of an uninterrupted run (with --grid: on the same grid, on any number of
        /// threads or MPI ranks). `--grid` here continues a decomposed run on another grid, from the stored
        /// particles (to rounding, not bitwise).
        #[arg(long, value_name = "DIR", conflicts_with_all = ["out", "sweep", "set", "seed", "variant", "strict"])]
        resume: Option<PathBuf>,
        /// Start from the particles of this state file instead of the scene's insertions
        /// (`cgdem bench --np` writes its prepared state into one for the ranks it starts).
        #[arg(long, value_name = "FILE", hide = true, conflicts_with_all = ["resume", "sweep", "checkpoint_every"])]
        initial_state: Option<PathBuf>,
    },
    /// Run a validation suite (validation/suites/*.toml) with cgdem and the reference codes,
    /// compare the runs and write DIR/index.html, DIR/summary.json, figures and their CSV.
    Validate {
        /// The suite: a name in validation/suites (smoke, nightly, full) or a path.
        #[arg(long, default_value = "smoke")]
        suite: String,
        /// Output directory.
        #[arg(long, default_value = "reports/latest")]
        out: PathBuf,
        /// Worker threads for cgdem (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Time limit of one reference-code run, seconds.
        #[arg(long, default_value_t = 3600)]
        reference_timeout: u64,
        /// No per-run progress lines.
        #[arg(long)]
        quiet: bool,
        /// Reuse runs already in OUT/runs that are exactly this suite's (same scene digest
        /// for cgdem, same deck for a reference code): resumes an interrupted suite, or
        /// rebuilds the report without re-running.
        #[arg(long)]
        reuse: bool,
        /// cgdem runs warn instead of stopping when a guard fires.
        #[arg(long)]
        keep_going: bool,
        /// Runs of a case, or of an accuracy sweep, made at the same time, each with threads /
        /// jobs of the threads (2 on 2 cores keeps both busy with small single-threaded runs).
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u16).range(1..))]
        jobs: u16,
        /// Plant a fault in cgdem's runs only: a scene override (`contact.friction=0.3`)
        /// applied after the case's own, the scene keeping its name, so its comparisons with
        /// the reference codes show that the verdicts can fail (repeatable;
        /// scripts/planted-faults.sh). Marked on the report's first screen.
        #[arg(long = "fault", value_name = "KEY=VALUE")]
        fault: Vec<String>,
        /// A nightly history directory (its history.json): the report's first screen says
        /// what moved since the last night recorded there.
        #[arg(long)]
        history: Option<PathBuf>,
        /// Run cgdem's runs on this grid (`2x1x1`, or a count for the grid with the least
        /// ghost surface per scene) instead of the one each scene chooses, stepped on
        /// --threads, to compare the verdicts with the default suite's. The reference codes
        /// run as without it.
        #[arg(long)]
        grid: Option<cgdem_core::decomposition::GridSpec>,
        /// As `cgdem run --balance`.
        #[arg(long, value_name = "THRESH|off", default_value_t)]
        balance: cgdem_core::decomposition::BalanceSpec,
        /// With --grid: run each of cgdem's runs as N MPI ranks (`mpirun -np N cgdem run
        /// RUN/scene.json --grid G ...`, the scene the harness built written beside the
        /// run), sharing --threads; bitwise the outputs of the same grid on threads. Needs
        /// mpirun and a cgdem built with `--features mpi` (this one, or --cgdem-bin).
        #[arg(long, value_name = "N", requires = "grid")]
        np: Option<usize>,
        /// The cgdem binary the ranks of --np run (default: this one).
        #[arg(long, value_name = "PATH", requires = "np")]
        cgdem_bin: Option<PathBuf>,
        /// cgdem's case and accuracy runs write restart files this many simulated seconds
        /// apart (as `cgdem run --checkpoint-every`); with --reuse, a run killed in an
        /// earlier attempt goes on from its last one instead of starting again (with --np,
        /// as ranks, from a file the ranks or threads on the same grid wrote).
        #[arg(long, value_name = "SECONDS")]
        checkpoint_every: Option<f64>,
    },
    /// Throughput of cgdem, LIGGGHTS and LAMMPS on the same case, side by side: every code
    /// starts from one state that cgdem prepares, runs the same steps, alternating (A B C,
    /// C B A, ...) over the repetitions, at each thread (MPI rank) count. Writes
    /// OUT/bench.json, OUT/bench_runs.csv and OUT/throughput.{png,svg,csv}, and prints the
    /// medians, the ratios cgdem / other per repetition and the heap each code leaves.
    Bench {
        /// Case files (one stage with a duration), e.g. validation/bench/heap.toml.
        #[arg(required = true)]
        cases: Vec<PathBuf>,
        /// Output directory.
        #[arg(long, default_value = "reports/bench")]
        out: PathBuf,
        /// Codes, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "cgdem,liggghts,lammps")]
        codes: Vec<String>,
        /// Thread (MPI rank) counts, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
        /// Repetitions of the alternating sequence (medians over them).
        #[arg(long, default_value_t = 5)]
        pairs: usize,
        /// Steps per timed run.
        #[arg(long, default_value_t = 10_000)]
        steps: u64,
        /// Simulated seconds cgdem runs each case before the timed window.
        #[arg(long, default_value_t = 0.15)]
        prepare: f64,
        /// Skip the untimed runs to the scene's end that compare the heaps.
        #[arg(long)]
        no_outcome: bool,
        /// Time limit of one reference-code run, seconds.
        #[arg(long, default_value_t = 1800)]
        reference_timeout: u64,
        /// Also time cgdem on this grid (`2x1x1`, as `run --grid`), as a case CASE-gridG in
        /// the same alternation (ratio per repetition to the run on the scene's own grid).
        #[arg(long)]
        grid: Option<cgdem_core::decomposition::GridSpec>,
        /// MPI rank counts, comma-separated: cgdem also runs the `--grid` case as that many
        /// ranks of one thread (`mpirun -np N cgdem run --grid G ...` from the prepared
        /// state), in the same alternation as the runs at N threads, in rows of its own
        /// ("cgdem (N ranks)"). Needs --grid with at least N subdomains, mpirun and a cgdem
        /// built with `--features mpi` (this one, or --cgdem-bin).
        #[arg(long, value_delimiter = ',', requires = "grid")]
        np: Vec<usize>,
        /// The cgdem binary the ranks of --np run (default: this one), e.g.
        /// target/release/cgdem of a `cargo build --release --features mpi`.
        #[arg(long, value_name = "PATH", requires = "np")]
        cgdem_bin: Option<PathBuf>,
    },
    /// Add a nightly report (a `cgdem validate` output) to the history in DIR: appends its
    /// metrics to DIR/history.json, rewrites DIR/index.html with the history table, trend
    /// plots and flags, and prints the metrics that moved beyond tolerance since the
    /// previous night (scripts/nightly.sh calls this).
    History {
        /// The history directory, e.g. reports/nightly.
        dir: PathBuf,
        /// The night's report directory.
        #[arg(long)]
        add: PathBuf,
        /// The night's date (YYYY-MM-DD).
        #[arg(long)]
        date: String,
        /// The cgdem commit the night ran.
        #[arg(long)]
        commit: String,
    },
    /// Which coarse-graining level and rule keeps a quantity within a target, from a stored
    /// matrix (a `cgdem validate` report whose sweeps vary lambda under each rule against a
    /// fine reference): the coarsest setting whose mean error over seeds plus twice its
    /// standard error is within the target, with its saving; "none" and the closest otherwise.
    Advise {
        /// The case: its scene file (e.g. validation/cases/aor_hertz.toml) or its name in the
        /// report (e.g. aor_hertz-fidelity).
        case: String,
        /// repose_angle (deg), profile, mass_flow, mass_flow_eq7, t_half, front_history,
        /// pore_size (relative) or porosity (absolute).
        #[arg(long)]
        quantity: String,
        /// The largest error allowed, in the quantity's unit (e.g. 2 for 2 deg, 0.05 for 5%).
        #[arg(long)]
        target: f64,
        /// The report directory (or its summary.json) holding the matrix.
        #[arg(long, default_value = "reports/cg_fidelity")]
        matrix: PathBuf,
        /// Print the answer as JSON.
        #[arg(long)]
        json: bool,
        /// First make the case's points the matrix lacks: its sweeps in --suite run as
        /// `cgdem validate --reuse` runs them, in MATRIX/runs (the runs already there are
        /// taken), with the case's own report in MATRIX/advise/CASE/, which the answer then
        /// reads; the matrix's report is left as it was (`cgdem validate --suite S --out
        /// MATRIX --reuse` rebuilds it with the new points).
        #[arg(long)]
        run: bool,
        /// With --run: the suite holding the case's sweeps, a name in validation/suites or a
        /// path (default: the suite the matrix was made from, else cg_fidelity).
        #[arg(long, requires = "run")]
        suite: Option<String>,
        /// With --run: worker threads (default: all cores).
        #[arg(long, requires = "run")]
        threads: Option<usize>,
        /// With --run: runs made at the same time, as `cgdem validate --jobs`.
        #[arg(long, default_value_t = 1, requires = "run", value_parser = clap::value_parser!(u16).range(1..))]
        jobs: u16,
    },
    /// Run a scene in a reference code (deck written from the scene, run, post-processed
    /// with cgdem's analysis into the same outputs).
    Reference {
        #[command(subcommand)]
        code: ReferenceCommand,
    },
    /// Geometry tools: the seed's screw-feeder meshes and the SDF accuracy study.
    Geometry {
        #[command(subcommand)]
        command: GeometryCommand,
    },
}

#[derive(Subcommand)]
enum ReferenceCommand {
    /// LAMMPS (`lmp` on PATH or $CGDEM_LMP): the seed's WCA model (reference/lammps/SEED_MODEL.md)
    /// and Hertz scenes (reference/MAPPING.md).
    Lammps(ReferenceArgs),
    /// LIGGGHTS (`liggghts` on PATH or $CGDEM_LIGGGHTS): Hertz scenes with LIGGGHTS's keywords.
    Liggghts(ReferenceArgs),
}

#[derive(Args)]
struct ReferenceArgs {
    /// The scene file, e.g. validation/cases/aor_collapse.toml.
    case: PathBuf,
    /// Coarse-graining level (a power of two), applied before the deck is written.
    #[arg(long, default_value_t = 1)]
    lambda: u32,
    /// Coarse-graining rule, as for `cgdem run`.
    #[arg(long, value_enum, default_value_t = CgRule::Seed)]
    cg_rule: CgRule,
    /// Insertion seed: insertion k uses seed + k (default: the seeds in the case file).
    #[arg(long)]
    seed: Option<u64>,
    /// Output directory (default: runs/CASE-lambdaN-CODE).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Override a scene field before validation, e.g. `--set wall_contact.friction=0.0`
    /// or `--set 'wall[2].point=[0.1, 0.0, 0.0]'` (TOML value; repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Name the variant the overrides make: appended to the scene's name
    /// (`aor_collapse-smooth-walls`), as a suite's `variant` does, so `validate --reuse`
    /// recognises the run.
    #[arg(long, requires = "set")]
    variant: Option<String>,
    /// MPI ranks (runs `mpirun --allow-run-as-root -np N lmp|liggghts`); default: serial.
    #[arg(long)]
    np: Option<u32>,
    /// Kill the code after this many seconds.
    #[arg(long, default_value_t = 7200)]
    timeout: u64,
    /// Write the deck even if the time step exceeds the stable limit.
    #[arg(long)]
    force_dt: bool,
    /// Do not run: post-process the outputs already in --out (e.g. of a run that
    /// was stopped; the samples it reached are used).
    #[arg(long)]
    postprocess_only: bool,
}

/// The SIGINT/SIGTERM handlers of the commands that poll the stop flag (a failure to install
/// them leaves the default action, ending the process, and says so).
fn install_interrupt() -> Option<interrupt::Interrupt> {
    match interrupt::Interrupt::install() {
        Ok(i) => Some(i),
        Err(e) => {
            eprintln!("warning: SIGINT/SIGTERM handlers not installed ({e}): an interrupt ends cgdem at once");
            None
        }
    }
}

/// The exit code 130/143 after a signal stopped the command, with what was kept.
fn interrupted(
    interrupt: &Option<interrupt::Interrupt>,
    kept: &std::path::Path,
) -> Option<ExitCode> {
    let (name, code) = interrupt.as_ref()?.received()?;
    eprintln!(
        "interrupted by {name}: stopped; the outputs written so far are kept in {}",
        kept.display()
    );
    Some(code)
}

fn reference_run(code: ReferenceCommand) -> Result<ExitCode, String> {
    use cgdem_harness::code::Code;
    use cgdem_harness::decks::{run_reference, ReferenceOptions, RunStatus, RunnerOptions};
    let (code, args) = match code {
        ReferenceCommand::Lammps(args) => (Code::Lammps, args),
        ReferenceCommand::Liggghts(args) => (Code::Liggghts, args),
    };
    let name = code.label();
    let ReferenceArgs {
        case,
        lambda,
        cg_rule,
        seed,
        out,
        np,
        timeout,
        force_dt,
        postprocess_only,
        set,
        variant,
    } = args;
    let scene = load_scene(&case, &set, variant.as_deref(), seed)?;
    let scene = coarse_grain_by(&scene, lambda, cg_rule.into()).map_err(|e| e.to_string())?;
    let out = out.unwrap_or_else(|| {
        PathBuf::from("runs").join(format!(
            "{}-lambda{}-{}",
            scene.name,
            scene.lambda,
            name.to_lowercase()
        ))
    });
    let interrupt = install_interrupt();
    let options = ReferenceOptions {
        code,
        runner: RunnerOptions {
            np,
            timeout: std::time::Duration::from_secs(timeout),
            stop: interrupt.as_ref().map(|i| i.flag()),
        },
        force_dt,
        postprocess_only,
    };
    let run = run_reference(&scene, &out, &options);
    if let Some(code) = interrupted(&interrupt, &out) {
        if let Err(e) = &run {
            eprintln!("{e}");
        }
        return Ok(code);
    }
    let run = run?;
    if let Some(w) = &run.dt_warning {
        eprintln!("warning: {w}");
    }
    if !postprocess_only {
        println!(
            "deck for {} at lambda = {} ({} particles, dt = {:.4e} s) in {}",
            scene.name,
            scene.lambda,
            run.n_particles,
            run.dt,
            out.display()
        );
    }
    match run.status {
        RunStatus::Completed { .. } => {
            let summary = run.summary.expect("a completed run is post-processed");
            println!(
                "{name}: {} steps, {:.1} s wall time, {:.3e} particle-steps/s (loop time)",
                summary.steps, summary.wall_s, summary.particle_steps_per_s
            );
            for s in &summary.repose_samples {
                println!(
                    "  t = {} s after `{}` start: repose angle {} deg, run-out {:.4} m",
                    s.time_after_start_s,
                    summary.stages.last().map_or("", |st| st.name.as_str()),
                    s.repose_angle_deg.map_or("-".into(), |a| format!("{a:.2}")),
                    s.runout_m
                );
            }
            println!("outputs in {}", out.display());
            Ok(ExitCode::SUCCESS)
        }
        RunStatus::Skipped {
            reason,
            install_hint,
        } => {
            println!("skipped: {reason}; install with `{install_hint}`");
            Ok(ExitCode::SUCCESS)
        }
        RunStatus::Failed {
            exit_code,
            log_tail,
        } => Err(format!(
            "{name} failed (exit code {exit_code:?}) in {}; log tail:\n{log_tail}",
            out.display()
        )),
        RunStatus::TimedOut { after_s, log_tail } => {
            // The partial outputs are kept, with a summary that says so when it could be made.
            let partial = run.partial_error.map_or(String::new(), |e| {
                format!(" (post-processing the partial run failed: {e})")
            });
            Err(format!(
                "{name} killed after {after_s:.0} s (--timeout) in {}{partial}; log tail:\n{log_tail}",
                out.display()
            ))
        }
    }
}

/// Reads a scene with its `--set` overrides (named `variant`) and, when given, an insertion
/// seed.
fn load_scene(
    case: &std::path::Path,
    set: &[String],
    variant: Option<&str>,
    seed: Option<u64>,
) -> Result<Scene, String> {
    let overrides = set
        .iter()
        .map(|o| Override::parse(o, std::path::Path::new("--set")))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let mut scene = Scene::load_with_overrides(case, &overrides).map_err(|e| e.to_string())?;
    if let Some(v) = variant {
        scene.name = format!("{}-{v}", scene.name);
    }
    Ok(match seed {
        Some(s) => scene.with_insertion_seed(s),
        None => scene,
    })
}

#[derive(Subcommand)]
enum GeometryCommand {
    /// Write screw.stl, casing.stl, hopper.stl and insertion.stl of paper A's screw feeder
    /// (reference/SCREW_GEOMETRY.md) and print the layout.
    ScrewFeeder {
        #[arg(long)]
        out: PathBuf,
    },
    /// Measure SDF-grid error, memory and build time against cell size (sphere, cylinder,
    /// helicoid flight); writes sdf_accuracy.csv and plots.
    SdfAccuracy {
        #[arg(long)]
        out: PathBuf,
        /// Cell sizes, m.
        #[arg(long, value_delimiter = ',', default_values_t = [0.016, 0.008, 0.004, 0.002])]
        cells: Vec<f64>,
        /// Sample points per grid (within 2 cells of the surface).
        #[arg(long, default_value_t = 5000)]
        samples: usize,
    },
}

fn geometry(command: GeometryCommand) -> ExitCode {
    match command {
        GeometryCommand::ScrewFeeder { out } => {
            let spec = ScrewFeederSpec::default();
            match screw_feeder::write_stl_files(&spec, &out) {
                Ok(paths) => {
                    for p in paths {
                        println!("wrote {}", p.display());
                    }
                    println!("{:#?}", spec.layout());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        GeometryCommand::SdfAccuracy {
            out,
            cells,
            samples,
        } => {
            if cells.is_empty() || cells.iter().any(|&h| !(h > 0.0 && h.is_finite())) {
                eprintln!("error: --cells must be positive cell sizes in metres, got {cells:?}");
                return ExitCode::from(2);
            }
            match write_sdf_accuracy_study(&out, &cells, samples) {
                Ok((rows, paths)) => {
                    print!("{}", format_accuracy_table(&rows));
                    for p in paths {
                        println!("wrote {}", p.display());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}

/// Rust starts programs with SIGPIPE ignored, so a closed pipe (`cgdem advise ... | head -1`)
/// makes every later `println!` panic with "Broken pipe". With the default action the process
/// ends quietly when its reader has gone, as `grep` or `lmp` do; files are written through
/// their own handles, which a closed stdout does not touch.
fn restore_default_sigpipe() {
    // SAFETY: called first in `main`, before any thread starts; `signal` with `SIG_DFL` only
    // resets the disposition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    restore_default_sigpipe();
    let cli = Cli::parse();
    match cli.command {
        Command::Validate {
            suite,
            out,
            threads,
            reference_timeout,
            quiet,
            reuse,
            keep_going,
            jobs,
            fault,
            history,
            grid,
            balance,
            np,
            cgdem_bin,
            checkpoint_every,
        } => {
            if let Some(t) = checkpoint_every {
                if !(t.is_finite() && t > 0.0) {
                    eprintln!("error: --checkpoint-every {t}: must be a positive number of simulated seconds");
                    return ExitCode::from(2);
                }
            }
            let ranks = match np
                .map(|n| cgdem_harness::ranks::Ranks::checked(n, grid, cgdem_bin.as_deref()))
                .transpose()
            {
                Ok(ranks) => ranks,
                Err(e) => {
                    eprintln!("error: --np: {e}");
                    return ExitCode::from(2);
                }
            };
            let suite_path = suite_path(&suite);
            let pool = match worker_pool(threads) {
                Ok(pool) => pool,
                Err(code) => return code,
            };
            let interrupt = install_interrupt();
            let options = cgdem_harness::validate::ValidateOptions {
                suite: suite_path,
                out: out.clone(),
                quiet,
                progress: progress_bar::progress(quiet),
                reference_timeout_s: reference_timeout,
                reuse,
                keep_going,
                jobs: usize::from(jobs),
                stop: interrupt.as_ref().map(|i| i.flag()),
                cgdem_faults: fault,
                history,
                decomposition: cgdem_harness::runs::CgdemDecomposition {
                    grid,
                    balance,
                    ranks,
                },
                checkpoint_every,
                runs_dir: None,
            };
            let result = pool.install(|| cgdem_harness::validate::validate(&options));
            if let Some(code) = interrupted(&interrupt, &out) {
                if let Err(e) = &result {
                    eprintln!("error: {e}");
                }
                return code;
            }
            match result {
                Ok(summary) => {
                    let failed = summary.comparisons.iter().filter(|c| !c.pass).count();
                    let known = summary
                        .comparisons
                        .iter()
                        .filter(|c| c.verdict == cgdem_harness::verdict::Verdict::KnownDifference)
                        .count();
                    let runs_failed = summary
                        .runs
                        .iter()
                        .filter(|r| r.status == cgdem_harness::validate::Outcome::Failed)
                        .count();
                    let mut extra = String::new();
                    if let Some(accuracy) = &summary.accuracy {
                        extra += &format!(", {} accuracy points", accuracy.points.len());
                    }
                    if !summary.stability.is_empty() {
                        use cgdem_harness::{stability::Verdict, suite::Code};
                        let failed = |cgdem: bool| {
                            summary
                                .stability
                                .iter()
                                .filter(|r| {
                                    r.verdict == Verdict::Failed && (r.code == Code::Cgdem) == cgdem
                                })
                                .count()
                        };
                        extra += &format!(
                            ", {} stability runs (failed: {} in cgdem, {} in the reference codes)",
                            summary.stability.len(),
                            failed(true),
                            failed(false)
                        );
                    }
                    println!(
                        "suite {}: {} runs ({} failed, {} skipped), {} comparisons ({} fail, {known} known differences){extra}; report in {}",
                        summary.suite,
                        summary.runs.len(),
                        runs_failed,
                        summary.runs.iter().filter(|r| r.status == cgdem_harness::validate::Outcome::Skipped).count(),
                        summary.comparisons.len(),
                        failed,
                        out.join("index.html").display()
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Reference { code } => match reference_run(code) {
            Ok(code) => code,
            Err(message) => {
                eprintln!("error: {message}");
                ExitCode::FAILURE
            }
        },
        Command::Geometry { command } => geometry(command),
        Command::Bench {
            cases,
            out,
            codes,
            threads,
            pairs,
            steps,
            prepare,
            no_outcome,
            reference_timeout,
            grid,
            np,
            cgdem_bin,
        } => {
            let mut parsed = Vec::new();
            for name in &codes {
                parsed.push(match name.as_str() {
                    "cgdem" => cgdem_harness::suite::Code::Cgdem,
                    "liggghts" => cgdem_harness::suite::Code::Liggghts,
                    "lammps" => cgdem_harness::suite::Code::Lammps,
                    other => {
                        eprintln!("error: --codes: `{other}` is not a code; allowed: cgdem, liggghts, lammps");
                        return ExitCode::FAILURE;
                    }
                });
            }
            if threads.contains(&0)
                || np.contains(&0)
                || pairs == 0
                || steps == 0
                || prepare.is_nan()
                || prepare < 0.0
            {
                eprintln!("error: --threads, --np, --pairs and --steps must be at least 1 and --prepare at least 0");
                return ExitCode::FAILURE;
            }
            let options = cgdem_harness::bench::BenchOptions {
                grid,
                np,
                cgdem_bin,
                cases,
                out: out.clone(),
                codes: parsed,
                threads,
                pairs,
                steps,
                prepare_s: prepare,
                outcome: !no_outcome,
                timeout: std::time::Duration::from_secs(reference_timeout),
            };
            match cgdem_harness::bench::bench(&options) {
                Ok(report) => {
                    print!("{}", cgdem_harness::bench::format_report(&report));
                    println!("report in {}", out.join("bench.json").display());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Advise {
            case,
            quantity,
            target,
            matrix,
            json,
            run,
            suite,
            threads,
            jobs,
        } => {
            let run = run.then_some(AdviseRun {
                suite,
                threads,
                jobs,
            });
            advise(&case, &quantity, target, &matrix, json, run)
        }
        Command::History {
            dir,
            add,
            date,
            commit,
        } => match cgdem_harness::history::add_night(&dir, &add, &date, &commit) {
            Ok(flags) => {
                for f in &flags {
                    println!(
                        "flag: {} moved from {:.4e} to {:.4e} (tolerance {}{})",
                        f.metric,
                        f.previous,
                        f.current,
                        f.tolerance,
                        if f.relative { " relative" } else { "" }
                    );
                }
                println!(
                    "history: {} ({} flags against the previous night)",
                    dir.join("index.html").display(),
                    flags.len()
                );
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
        Command::Run {
            case,
            lambda,
            cg_rule,
            seed,
            out,
            threads,
            quiet,
            force_dt,
            keep_going,
            strict,
            reuse,
            sweep,
            set,
            variant,
            grid,
            balance,
            checkpoint_every,
            resume,
            initial_state,
        } => {
            let sweep = match sweep.as_deref().map(Sweep::parse).transpose() {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            if checkpoint_every.is_some() && sweep.is_some() {
                eprintln!("error: --checkpoint-every: not supported with --sweep (each run of a sweep is its own run; --reuse skips the finished ones)");
                return ExitCode::from(2);
            }
            if let Some(t) = checkpoint_every {
                if !(t.is_finite() && t > 0.0) {
                    eprintln!("error: --checkpoint-every {t}: must be a positive number of simulated seconds");
                    return ExitCode::from(2);
                }
            }
            // What rebuilds the scene: this command line, or the one a resumed run stored
            // when no scene file is given.
            let (invocation, resumed) = match (&resume, &case) {
                (Some(dir), None) => match RunInvocation::resumed(dir) {
                    Ok((inv, loaded)) => (inv, Some(loaded)),
                    Err(e) => {
                        eprintln!("error: {e}");
                        return ExitCode::FAILURE;
                    }
                },
                (resume, _) => (
                    RunInvocation {
                        case: case
                            .clone()
                            .map(|c| std::path::absolute(&c).unwrap_or(c))
                            .unwrap_or_default(),
                        lambda,
                        cg_rule: cg_rule.into(),
                        seed,
                        set: set.clone(),
                        variant: variant.clone(),
                        force_dt,
                        keep_going,
                        grid: grid.map(|g| g.to_string()),
                        balance: grid.map(|_| balance.to_string()),
                    },
                    match resume.as_deref().map(restart::read_latest).transpose() {
                        Ok(loaded) => {
                            if let Some(l) = &loaded {
                                eprintln!("resuming from {}", l.path.display());
                            }
                            loaded.map(std::sync::Arc::new)
                        }
                        Err(e) => {
                            eprintln!("error: {e}");
                            return ExitCode::FAILURE;
                        }
                    },
                ),
            };
            // A resumed run keeps its grid and balance unless given another grid.
            let (grid, balance) = match (grid, &invocation.grid) {
                (None, Some(stored)) => {
                    use cgdem_core::decomposition::{BalanceSpec, GridSpec};
                    let balance: Result<BalanceSpec, String> = invocation
                        .balance
                        .as_deref()
                        .map_or(Ok(BalanceSpec::default()), str::parse);
                    let parsed = stored
                        .parse::<GridSpec>()
                        .and_then(|g| Ok((Some(g), balance?)));
                    match parsed {
                        Ok(p) => p,
                        Err(e) => {
                            eprintln!("error: the stored --grid/--balance: {e}");
                            return ExitCode::from(2);
                        }
                    }
                }
                _ => (grid, balance),
            };
            // The restart files the run writes from now on name the grid it runs on.
            let invocation = RunInvocation {
                grid: grid.map(|g| g.to_string()),
                balance: grid.map(|_| balance.to_string()),
                ..invocation
            };
            let checkpoint_every =
                checkpoint_every.or_else(|| resumed.as_ref().map(|l| l.restart.checkpoint_every));
            let RunInvocation {
                case,
                lambda,
                seed,
                set,
                variant,
                force_dt,
                keep_going,
                ..
            } = invocation.clone();
            let cg_rule = invocation.cg_rule;
            let out = resume.clone().or(out);
            // Under mpirun (a build with the `mpi` feature) each rank steps its subdomains;
            // rank 0 writes the outputs, the others write theirs into a scratch directory.
            let comm = match cgdem_core::decomposition::Comm::from_environment() {
                Ok(comm) => comm,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            if comm.is_distributed() && sweep.is_some() {
                if comm.is_root() {
                    eprintln!(
                        "error: under mpirun ({} ranks) cgdem run takes no --sweep",
                        comm.size()
                    );
                }
                return ExitCode::from(2);
            }
            let root = comm.is_root();
            let scratch = (!root).then(|| {
                std::env::temp_dir().join(format!(
                    "cgdem-rank{}-{}",
                    comm.rank(),
                    std::process::id()
                ))
            });
            let pool = match worker_pool(threads) {
                Ok(pool) => pool,
                Err(code) => return code,
            };
            let mut figures = Vec::new();
            // Sweeps run their own options and do not poll the stop flag: a signal ends them.
            let interrupt = if sweep.is_none() {
                install_interrupt()
            } else {
                None
            };
            let mut out_used = None;
            let result = pool.install(|| {
                load_scene(&case, &set, variant.as_deref(), seed)
                    .and_then(|scene| {
                        let checks = coarse_grain_checks(&scene, lambda, cg_rule);
                        let refused: Vec<String> = checks
                            .iter()
                            .filter(|c| c.severity == CgSeverity::Inconsistent)
                            .map(|c| format!("{}: {}", c.parameter, c.message))
                            .collect();
                        if strict && !refused.is_empty() {
                            return Err(format!(
                                "{}: --strict: the {} rule cannot keep this scene consistent at lambda = {lambda}:\n  {}",
                                case.display(),
                                cg_rule.name(),
                                refused.join("\n  ")
                            ));
                        }
                        for c in &checks {
                            eprintln!("warning: coarse-graining: {c}");
                        }
                        coarse_grain_by(&scene, lambda, cg_rule).map_err(|e| e.to_string())
                    })
                    .and_then(|scene| {
                        let out_dir = out.unwrap_or_else(|| default_out_dir(&scene));
                        if let Some(Sweep::Diameter(diameters)) = &sweep {
                            let results = cgdem_harness::sweep::diameter_sweep(&scene, diameters, &out_dir, progress_bar::progress(quiet), force_dt, keep_going)?;
                            for (d, s) in &results {
                                let porosity = s.packing.as_ref().map_or("not measured".into(), |p| format!("{:.4}", p.porosity));
                                println!("d = {:.3e} m: {} particles, {} steps of {:.3e} s, porosity {porosity}, wall {:.1} s", d, s.n_particles, s.steps, s.dt_s, s.wall_s);
                            }
                            println!("porosity_vs_diameter.csv, pore_size_vs_diameter.csv and plots in {}", out_dir.display());
                            let last = results.into_iter().last().map(|r| r.1).ok_or("empty sweep")?;
                            return Ok((last, out_dir));
                        }
                        if let Some(Sweep::ScrewRatio(ratios)) = &sweep {
                            let results = cgdem_harness::sweep::screw_ratio_sweep(&scene, ratios, &out_dir, progress_bar::progress(quiet), force_dt, keep_going, reuse)?;
                            for (r, s) in &results {
                                if let Some(c) = &s.conveying {
                                    println!("r_s/r_p = {r}: {} screw particles, {:.4} +- {:.4} kg/s, Eq. (7) {:.4} kg/s (ratio {:.3}), wall {:.1} s", s.n_body_particles, c.mass_flow_kg_s, c.mass_flow_std_error_kg_s, c.eq7_mass_flow_kg_s, c.ratio_to_eq7, s.wall_s);
                                }
                            }
                            let last = results.into_iter().last().map(|r| r.1).ok_or("empty sweep")?;
                            return Ok((last, out_dir));
                        }
                        if let Some(Sweep::Rpm(speeds)) = &sweep {
                            let results = cgdem_harness::sweep::rpm_sweep(&scene, speeds, &out_dir, progress_bar::progress(quiet), force_dt, keep_going, reuse)?;
                            for (rpm, s) in &results {
                                if let Some(c) = &s.conveying {
                                    println!("{rpm} rpm: {:.4} +- {:.4} kg/s, Eq. (7) {:.4} kg/s (a = {:.3}), wall {:.1} s", c.mass_flow_kg_s, c.mass_flow_std_error_kg_s, c.eq7_mass_flow_kg_s, c.fill_ratio, s.wall_s);
                                }
                            }
                            let last = results.into_iter().last().map(|r| r.1).ok_or("empty sweep")?;
                            return Ok((last, out_dir));
                        }
                        out_used = Some(out_dir.clone());
                        let initial_state = initial_state
                            .as_deref()
                            .map(|path| cgdem_core::run::state_file::read(path, &scene))
                            .transpose()?;
                        let options = RunOptions {
                            initial_state,
                            out_dir: scratch.clone().unwrap_or_else(|| out_dir.clone()),
                            progress: progress_bar::progress(quiet || !root),
                            force_dt,
                            keep_going,
                            stop: interrupt.as_ref().map(|i| i.flag()),
                            grid,
                            balance,
                            checkpoint: checkpoint_every.map(|every| CheckpointOptions {
                                every,
                                invocation: serde_json::to_string(&invocation).expect("plain data"),
                            }),
                            resume: resumed.clone(),
                            comm: comm.clone(),
                            ..Default::default()
                        };
                        let summary = run(&scene, &options).map_err(|e| e.to_string());
                        if let Some(dir) = &scratch {
                            let _ = std::fs::remove_dir_all(dir);
                            return summary.map(|s| (s, out_dir));
                        }
                        let summary = summary?;
                        // A figure that cannot be drawn does not fail the run it shows.
                        match cgdem_harness::report::run_figures::write_run_figures(&scene, &summary, &out_dir) {
                            Ok(files) => figures.extend(files.into_iter().map(|f| f.png)),
                            Err(e) => eprintln!("warning: figure not written: {e}"),
                        }
                        Ok((summary, out_dir))
                    })
            });
            if !root {
                // Rank 0 reports; every rank ends with the same status.
                return if result.is_ok() {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::FAILURE
                };
            }
            if let Some(out_dir) = &out_used {
                if let Some(code) = interrupted(&interrupt, out_dir) {
                    if let Err(message) = &result {
                        eprintln!("{message}");
                    }
                    return code;
                }
            }
            match result {
                Ok((summary, out_dir)) => {
                    println!("case {} at lambda = {}: {} particles, {} steps of {:.3e} s, {:.1} s wall time, {:.3e} particle-steps/s", summary.case, summary.lambda, summary.n_particles, summary.steps, summary.dt_s, summary.wall_s, summary.particle_steps_per_s);
                    if let Some(angle) = summary.repose_angle_deg {
                        println!(
                            "repose angle {angle:.2} deg (R^2 = {:.3}), run-out {:.4} m",
                            summary.repose_fit_r2.unwrap_or(f64::NAN),
                            summary.runout_m.unwrap_or(f64::NAN)
                        );
                        if let Some(rule) = &summary.repose_rule {
                            println!("  rule: {rule}");
                        }
                    }
                    if let Some(p) = &summary.packing {
                        println!(
                            "porosity {:.4} between z = {:.4e} and {:.4e} m ({:.1} d; bed height {:.1} d); mean pore diameter {:.3e} m",
                            p.porosity, p.region_z_m[0], p.region_z_m[1], p.region_height_diameters, p.bed_height_diameters, p.mean_pore_diameter_m
                        );
                    }
                    if let Some(c) = &summary.conveying {
                        println!(
                            "mass flow {:.4} +- {:.4} kg/s over {:.2}..{:.2} s; fill ratio {:.3} (solid), a = {:.3} (bulk), bulk density {:.1} kg/m3, drive torque {:.2} N m; Eq. (7): {:.4} kg/s (measured a), {:.4} kg/s (a = 1)",
                            c.mass_flow_kg_s, c.mass_flow_std_error_kg_s, c.window_s[0], c.window_s[1], c.fill_ratio, c.fill_ratio_bulk, c.bulk_density_kg_m3, c.drive_torque_nm, c.eq7_mass_flow_kg_s, c.eq7_full_mass_flow_kg_s
                        );
                    }
                    for png in &figures {
                        println!("figure {} (.svg, .csv beside it)", png.display());
                    }
                    println!("outputs in {}", out_dir.display());
                    ExitCode::SUCCESS
                }
                Err(message) => {
                    eprintln!("error: {message}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}

/// `runs/<case>-lambda<N>`, with the rule appended when it is not the seed's.
fn default_out_dir(scene: &Scene) -> PathBuf {
    let mut name = format!("{}-lambda{}", scene.name, scene.lambda);
    if scene.cg_rule != CoarseGrainRule::Seed {
        name += &format!("-{}", scene.cg_rule.name());
    }
    PathBuf::from("runs").join(name)
}

/// The worker pool a command runs inside. Running the whole simulation inside it means
/// parallel loops started from a worker thread run small jobs inline instead of handing them
/// across threads every step.
fn worker_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, ExitCode> {
    if threads == Some(0) {
        eprintln!("error: --threads must be at least 1");
        return Err(ExitCode::from(2));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| {
            eprintln!("error: cannot start the worker threads: {e}");
            ExitCode::FAILURE
        })
}

/// `cgdem advise --run`'s settings.
struct AdviseRun {
    suite: Option<String>,
    threads: Option<usize>,
    jobs: u16,
}

/// The suite file a suite argument names: a path, or a name in validation/suites.
fn suite_path(suite: &str) -> PathBuf {
    if suite.ends_with(".toml") || suite.contains('/') {
        PathBuf::from(suite)
    } else {
        PathBuf::from("validation/suites").join(format!("{suite}.toml"))
    }
}

/// `advise --run`: the case's sweeps made into the matrix's runs; the directory of the
/// case's own report, or the exit code of a failure (already reported).
fn advise_run(case: &str, matrix: &Path, run: AdviseRun) -> Result<PathBuf, ExitCode> {
    // The suite the matrix was made from, as its provenance names it.
    let made_from = || -> Option<String> {
        let (_, file) = cgdem_harness::advise::matrix_paths(matrix);
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(file).ok()?).ok()?;
        summary["provenance"]["suite file"]
            .as_str()
            .map(str::to_string)
    };
    let suite = run
        .suite
        .or_else(made_from)
        .unwrap_or_else(|| "cg_fidelity".into());
    let suite = match cgdem_harness::suite::Suite::load(&suite_path(&suite)) {
        Ok(suite) => suite,
        Err(e) => {
            eprintln!("error: --suite: {e}");
            return Err(ExitCode::FAILURE);
        }
    };
    let pool = worker_pool(run.threads)?;
    let interrupt = install_interrupt();
    let options = cgdem_harness::validate::ValidateOptions {
        progress: progress_bar::progress(false),
        jobs: usize::from(run.jobs),
        stop: interrupt.as_ref().map(|i| i.flag()),
        ..Default::default()
    };
    let result = pool.install(|| cgdem_harness::advise::run_case(&suite, case, matrix, &options));
    if let Some(code) = interrupted(&interrupt, matrix) {
        return Err(code);
    }
    result.map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::FAILURE
    })
}

/// `cgdem advise`: the answer from the stored matrix (with `--run`, after making the case's
/// missing points), in words or as JSON.
fn advise(
    case: &str,
    quantity: &str,
    target: f64,
    matrix: &Path,
    json: bool,
    run: Option<AdviseRun>,
) -> ExitCode {
    use cgdem_harness::accuracy::Measure;
    use cgdem_harness::advise;
    let Some(m) = Measure::from_quantity(quantity) else {
        let known: Vec<&str> = Measure::ALL.iter().map(|m| m.quantity()).collect();
        eprintln!(
            "error: --quantity {quantity:?} is not allowed: one of {}",
            known.join(", ")
        );
        return ExitCode::FAILURE;
    };
    if !(target.is_finite() && target > 0.0) {
        eprintln!(
            "error: --target {target} is not allowed: a positive number in the quantity's unit"
        );
        return ExitCode::FAILURE;
    }
    // A scene file names its case by the scene's name; anything else is a case name.
    let name = if case.ends_with(".toml") {
        match cgdem_core::scene::Scene::load(Path::new(case)) {
            Ok(scene) => scene.name,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        }
    } else {
        case.to_string()
    };
    let matrix = match run {
        Some(run) => match advise_run(&name, matrix, run) {
            Ok(dir) => dir,
            Err(code) => return code,
        },
        None => matrix.to_path_buf(),
    };
    let answer = advise::read_matrix(&matrix)
        .and_then(|(file, points)| advise::advise(&file, &points, &name, m, target));
    match answer {
        Ok(a) if json => match serde_json::to_string_pretty(&a) {
            Ok(text) => {
                println!("{text}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: cannot write the answer as JSON: {e}");
                ExitCode::FAILURE
            }
        },
        Ok(a) => {
            println!("{}", a.text(m));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
