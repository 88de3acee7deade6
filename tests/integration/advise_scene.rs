//! `cgdem advise CASE.toml --run` on a scene of one's own, from a directory outside the
//! repository: the matrix from the scene alone, its expected cost printed before it runs
//! (and equal to what the runs then took), the answer and its exit status, an interrupt
//! (exit 130) and the same command again going on from the runs already made.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::bead_scene::{BEAD_CONTACT, BEAD_WALL_CONTACT};

/// A small Hertz collapse (320 beads of 10 mm behind a gate, then 0.2 s of spreading): a
/// case no suite names.
fn heap() -> String {
    format!(
        r#"
name = "my_heap"

[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.3, 0.05, 0.3]
periodic = [false, true, false]

[[species]]
name = "bead"
diameter = 1.0e-2
density = 2500.0

{BEAD_CONTACT}
{BEAD_WALL_CONTACT}
[[wall]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[wall]]
name = "back"
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]

[[wall]]
name = "gate"
point = [0.08, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]

[[wall]]
name = "end"
point = [0.3, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]

[time]
dt_fraction = 0.05
integrator = "verlet"

[[insert]]
species = "bead"
lo = [0.0, 0.0, 0.0]
hi = [0.08, 0.05, 0.29]
count = 320
seed = 1

[[stage]]
name = "settle"
min_duration = 0.2
until_kinetic_energy_per_mass_below = 1e-4
max_duration = 0.3

[[stage]]
name = "collapse"
remove_walls = ["gate"]
duration = 0.2

[output]
timeseries_interval = 0.01
vtk_interval = 0.0

[repose]
stage = "collapse"
wall_x = 0.0
at_times = [0.1]
at_stage_end = true
bin_width_diameters = 1.0
exclude_wall_fraction = 0.15
exclude_toe_fraction = 0.15
"#
    )
}

/// A fresh working directory outside the repository, holding the scene.
fn workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cgdem-advise-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("heap.toml"), heap()).unwrap();
    dir
}

fn advise(dir: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cgdem"));
    c.current_dir(dir)
        .args(["advise", "heap.toml", "--quantity", "repose_angle"])
        .args(args);
    c
}

fn text(out: &Output) -> (String, String) {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!stderr.contains("panicked"), "{stderr}");
    (String::from_utf8_lossy(&out.stdout).to_string(), stderr)
}

/// The (shortest, longest) particle-steps "in all" that the cost line printed.
fn printed_total(stderr: &str) -> (f64, f64) {
    let line = stderr
        .lines()
        .find(|l| l.starts_with("expected cost (an estimate): "))
        .unwrap_or_else(|| panic!("no cost line: {stderr}"));
    let all = line.split(", of ").nth(1).unwrap();
    let all = all.split(" in all").next().unwrap();
    let mut numbers = all.split(" to ").map(|n| n.parse::<f64>().unwrap());
    let lo = numbers.next().unwrap();
    (lo, numbers.next().unwrap_or(lo))
}

/// Particle-steps the matrix's runs took, from their summaries.
fn taken(dir: &Path) -> (usize, f64) {
    let runs = dir.join("cgdem-advise/my_heap/runs/my_heap-advise/accuracy");
    let mut n = 0;
    let mut total = 0.0;
    for entry in std::fs::read_dir(runs).unwrap() {
        let text = std::fs::read_to_string(entry.unwrap().path().join("summary.json")).unwrap();
        let s: serde_json::Value = serde_json::from_str(&text).unwrap();
        total += s["particle_steps"].as_f64().unwrap();
        n += 1;
    }
    (n, total)
}

const SMALL: [&str; 6] = ["--lambdas", "1,2", "--seeds", "1,2", "--threads", "1"];

#[test]
fn advise_run_on_a_scene_alone_prints_its_cost_answers_and_exits_by_the_answer() {
    let dir = workdir("scene");
    let out = advise(&dir, &["--target", "90", "--run"])
        .args(SMALL)
        .output()
        .unwrap();
    let (stdout, stderr) = text(&out);
    // A target any level meets: the coarsest, lambda 2, exit 0.
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stdout.starts_with(
            "my_heap-advise: repose_angle within 90.00 deg: lambda = 2 under the relative-overlap rule"
        ),
        "{stdout}"
    );
    // The plan and its cost came before the first run, said to be an estimate and from what.
    let cost_at = stderr.find("expected cost (an estimate)").unwrap();
    assert!(cost_at < stderr.find("[1/4]").unwrap(), "{stderr}");
    assert!(
        stderr.contains("levels: lambda = 1 (320 particles")
            && stderr.contains("2 (40 particles")
            && stderr.contains("warning: lambda = 2 keeps 40 particles, fewer than 200")
            && stderr.contains("measured by a probe of 300 steps"),
        "{stderr}"
    );
    // The cost printed is what the four runs took (settling between its bounds).
    let (lo, hi) = printed_total(&stderr);
    let (n, total) = taken(&dir);
    assert_eq!(n, 4);
    assert!(
        lo <= total * (1.0 + 1e-9) && total <= hi * (1.0 + 1e-9),
        "{lo} .. {hi} vs {total}"
    );
    // Outputs in the working directory, none beside the scene.
    assert!(dir.join("cgdem-advise/my_heap/summary.json").is_file());
    assert!(dir.join("cgdem-advise/my_heap/index.html").is_file());

    // The same question with a target nothing meets: the runs are taken, nothing left to
    // run, the answer "none" and exit 1.
    let out = advise(&dir, &["--target", "1e-9", "--run"])
        .args(SMALL)
        .output()
        .unwrap();
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}\n{stderr}");
    assert!(
        stdout.contains(": none; the closest is lambda = 2"),
        "{stdout}"
    );
    assert!(
        stderr.contains("4 already made") && stderr.contains("nothing left to run"),
        "{stderr}"
    );
    // Without --run the answer comes from the scene's matrix in the working directory.
    let out = advise(&dir, &["--target", "90"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));

    // A quantity the scene cannot measure, a target that is not one, a default matrix the
    // scene is too small for: exit 2, saying what is allowed.
    for (args, says) in [
        (
            vec!["--quantity", "porosity", "--target", "0.02", "--run"],
            "the scene cannot measure porosity; it can measure: repose_angle, profile, t_half, front_history",
        ),
        (vec!["--target", "0", "--run"], "--target 0 is not allowed"),
        (
            vec!["--target", "2", "--run"],
            "lambda = 2 keeps 40 particles, fewer than 200); choose levels with --lambdas",
        ),
        (
            vec!["--target", "2", "--run", "--rules", "bulk-viscosity"],
            "--rules bulk-viscosity is not allowed: not defined for the scene's law (hertz)",
        ),
    ] {
        let mut c = Command::new(env!("CARGO_BIN_EXE_cgdem"));
        c.current_dir(&dir).args(["advise", "heap.toml"]);
        if args[0] != "--quantity" {
            c.args(["--quantity", "repose_angle"]);
        }
        let out = c.args(&args).output().unwrap();
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Ctrl-C during the matrix stops it (exit 130, the runs made kept); the same command again
/// takes them, goes on from the interrupted run's restart file and answers.
#[test]
fn an_interrupted_advise_run_goes_on_from_the_runs_already_made() {
    let dir = workdir("resume");
    // The first seed alone: two runs, made.
    let out = advise(&dir, &["--target", "90", "--run"])
        .args(["--lambdas", "1,2", "--seeds", "1", "--threads", "1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
    // Two seeds: the first seed's runs are taken; interrupted while the third run is made.
    let mut child = advise(&dir, &["--target", "90", "--run"])
        .args(SMALL)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let third = dir.join("cgdem-advise/my_heap/runs/my_heap-advise/accuracy/cgdem-reference-seed2");
    let started = Instant::now();
    while !third.join("timeseries.csv").exists() && started.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no exit after SIGINT"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = child.wait_with_output().unwrap();
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(
        stderr.contains("2 already made")
            && stderr.contains("interrupted by SIGINT")
            && stderr.contains("the same command again takes the runs already made"),
        "{stderr}"
    );
    // Again: the runs made are taken, the rest made, the answer given.
    let out = advise(&dir, &["--target", "90", "--run"])
        .args(SMALL)
        .output()
        .unwrap();
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    let made: usize = stderr
        .lines()
        .find(|l| l.starts_with("expected cost"))
        .and_then(|l| l.split(" already made").next())
        .and_then(|l| l.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{stderr}"));
    assert!((2..4).contains(&made), "{made} runs already made: {stderr}");
    assert!(stdout.starts_with("my_heap-advise: repose_angle within 90.00 deg: lambda = 2"));
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("cgdem-advise/my_heap/summary.json")).unwrap(),
    )
    .unwrap();
    let points = summary["accuracy"]["points"].as_array().unwrap();
    assert_eq!(points.len(), 4);
    let reused = points.iter().filter(|p| p["reused"] == true).count();
    assert_eq!(reused, made, "{summary}");
    let _ = std::fs::remove_dir_all(&dir);
}
