//! `cgdem run`: one scene (or a sweep of it) run and its figures reported; `--resume` goes
//! on from a restart file, with the command line and grid it stored (`run::restart`).

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use clap::Args;

use super::{
    checked_checkpoint_every, install_interrupt, interrupted, load_scene, worker_pool, SceneArgs,
};
use crate::progress_bar::progress;
use cgdem_core::coarse_graining::{coarse_grain_by, coarse_grain_checks, CgSeverity};
use cgdem_core::decomposition::{BalanceSpec, Comm, GridSpec};
use cgdem_core::run::restart::{RestartLoaded, RunInvocation};
use cgdem_core::run::{run, CheckpointOptions, RunOptions, RunSummary};
use cgdem_core::scene::Scene;
use cgdem_harness::sweep::{Sweep, SweepSettings};

#[derive(Args)]
pub(super) struct RunArgs {
    /// The scene file, e.g. validation/cases/aor_collapse.toml, or the `scene.json` a
    /// harness run wrote (`validate --np`), run as written. With --resume it names the
    /// scene to continue instead of the command line the run stored (the digests must
    /// match): how `validate --np` resumes the runs it started.
    #[arg(required_unless_present = "resume")]
    case: Option<PathBuf>,
    #[command(flatten)]
    scene: SceneArgs,
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
    /// the scene (e.g. the relative-overlap rule with van der Waals cohesion under gravity: the Bond
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
    grid: Option<GridSpec>,
    /// At each list rebuild, when the imbalance (most particles in one subdomain over
    /// the mean) passes this threshold, move the cut planes so that each slab along each
    /// axis holds the same number of particles (LAMMPS `fix balance ... shift`), never
    /// thinner than the ghost layer; `off` keeps the start's planes. At least 1.0;
    /// default 1.1, or with --resume the one the run started with. summary.json's
    /// `decomposition` gives the shifts and the imbalance the start's planes would give.
    #[arg(long, value_name = "THRESH|off")]
    balance: Option<BalanceSpec>,
    /// With `--sweep rpm=` or `screw_ratio=`: a run directory whose summary.json holds
    /// the same scene (digest) is not run again, so a sweep can be resumed or extended.
    #[arg(long)]
    reuse: bool,
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
}

pub(super) fn execute(args: RunArgs) -> ExitCode {
    match planned(args) {
        Ok(plan) => plan.execute(),
        Err(code) => code,
    }
}

/// Everything one `cgdem run` does, checked and resolved before anything runs.
struct RunPlan {
    /// What rebuilds the scene (this command line or the resumed one's), naming the grid.
    invocation: RunInvocation,
    resumed: Option<Arc<RestartLoaded>>,
    sweep: Option<Sweep>,
    out: Option<PathBuf>,
    threads: Option<usize>,
    quiet: bool,
    strict: bool,
    reuse: bool,
    grid: Option<GridSpec>,
    balance: BalanceSpec,
    checkpoint_every: Option<f64>,
    initial_state: Option<PathBuf>,
    comm: Comm,
}

/// The arguments checked and the resumed run's command line and grid restored; the exit
/// code of a refusal (already said) otherwise.
fn planned(args: RunArgs) -> Result<RunPlan, ExitCode> {
    let usage = |message: String| {
        eprintln!("error: {message}");
        ExitCode::from(2)
    };
    let sweep = args.sweep.as_deref().map(Sweep::parse).transpose();
    let sweep = sweep.map_err(|e| usage(e.to_string()))?;
    if args.checkpoint_every.is_some() && sweep.is_some() {
        return Err(usage("--checkpoint-every: not supported with --sweep (each run of a sweep is its own run; --reuse skips the finished ones)".into()));
    }
    let checkpoint_every = checked_checkpoint_every(args.checkpoint_every)?;
    let given = RunInvocation {
        case: args
            .case
            .clone()
            .map(|c| std::path::absolute(&c).unwrap_or(c))
            .unwrap_or_default(),
        lambda: args.scene.lambda,
        cg_rule: args.scene.cg_rule.into(),
        seed: args.scene.seed,
        set: args.scene.set,
        variant: args.scene.variant,
        force_dt: args.force_dt,
        keep_going: args.keep_going,
        grid: args.grid.map(|g| g.to_string()),
        balance: args.balance.map(|b| b.to_string()),
    };
    let (invocation, resumed) =
        RunInvocation::resolve(given, args.case.is_some(), args.resume.as_deref()).map_err(
            |e| {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            },
        )?;
    if let Some(loaded) = &resumed {
        eprintln!("resuming from {}", loaded.path.display());
    }
    let (invocation, grid, balance) = invocation
        .with_grid(args.grid, args.balance)
        .map_err(usage)?;
    let checkpoint_every =
        checkpoint_every.or_else(|| resumed.as_ref().map(|l| l.restart.checkpoint_every));
    // Under mpirun (a build with the `mpi` feature) each rank steps its subdomains; rank 0
    // writes the outputs, the others write theirs into a scratch directory.
    let comm = Comm::from_environment().map_err(|e| usage(e.to_string()))?;
    if comm.is_distributed() && sweep.is_some() {
        if comm.is_root() {
            eprintln!(
                "error: under mpirun ({} ranks) cgdem run takes no --sweep",
                comm.size()
            );
        }
        return Err(ExitCode::from(2));
    }
    Ok(RunPlan {
        invocation,
        resumed,
        sweep,
        out: args.resume.or(args.out),
        threads: args.threads,
        quiet: args.quiet,
        strict: args.strict,
        reuse: args.reuse,
        grid,
        balance,
        checkpoint_every,
        initial_state: args.initial_state,
        comm,
    })
}

impl RunPlan {
    /// Runs the scene (or its sweep) on the worker pool; rank 0 reports.
    fn execute(self) -> ExitCode {
        let pool = match worker_pool(self.threads) {
            Ok(pool) => pool,
            Err(code) => return code,
        };
        // Sweeps run their own options and do not poll the stop flag: a signal ends them.
        let interrupt = self.sweep.is_none().then(install_interrupt).flatten();
        let stop = interrupt.as_ref().map(|i| i.flag());
        let mut figures = Vec::new();
        let mut out_used = None;
        let result = pool.install(|| self.scene_run(stop, &mut out_used, &mut figures));
        if !self.comm.is_root() {
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
                print_summary(&summary, &figures, &out_dir);
                ExitCode::SUCCESS
            }
            Err(message) => {
                eprintln!("error: {message}");
                ExitCode::FAILURE
            }
        }
    }

    /// The scene built and run, or its sweep; `out_used` names the output directory of a
    /// single run, `figures` the figures drawn of it.
    fn scene_run(
        &self,
        stop: Option<Arc<AtomicBool>>,
        out_used: &mut Option<PathBuf>,
        figures: &mut Vec<PathBuf>,
    ) -> Result<(RunSummary, PathBuf), String> {
        let scene = self.coarse_grained_scene()?;
        let out_dir = self.out.clone().unwrap_or_else(|| default_out_dir(&scene));
        if let Some(sweep) = &self.sweep {
            let settings = SweepSettings {
                progress: progress(self.quiet),
                force_dt: self.invocation.force_dt,
                keep_going: self.invocation.keep_going,
                reuse: self.reuse,
            };
            let done = sweep.run(&scene, &out_dir, settings)?;
            for line in &done.lines {
                println!("{line}");
            }
            return Ok((done.last, out_dir));
        }
        *out_used = Some(out_dir.clone());
        let summary = self.single_run(&scene, &out_dir, stop)?;
        if self.comm.is_root() {
            // A figure that cannot be drawn does not fail the run it shows.
            match cgdem_harness::report::run_figures::write_run_figures(&scene, &summary, &out_dir)
            {
                Ok(files) => figures.extend(files.into_iter().map(|f| f.png)),
                Err(e) => eprintln!("warning: figure not written: {e}"),
            }
        }
        Ok((summary, out_dir))
    }

    /// The scene of the command line, checked against `--strict` and coarse-grained.
    fn coarse_grained_scene(&self) -> Result<Scene, String> {
        let inv = &self.invocation;
        let scene = load_scene(&inv.case, &inv.set, inv.variant.as_deref(), inv.seed)?;
        let (lambda, cg_rule) = (inv.lambda, inv.cg_rule);
        for w in scene.implausible_parameters() {
            eprintln!("warning: {w}");
        }
        let checks = coarse_grain_checks(&scene, lambda, cg_rule);
        let refused: Vec<String> = checks
            .iter()
            .filter(|c| c.severity == CgSeverity::Inconsistent)
            .map(|c| format!("{}: {}", c.parameter, c.message))
            .collect();
        if self.strict && !refused.is_empty() {
            return Err(format!(
                "{}: --strict: the {} rule cannot keep this scene consistent at lambda = {lambda}:\n  {}",
                inv.case.display(),
                cg_rule.name(),
                refused.join("\n  ")
            ));
        }
        for c in &checks {
            eprintln!("warning: coarse-graining: {c}");
        }
        coarse_grain_by(&scene, lambda, cg_rule).map_err(|e| e.to_string())
    }

    /// One run of `scene` into `out_dir` (ranks other than 0 into a scratch directory they
    /// remove afterwards).
    fn single_run(
        &self,
        scene: &Scene,
        out_dir: &std::path::Path,
        stop: Option<Arc<AtomicBool>>,
    ) -> Result<RunSummary, String> {
        let root = self.comm.is_root();
        let scratch = (!root).then(|| {
            std::env::temp_dir().join(format!(
                "cgdem-rank{}-{}",
                self.comm.rank(),
                std::process::id()
            ))
        });
        let initial_state = self
            .initial_state
            .as_deref()
            .map(|path| cgdem_core::run::state_file::read(path, scene))
            .transpose()?;
        let options = RunOptions {
            initial_state,
            out_dir: scratch.clone().unwrap_or_else(|| out_dir.to_path_buf()),
            progress: progress(self.quiet || !root),
            force_dt: self.invocation.force_dt,
            keep_going: self.invocation.keep_going,
            stop,
            grid: self.grid,
            balance: self.balance,
            checkpoint: self.checkpoint_every.map(|every| CheckpointOptions {
                every,
                invocation: serde_json::to_string(&self.invocation).expect("plain data"),
            }),
            resume: self.resumed.clone(),
            comm: self.comm.clone(),
            ..Default::default()
        };
        let summary = run(scene, &options).map_err(|e| e.to_string());
        if let Some(dir) = &scratch {
            let _ = std::fs::remove_dir_all(dir);
        }
        summary
    }
}

/// `runs/<case>-lambda<N>`, with the rule appended when it is not the default
/// (`relative-overlap`).
fn default_out_dir(scene: &Scene) -> PathBuf {
    let mut name = format!("{}-lambda{}", scene.name, scene.lambda);
    if scene.cg_rule != cgdem_core::coarse_graining::CoarseGrainRule::RelativeOverlap {
        name += &format!("-{}", scene.cg_rule.name());
    }
    PathBuf::from("runs").join(name)
}

/// What the run measured, its figures and where its outputs are.
fn print_summary(summary: &RunSummary, figures: &[PathBuf], out_dir: &std::path::Path) {
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
    } else if let Some(reason) = &summary.repose_not_measured {
        println!("repose angle not measured: {reason}");
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
    for png in figures {
        println!("figure {} (.svg, .csv beside it)", png.display());
    }
    println!("outputs in {}", out_dir.display());
}
