//! cgdem's runs as MPI ranks (`validate --np`, `bench --np`): a process tree under `mpirun`,
//! as the reference codes run beyond one worker.
//!
//! The harness builds each scene in memory (the case, the suite's overrides, the
//! coarse-graining level and rule, the seed), so the ranks are handed exactly that scene:
//! it is written beside the run as `scene.json` ([`Scene::to_json`], every number to the
//! last bit), `mpirun -np N cgdem run DIR/scene.json --grid G ...` runs it, and the run is
//! accepted only when its `summary.json` names the same scene digest. A run on N ranks is
//! bitwise the run on the same grid on threads (scripts/mpi-check.sh), so `--reuse` takes
//! either for the other. Restart files too: with `--checkpoint-every` the ranks write them
//! (rank 0 gathers), and a run killed in an earlier attempt goes on as ranks from its last
//! one (`cgdem run DIR/scene.json --resume DIR`: the scene is the written one, not the
//! command line the file stores, so it may have been written by threads in the harness).

use std::path::{Path, PathBuf};
use std::time::Duration;

use cgdem_core::decomposition::GridSpec;
use cgdem_core::run::{RunOptions, RunSummary};
use cgdem_core::scene::Scene;

use crate::decks::runner::{self, RunStatus, RunnerOptions};

/// What `cgdem --version` prints in a build with the `mpi` feature (src/main.rs).
pub const MPI_MARK: &str = "with MPI";

/// cgdem's runs as `np` MPI ranks of `bin` (a build with the `mpi` feature).
#[derive(Clone, Debug, PartialEq)]
pub struct Ranks {
    pub np: usize,
    pub bin: PathBuf,
}

impl Ranks {
    /// `np` ranks of `bin` (or of this binary), after checking what they need: at least one
    /// rank, a grid of at least `np` subdomains, a binary built with MPI, `mpirun` on PATH.
    pub fn checked(np: usize, grid: Option<GridSpec>, bin: Option<&Path>) -> Result<Ranks, String> {
        if np == 0 {
            return Err("rank counts must be at least 1".into());
        }
        let subdomains = match grid {
            None => return Err("cgdem's ranks step subdomains: give --grid (e.g. 2x1x1)".into()),
            Some(GridSpec::Given(c)) => c.iter().product(),
            Some(GridSpec::Auto(n)) => n,
        };
        if subdomains < np {
            return Err(format!(
                "{np} ranks need at least {np} subdomains; --grid {} has {subdomains}",
                grid.expect("checked")
            ));
        }
        Ok(Ranks {
            np,
            bin: mpi_binary(bin)?,
        })
    }
}

/// The cgdem binary MPI ranks run: `given`, or this one; it must be built with MPI, and
/// `mpirun` must be on PATH.
pub fn mpi_binary(given: Option<&Path>) -> Result<PathBuf, String> {
    let bin = match given {
        Some(bin) => bin.to_path_buf(),
        None => {
            std::env::current_exe().map_err(|e| format!("cannot find this cgdem's binary: {e}"))?
        }
    };
    // `cgdem --version` names the MPI feature when built with it.
    let version = std::process::Command::new(&bin)
        .arg("--version")
        .output()
        .map_err(|e| format!("cannot run {} --version: {e}", bin.display()))?;
    let version = String::from_utf8_lossy(&version.stdout);
    if !version.contains(MPI_MARK) {
        return Err(format!(
            "{} ({}) is built without MPI: build one with `cargo build --release --features mpi` and give it with --cgdem-bin PATH (or run that binary)",
            bin.display(),
            version.trim()
        ));
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    if !std::env::split_paths(&path).any(|dir| dir.join("mpirun").is_file()) {
        return Err(
            "mpirun not found on PATH; install OpenMPI (apt-get install openmpi-bin libopenmpi-dev)"
                .into(),
        );
    }
    Ok(std::path::absolute(&bin).unwrap_or(bin))
}

/// Runs `scene` as `options` ask: in this process, or with `ranks` as that many MPI ranks
/// (`options.grid` must be set) sharing the threads of the calling pool (at least one each).
/// Once `options.stop` is raised no run starts (its directory is left as it was), as for
/// the reference codes.
pub fn run_scene(
    scene: &Scene,
    options: &RunOptions,
    ranks: Option<&Ranks>,
) -> Result<RunSummary, String> {
    if options
        .stop
        .as_ref()
        .is_some_and(|s| s.load(std::sync::atomic::Ordering::SeqCst))
    {
        return Err(format!("{}: not started", runner::INTERRUPTED));
    }
    match ranks {
        None => cgdem_core::run::run(scene, options).map_err(|e| e.to_string()),
        Some(ranks) => {
            let threads = (rayon::current_num_threads() / ranks.np).max(1);
            run_as_ranks(scene, options, ranks, threads)
        }
    }
}

/// `mpirun -np N BIN run DIR/scene.json ...` in the run directory, then rank 0's
/// summary.json, checked to be this scene's.
fn run_as_ranks(
    scene: &Scene,
    options: &RunOptions,
    ranks: &Ranks,
    threads: usize,
) -> Result<RunSummary, String> {
    let dir = std::path::absolute(&options.out_dir).unwrap_or_else(|_| options.out_dir.clone());
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    // A summary left by an earlier run must not pass for this one's.
    let summary_path = dir.join("summary.json");
    match std::fs::remove_file(&summary_path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(format!("cannot remove {}: {e}", summary_path.display()))
        }
        _ => {}
    }
    let scene_path = dir.join("scene.json");
    cgdem_core::io::write_atomic(&scene_path, scene.to_json().as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", scene_path.display()))?;
    let argv = ranks_argv(scene, options, ranks, threads, &scene_path, &dir)?;
    let runner_options = RunnerOptions {
        np: None,
        // cgdem's own runs have no time limit in the harness, as in one process.
        timeout: Duration::MAX,
        stop: options.stop.clone(),
    };
    match runner::run_command(&argv, &dir, "stdout.txt", &runner_options) {
        RunStatus::Completed { .. } => {}
        RunStatus::Failed {
            exit_code,
            log_tail,
        } => return Err(ranks_failure(exit_code, &log_tail)),
        RunStatus::TimedOut { log_tail, .. } => return Err(ranks_failure(None, &log_tail)),
        RunStatus::Skipped { reason, .. } => return Err(reason),
    }
    let text = std::fs::read_to_string(&summary_path)
        .map_err(|e| format!("{}: {e}", summary_path.display()))?;
    let summary: RunSummary =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", summary_path.display()))?;
    if summary.scene_digest != scene.digest() {
        return Err(format!(
            "{}: the ranks ran scene {}, not the scene the harness wrote ({})",
            summary_path.display(),
            summary.scene_digest,
            scene.digest()
        ));
    }
    Ok(summary)
}

/// The command line of the ranks: they start in the harness's directory (`-wdir`), where
/// the scene's relative paths (STL files) lead, and write into `dir`.
fn ranks_argv(
    scene: &Scene,
    options: &RunOptions,
    ranks: &Ranks,
    threads: usize,
    scene_path: &Path,
    dir: &Path,
) -> Result<Vec<String>, String> {
    let grid = options
        .grid
        .ok_or("cgdem's ranks step subdomains: give --grid (e.g. 2x1x1)")?;
    let here = std::env::current_dir().map_err(|e| format!("the current directory: {e}"))?;
    let mut argv = runner::mpirun_argv(ranks.np as u32, runner::cores());
    argv.extend(["-wdir".into(), here.display().to_string()]);
    argv.extend([
        ranks.bin.display().to_string(),
        "run".into(),
        scene_path.display().to_string(),
        // At lambda 1 the rule is only recorded: the scene's own keeps its digest.
        "--cg-rule".into(),
        scene.cg_rule.name().into(),
        "--grid".into(),
        grid.to_string(),
        "--balance".into(),
        options.balance.to_string(),
        "--threads".into(),
        threads.max(1).to_string(),
        "--quiet".into(),
    ]);
    // A run killed in an earlier attempt goes on from the restart file the harness found
    // (`options.resume`, checked to hold this scene): the ranks read it from the run's
    // directory, which is then their output directory too.
    if options.resume.is_some() {
        argv.extend(["--resume".into(), dir.display().to_string()]);
    } else {
        argv.extend(["--out".into(), dir.display().to_string()]);
    }
    if let Some(c) = &options.checkpoint {
        argv.extend(["--checkpoint-every".into(), c.every.to_string()]);
    }
    if options.keep_going {
        argv.push("--keep-going".into());
    }
    if options.force_dt {
        argv.push("--force-dt".into());
    }
    Ok(argv)
}

/// The ranks' error as cgdem's own message where the log has one (from its `error: ` line
/// to the notice mpirun adds, whose lines begin with dashes), so that callers read the same
/// text as from a run in this process.
fn ranks_failure(exit_code: Option<i32>, log_tail: &str) -> String {
    let lines: Vec<&str> = log_tail.lines().collect();
    match lines.iter().rposition(|l| l.starts_with("error: ")) {
        Some(at) => {
            let message: Vec<&str> = std::iter::once(&lines[at]["error: ".len()..])
                .chain(
                    lines[at + 1..]
                        .iter()
                        .take_while(|l| !l.starts_with("-----"))
                        .copied(),
                )
                .collect();
            message.join("\n").trim_end().to_string()
        }
        None => format!(
            "the MPI ranks failed (exit {}): {}",
            exit_code.map_or("none".into(), |c| c.to_string()),
            log_tail.trim()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cgdem_core::decomposition::BalanceSpec;

    #[test]
    fn the_ranks_run_the_written_scene_on_the_grid_in_the_harness_directory_with_its_checkpoints() {
        crate::at_repo_root();
        let scene = Scene::load(Path::new("validation/cases/aor_hertz.toml")).unwrap();
        let options = RunOptions {
            out_dir: "/tmp/x".into(),
            grid: Some("2x1x1".parse::<GridSpec>().unwrap()),
            balance: BalanceSpec::Shift(1.2),
            keep_going: true,
            checkpoint: Some(cgdem_core::run::CheckpointOptions {
                every: 0.25,
                invocation: "cgdem validate".into(),
            }),
            ..Default::default()
        };
        let ranks = Ranks {
            np: 2,
            bin: "/opt/cgdem".into(),
        };
        let argv = ranks_argv(
            &scene,
            &options,
            &ranks,
            1,
            Path::new("/tmp/x/scene.json"),
            Path::new("/tmp/x"),
        )
        .unwrap();
        let line = argv.join(" ");
        let here = std::env::current_dir().unwrap();
        assert!(line.starts_with("mpirun --allow-run-as-root"), "{line}");
        assert!(
            line.contains(&format!(
                "-np 2 -wdir {} /opt/cgdem run /tmp/x/scene.json --cg-rule relative-overlap --grid 2x1x1 --balance 1.2 --threads 1 --quiet --out /tmp/x --checkpoint-every 0.25 --keep-going",
                here.display()
            )),
            "{line}"
        );
        let without_grid = RunOptions {
            grid: None,
            ..options
        };
        let e = ranks_argv(
            &scene,
            &without_grid,
            &ranks,
            1,
            Path::new("s"),
            Path::new("d"),
        );
        assert!(e.unwrap_err().contains("--grid"));
    }

    #[test]
    fn no_run_starts_once_the_stop_flag_is_raised() {
        let dir = std::env::temp_dir().join(format!("cgdem-stopped-{}", std::process::id()));
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
        let options = RunOptions {
            out_dir: dir.clone(),
            stop: Some(stop),
            ..Default::default()
        };
        crate::at_repo_root();
        let scene = Scene::load(Path::new("tests/data/tiny_hertz_collapse.toml")).unwrap();
        let e = run_scene(&scene, &options, None).unwrap_err();
        assert!(e.contains("not started"), "{e}");
        assert!(!dir.exists(), "the run's directory was created");
    }

    #[test]
    fn a_ranks_failure_reads_as_cgdems_own_message() {
        let tail = "warning: x\nerror: overlap guard: particle 3 ...\n--------\nmpirun noticed that process rank 0 exited";
        assert_eq!(
            ranks_failure(Some(1), tail),
            "overlap guard: particle 3 ..."
        );
        assert!(ranks_failure(Some(134), "Segmentation fault").contains("exit 134"));
    }

    #[test]
    fn ranks_need_a_grid_with_a_subdomain_each() {
        let two = Some(GridSpec::Given([2, 1, 1]));
        assert!(Ranks::checked(0, two, None)
            .unwrap_err()
            .contains("at least 1"));
        assert!(Ranks::checked(2, None, None)
            .unwrap_err()
            .contains("--grid"));
        let e = Ranks::checked(4, two, None).unwrap_err();
        assert!(
            e.contains("4 ranks need at least 4 subdomains; --grid 2x1x1 has 2"),
            "{e}"
        );
        let e = Ranks::checked(4, Some(GridSpec::Auto(3)), None).unwrap_err();
        assert!(e.contains("has 3"), "{e}");
    }
}
