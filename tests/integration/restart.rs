//! Restart files: a run resumed from a checkpoint writes exactly the outputs of the
//! uninterrupted run (cmp), whatever a killed run left after the checkpoint; a truncated or
//! corrupt restart file is refused by name and the previous one is used.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("restart")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.parent().unwrap()).unwrap();
    dir
}

fn cgdem(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cgdem"))
        .args(args)
        .arg(out)
        .output()
        .unwrap()
}

fn resume(dir: &Path, threads: &str) -> Output {
    cgdem(&["run", "--quiet", "--threads", threads, "--resume"], dir)
}

/// Every file below `dir` (relative), restart files left out.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if !p.to_string_lossy().ends_with(".cgr") {
                found.push(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    found.sort();
    found
}

/// summary.json without its wall-clock fields (they differ between any two runs) and the
/// thread count (the resume runs on another one).
fn summary(dir: &Path) -> serde_json::Value {
    let mut s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    for k in ["wall_s", "particle_steps_per_s", "threads"] {
        s.as_object_mut().unwrap().remove(k);
    }
    s
}

fn assert_same_outputs(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    assert_eq!(fa, fb, "different output files");
    for f in &fa {
        if f.as_os_str() == "summary.json" {
            assert_eq!(summary(a), summary(b), "summary.json differs");
        } else {
            assert!(
                std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap(),
                "{} differs from the uninterrupted run's",
                f.display()
            );
        }
    }
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        if e.path().is_dir() {
            copy_dir(&e.path(), &to.join(e.file_name()));
        } else {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

/// A copy of the uninterrupted run as a kill after its last periodic checkpoint leaves it:
/// outputs ahead of the checkpoint, a torn time-series row, no summary, the newest restart
/// file damaged by `damage`; the resume must fall back to restart.prev.cgr.
fn killed_copy(reference: &Path, name: &str, damage: impl Fn(&mut Vec<u8>)) -> PathBuf {
    let dir = tmp(name);
    copy_dir(reference, &dir);
    std::fs::remove_file(dir.join("summary.json")).unwrap();
    let mut series = std::fs::read(dir.join("timeseries.csv")).unwrap();
    series.extend_from_slice(b"9.99e-1,collapse,1.2");
    std::fs::write(dir.join("timeseries.csv"), series).unwrap();
    let path = dir.join("restart.cgr");
    let mut bytes = std::fs::read(&path).unwrap();
    damage(&mut bytes);
    std::fs::write(&path, bytes).unwrap();
    dir
}

#[test]
fn resumed_runs_write_the_uninterrupted_outputs_and_refuse_damaged_restart_files() {
    let reference = tmp("reference");
    let args = [
        "run",
        "tests/data/tiny_hertz_collapse.toml",
        "--quiet",
        "--threads",
        "1",
        "--set",
        "output.vtk_interval=0.05",
        "--checkpoint-every",
        "0.12",
        "--out",
    ];
    let run = cgdem(&args, &reference);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(reference.join("restart.prev.cgr").is_file());
    assert!(reference.join("vtk/particles.pvd").is_file());
    for (name, damage) in [
        (
            "truncated",
            Box::new(|b: &mut Vec<u8>| b.truncate(b.len() / 2)) as Box<dyn Fn(&mut Vec<u8>)>,
        ),
        (
            "flipped",
            Box::new(|b: &mut Vec<u8>| {
                let k = b.len() - 100;
                b[k] ^= 0x04;
            }),
        ),
    ] {
        let dir = killed_copy(&reference, name, damage);
        // Another thread count than the run's: the file does not depend on it.
        let out = resume(&dir, "2");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{name}: {stderr}");
        assert!(
            stderr.contains("restart.cgr: not usable")
                && stderr.contains("resuming from")
                && stderr.contains("restart.prev.cgr"),
            "{name}: {stderr}"
        );
        assert_same_outputs(&reference, &dir);
    }
    // Both files damaged: an error naming both, nothing resumed.
    let dir = killed_copy(&reference, "both", |b| b.truncate(10));
    let prev = dir.join("restart.prev.cgr");
    let mut bytes = std::fs::read(&prev).unwrap();
    let k = bytes.len() / 2;
    bytes[k] ^= 0x01;
    std::fs::write(&prev, bytes).unwrap();
    let out = resume(&dir, "1");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("restart.cgr") && stderr.contains("restart.prev.cgr: checksum mismatch"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// A decomposed run (`--grid`) resumed from a checkpoint within a stage writes exactly the
/// uninterrupted run's outputs on its grid (on another thread count); on another grid it
/// goes on from the stored particles; the restart file and `--grid` must agree on whether
/// the run is decomposed.
#[test]
fn grid_runs_resume_bit_for_bit_on_their_grid_and_go_on_on_another() {
    let reference = tmp("grid-reference");
    let args = [
        "run",
        "tests/data/tiny_hertz_collapse.toml",
        "--quiet",
        "--threads",
        "2",
        "--grid",
        "2x1x1",
        "--checkpoint-every",
        "0.03",
        "--out",
    ];
    let run = cgdem(&args, &reference);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    // The newest file torn: the last periodic checkpoint, within the collapse, is used.
    let dir = killed_copy(&reference, "grid-torn", |b| b.truncate(b.len() / 2));
    let out = resume(&dir, "1");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("restart.prev.cgr"), "{stderr}");
    assert_same_outputs(&reference, &dir);
    // Another grid: dealt out again, on it to the end.
    let dir = killed_copy(&reference, "grid-other", |b| b.truncate(b.len() / 2));
    let out = cgdem(
        &[
            "run",
            "--quiet",
            "--threads",
            "1",
            "--grid",
            "1x1x2",
            "--resume",
        ],
        &dir,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert_eq!(
        summary(&dir)["decomposition"]["grid"],
        serde_json::json!([1, 1, 2])
    );
    assert_eq!(summary(&dir)["steps"], summary(&reference)["steps"]);
    // With the scene file given (as `validate --np` resumes its runs), the scene comes from
    // it, not from the stored command line: bit for bit again, and another scene is refused.
    let dir = killed_copy(&reference, "grid-case-given", |b| b.truncate(b.len() / 2));
    let given = |case: &str| {
        cgdem(
            &[
                "run",
                case,
                "--quiet",
                "--threads",
                "1",
                "--grid",
                "2x1x1",
                "--resume",
            ],
            &dir,
        )
    };
    let out = given("tests/data/tiny_drop.toml");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("written for a scene with digest")
            && stderr.contains("tiny_drop.toml")
            && !stderr.contains("panicked"),
        "{stderr}"
    );
    let out = given("tests/data/tiny_hertz_collapse.toml");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("restart.prev.cgr"), "{stderr}");
    assert_same_outputs(&reference, &dir);
    // A run without --grid ran on the scene's grid (one subdomain here): resumed with a
    // grid, its particles are dealt out again over it.
    let plain = tmp("grid-plain");
    let run = cgdem(
        &[
            "run",
            "tests/data/tiny_hertz_collapse.toml",
            "--quiet",
            "--set",
            "stage[0].max_duration=0.01",
            "--set",
            "stage[0].min_duration=0.01",
            "--set",
            "stage[1].duration=0.01",
            "--set",
            "repose.at_times=[0.005]",
            "--checkpoint-every",
            "0.1",
            "--out",
        ],
        &plain,
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(
        summary(&plain)["decomposition"]["grid"],
        serde_json::json!([1, 1, 1])
    );
    let out = cgdem(&["run", "--quiet", "--grid", "2x1x1", "--resume"], &plain);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert_eq!(
        summary(&plain)["decomposition"]["grid"],
        serde_json::json!([2, 1, 1])
    );
}

/// `validate --checkpoint-every` with `--reuse`: a suite whose cgdem run was stopped after a
/// checkpoint goes on from it (its interrupted summary is not taken for a finished run),
/// and the run's outputs are the uninterrupted run's.
#[test]
fn validate_resumes_a_killed_run_from_its_restart_file() {
    let validate = |out: &Path, reuse: bool| {
        let mut args = vec![
            "validate",
            "--suite",
            "tests/data/tiny_suite.toml",
            "--threads",
            "1",
            "--quiet",
            "--checkpoint-every",
            "0.12",
        ];
        if reuse {
            args.push("--reuse");
        }
        args.push("--out");
        let o = cgdem(&args, out);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let run = "runs/tiny_hertz_collapse-short/cgdem-lambda1-seed1";
    let whole = tmp("validate-whole");
    validate(&whole, false);
    assert!(whole.join(run).join("restart.cgr").is_file());
    // As SIGTERM after the last checkpoint leaves the suite: the run's summary says its last
    // stage was interrupted (so --reuse must not take it as finished), a torn row, no report.
    let killed = tmp("validate-killed");
    copy_dir(&whole.join(run), &killed.join(run));
    let mut s: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(whole.join(run).join("summary.json")).unwrap(),
    )
    .unwrap();
    let last = s["stages"].as_array().unwrap().len() - 1;
    s["stages"][last]["ended_by"] = "interrupted (SIGINT/SIGTERM)".into();
    std::fs::write(killed.join(run).join("summary.json"), s.to_string()).unwrap();
    let mut series = std::fs::read(killed.join(run).join("timeseries.csv")).unwrap();
    series.extend_from_slice(b"9.99e-1,collapse,1.2");
    std::fs::write(killed.join(run).join("timeseries.csv"), series).unwrap();
    let stderr = validate(&killed, true);
    assert!(stderr.contains("resuming"), "{stderr}");
    assert_same_outputs(&whole.join(run), &killed.join(run));
}
