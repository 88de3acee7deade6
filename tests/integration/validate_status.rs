//! `cgdem validate` as a nightly job sees it: run from a directory outside the repository,
//! on a suite or on a scene file alone, its exit status says the verdict (0 green or amber,
//! 2 could not run, 3 incomplete) and `summary.json` says the same.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// A fresh scratch directory outside the repository, the working directory of the run.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cgdem-status-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `cgdem validate ARGS` in `dir`, with LAMMPS named by a path that does not exist (a
/// machine without it, whatever this one has).
fn validate(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cgdem"))
        .arg("validate")
        .args(args)
        .args(["--quiet", "--threads", "1"])
        .current_dir(dir)
        .env("CGDEM_LMP", dir.join("no-lammps-here"))
        .output()
        .unwrap()
}

fn summary(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// A suite file in another directory, naming its scene relative to itself; run from a third
/// directory; the default output goes under the working directory.
#[test]
fn a_suite_runs_from_any_directory_with_its_files_named_relative_to_it() {
    let dir = scratch("suite");
    let suites = dir.join("suites");
    std::fs::create_dir_all(&suites).unwrap();
    std::fs::copy(
        Path::new(ROOT).join("tests/data/tiny_drop.toml"),
        dir.join("tiny_drop.toml"),
    )
    .unwrap();
    std::fs::write(
        suites.join("mine.toml"),
        "name = \"mine\"\n[[case]]\nfile = \"../tiny_drop.toml\"\ncodes = [\"cgdem\"]\nlambdas = [1]\nseeds = [1]\n",
    )
    .unwrap();
    let work = dir.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let out = validate(&work, &["--suite", "../suites/mine.toml"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let s = summary(&work.join("cgdem-reports/mine/summary.json"));
    assert_eq!(s["status"], "green", "{s}");
}

/// A comparison that cannot be made because LAMMPS is missing is not green: the status is
/// incomplete, with exit status 3, and the runs not made are on the report's first screen.
#[test]
fn a_scene_alone_without_its_reference_code_is_incomplete_not_green() {
    let dir = scratch("incomplete");
    let scene = Path::new(ROOT).join("tests/data/tiny_drop.toml");
    let out = validate(
        &dir,
        &[
            scene.to_str().unwrap(),
            "--codes",
            "cgdem,lammps",
            "--seeds",
            "1",
            "--out",
            "report",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    let s = summary(&dir.join("report/summary.json"));
    assert_eq!(s["status"], "incomplete", "{s}");
    let skipped: Vec<&serde_json::Value> = s["runs"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["status"] == "skipped")
        .collect();
    assert_eq!(skipped.len(), 1, "{s}");
    assert_eq!(skipped[0]["code"], "lammps");
    assert!(s["provenance"]["LAMMPS version"]
        .as_str()
        .unwrap()
        .starts_with("not available"));
    let html = std::fs::read_to_string(dir.join("report/index.html")).unwrap();
    assert!(html.contains("Status: incomplete"), "first screen");
    assert!(html.contains("Runs not made"), "first screen lists them");
}

/// A suite or a scene that cannot be read is exit status 2, naming the file.
#[test]
fn an_unreadable_suite_or_scene_is_exit_status_two() {
    let dir = scratch("bad");
    let out = validate(&dir, &["--suite", "no/such/suite.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/suite.toml"));
    let out = validate(&dir, &["missing_scene.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing_scene.toml"));
}

/// The screw's speed fault is refused before any run: with a factor that is not one, and on a
/// scene without a screw, where it would change nothing (exit status 2, no report written).
#[test]
fn a_screw_speed_fault_without_a_screw_or_with_a_bad_factor_is_exit_status_two() {
    let dir = scratch("screw-fault");
    let scene = Path::new(ROOT).join("tests/data/tiny_drop.toml");
    for (fault, says) in [
        ("rpm_factor=0.8", "has a screw"),
        ("rpm_factor=0", "a factor > 0"),
    ] {
        let args = [scene.to_str().unwrap(), "--codes", "cgdem", "--seeds", "1"];
        let out = validate(
            &dir,
            &[&args[..], &["--out", "faulted", "--fault", fault]].concat(),
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{fault}: {stderr}");
        assert!(
            stderr.contains("rpm_factor") && stderr.contains(says),
            "{stderr}"
        );
        assert!(
            !dir.join("faulted").exists(),
            "{fault}: no report without a run"
        );
    }
}
