//! The `cgdem` command: a thin layer that turns arguments into validated settings, calls the
//! library and reports errors as messages with a non-zero exit code.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use cgdem::coarse_graining::coarse_grain;
use cgdem::geometry::accuracy::format_accuracy_table;
use cgdem::geometry::screw_feeder::{self, ScrewFeederSpec};
use cgdem::report::sdf_study::write_sdf_accuracy_study;
use cgdem::run::{run, RunOptions};
use cgdem::scene::Scene;

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
        /// Screw-speed sweep, e.g. `rpm=20,40,60`: one run per speed of the `[conveying]`
        /// body into OUT/rpm<N>/, then OUT/mass_flow_vs_rpm.csv and a plot with Eq. (7).
        #[arg(long)]
        sweep: Option<String>,
    },
    /// Geometry tools: the seed's screw-feeder meshes and the SDF accuracy study.
    Geometry {
        #[command(subcommand)]
        command: GeometryCommand,
    },
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
        Command::Geometry { command } => geometry(command),
        Command::Run {
            case,
            lambda,
            out,
            threads,
            quiet,
            force_dt,
            sweep,
        } => {
            let speeds: Option<Vec<f64>> = match sweep.as_deref().map(|s| s.strip_prefix("rpm=")) {
                None => None,
                Some(Some(list)) => match list
                    .split(',')
                    .map(|v| v.trim().parse::<f64>())
                    .collect::<Result<Vec<_>, _>>()
                {
                    Ok(v) if !v.is_empty() && v.iter().all(|x| x.is_finite() && *x > 0.0) => {
                        Some(v)
                    }
                    _ => {
                        eprintln!("error: --sweep expects rpm=<positive numbers separated by commas>, got `{list}`");
                        return ExitCode::from(2);
                    }
                },
                Some(None) => {
                    eprintln!("error: --sweep expects rpm=<list>, e.g. rpm=20,40,60");
                    return ExitCode::from(2);
                }
            };
            if threads == Some(0) {
                eprintln!("error: --threads must be at least 1");
                return ExitCode::from(2);
            }
            // The whole run executes inside the pool: parallel loops started from a worker
            // thread run small jobs inline instead of handing them across threads each step.
            let pool = match rayon::ThreadPoolBuilder::new()
                .num_threads(threads.unwrap_or(0))
                .build()
            {
                Ok(pool) => pool,
                Err(e) => {
                    eprintln!("error: cannot start the worker threads: {e}");
                    return ExitCode::FAILURE;
                }
            };
            let result = pool.install(|| {
                Scene::load(&case)
                    .map_err(|e| e.to_string())
                    .and_then(|scene| coarse_grain(&scene, lambda).map_err(|e| e.to_string()))
                    .and_then(|scene| {
                        let out_dir = out.unwrap_or_else(|| {
                            PathBuf::from("runs")
                                .join(format!("{}-lambda{}", scene.name, scene.lambda))
                        });
                        if let Some(speeds) = &speeds {
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
