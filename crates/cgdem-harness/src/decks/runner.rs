//! Running a reference code (or `mpirun` with cgdem's ranks) in its own directory, under a
//! time limit.
//!
//! The binary is found by the dialect (`$CGDEM_LMP`, else `lmp` on `PATH`; likewise
//! `liggghts`). The run directory keeps the deck, the code's log, `stdout.txt` and the exact
//! command line (`command.txt`).
//!
//! The child starts in a process group of its own. At the time limit or when the stop flag is
//! raised (SIGINT/SIGTERM in the command), exactly that run is ended: SIGTERM to its group
//! (mpirun forwards it to its ranks), then SIGKILL to the group and to the processes that
//! descended from the child when the end began (OpenMPI moves each rank into a group of its
//! own). Nothing else is signalled.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

pub const INSTALL_HINT: &str = "bash scripts/install-references.sh";

#[derive(Clone, Debug)]
pub struct RunnerOptions {
    /// MPI ranks: `Some(n)` runs `mpirun --allow-run-as-root -np n lmp ...`.
    pub np: Option<u32>,
    /// The run is stopped when its processes have used this much CPU time per rank, or
    /// [`WALL_BACKSTOP`] times this of wall clock (a hang that sleeps). CPU time, because a
    /// run that shares a loaded machine, or is paused, still progresses at its CPU's pace.
    pub timeout: Duration,
    /// Raised by the command on SIGINT/SIGTERM: the run is ended (its whole tree) and reported
    /// as failed with [`INTERRUPTED`]; no run starts while it is raised.
    pub stop: Option<Arc<AtomicBool>>,
}

impl Default for RunnerOptions {
    fn default() -> Self {
        RunnerOptions {
            np: None,
            timeout: Duration::from_secs(3600),
            stop: None,
        }
    }
}

/// A run is stopped at this many times its CPU-time limit of wall clock.
pub const WALL_BACKSTOP: u32 = 4;

/// How an interrupted run's failure begins (`RunStatus::Failed::log_tail`).
pub const INTERRUPTED: &str = "interrupted (SIGINT/SIGTERM)";

/// How long the run's group has after SIGTERM before SIGKILL.
const TERM_GRACE: Duration = Duration::from_secs(5);

fn stop_raised(options: &RunnerOptions) -> bool {
    options
        .stop
        .as_ref()
        .is_some_and(|s| s.load(Ordering::SeqCst))
}

#[derive(Clone, Debug, PartialEq)]
pub enum RunStatus {
    Completed {
        wall_s: f64,
    },
    /// The code is not installed: the comparison cannot run, which is not a failure of cgdem.
    Skipped {
        reason: String,
        install_hint: String,
    },
    Failed {
        exit_code: Option<i32>,
        log_tail: String,
    },
    /// Stopped at its limit: `after_s` of wall clock, `cpu_s` of CPU time per rank.
    TimedOut {
        after_s: f64,
        cpu_s: f64,
        log_tail: String,
    },
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

/// `mpirun` for `np` ranks as the harness starts every MPI run (root allowed, as in the
/// containers this runs in; `--oversubscribe` when there are more ranks than `cores`, which
/// OpenMPI otherwise refuses).
pub fn mpirun_argv(np: u32, cores: usize) -> Vec<String> {
    let mut argv = vec!["mpirun".to_string(), "--allow-run-as-root".to_string()];
    if np as usize > cores {
        argv.push("--oversubscribe".into());
    }
    argv.extend(["-np".to_string(), np.to_string()]);
    argv
}

/// Cores this machine offers (1 if unknown).
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
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
        argv.extend(mpirun_argv(np, cores()));
    }
    argv.extend([
        program.display().to_string(),
        "-in".into(),
        deck_file.into(),
        "-log".into(),
        log_file.into(),
    ]);
    run_command(&argv, dir, log_file, options)
}

/// Runs `argv` in `dir` (which keeps `command.txt` and `stdout.txt`) and waits, ending its
/// whole process tree at the time limit or when the stop flag is raised; a failure's tail
/// is `log_file`'s (or stdout's). `options.np` is not read: `argv` holds any `mpirun`.
pub fn run_command(
    argv: &[String],
    dir: &Path,
    log_file: &str,
    options: &RunnerOptions,
) -> RunStatus {
    let failed = |message: String| RunStatus::Failed {
        exit_code: None,
        log_tail: message,
    };
    if stop_raised(options) {
        return failed(format!("{INTERRUPTED}: not started"));
    }
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
    let ranks = options.np.unwrap_or(1).max(1) as f64;
    let wall_limit = options.timeout.saturating_mul(WALL_BACKSTOP);
    // The tree's CPU time is read about once a second (a walk of /proc).
    let (mut cpu_s, mut cpu_read) = (0.0, started);
    loop {
        if cpu_read.elapsed() >= Duration::from_secs(1) {
            cpu_s = tree_cpu_seconds(child.id()) / ranks;
            cpu_read = Instant::now();
        }
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
            Ok(None)
                if cpu_s >= options.timeout.as_secs_f64() || started.elapsed() >= wall_limit =>
            {
                end_run_tree(&mut child);
                return RunStatus::TimedOut {
                    after_s: started.elapsed().as_secs_f64(),
                    cpu_s,
                    log_tail: log_tail_of(dir, log_file, 20),
                };
            }
            Ok(None) if stop_raised(options) => {
                end_run_tree(&mut child);
                return failed(format!(
                    "{INTERRUPTED} after {:.1} s: the run's process tree was ended; log tail: {}",
                    started.elapsed().as_secs_f64(),
                    log_tail_of(dir, log_file, 20)
                ));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(50)),
            Err(e) => return failed(format!("waiting for {}: {e}", argv[0])),
        }
    }
}

/// Ends the child's run: SIGTERM to its process group, up to [`TERM_GRACE`] for it to exit,
/// then SIGKILL to the group and to every process that descended from the child at the start
/// (mpirun's ranks sit in groups of their own). The child is reaped.
fn end_run_tree(child: &mut Child) {
    #[cfg(unix)]
    {
        let pgid = child.id() as i32;
        let tree = descendants(child.id());
        // SAFETY: kill(2) with a negative pid signals only the group the child leads.
        unsafe { libc::kill(-pgid, libc::SIGTERM) };
        let deadline = Instant::now() + TERM_GRACE;
        while Instant::now() < deadline {
            if matches!(child.try_wait(), Ok(Some(_))) && tree.iter().all(|p| !p.alive()) {
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        unsafe { libc::kill(-pgid, libc::SIGKILL) };
        for p in &tree {
            if p.alive() {
                // The start time was checked: this pid is still the process seen before.
                unsafe { libc::kill(p.pid as i32, libc::SIGKILL) };
            }
        }
    }
    let _ = child.kill();
    let _ = child.wait();
}

/// A process seen under /proc: its pid and start time (a reused pid has another).
#[derive(Clone, Copy, Debug, PartialEq)]
struct ProcessId {
    pid: u32,
    start: u64,
}

impl ProcessId {
    fn alive(&self) -> bool {
        proc_stat(self.pid).is_some_and(|s| s.start == self.start && s.state != 'Z')
    }
}

/// What /proc/PID/stat says of a process.
struct ProcStat {
    ppid: u32,
    /// Start time, in clock ticks since boot (with the pid, it names the process).
    start: u64,
    state: char,
    /// User plus system CPU time, in clock ticks.
    cpu_ticks: u64,
}

fn proc_stat(pid: u32) -> Option<ProcStat> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name may hold spaces and parentheses: fields follow the last ')'.
    let rest = &text[text.rfind(')')? + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let number = |i: usize| fields.get(i)?.parse::<u64>().ok();
    Some(ProcStat {
        ppid: fields.get(1)?.parse().ok()?,
        start: number(19)?,
        state: fields.first()?.chars().next()?,
        cpu_ticks: number(11)? + number(12)?,
    })
}

/// CPU time (user and system) in seconds of `root` and every living process below it; 0
/// where /proc cannot be read. A rank that has exited no longer counts: the limit is for
/// runs that go on.
fn tree_cpu_seconds(root: u32) -> f64 {
    #[cfg(unix)]
    {
        // SAFETY: sysconf has no preconditions.
        let ticks = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
        let ticks = if ticks > 0 { ticks as f64 } else { 100.0 };
        let of = |pid: u32| proc_stat(pid).map_or(0, |s| s.cpu_ticks);
        let total = of(root) + descendants(root).iter().map(|p| of(p.pid)).sum::<u64>();
        total as f64 / ticks
    }
    #[cfg(not(unix))]
    {
        let _ = root;
        0.0
    }
}

/// Every living process below `root` (not `root` itself), by walking /proc's parent links.
fn descendants(root: u32) -> Vec<ProcessId> {
    let mut all: Vec<(u32, u32, u64)> = Vec::new();
    if let Ok(entries) = std::fs::read_dir("/proc") {
        for entry in entries.flatten() {
            let Some(pid) = entry.file_name().to_str().and_then(|n| n.parse().ok()) else {
                continue;
            };
            if let Some(s) = proc_stat(pid) {
                all.push((pid, s.ppid, s.start));
            }
        }
    }
    let mut found = Vec::new();
    let mut frontier = vec![root];
    while let Some(parent) = frontier.pop() {
        for &(pid, ppid, start) in &all {
            if ppid == parent && pid != root {
                found.push(ProcessId { pid, start });
                frontier.push(pid);
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    fn alive(pid: u32) -> bool {
        proc_stat(pid).is_some_and(|s| s.state != 'Z')
    }

    /// A throwaway tree: a shell in its own group starts sleeps, one of them in a group of its
    /// own (as mpirun's ranks); a decoy sleep outside the tree shares our group. Ending the run
    /// must end the whole tree and leave the decoy (and this process) alone.
    #[test]
    fn ending_a_run_ends_its_tree_and_nothing_outside_it() {
        let dir = std::env::temp_dir().join(format!("cgdem_runner_tree_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut decoy = Command::new("sleep").arg("60").spawn().unwrap();
        let script = "sleep 60 & sleep 60 & setsid sleep 61 & \
                      (trap '' TERM; sleep 62) & echo started > started.txt; wait";
        let mut command = Command::new("sh");
        command.args(["-c", script]).current_dir(&dir);
        use std::os::unix::process::CommandExt;
        command.process_group(0);
        let mut child = command.spawn().unwrap();
        let deadline = Instant::now() + Duration::from_secs(10);
        while descendants(child.id()).len() < 4 && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        let tree = descendants(child.id());
        assert!(tree.len() >= 4, "{tree:?}");
        // One member left the group (setsid), as OpenMPI's ranks do.
        let started = Instant::now();
        end_run_tree(&mut child);
        assert!(started.elapsed() < TERM_GRACE + Duration::from_secs(2));
        std::thread::sleep(Duration::from_millis(100));
        for p in &tree {
            assert!(!p.alive(), "{} survived", p.pid);
        }
        assert!(
            alive(decoy.id()),
            "the decoy outside the run's tree was signalled"
        );
        assert!(alive(std::process::id()));
        decoy.kill().unwrap();
        decoy.wait().unwrap();
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_raised_stop_flag_ends_the_run_and_starts_none() {
        let dir = std::env::temp_dir().join(format!("cgdem_runner_stop_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let options = RunnerOptions {
            np: None,
            timeout: Duration::from_secs(60),
            stop: Some(stop.clone()),
        };
        let raiser = {
            let stop = stop.clone();
            std::thread::spawn(move || {
                std::thread::sleep(Duration::from_millis(300));
                stop.store(true, Ordering::SeqCst);
            })
        };
        // `sleep -in deck -log log` fails at once; a script that ignores its arguments runs.
        let program = dir.join("fake_lmp.sh");
        std::fs::write(&program, "#!/bin/sh\nsleep 30 & wait\n").unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&program, std::fs::Permissions::from_mode(0o755)).unwrap();
        let started = Instant::now();
        let status = run_program(&program, &dir, "deck.in", "log.txt", &options);
        raiser.join().unwrap();
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "{:?}",
            started.elapsed()
        );
        let RunStatus::Failed {
            exit_code: None,
            log_tail,
        } = &status
        else {
            panic!("{status:?}");
        };
        assert!(log_tail.starts_with(INTERRUPTED), "{log_tail}");
        let again = run_program(&program, &dir, "deck.in", "log.txt", &options);
        assert!(
            matches!(&again, RunStatus::Failed { log_tail, .. } if log_tail.ends_with("not started")),
            "{again:?}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A script standing in for a reference code (it ignores its arguments).
    fn fake_code(dir: &Path, body: &str) -> PathBuf {
        let program = dir.join("fake_code.sh");
        std::fs::write(&program, format!("#!/bin/sh\n{body}\n")).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&program, std::fs::Permissions::from_mode(0o755)).unwrap();
        program
    }

    #[test]
    fn the_limit_is_cpu_time_of_the_whole_tree_with_wall_clock_only_as_a_backstop() {
        let dir = std::env::temp_dir().join(format!("cgdem_runner_cpu_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let options = RunnerOptions {
            np: None,
            timeout: Duration::from_secs(1),
            stop: None,
        };
        // The CPU is used by a child of the script, as by mpirun's ranks.
        let busy = fake_code(&dir, "sh -c 'while :; do :; done' & wait");
        let status = run_program(&busy, &dir, "deck.in", "log.txt", &options);
        let RunStatus::TimedOut { after_s, cpu_s, .. } = status else {
            panic!("{status:?}");
        };
        assert!(
            cpu_s >= 1.0 && after_s < 30.0,
            "{cpu_s} s CPU, {after_s} s wall"
        );
        // Asleep (as a run paused or starved on a loaded machine) it is not stopped after a
        // second of wall clock: it ends by itself, within the wall-clock backstop.
        let asleep = fake_code(&dir, "sleep 2 & wait");
        let status = run_program(&asleep, &dir, "deck.in", "log.txt", &options);
        assert!(
            matches!(status, RunStatus::Completed { wall_s } if wall_s >= 2.0),
            "{status:?}"
        );
        // A hang that sleeps is stopped at the backstop.
        let hang = fake_code(&dir, "sleep 30 & wait");
        let status = run_program(&hang, &dir, "deck.in", "log.txt", &options);
        let RunStatus::TimedOut { after_s, cpu_s, .. } = status else {
            panic!("{status:?}");
        };
        assert!(
            after_s >= WALL_BACKSTOP as f64 && after_s < 20.0 && cpu_s < 1.0,
            "{cpu_s} s CPU, {after_s} s wall"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
