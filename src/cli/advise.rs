//! `cgdem advise`: which coarse-graining level and rule keeps a quantity within a target,
//! from a stored matrix (with `--run`, after making the case's missing points).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;

use super::{install_interrupt, interrupted, suite_path, worker_pool};
use cgdem_harness::accuracy::Measure;
use cgdem_harness::advise;

#[derive(Args)]
pub(super) struct AdviseArgs {
    /// The case: its scene file (e.g. validation/cases/aor_hertz.toml) or its name in the
    /// report (e.g. aor_hertz-fidelity).
    case: String,
    /// repose_angle (deg), profile, mass_flow, mass_flow_eq7, t_half, front_history,
    /// pore_size, discharge_rate (relative) or porosity (absolute).
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
}

/// The answer from the stored matrix, in words or as JSON.
pub(super) fn execute(args: AdviseArgs) -> ExitCode {
    let Some(m) = Measure::from_quantity(&args.quantity) else {
        let known: Vec<&str> = Measure::ALL.iter().map(|m| m.quantity()).collect();
        eprintln!(
            "error: --quantity {:?} is not allowed: one of {}",
            args.quantity,
            known.join(", ")
        );
        return ExitCode::FAILURE;
    };
    let target = args.target;
    if !(target.is_finite() && target > 0.0) {
        eprintln!(
            "error: --target {target} is not allowed: a positive number in the quantity's unit"
        );
        return ExitCode::FAILURE;
    }
    // A scene file names its case by the scene's name; anything else is a case name.
    let name = if args.case.ends_with(".toml") {
        match cgdem_core::scene::Scene::load(Path::new(&args.case)) {
            Ok(scene) => scene.name,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        }
    } else {
        args.case.clone()
    };
    let matrix = if args.run {
        match advise_run(&name, &args) {
            Ok(dir) => dir,
            Err(code) => return code,
        }
    } else {
        args.matrix.clone()
    };
    let answer = advise::read_matrix(&matrix)
        .and_then(|(file, points)| advise::advise(&file, &points, &name, m, target));
    super::exit_with(answer.map_err(|e| e.to_string()).and_then(|a| {
        if args.json {
            let text = serde_json::to_string_pretty(&a)
                .map_err(|e| format!("cannot write the answer as JSON: {e}"))?;
            println!("{text}");
        } else {
            println!("{}", a.text(m));
        }
        Ok(())
    }))
}

/// `advise --run`: the case's sweeps made into the matrix's runs; the directory of the
/// case's own report, or the exit code of a failure (already reported).
fn advise_run(case: &str, args: &AdviseArgs) -> Result<PathBuf, ExitCode> {
    let matrix = args.matrix.as_path();
    // The suite the matrix was made from, as its provenance names it.
    let made_from = || -> Option<String> {
        let (_, file) = advise::matrix_paths(matrix);
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(file).ok()?).ok()?;
        summary["provenance"]["suite file"]
            .as_str()
            .map(str::to_string)
    };
    let suite = args
        .suite
        .clone()
        .or_else(made_from)
        .unwrap_or_else(|| "cg_fidelity".into());
    let suite = match cgdem_harness::suite::Suite::load(&suite_path(&suite)) {
        Ok(suite) => suite,
        Err(e) => {
            eprintln!("error: --suite: {e}");
            return Err(ExitCode::FAILURE);
        }
    };
    let pool = worker_pool(args.threads)?;
    let interrupt = install_interrupt();
    let options = cgdem_harness::validation::ValidateOptions {
        progress: crate::progress_bar::progress(false),
        jobs: usize::from(args.jobs),
        stop: interrupt.as_ref().map(|i| i.flag()),
        ..Default::default()
    };
    let result = pool.install(|| advise::run_case(&suite, case, matrix, &options));
    if let Some(code) = interrupted(&interrupt, matrix) {
        return Err(code);
    }
    result.map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::FAILURE
    })
}
