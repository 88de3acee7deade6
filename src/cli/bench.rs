//! `cgdem bench`: throughput of cgdem and the reference codes, side by side.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use cgdem_harness::bench::builds::BuildSpec;
use cgdem_harness::bench::{bench, format_report, BenchOptions};
use cgdem_harness::suite::Code;

#[derive(Args)]
pub(super) struct BenchArgs {
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
    /// Time limit of one reference-code run: seconds of CPU time per rank (a loaded or paused
    /// machine does not use it up), and 4 times that of wall clock (a hang).
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
    /// A build of a reference code to time, as CODE=LABEL:PATH (repeat the option for
    /// several), e.g. `--build lammps=native:/opt/lammps/build/lmp`. Each build runs in the
    /// same alternation, with rows of its own; at more than one worker a LAMMPS build with
    /// the OPENMP package also runs as one process of that many OpenMP threads. The `mpirun`
    /// beside the binary starts its ranks if there is one (a Python environment's MPI), else
    /// the one on PATH. A code given no build runs the one found as usual ($CGDEM_LMP or
    /// `lmp` on PATH; $CGDEM_LIGGGHTS or `liggghts`), labelled by its release.
    #[arg(long = "build", value_name = "CODE=LABEL:PATH")]
    builds: Vec<BuildSpec>,
}

pub(super) fn execute(args: BenchArgs) -> ExitCode {
    let mut codes = Vec::new();
    for name in &args.codes {
        codes.push(match name.as_str() {
            "cgdem" => Code::Cgdem,
            "liggghts" => Code::Liggghts,
            "lammps" => Code::Lammps,
            other => {
                eprintln!(
                    "error: --codes: `{other}` is not a code; allowed: cgdem, liggghts, lammps"
                );
                return ExitCode::FAILURE;
            }
        });
    }
    if args.threads.contains(&0)
        || args.np.contains(&0)
        || args.pairs == 0
        || args.steps == 0
        || args.prepare.is_nan()
        || args.prepare < 0.0
    {
        eprintln!("error: --threads, --np, --pairs and --steps must be at least 1 and --prepare at least 0");
        return ExitCode::FAILURE;
    }
    let out = args.out.clone();
    let options = BenchOptions {
        grid: args.grid,
        np: args.np,
        cgdem_bin: args.cgdem_bin,
        builds: args.builds,
        cases: args.cases,
        out: args.out,
        codes,
        threads: args.threads,
        pairs: args.pairs,
        steps: args.steps,
        prepare_s: args.prepare,
        outcome: !args.no_outcome,
        timeout: std::time::Duration::from_secs(args.reference_timeout),
    };
    super::exit_with(bench(&options).map(|report| {
        print!("{}", format_report(&report));
        println!("report in {}", out.join("bench.json").display());
    }))
}
