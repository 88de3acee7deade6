//! `cgdem validate`: a suite run with cgdem and the reference codes, compared and reported.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use super::{checked_checkpoint_every, install_interrupt, interrupted, suite_path, worker_pool};
use cgdem_core::decomposition::{BalanceSpec, GridSpec};
use cgdem_harness::code::Code;
use cgdem_harness::runs::CgdemDecomposition;
use cgdem_harness::suite::Suite;
use cgdem_harness::validation::{validate_suite, Outcome, ValidateOptions, ValidationSummary};
use cgdem_harness::verdict::Verdict;

#[derive(Args)]
pub(super) struct ValidateArgs {
    /// A scene file of your own, validated without a suite file: run in cgdem, LIGGGHTS and
    /// LAMMPS (--codes), 3 seeds (--seeds), and measured as its observers say ([repose],
    /// [conveying], [discharge], [packing]), judged by the default tolerances.
    #[arg(value_name = "CASE.toml", conflicts_with = "suite")]
    case: Option<PathBuf>,
    /// The suite: a shipped one (smoke, nightly, full, ...: validation/suites) or a suite
    /// file's path; files it names are relative to it. Default: smoke.
    #[arg(long)]
    suite: Option<String>,
    /// With CASE.toml: the codes that run it (cgdem,liggghts,lammps).
    #[arg(
        long,
        value_delimiter = ',',
        requires = "case",
        default_value = "cgdem,liggghts,lammps"
    )]
    codes: Vec<String>,
    /// With CASE.toml: the coarse-graining levels (powers of two; 1 is the scene as written).
    #[arg(long, value_delimiter = ',', requires = "case", default_value = "1")]
    lambdas: Vec<u32>,
    /// With CASE.toml: the insertion seeds, one run per code, level and seed.
    #[arg(
        long,
        value_delimiter = ',',
        requires = "case",
        default_value = "1,2,3"
    )]
    seeds: Vec<u64>,
    /// Output directory (default: cgdem-reports/NAME in the working directory, NAME the
    /// suite's or the case's name).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Worker threads for cgdem (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Time limit of one reference-code run: seconds of CPU time per rank (a loaded or paused
    /// machine does not use it up), and 4 times that of wall clock (a hang).
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
    /// applied after the case's own, or `rpm_factor=F` (the screw of a conveying case
    /// turning F times as fast as the case says), the scene keeping its name, so its
    /// comparisons with the reference codes show that the verdicts can fail (repeatable;
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
    grid: Option<GridSpec>,
    /// As `cgdem run --balance`.
    #[arg(long, value_name = "THRESH|off", default_value_t)]
    balance: BalanceSpec,
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
}

pub(super) fn execute(args: ValidateArgs) -> ExitCode {
    let checkpoint_every = match checked_checkpoint_every(args.checkpoint_every) {
        Ok(every) => every,
        Err(code) => return code,
    };
    let ranks = args
        .np
        .map(|n| cgdem_harness::ranks::Ranks::checked(n, args.grid, args.cgdem_bin.as_deref()))
        .transpose();
    let ranks = match ranks {
        Ok(ranks) => ranks,
        Err(e) => {
            eprintln!("error: --np: {e}");
            return ExitCode::from(2);
        }
    };
    let pool = match worker_pool(args.threads) {
        Ok(pool) => pool,
        Err(code) => return code,
    };
    let suite = match load_suite(&args) {
        Ok(suite) => suite,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("cgdem-reports").join(&suite.name));
    let interrupt = install_interrupt();
    let options = ValidateOptions {
        suite: suite.source.clone(),
        out: out.clone(),
        quiet: args.quiet,
        progress: crate::progress_bar::progress(args.quiet),
        reference_timeout_s: args.reference_timeout,
        reuse: args.reuse,
        keep_going: args.keep_going,
        jobs: usize::from(args.jobs),
        stop: interrupt.as_ref().map(|i| i.flag()),
        cgdem_faults: args.fault,
        history: args.history,
        decomposition: CgdemDecomposition {
            grid: args.grid,
            balance: args.balance,
            ranks,
        },
        checkpoint_every,
        runs_dir: None,
    };
    let result = pool.install(|| validate_suite(&suite, &options));
    if let Some(code) = interrupted(&interrupt, &out) {
        if let Err(e) = &result {
            eprintln!("error: {e}");
        }
        return code;
    }
    match result {
        Ok(summary) => {
            println!(
                "{}; status {}; report in {}",
                counts(&summary),
                summary.status.word(),
                out.join("index.html").display()
            );
            ExitCode::from(summary.status.exit_code())
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// The suite to run: the one named by --suite (default smoke), or one made for CASE.toml.
fn load_suite(args: &ValidateArgs) -> Result<Suite, String> {
    let Some(case) = &args.case else {
        let path = suite_path(args.suite.as_deref().unwrap_or("smoke"));
        return Suite::load(&path).map_err(|e| e.to_string());
    };
    let scene = cgdem_core::scene::Scene::load(case).map_err(|e| e.to_string())?;
    for w in scene.implausible_parameters() {
        eprintln!("warning: {w}");
    }
    let codes = args
        .codes
        .iter()
        .map(|name| {
            Code::from_name(name).ok_or_else(|| {
                format!("--codes {name:?}: not a code; allowed: cgdem, liggghts, lammps")
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Suite::for_scene(case, &scene.name, &codes, &args.lambdas, &args.seeds)
        .map_err(|e| e.to_string())
}

/// The suite's runs, comparisons, accuracy points and stability runs, counted with their
/// failures.
fn counts(summary: &ValidationSummary) -> String {
    let failed = summary.comparisons.iter().filter(|c| !c.pass).count();
    let known = summary
        .comparisons
        .iter()
        .filter(|c| c.verdict == Verdict::KnownDifference)
        .count();
    let runs = |status: Outcome| summary.runs.iter().filter(|r| r.status == status).count();
    let mut extra = String::new();
    if let Some(accuracy) = &summary.accuracy {
        extra += &format!(", {} accuracy points", accuracy.points.len());
    }
    if !summary.stability.is_empty() {
        use cgdem_harness::stability::Verdict;
        let failed = |cgdem: bool| {
            summary
                .stability
                .iter()
                .filter(|r| r.verdict == Verdict::Failed && (r.code == Code::Cgdem) == cgdem)
                .count()
        };
        extra += &format!(
            ", {} stability runs (failed: {} in cgdem, {} in the reference codes)",
            summary.stability.len(),
            failed(true),
            failed(false)
        );
    }
    format!(
        "suite {}: {} runs ({} failed, {} skipped: code missing, {} unsupported: code cannot express the case), {} comparisons ({} fail, {known} known differences){extra}",
        summary.suite,
        summary.runs.len(),
        runs(Outcome::Failed),
        runs(Outcome::Skipped),
        runs(Outcome::Unsupported),
        summary.comparisons.len(),
        failed,
    )
}
