//! Running `lmp` on a deck in its own directory, under a time limit.
//!
//! The binary is `$CGDEM_LMP` if set, else `lmp` on `PATH`. The run directory keeps the
//! deck, `log.lammps`, `stdout.txt` and the exact command line (`command.txt`).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::deck::DECK_FILE;
pub use super::deck::LOG_FILE;

pub const INSTALL_HINT: &str = "bash scripts/install-references.sh";

#[derive(Clone, Debug)]
pub struct RunnerOptions {
    /// MPI ranks: `Some(n)` runs `mpirun --allow-run-as-root -np n lmp ...`.
    pub np: Option<u32>,
    pub timeout: Duration,
}

impl Default for RunnerOptions {
    fn default() -> Self {
        RunnerOptions {
            np: None,
            timeout: Duration::from_secs(3600),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum RunStatus {
    Completed {
        wall_s: f64,
    },
    /// LAMMPS is not installed: the comparison cannot run, which is not a failure of cgdem.
    Skipped {
        reason: String,
        install_hint: String,
    },
    Failed {
        exit_code: Option<i32>,
        log_tail: String,
    },
    TimedOut {
        after_s: f64,
        log_tail: String,
    },
}

/// The `lmp` binary: `$CGDEM_LMP`, else `lmp` on `PATH`.
pub fn find_lmp() -> Result<PathBuf, String> {
    find_program("lmp", "CGDEM_LMP")
}

/// A reference binary: the file named by `$env_var` if set, else `name` on `PATH`.
pub fn find_program(name: &str, env_var: &str) -> Result<PathBuf, String> {
    if let Some(explicit) = std::env::var_os(env_var) {
        let path = PathBuf::from(explicit);
        return if path.is_file() {
            Ok(path)
        } else {
            Err(format!("{env_var} = {} is not a file", path.display()))
        };
    }
    let path_var = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path_var)
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
        .ok_or_else(|| format!("{name} not found on PATH (set {env_var} to its path)"))
}

/// Last `lines` lines of the run's log (or of stdout if there is no log).
pub fn log_tail(dir: &Path, lines: usize) -> String {
    log_tail_of(dir, LOG_FILE, lines)
}

/// Last `lines` lines of `dir/log_file` (or of stdout if there is no log).
pub fn log_tail_of(dir: &Path, log_file: &str, lines: usize) -> String {
    // Lossy: LIGGGHTS's "Lost atoms" error writes stray bytes after its message.
    let read = |name: &str| {
        std::fs::read(dir.join(name)).map(|b| String::from_utf8_lossy(&b).into_owned())
    };
    let text = read(log_file)
        .or_else(|_| read("stdout.txt"))
        .unwrap_or_default();
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}

/// Runs the deck in `dir` (which must hold it) and waits, killing LAMMPS at the time limit.
pub fn run_deck(dir: &Path, options: &RunnerOptions) -> RunStatus {
    match find_lmp() {
        Ok(lmp) => run_program(&lmp, dir, DECK_FILE, LOG_FILE, options),
        Err(reason) => RunStatus::Skipped {
            reason,
            install_hint: INSTALL_HINT.into(),
        },
    }
}

/// Runs `program -in deck_file -log log_file` in `dir` (LAMMPS and LIGGGHTS take the same
/// arguments) and waits, killing it at the time limit.
pub fn run_program(
    program: &Path,
    dir: &Path,
    deck_file: &str,
    log_file: &str,
    options: &RunnerOptions,
) -> RunStatus {
    let mut argv: Vec<String> = Vec::new();
    if let Some(np) = options.np {
        argv.extend([
            "mpirun".into(),
            "--allow-run-as-root".into(),
            "-np".into(),
            np.to_string(),
        ]);
    }
    argv.extend([
        program.display().to_string(),
        "-in".into(),
        deck_file.into(),
        "-log".into(),
        log_file.into(),
    ]);
    let failed = |message: String| RunStatus::Failed {
        exit_code: None,
        log_tail: message,
    };
    if let Err(e) = std::fs::write(
        dir.join("command.txt"),
        format!("cd {} && {}\n", dir.display(), argv.join(" ")),
    ) {
        return failed(format!(
            "cannot write {}: {e}",
            dir.join("command.txt").display()
        ));
    }
    let stdout = match std::fs::File::create(dir.join("stdout.txt")) {
        Ok(f) => f,
        Err(e) => {
            return failed(format!(
                "cannot create {}: {e}",
                dir.join("stdout.txt").display()
            ))
        }
    };
    let stderr = match stdout.try_clone() {
        Ok(f) => f,
        Err(e) => return failed(e.to_string()),
    };
    let mut command = Command::new(&argv[0]);
    command
        .args(&argv[1..])
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr);
    #[cfg(unix)]
    {
        // Own process group, so a timeout kills mpirun and every rank together.
        use std::os::unix::process::CommandExt;
        command.process_group(0);
    }
    let started = Instant::now();
    let mut child = match command.spawn() {
        Ok(child) => child,
        Err(e) => return failed(format!("cannot start `{}`: {e}", argv.join(" "))),
    };
    loop {
        match child.try_wait() {
            Ok(Some(status)) => {
                let wall_s = started.elapsed().as_secs_f64();
                return if status.success() {
                    RunStatus::Completed { wall_s }
                } else {
                    RunStatus::Failed {
                        exit_code: status.code(),
                        log_tail: log_tail_of(dir, log_file, 20),
                    }
                };
            }
            Ok(None) if started.elapsed() >= options.timeout => {
                #[cfg(unix)]
                let _ = Command::new("kill")
                    .args(["-KILL", &format!("-{}", child.id())])
                    .status();
                let _ = child.kill();
                let _ = child.wait();
                return RunStatus::TimedOut {
                    after_s: started.elapsed().as_secs_f64(),
                    log_tail: log_tail_of(dir, log_file, 20),
                };
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(50)),
            Err(e) => return failed(format!("waiting for {}: {e}", program.display())),
        }
    }
}
