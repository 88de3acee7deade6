//! `cgdem advise`: which coarse-graining level and rule keeps a quantity within a target,
//! from a stored matrix (with `--run`, after making the case's missing points: from a
//! suite's sweeps, or for a scene no suite names, from the scene alone).
//!
//! Exit status: 0 a setting meets the target, 1 none does, 2 bad arguments or input (or a
//! run that cannot be written), 130/143 interrupted by SIGINT/SIGTERM.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;

use super::{install_interrupt, interrupted, suite_path, worker_pool, CgRule};
use cgdem_core::scene::Scene;
use cgdem_harness::accuracy::Measure;
use cgdem_harness::advise::{self, MatrixChoice, SceneMatrix};
use cgdem_harness::validation::ValidateOptions;

/// Exit status of bad arguments or input.
const BAD_INPUT: u8 = 2;
/// Exit status when no setting meets the target.
const NONE_MEETS: u8 = 1;

/// Where `advise CASE.toml --run` keeps a scene's matrix when no --matrix is given: in the
/// working directory, outside any tracked file.
const SCENE_MATRICES: &str = "cgdem-advise";

#[derive(Args)]
pub(super) struct AdviseArgs {
    /// The case: its scene file (e.g. validation/cases/aor_hertz.toml) or its name in the
    /// report (e.g. aor_hertz-fidelity).
    case: String,
    /// repose_angle (deg), profile, mass_flow, mass_flow_eq7, t_half, front_history,
    /// pore_size, discharge_rate (relative), porosity (absolute); for a rotating drum measured
    /// by a suite: dynamic_angle (deg), mixing_period (relative), mixing_index (absolute).
    #[arg(long)]
    quantity: String,
    /// The largest error allowed, in the quantity's unit (e.g. 2 for 2 deg, 0.05 for 5%).
    #[arg(long)]
    target: f64,
    /// The report directory (or its summary.json) holding the matrix (default: for a scene
    /// file no suite names, cgdem-advise/SCENE_NAME in the working directory; otherwise
    /// reports/cg_fidelity).
    #[arg(long)]
    matrix: Option<PathBuf>,
    /// Print the answer as JSON.
    #[arg(long)]
    json: bool,
    /// First make the case's points the matrix lacks. For a case a suite's sweeps name: they
    /// run as `cgdem validate --reuse` runs them, in MATRIX/runs (the runs already there are
    /// taken), with the case's own report in MATRIX/advise/CASE/, which the answer then
    /// reads; the matrix's report is left as it was (`cgdem validate --suite S --out MATRIX
    /// --reuse` rebuilds it with the new points). For a scene file no suite names: a matrix
    /// from the scene alone (levels 1, 2, 4, ... down to the coarsest keeping 200 particles
    /// and 5 parcel diameters across an orifice; the rules defined for its law; seeds 1, 2,
    /// 3), its expected cost printed first (particle-steps, and hours from a short probe
    /// run), its runs and report in MATRIX. Interrupted (Ctrl-C: exit 130), the same
    /// command again takes the runs already made and goes on.
    #[arg(long)]
    run: bool,
    /// With --run on a scene file: the levels of its matrix, powers of two, the finest the
    /// reference (e.g. 1,2,4).
    #[arg(
        long,
        requires = "run",
        conflicts_with = "suite",
        value_delimiter = ','
    )]
    lambdas: Option<Vec<u32>>,
    /// With --run on a scene file: the coarse-graining rules of its matrix (e.g.
    /// seed,scaled-particle; default: every rule defined for its law, once per distinct set
    /// of parameters).
    #[arg(
        long,
        requires = "run",
        conflicts_with = "suite",
        value_enum,
        value_delimiter = ','
    )]
    rules: Option<Vec<CgRule>>,
    /// With --run on a scene file: the insertion seeds every setting runs with (e.g. 1,2,3).
    #[arg(
        long,
        requires = "run",
        conflicts_with = "suite",
        value_delimiter = ','
    )]
    seeds: Option<Vec<u64>>,
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
}

/// The answer from the stored matrix (made first with `--run`), in words or as JSON.
pub(super) fn execute(args: AdviseArgs) -> ExitCode {
    let Some(m) = Measure::from_quantity(&args.quantity) else {
        let known: Vec<&str> = Measure::ALL.iter().map(|m| m.quantity()).collect();
        eprintln!(
            "error: --quantity {:?} is not allowed: one of {}",
            args.quantity,
            known.join(", ")
        );
        return ExitCode::from(BAD_INPUT);
    };
    let target = args.target;
    if !(target.is_finite() && target > 0.0) {
        eprintln!(
            "error: --target {target} is not allowed: a positive number in the quantity's unit"
        );
        return ExitCode::from(BAD_INPUT);
    }
    // A scene file names its case by the scene's name; anything else is a case name.
    let scene = if args.case.ends_with(".toml") {
        match Scene::load(Path::new(&args.case)) {
            Ok(scene) => Some(scene),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(BAD_INPUT);
            }
        }
    } else {
        None
    };
    let name = scene.as_ref().map_or(args.case.clone(), |s| s.name.clone());
    let matrix = match (scene, args.run) {
        (Some(scene), true) if scene_alone(&args, &scene) => {
            match scene_run(scene, m, target, &args) {
                Ok(dir) => dir,
                Err(code) => return code,
            }
        }
        (_, true) => match advise_run(&name, &args) {
            Ok(dir) => dir,
            Err(code) => return code,
        },
        (_, false) => args.matrix.clone().unwrap_or_else(|| default_matrix(&name)),
    };
    answer(&matrix, &name, m, target, args.json)
}

/// The answer read from `matrix`, printed; the exit status says whether a setting meets the
/// target.
fn answer(matrix: &Path, case: &str, m: Measure, target: f64, json: bool) -> ExitCode {
    let advice = advise::read_matrix(matrix)
        .and_then(|(file, points)| advise::advise(&file, &points, case, m, target));
    let advice = match advice {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    if json {
        match serde_json::to_string_pretty(&advice) {
            Ok(text) => println!("{text}"),
            Err(e) => {
                eprintln!("error: cannot write the answer as JSON: {e}");
                return ExitCode::from(BAD_INPUT);
            }
        }
    } else {
        println!("{}", advice.text(m));
    }
    if advice.advised.is_some() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(NONE_MEETS)
    }
}

/// The matrix of case `name` when no --matrix is given: a scene's own (cgdem-advise/NAME)
/// when one was made, else the shipped cases' (reports/cg_fidelity).
fn default_matrix(name: &str) -> PathBuf {
    let own = Path::new(SCENE_MATRICES).join(name);
    if own.join("summary.json").is_file() {
        own
    } else {
        PathBuf::from("reports/cg_fidelity")
    }
}

/// The suite `--run` takes a case's sweeps from: --suite, the one the matrix was made from
/// (its provenance), else cg_fidelity.
fn suite_name(args: &AdviseArgs) -> String {
    let made_from = || -> Option<String> {
        let (_, file) = advise::matrix_paths(args.matrix.as_deref()?);
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(file).ok()?).ok()?;
        summary["provenance"]["suite file"]
            .as_str()
            .map(str::to_string)
    };
    args.suite
        .clone()
        .or_else(made_from)
        .unwrap_or_else(|| "cg_fidelity".into())
}

/// Whether `--run` on `scene` makes a matrix from the scene alone: when the matrix is chosen
/// on the command line, or when no suite (--suite, the matrix's, cg_fidelity where it can
/// be read) has a sweep of it.
fn scene_alone(args: &AdviseArgs, scene: &Scene) -> bool {
    if args.lambdas.is_some() || args.rules.is_some() || args.seeds.is_some() {
        return true;
    }
    if args.suite.is_some() {
        return false;
    }
    let Ok(suite) = cgdem_harness::suite::Suite::load(&suite_path(&suite_name(args))) else {
        return true;
    };
    let names: Vec<String> = suite
        .accuracy
        .iter()
        .filter_map(|s| s.case_name(&suite.source).ok())
        .collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    // Several variants of it (a suite's): the answer asks for one of them by name.
    matches!(advise::resolve_case(&refs, &scene.name), Err(v) if v.is_empty())
}

/// `advise --run`: the case's sweeps made into the matrix's runs; the directory of the
/// case's own report, or the exit code of a failure (already reported).
fn advise_run(case: &str, args: &AdviseArgs) -> Result<PathBuf, ExitCode> {
    let matrix = args
        .matrix
        .clone()
        .unwrap_or_else(|| PathBuf::from("reports/cg_fidelity"));
    let suite = match cgdem_harness::suite::Suite::load(&suite_path(&suite_name(args))) {
        Ok(suite) => suite,
        Err(e) => {
            eprintln!("error: --suite: {e}");
            return Err(ExitCode::from(BAD_INPUT));
        }
    };
    let pool = worker_pool(args.threads)?;
    let interrupt = install_interrupt();
    let options = ValidateOptions {
        progress: crate::progress_bar::progress(false),
        jobs: usize::from(args.jobs),
        stop: interrupt.as_ref().map(|i| i.flag()),
        ..Default::default()
    };
    let result = pool.install(|| advise::run_case(&suite, case, &matrix, &options));
    if let Some(code) = interrupted(&interrupt, &matrix) {
        return Err(code);
    }
    result.map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::from(BAD_INPUT)
    })
}

/// `advise CASE.toml --run` for a scene no suite names: its matrix planned and printed with
/// its expected cost, then made (the runs already made taken); the matrix's directory.
fn scene_run(
    scene: Scene,
    m: Measure,
    target: f64,
    args: &AdviseArgs,
) -> Result<PathBuf, ExitCode> {
    let bad = |e: &dyn std::fmt::Display| {
        eprintln!("error: {e}");
        ExitCode::from(BAD_INPUT)
    };
    let dir = args
        .matrix
        .clone()
        .unwrap_or_else(|| Path::new(SCENE_MATRICES).join(&scene.name));
    let choice = MatrixChoice {
        lambdas: args.lambdas.clone(),
        rules: args
            .rules
            .as_ref()
            .map(|r| r.iter().map(|&r| r.into()).collect()),
        seeds: args.seeds.clone(),
    };
    if let Some(seeds) = &choice.seeds {
        let mut distinct = seeds.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() != seeds.len() {
            return Err(bad(&format!(
                "--seeds {seeds:?} is not allowed: distinct insertion seeds, e.g. 1,2,3"
            )));
        }
    }
    let path = PathBuf::from(&args.case);
    let plan = advise::scene_matrix(&path, scene, m, target, &choice).map_err(|e| bad(&e))?;
    eprint!("{}", describe_plan(&plan, &dir));
    let pool = worker_pool(args.threads)?;
    let interrupt = install_interrupt();
    let options = ValidateOptions {
        out: dir.clone(),
        progress: crate::progress_bar::progress(false),
        jobs: usize::from(args.jobs),
        stop: interrupt.as_ref().map(|i| i.flag()),
        // Restart files at the start, at each stage end and at an interrupt: an
        // interrupted run goes on from where it stopped.
        checkpoint_every: Some(simulated_s(&plan.scene)),
        ..Default::default()
    };
    let cost = advise::matrix_cost(&plan, &options).map_err(|e| bad(&e))?;
    let throughput = pool.install(|| throughput(&plan, &cost, &dir, &options));
    if let Some(code) = interrupted(&interrupt, &dir) {
        return Err(code);
    }
    eprintln!("{}", describe_cost(&cost, throughput.as_ref()));
    let result = pool.install(|| advise::run_scene_matrix(&plan, &options));
    if let Some(code) = interrupted(&interrupt, &dir) {
        eprintln!("the same command again takes the runs already made and goes on");
        return Err(code);
    }
    result.map_err(|e| bad(&e))?;
    Ok(dir)
}

/// The scene's longest simulated time (every stage at its longest), s.
fn simulated_s(scene: &Scene) -> f64 {
    use cgdem_core::scene::StageEnd;
    scene
        .stages
        .iter()
        .map(|s| match s.end {
            StageEnd::Duration(d) => d,
            StageEnd::Settled { max_duration, .. } => max_duration,
        })
        .sum::<f64>()
        .max(1e-9)
}

/// The machine's throughput for the estimate: particle-steps per second, seconds of setup
/// per run (None: not measured), and where they come from: the runs already made, else a
/// probe of the finest level; None when nothing is left to make or the probe failed (said).
type Throughput = (f64, Option<f64>, String);

fn throughput(
    plan: &SceneMatrix,
    cost: &advise::MatrixCost,
    dir: &Path,
    options: &ValidateOptions,
) -> Option<Throughput> {
    if cost.remaining().1 == 0.0 {
        return None;
    }
    if let Some((rate, n)) = cost.measured_throughput() {
        return Some((
            rate,
            None,
            format!("the {n} run(s) of this matrix already made (their setup not counted)"),
        ));
    }
    match advise::probe(plan, &dir.join("probe"), advise::PROBE_STEPS, options.stop.clone()) {
        Ok(p) => Some((
            p.particle_steps_per_s,
            Some(p.setup_s),
            format!(
                "a probe of {} steps of the first stage at lambda = {} ({} particles, {:.2} s on {} thread(s), after {:.1} s of setup, counted once per run); a denser flow than the probe's may run slower",
                p.steps,
                p.lambda,
                p.particles,
                p.wall_s,
                rayon::current_num_threads(),
                p.setup_s
            ),
        )),
        Err(e) => {
            eprintln!("warning: the probe run failed ({e}): no estimate of the hours");
            None
        }
    }
}

/// "a" or "a to b", in particle-steps.
fn range(r: (f64, f64)) -> String {
    if (r.1 - r.0).abs() <= 1e-9 * r.1 {
        format!("{:.3e}", r.1)
    } else {
        format!("{:.3e} to {:.3e}", r.0, r.1)
    }
}

/// Seconds in the unit that reads best: s, min or h.
fn wall_time(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.0} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

/// The expected cost, in words: particle-steps still to make and in all, and wall time.
fn describe_cost(cost: &advise::MatrixCost, throughput: Option<&Throughput>) -> String {
    let remaining = cost.remaining();
    let left = cost.runs.len() - cost.done();
    let mut text = format!(
        "expected cost (an estimate): {} particle-steps still to make in {left} run(s), of {} in all ({} run(s), {} already made); particles and steps of each run counted from the scene at its level, each settling stage between its min_duration and max_duration",
        range(remaining),
        range(cost.total()),
        cost.runs.len(),
        cost.done()
    );
    match throughput {
        Some((rate, setup, from)) => {
            let setup = setup.unwrap_or(0.0) * left as f64;
            text.push_str(&format!(
                "; about {} on this machine at {rate:.3e} particle-steps/s, measured by {from}",
                match (
                    wall_time(remaining.0 / rate + setup),
                    wall_time(remaining.1 / rate + setup)
                ) {
                    (lo, hi) if lo == hi => hi,
                    (lo, hi) => format!("{lo} to {hi}"),
                }
            ))
        }
        None if remaining.1 == 0.0 => text.push_str("; nothing left to run"),
        None => {}
    }
    text
}

/// The matrix in words: levels, rules, seeds, why the coarsest level is where it is.
fn describe_plan(plan: &SceneMatrix, dir: &Path) -> String {
    let mut text = format!(
        "coarse-graining matrix of {} from the scene alone (case {}-{}), in {}\n",
        plan.sweep.file.display(),
        plan.scene.name,
        advise::VARIANT,
        dir.display()
    );
    let levels: Vec<String> = plan
        .levels
        .iter()
        .map(|l| {
            format!(
                "{} ({:.0} particles of {:.3e} m{})",
                l.lambda,
                l.particles,
                l.diameter_m,
                l.across_opening
                    .map_or(String::new(), |a| format!(", {a:.1} across the opening"))
            )
        })
        .collect();
    text.push_str(&format!(
        "  levels: lambda = {} (the first the reference)\n",
        levels.join(", ")
    ));
    if let Some(because) = &plan.coarsest_because {
        text.push_str(&format!(
            "  coarsest level: {}, the last to keep {} particles{}; {because}\n",
            plan.levels.last().map_or(1, |l| l.lambda),
            advise::MIN_PARTICLES,
            if plan.opening.is_some() {
                format!(
                    " and {} parcel diameters across the opening",
                    advise::MIN_ACROSS_OPENING
                )
            } else {
                String::new()
            }
        ));
    }
    if let Some(o) = &plan.opening {
        text.push_str(&format!("  opening: {:.4} m, {}\n", o.diameter_m, o.source));
    }
    for w in &plan.warnings {
        text.push_str(&format!("  warning: {w}\n"));
    }
    let rules: Vec<&str> = plan.rules.iter().map(|r| r.name()).collect();
    text.push_str(&format!("  rules: {}\n", rules.join(", ")));
    for (rule, first) in &plan.same_as {
        text.push_str(&format!(
            "    {} gives this scene the {} rule's parameters: not run again\n",
            rule.name(),
            first.name()
        ));
    }
    let seeds: Vec<String> = plan.seeds.iter().map(u64::to_string).collect();
    text.push_str(&format!("  seeds: {}\n", seeds.join(", ")));
    text
}
