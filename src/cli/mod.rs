//! The command line: one file per subcommand, each with its arguments (clap derive) and the
//! few lines that turn them into the libraries' settings, call them and report. What two
//! subcommands share (the scene arguments, the worker pool, the signal handlers) is here.

mod advise;
mod bench;
mod geometry;
mod history;
mod reference;
mod run;
mod validate;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::interrupt::Interrupt;
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::{Override, Scene};

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
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (a TOML case file) and write its outputs.
    Run(run::RunArgs),
    /// Run a validation suite (validation/suites/*.toml), or a scene file of your own, with
    /// cgdem and the reference codes, compare the runs and write DIR/index.html,
    /// DIR/summary.json, figures and their CSV. Exit status: 0 green or amber (only declared
    /// known differences), 1 red, 2 could not run (bad arguments or files), 3 incomplete
    /// (comparisons not made: a reference code missing or unable to express the case),
    /// 130/143 interrupted.
    Validate(validate::ValidateArgs),
    /// Throughput of cgdem, LIGGGHTS and LAMMPS on the same case, side by side: every code
    /// starts from one state that cgdem prepares, runs the same steps, alternating (A B C,
    /// C B A, ...) over the repetitions, at each thread (MPI rank) count. Writes
    /// OUT/bench.json, OUT/bench_runs.csv and OUT/throughput.{png,svg,csv}, and prints the
    /// medians, the ratios cgdem / other per repetition and the heap each code leaves.
    Bench(bench::BenchArgs),
    /// Add a nightly report (a `cgdem validate` output) to the history in DIR: appends its
    /// metrics to DIR/history.json, rewrites DIR/index.html with the history table, trend
    /// plots and flags, and prints the metrics that moved beyond tolerance since the
    /// previous night (scripts/nightly.sh calls this).
    History(history::HistoryArgs),
    /// Which coarse-graining level and rule keeps a quantity within a target, from a stored
    /// matrix (a `cgdem validate` report whose sweeps vary lambda under each rule against a
    /// fine reference; with --run, made first, for a scene file of one's own from the scene
    /// alone): the coarsest setting whose mean error over seeds plus twice its standard error
    /// is within the target, with its saving; "none" and the closest otherwise.
    #[command(
        after_help = "Exit status: 0 a setting meets the target; 1 none does (the answer says \"none\"); 2 bad arguments or input (an unknown quantity, a bad target, an unreadable scene, a scene that cannot measure the quantity, a matrix with no points for the case) or a run that cannot be written; 130 interrupted by SIGINT (Ctrl-C), 143 by SIGTERM: the runs already made are kept, and the same command again goes on from them."
    )]
    Advise(advise::AdviseArgs),
    /// Run a scene in a reference code (deck written from the scene, run, post-processed
    /// with cgdem's analysis into the same outputs).
    #[command(after_help = reference::EXIT_STATUS)]
    Reference {
        #[command(subcommand)]
        code: reference::ReferenceCommand,
    },
    /// Geometry tools: the meshes of Hirose's screw feeder and the SDF accuracy study.
    Geometry {
        #[command(subcommand)]
        command: geometry::GeometryCommand,
    },
}

impl Cli {
    /// Runs the subcommand; the exit code says how it ended (2: bad arguments).
    pub fn execute(self) -> ExitCode {
        match self.command {
            Command::Run(args) => run::execute(args),
            Command::Validate(args) => validate::execute(args),
            Command::Bench(args) => bench::execute(args),
            Command::History(args) => history::execute(args),
            Command::Advise(args) => advise::execute(args),
            Command::Reference { code } => reference::execute(code),
            Command::Geometry { command } => geometry::execute(command),
        }
    }
}

/// The coarse-graining rules as command-line values (`relative-overlap`, `bulk-viscosity`,
/// `scaled-particle`, `liggghts-pfm`); `seed`, the first name of `relative-overlap`, is still
/// accepted.
#[derive(Clone, Copy, ValueEnum)]
enum CgRule {
    #[value(alias = "seed")]
    RelativeOverlap,
    BulkViscosity,
    ScaledParticle,
    LiggghtsPfm,
}

impl From<CgRule> for CoarseGrainRule {
    fn from(rule: CgRule) -> Self {
        match rule {
            CgRule::RelativeOverlap => CoarseGrainRule::RelativeOverlap,
            CgRule::BulkViscosity => CoarseGrainRule::BulkViscosity,
            CgRule::ScaledParticle => CoarseGrainRule::ScaledParticle,
            CgRule::LiggghtsPfm => CoarseGrainRule::LiggghtsPfm,
        }
    }
}

/// How a scene file becomes the scene a command runs: its coarse-graining, insertion seed and
/// overrides (`cgdem run` and `cgdem reference`).
#[derive(Args)]
struct SceneArgs {
    /// Coarse-graining level: a power of two (1 = the original, uncoarsened system).
    /// Diameters grow by lambda, the particle count falls by lambda^3 (Hirose, Eq. 3-6).
    #[arg(long, default_value_t = 1)]
    lambda: u32,
    /// Coarse-graining rule. WCA: `relative-overlap` (Hirose's rule: eps' = lambda^3 eps,
    /// gamma' = lambda^2 gamma; keeps each contact's restitution and its overlap relative to
    /// the diameter; `seed` is its former name) or `bulk-viscosity` (eps' = lambda eps,
    /// gamma' = lambda gamma: keeps gamma/d, so viscous flows keep their speed). Hertz:
    /// `relative-overlap` (every contact force x lambda^2),
    /// `scaled-particle` (the same material in larger particles) or `liggghts-pfm`
    /// (LIGGGHTS-PFM's coarsegraining, cohesion scaled like the weight). What each keeps:
    /// reference/COARSE_GRAINING.md.
    #[arg(long, value_enum, default_value_t = CgRule::RelativeOverlap)]
    cg_rule: CgRule,
    /// Insertion seed: insertion k uses seed + k (default: the seeds in the case file).
    #[arg(long)]
    seed: Option<u64>,
    /// Override a scene field before validation, e.g. `--set wall_contact.friction=0.0`
    /// or `--set 'wall[2].point=[0.1, 0.0, 0.0]'` (TOML value; repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Name the variant the overrides make: appended to the scene's name
    /// (`aor_collapse-smooth-walls`), as a suite's `variant` does, so `validate --reuse`
    /// recognises the run.
    #[arg(long, requires = "set")]
    variant: Option<String>,
}

/// Reads a scene with its `--set` overrides (named `variant`) and, when given, an insertion
/// seed.
fn load_scene(
    case: &Path,
    set: &[String],
    variant: Option<&str>,
    seed: Option<u64>,
) -> Result<Scene, String> {
    let overrides = set
        .iter()
        .map(|o| Override::parse(o, Path::new("--set")))
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

/// `--checkpoint-every`, checked: a positive number of simulated seconds (exit code 2
/// otherwise, said).
fn checked_checkpoint_every(every: Option<f64>) -> Result<Option<f64>, ExitCode> {
    match every {
        Some(t) if !(t.is_finite() && t > 0.0) => {
            eprintln!(
                "error: --checkpoint-every {t}: must be a positive number of simulated seconds"
            );
            Err(ExitCode::from(2))
        }
        _ => Ok(every),
    }
}

/// The SIGINT/SIGTERM handlers of the commands that poll the stop flag (a failure to install
/// them leaves the default action, ending the process, and says so).
fn install_interrupt() -> Option<Interrupt> {
    match Interrupt::install() {
        Ok(i) => Some(i),
        Err(e) => {
            eprintln!("warning: SIGINT/SIGTERM handlers not installed ({e}): an interrupt ends cgdem at once");
            None
        }
    }
}

/// The exit code 130/143 after a signal stopped the command, with what was kept.
fn interrupted(interrupt: &Option<Interrupt>, kept: &Path) -> Option<ExitCode> {
    let (name, code) = interrupt.as_ref()?.received()?;
    eprintln!(
        "interrupted by {name}: stopped; the outputs written so far are kept in {}",
        kept.display()
    );
    Some(code)
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

/// The suite file a suite argument names: a path, or the name of a shipped suite, looked
/// for in the working directory's validation/suites, then in the repository this cgdem was
/// built from (so `--suite smoke` works from any directory on the machine that built it).
fn suite_path(suite: &str) -> PathBuf {
    if suite.ends_with(".toml") || suite.contains('/') {
        return PathBuf::from(suite);
    }
    let file = format!("{suite}.toml");
    let here = PathBuf::from("validation/suites").join(&file);
    let built_from = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("validation/suites")
        .join(&file);
    if !here.is_file() && built_from.is_file() {
        built_from
    } else {
        here
    }
}

/// Success, or the error said (`error: ...`) with exit code 1.
fn exit_with<E: std::fmt::Display>(result: Result<(), E>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
