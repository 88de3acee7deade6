//! The `cgdem` command: a thin layer that turns arguments into validated settings, calls the
//! library and reports errors as messages with a non-zero exit code.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use cgdem::coarse_graining::{
    coarse_grain, coarse_grain_by, coarse_grain_warnings, CoarseGrainRule,
};
use cgdem::geometry::accuracy::format_accuracy_table;
use cgdem::geometry::screw_feeder::{self, ScrewFeederSpec};
use cgdem::report::sdf_study::write_sdf_accuracy_study;
use cgdem::run::{run, RunOptions};
use cgdem::scene::Scene;
use cgdem::sweep::Sweep;

#[derive(Parser)]
#[command(
    name = "cgdem",
    version,
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
        /// The scene file, e.g. validation/cases/aor_collapse.toml.
        case: PathBuf,
        /// Coarse-graining level: a power of two (1 = the original, uncoarsened system).
        /// Diameters grow by lambda, the particle count falls by lambda^3 (paper A Eq. 3-6).
        #[arg(long, default_value_t = 1)]
        lambda: u32,
        /// Coarse-graining rule: `seed` (paper A: eps' = lambda^3 eps, gamma' = lambda^2 gamma)
        /// or `bulk-viscosity` (eps' = lambda eps, gamma' = lambda gamma: keeps gamma/d, so
        /// viscous flows keep their speed; see reference/COARSE_GRAINING.md).
        #[arg(long, value_enum, default_value_t = CoarseGrainRule::Seed)]
        cg_rule: CoarseGrainRule,
        /// Insertion seed: insertion k uses seed + k (default: the seeds in the case file).
        #[arg(long)]
        seed: Option<u64>,
        /// Output directory (default: runs/<case>-lambda<N>).
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
        /// Refuse to coarse-grain where the scaling rule is inconsistent for the scene's
        /// model (gravity, cohesion, rolling with Hertz), instead of warning.
        #[arg(long)]
        strict: bool,
        /// A sweep, one run per value: `rpm=20,40,60` (screw speed of the `[conveying]` body;
        /// OUT/rpm<N>/, OUT/mass_flow_vs_rpm.csv and a plot with Eq. (7)) or
        /// `diameter=1e-6,1e-5,1e-4` (m; a `[packing]` scene rescaled to each diameter with the
        /// material held; OUT/d<um>um/, OUT/porosity_vs_diameter.csv, pore_size_vs_diameter.csv
        /// and plots with the published points).
        #[arg(long)]
        sweep: Option<String>,
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
    },
    /// Run a scene in a reference code (deck written from the scene, run, post-processed
    /// with cgdem's analysis into the same outputs).
    Reference {
        #[command(subcommand)]
        code: ReferenceCode,
    },
    /// Geometry tools: the seed's screw-feeder meshes and the SDF accuracy study.
    Geometry {
        #[command(subcommand)]
        command: GeometryCommand,
    },
}

#[derive(Subcommand)]
enum ReferenceCode {
    /// LAMMPS (`lmp` on PATH or $CGDEM_LMP); see reference/lammps/SEED_MODEL.md.
    Lammps {
        /// The scene file, e.g. validation/cases/aor_collapse.toml.
        case: PathBuf,
        /// Coarse-graining level (a power of two), applied before the deck is written.
        #[arg(long, default_value_t = 1)]
        lambda: u32,
        /// Insertion seed: insertion k uses seed + k (default: the seeds in the case file).
        #[arg(long)]
        seed: Option<u64>,
        /// Output directory (default: runs/<case>-lambda<N>-lammps).
        #[arg(long)]
        out: Option<PathBuf>,
        /// MPI ranks (runs `mpirun --allow-run-as-root -np N lmp`); default: serial.
        #[arg(long)]
        np: Option<u32>,
        /// Kill LAMMPS after this many seconds.
        #[arg(long, default_value_t = 7200)]
        timeout: u64,
        /// Write the deck even if the time step exceeds the stable limit.
        #[arg(long)]
        force_dt: bool,
        /// Do not run: post-process the LAMMPS outputs already in --out (e.g. of a run that
        /// was stopped; the samples it reached are used).
        #[arg(long)]
        postprocess_only: bool,
    },
}

#[allow(clippy::too_many_arguments)]
fn reference_lammps(
    case: &std::path::Path,
    lambda: u32,
    seed: Option<u64>,
    out: Option<PathBuf>,
    np: Option<u32>,
    timeout: u64,
    force_dt: bool,
    postprocess_only: bool,
) -> Result<ExitCode, String> {
    use cgdem::harness::lammps::{self, RunStatus, RunnerOptions};
    let scene = Scene::load(case).map_err(|e| e.to_string())?;
    let scene = match seed {
        Some(s) => scene.with_insertion_seed(s),
        None => scene,
    };
    let scene = coarse_grain(&scene, lambda).map_err(|e| e.to_string())?;
    let out = out.unwrap_or_else(|| {
        PathBuf::from("runs").join(format!("{}-lambda{}-lammps", scene.name, scene.lambda))
    });
    let (dt, scales, warning) =
        cgdem::run::time_step(&scene, force_dt).map_err(|e| e.to_string())?;
    if let Some(w) = warning {
        eprintln!("warning: {w}");
    }
    let particles = cgdem::run::initial_particles(&scene, false, &[]).map_err(|e| e.to_string())?;
    let deck = lammps::write_deck(&scene, &particles, dt).map_err(|e| e.to_string())?;
    let finish = |wall_s: f64, note: Option<String>| -> Result<cgdem::run::RunSummary, String> {
        let mut summary = lammps::postprocess(
            &scene,
            &out,
            &deck.plan,
            &scales,
            wall_s,
            np.unwrap_or(1) as usize,
        )
        .map_err(|e| e.to_string())?;
        summary.warnings.extend(note);
        lammps::write_summary(&summary, &out).map_err(|e| e.to_string())?;
        Ok(summary)
    };
    let status = if postprocess_only {
        let previous = std::fs::read_to_string(out.join(lammps::deck::DECK_FILE)).map_err(|e| {
            format!(
                "--postprocess-only: cannot read {}: {e}",
                out.join(lammps::deck::DECK_FILE).display()
            )
        })?;
        if previous != deck.input {
            return Err(format!(
                "--postprocess-only: {} was not written for this case, lambda and seed",
                out.join(lammps::deck::DECK_FILE).display()
            ));
        }
        RunStatus::Completed { wall_s: f64::NAN }
    } else {
        deck.write_to(&out)
            .map_err(|e| format!("cannot write the deck into {}: {e}", out.display()))?;
        println!(
            "deck for {} at lambda = {} ({} particles, dt = {dt:.4e} s) in {}",
            scene.name,
            scene.lambda,
            particles.len(),
            out.display()
        );
        let options = RunnerOptions {
            np,
            timeout: std::time::Duration::from_secs(timeout),
        };
        lammps::run_deck(&out, &options)
    };
    match status {
        RunStatus::Completed { wall_s } => {
            let summary = finish(wall_s, None)?;
            println!(
                "LAMMPS: {} steps, {:.1} s wall time, {:.3e} particle-steps/s (loop time)",
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
            "LAMMPS failed (exit code {exit_code:?}) in {}; log tail:\n{log_tail}",
            out.display()
        )),
        RunStatus::TimedOut { after_s, log_tail } => {
            // Keep what the run reached: partial outputs and a summary that says so.
            let note = format!("LAMMPS killed after {after_s:.0} s (--timeout): partial run");
            let partial = finish(after_s, Some(note))
                .err()
                .map_or(String::new(), |e| {
                    format!(" (post-processing the partial run failed: {e})")
                });
            Err(format!("LAMMPS killed after {after_s:.0} s (--timeout) in {}{partial}; log tail:\n{log_tail}", out.display()))
        }
    }
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Validate {
            suite,
            out,
            threads,
            reference_timeout,
            quiet,
        } => {
            let suite_path = if suite.ends_with(".toml") || suite.contains('/') {
                PathBuf::from(&suite)
            } else {
                PathBuf::from("validation/suites").join(format!("{suite}.toml"))
            };
            let pool = match worker_pool(threads) {
                Ok(pool) => pool,
                Err(code) => return code,
            };
            let options = cgdem::harness::validate::ValidateOptions {
                suite: suite_path,
                out: out.clone(),
                quiet,
                reference_timeout_s: reference_timeout,
            };
            match pool.install(|| cgdem::harness::validate::validate(&options)) {
                Ok(summary) => {
                    let failed = summary.comparisons.iter().filter(|c| !c.pass).count();
                    let runs_failed = summary.runs.iter().filter(|r| r.status == "failed").count();
                    println!(
                        "suite {}: {} runs ({} failed, {} skipped), {} comparisons ({} outside tolerance); report in {}",
                        summary.suite,
                        summary.runs.len(),
                        runs_failed,
                        summary.runs.iter().filter(|r| r.status == "skipped").count(),
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
        Command::Reference {
            code:
                ReferenceCode::Lammps {
                    case,
                    lambda,
                    seed,
                    out,
                    np,
                    timeout,
                    force_dt,
                    postprocess_only,
                },
        } => match reference_lammps(
            &case,
            lambda,
            seed,
            out,
            np,
            timeout,
            force_dt,
            postprocess_only,
        ) {
            Ok(code) => code,
            Err(message) => {
                eprintln!("error: {message}");
                ExitCode::FAILURE
            }
        },
        Command::Geometry { command } => geometry(command),
        Command::Run {
            case,
            lambda,
            cg_rule,
            seed,
            out,
            threads,
            quiet,
            force_dt,
            strict,
            sweep,
        } => {
            let sweep = match sweep.as_deref().map(Sweep::parse).transpose() {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            let pool = match worker_pool(threads) {
                Ok(pool) => pool,
                Err(code) => return code,
            };
            let result = pool.install(|| {
                Scene::load(&case)
                    .map_err(|e| e.to_string())
                    .map(|scene| match seed {
                        Some(s) => scene.with_insertion_seed(s),
                        None => scene,
                    })
                    .and_then(|scene| {
                        let warnings = coarse_grain_warnings(&scene, lambda);
                        if strict && !warnings.is_empty() {
                            return Err(format!(
                                "{}: --strict: coarse-graining by lambda = {lambda} is inconsistent:\n  {}",
                                case.display(),
                                warnings.join("\n  ")
                            ));
                        }
                        for w in &warnings {
                            eprintln!("warning: coarse-graining: {w}");
                        }
                        coarse_grain_by(&scene, lambda, cg_rule).map_err(|e| e.to_string())
                    })
                    .and_then(|scene| {
                        let out_dir = out.unwrap_or_else(|| default_out_dir(&scene));
                        if let Some(Sweep::Diameter(diameters)) = &sweep {
                            let results = cgdem::sweep::diameter_sweep(&scene, diameters, &out_dir, quiet, force_dt)?;
                            for (d, s) in &results {
                                let porosity = s.packing.as_ref().map_or("not measured".into(), |p| format!("{:.4}", p.porosity));
                                println!("d = {:.3e} m: {} particles, {} steps of {:.3e} s, porosity {porosity}, wall {:.1} s", d, s.n_particles, s.steps, s.dt_s, s.wall_s);
                            }
                            println!("porosity_vs_diameter.csv, pore_size_vs_diameter.csv and plots in {}", out_dir.display());
                            let last = results.into_iter().last().map(|r| r.1).ok_or("empty sweep")?;
                            return Ok((last, out_dir));
                        }
                        if let Some(Sweep::Rpm(speeds)) = &sweep {
                            let results = cgdem::sweep::rpm_sweep(&scene, speeds, &out_dir, quiet, force_dt)?;
                            for (rpm, s) in &results {
                                if let Some(c) = &s.conveying {
                                    println!("{rpm} rpm: {:.4} +- {:.4} kg/s, Eq. (7) {:.4} kg/s (a = {:.3}), wall {:.1} s", c.mass_flow_kg_s, c.mass_flow_std_error_kg_s, c.eq7_mass_flow_kg_s, c.fill_ratio, s.wall_s);
                                }
                            }
                            let last = results.into_iter().last().map(|r| r.1).ok_or("empty sweep")?;
                            return Ok((last, out_dir));
                        }
                        let options = RunOptions {
                            out_dir: out_dir.clone(),
                            quiet,
                            force_dt,
                        };
                        run(&scene, &options)
                            .map(|summary| (summary, out_dir))
                            .map_err(|e| e.to_string())
                    })
            });
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
        if let Some(rule) = scene.cg_rule.to_possible_value() {
            name += &format!("-{}", rule.get_name());
        }
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
