//! `cgdem reference lammps|liggghts`: a scene run in a reference code.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand};

use super::{install_interrupt, interrupted, load_scene, SceneArgs};
use cgdem_core::coarse_graining::coarse_grain_by;
use cgdem_harness::code::Code;
use cgdem_harness::decks::{
    run_reference, ReferenceOptions, ReferenceRun, RunStatus, RunnerOptions,
};

/// The exit statuses of `cgdem reference`, shown under its help and its codes' help.
pub(super) const EXIT_STATUS: &str = "Exit status: 0 the code ran and its outputs were post-processed; 1 the scene could not be written as a deck, or the code failed or timed out (its log's tail is printed); 3 the code is not installed (the deck is written in the output directory, to be run where it is); 130 interrupted by SIGINT (Ctrl-C), 143 by SIGTERM.";

/// The exit status of a run the code was not there for: a script that asked for a reference
/// run must not read it as done (`cgdem validate` calls such a suite incomplete, also 3).
const NOT_INSTALLED: u8 = 3;

#[derive(Subcommand)]
pub(super) enum ReferenceCommand {
    /// LAMMPS (`lmp` on PATH or $CGDEM_LMP): the WCA model of Hirose
    /// (reference/lammps/SEED_MODEL.md) and Hertz scenes (reference/MAPPING.md).
    #[command(after_help = EXIT_STATUS)]
    Lammps(ReferenceArgs),
    /// LIGGGHTS (`liggghts` on PATH or $CGDEM_LIGGGHTS): Hertz scenes with LIGGGHTS's keywords.
    #[command(after_help = EXIT_STATUS)]
    Liggghts(ReferenceArgs),
}

#[derive(Args)]
pub(super) struct ReferenceArgs {
    /// The scene file, e.g. validation/cases/aor_collapse.toml.
    case: PathBuf,
    #[command(flatten)]
    scene: SceneArgs,
    /// Output directory (default: runs/CASE-lambdaN-CODE).
    #[arg(long)]
    out: Option<PathBuf>,
    /// MPI ranks (runs `mpirun --allow-run-as-root -np N lmp|liggghts`); default: serial.
    #[arg(long)]
    np: Option<u32>,
    /// Kill the code after this many seconds of CPU time per rank (a loaded or paused machine
    /// does not use it up), or 4 times that of wall clock (a hang).
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

pub(super) fn execute(command: ReferenceCommand) -> ExitCode {
    match reference_run(command) {
        Ok(code) => code,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn reference_run(command: ReferenceCommand) -> Result<ExitCode, String> {
    let (code, args) = match command {
        ReferenceCommand::Lammps(args) => (Code::Lammps, args),
        ReferenceCommand::Liggghts(args) => (Code::Liggghts, args),
    };
    let SceneArgs {
        lambda,
        cg_rule,
        seed,
        set,
        variant,
    } = args.scene;
    let scene = load_scene(&args.case, &set, variant.as_deref(), seed)?;
    let scene = coarse_grain_by(&scene, lambda, cg_rule.into()).map_err(|e| e.to_string())?;
    let out = args.out.unwrap_or_else(|| {
        PathBuf::from("runs").join(format!(
            "{}-lambda{}-{}",
            scene.name,
            scene.lambda,
            code.label().to_lowercase()
        ))
    });
    let interrupt = install_interrupt();
    let options = ReferenceOptions {
        code,
        runner: RunnerOptions {
            np: args.np,
            timeout: std::time::Duration::from_secs(args.timeout),
            stop: interrupt.as_ref().map(|i| i.flag()),
        },
        force_dt: args.force_dt,
        postprocess_only: args.postprocess_only,
    };
    let run = run_reference(&scene, &out, &options);
    if let Some(code) = interrupted(&interrupt, &out) {
        if let Err(e) = &run {
            eprintln!("{e}");
        }
        return Ok(code);
    }
    let run = run.map_err(|e| e.to_string())?;
    if let Some(w) = &run.dt_warning {
        eprintln!("warning: {w}");
    }
    if !args.postprocess_only {
        println!(
            "deck for {} at lambda = {} ({} particles, dt = {:.4e} s) in {}",
            scene.name,
            scene.lambda,
            run.n_particles,
            run.dt,
            out.display()
        );
    }
    report(code, run, &out)
}

/// What the reference run did: its figures, a skip, or the failure with its log's tail.
fn report(code: Code, run: ReferenceRun, out: &std::path::Path) -> Result<ExitCode, String> {
    let name = code.label();
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
            eprintln!(
                "error: {name} is not installed, so it did not run: {reason}; install with `{install_hint}`. The deck is in {}",
                out.display()
            );
            Ok(ExitCode::from(NOT_INSTALLED))
        }
        RunStatus::Failed {
            exit_code,
            log_tail,
        } => Err(format!(
            "{name} failed (exit code {exit_code:?}) in {}; log tail:\n{log_tail}",
            out.display()
        )),
        RunStatus::TimedOut {
            after_s,
            cpu_s,
            log_tail,
        } => {
            // The partial outputs are kept, with a summary that says so when it could be made.
            let partial = run.partial_error.map_or(String::new(), |e| {
                format!(" (post-processing the partial run failed: {e})")
            });
            Err(format!(
                "{name} killed after {cpu_s:.0} s of CPU per rank, {after_s:.0} s of wall clock (--timeout) in {}{partial}; log tail:\n{log_tail}",
                out.display()
            ))
        }
    }
}
