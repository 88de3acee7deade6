//! SIGINT/SIGTERM: a `cgdem run` stops at the end of a step with its outputs and exits
//! 130/143; `cgdem validate` and `cgdem reference` end exactly the reference run's process tree
//! (no `lmp`, `liggghts` or `mpirun` left) and touch nothing outside it.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("interrupt")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir.canonicalize().unwrap()
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

fn wait_with_limit(child: &mut Child, limit: Duration) -> std::process::ExitStatus {
    let started = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            panic!("cgdem did not exit within {limit:?} of the signal");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Processes (pid, name) whose working directory is inside `dir`: the reference runs'.
fn processes_in(dir: &Path) -> Vec<(u32, String)> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Some(pid) = entry
            .file_name()
            .to_str()
            .and_then(|n| n.parse::<u32>().ok())
        else {
            continue;
        };
        let Ok(cwd) = std::fs::read_link(entry.path().join("cwd")) else {
            continue;
        };
        if cwd.starts_with(dir) {
            let name = std::fs::read_to_string(entry.path().join("comm")).unwrap_or_default();
            found.push((pid, name.trim().to_string()));
        }
    }
    found
}

fn alive(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .is_ok_and(|s| !s[s.rfind(')').unwrap() + 2..].starts_with('Z'))
}

fn interrupted_run(signal_name: &str, expected_code: i32) {
    let out = tmp(&format!("run_{signal_name}"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_cgdem"))
        .args([
            "run",
            "tests/data/tiny_hertz_collapse.toml",
            "--quiet",
            "--threads",
            "1",
            "--set",
            "stage[1].duration=1000.0",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Into the long second stage: the first time-series rows are written.
    let started = Instant::now();
    while !out.join("timeseries.csv").is_file() && started.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, signal_name);
    let status = wait_with_limit(&mut child, Duration::from_secs(30));
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(status.code(), Some(expected_code), "{stderr}");
    assert!(
        stderr.contains(&format!("interrupted by SIG{signal_name}")),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let stages = summary["stages"].as_array().unwrap();
    let last = stages.last().unwrap();
    assert!(
        last["ended_by"]
            .as_str()
            .unwrap()
            .starts_with("interrupted"),
        "{last}"
    );
    // Stopped at the end of a whole step: the recorded time is that step's.
    let (steps, dt, t) = (
        summary["steps"].as_f64().unwrap(),
        summary["dt_s"].as_f64().unwrap(),
        summary["simulated_s"].as_f64().unwrap(),
    );
    assert!(
        (t - steps * dt).abs() <= 1e-9 * t.max(1.0),
        "{t} vs {steps} x {dt}"
    );
    for file in ["timeseries.csv", "summary.json"] {
        assert!(out.join(file).is_file(), "{file}");
    }
}

#[test]
fn sigint_stops_a_run_at_a_step_end_with_its_outputs_and_exit_130() {
    interrupted_run("INT", 130);
}

#[test]
fn sigterm_stops_a_run_at_a_step_end_with_its_outputs_and_exit_143() {
    interrupted_run("TERM", 143);
}

/// Starts `args` (a command that runs LAMMPS in `dir`), waits until `lmp` runs there, sends
/// SIGINT and checks: exit 130, nothing left running in `dir`, a decoy outside untouched.
fn interrupt_during_lammps(args: &[&str], dir: &Path) {
    if let Err(reason) = cgdem_harness::decks::lammps::find_lmp() {
        // This test is about the live process tree: there is nothing to end without lmp.
        println!("not run: {reason}");
        return;
    }
    let mut decoy = Command::new("sleep").arg("120").spawn().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_cgdem"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let running = loop {
        let found = processes_in(dir);
        if found.iter().any(|(_, name)| name == "lmp") {
            break found;
        }
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "lmp never started in {}",
            dir.display()
        );
        if let Some(status) = child.try_wait().unwrap() {
            panic!("cgdem ended before lmp started: {status:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    std::thread::sleep(Duration::from_millis(500));
    signal(&child, "INT");
    let status = wait_with_limit(&mut child, Duration::from_secs(30));
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted by SIGINT"), "{stderr}");
    std::thread::sleep(Duration::from_millis(200));
    let left: Vec<_> = processes_in(dir)
        .into_iter()
        .filter(|(pid, _)| alive(*pid))
        .collect();
    assert!(left.is_empty(), "left running: {left:?} (were {running:?})");
    for (pid, name) in &running {
        assert!(!alive(*pid), "{name} ({pid}) survived");
    }
    assert!(alive(decoy.id()), "a process outside the run was signalled");
    decoy.kill().unwrap();
    decoy.wait().unwrap();
}

#[test]
fn sigint_to_validate_during_a_lammps_run_ends_exactly_its_process_tree() {
    let out = tmp("validate");
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tiny_hertz_collapse.toml");
    let suite = out.join("suite.toml");
    std::fs::write(
        &suite,
        format!(
            "name = \"interrupt\"\ndescription = \"a long LAMMPS run to interrupt\"\n\
             [[case]]\nfile = \"{}\"\ncodes = [\"lammps\"]\nlambdas = [1]\nseeds = [1]\n\
             set = [\"stage[1].duration = 1000.0\"]\nvariant = \"long\"\n",
            case.display()
        ),
    )
    .unwrap();
    let report = out.join("report");
    interrupt_during_lammps(
        &[
            "validate",
            "--suite",
            suite.to_str().unwrap(),
            "--out",
            report.to_str().unwrap(),
            "--quiet",
        ],
        &out,
    );
}

#[test]
fn sigint_to_reference_lammps_on_two_mpi_ranks_ends_mpirun_and_its_ranks() {
    let out = tmp("reference_np2");
    interrupt_during_lammps(
        &[
            "reference",
            "lammps",
            "tests/data/tiny_hertz_collapse.toml",
            "--np",
            "2",
            "--set",
            "stage[1].duration=1000.0",
            "--out",
            out.to_str().unwrap(),
        ],
        &out,
    );
}
