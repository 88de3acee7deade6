//! The multi-stage Hertz decks in LIGGGHTS and LAMMPS: a tiny collapse settles until at rest,
//! loses its gate (`unfix`), runs a timed stage with a repose sample, and goes through the
//! post-processing cgdem's own runs share. What the codes measured is stored in
//! `reference/golden/reference_stages.csv`: cgdem's run of the same scene is compared with it
//! always; an installed code is run too, checked as before, and must reproduce its numbers.

use std::path::{Path, PathBuf};

use cgdem_core::run::SampleTrigger;
use cgdem_core::scene::Scene;
use cgdem_harness::code::Code;
use cgdem_harness::decks::{self, lammps, liggghts, read_dump, RunStatus, RunnerOptions};

use crate::common::completed_reference_run;
use crate::golden::GoldenFile;

const GOLDEN_FILE: &str = "reference_stages.csv";
const CASE: &str = "tiny collapse";

fn scene() -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tiny_hertz_collapse.toml"))
        .expect("scene")
}

fn key(code: Code) -> String {
    code.name().to_string()
}

/// Runs the deck when the code is installed (checks as before, numbers fed to the golden file),
/// then compares cgdem's run of the same scene with the stored numbers.
fn check(code: Code) {
    let mut golden = GoldenFile::load(GOLDEN_FILE);
    if let Some(measured) = live_check(code) {
        for (quantity, value) in measured {
            golden.live(CASE, quantity, &key(code), value);
        }
    }
    golden.finish();
    let stored = |quantity: &str| golden.get(CASE, quantity, &key(code));

    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("reference_stages/cgdem_vs_{}", key(code)));
    let _ = std::fs::remove_dir_all(&out);
    let options = cgdem_core::run::RunOptions {
        out_dir: out.clone(),
        ..Default::default()
    };
    let cg = cgdem_core::run::run(&scene(), &options).expect("cgdem run");
    let name = code.label();
    assert_eq!(cg.n_particles as f64, stored("particles"), "{name}");
    let stages: Vec<&str> = cg.stages.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(stages, ["settle", "collapse"]);
    // Same dt and duration: the timed stage has as many steps in every code.
    assert_eq!(
        cg.stages[1].steps as f64,
        stored("collapse steps"),
        "{name}: collapse steps"
    );
    let settle_end = cg.stages[0].end_s;
    assert!(
        (0.2 - 1e-9..=0.4 + 0.011).contains(&settle_end),
        "cgdem settle end {settle_end}"
    );
    let triggers: Vec<SampleTrigger> = cg.repose_samples.iter().map(|s| s.trigger).collect();
    assert_eq!(
        triggers,
        [SampleTrigger::FixedTime, SampleTrigger::StageEnd]
    );
    assert_eq!(
        cg.repose_samples[0].time_after_start_s,
        stored("fixed-time sample (s after stage start)")
    );
    // 40 beads of d = 1 cm settle into a few layers: each code's heap differs by where single
    // beads land, so heights and runout agree within one diameter (one bin of the profile).
    let d = 0.01;
    for (k, quantity) in [
        (0, "wall height fixed time (m)"),
        (1, "wall height stage end (m)"),
    ] {
        let (c, r) = (cg.repose_samples[k].wall_height_m, stored(quantity));
        println!("STAGES | {name} | {quantity} | cgdem {c:.6e} | stored {r:.6e}");
        assert!((c - r).abs() <= d, "{name}: {quantity}: cgdem {c} vs {r}");
    }
    let (c, r) = (cg.runout_m.expect("cgdem runout"), stored("runout (m)"));
    println!("STAGES | {name} | runout (m) | cgdem {c:.6e} | stored {r:.6e}");
    assert!((c - r).abs() <= d, "{name}: runout: cgdem {c} vs {r}");
}

/// The deck run in the installed code with the structural checks; its numbers for the golden
/// file. None when the code is not installed.
fn live_check(code: Code) -> Option<Vec<(&'static str, f64)>> {
    let dir = format!("reference_stages/{}", code.name());
    let (run, dir) = completed_reference_run(code, &scene(), &dir, 120)?;
    let summary = run.summary.expect("summary");
    assert_eq!(summary.code, code.name());
    assert_eq!(summary.n_particles, 40);
    let stages: Vec<(&str, &str)> = summary
        .stages
        .iter()
        .map(|s| (s.name.as_str(), s.ended_by.as_str()))
        .collect();
    assert_eq!(stages.len(), 2, "{stages:?}");
    assert_eq!(stages[0].0, "settle");
    assert!(
        ["settled", "max_duration"].contains(&stages[0].1),
        "{stages:?}"
    );
    assert_eq!(stages[1], ("collapse", "duration"));
    let settle = &summary.stages[0];
    assert!(settle.end_s - settle.start_s >= 0.2 - 1e-9 && settle.end_s <= 0.4 + 0.011);
    let collapse = &summary.stages[1];
    assert!((collapse.end_s - collapse.start_s - 0.2).abs() <= summary.dt_s);
    // The fixed-time sample and the stage-end sample, both measured.
    let triggers: Vec<SampleTrigger> = summary.repose_samples.iter().map(|s| s.trigger).collect();
    assert_eq!(
        triggers,
        [SampleTrigger::FixedTime, SampleTrigger::StageEnd]
    );
    assert!((summary.repose_samples[0].time_after_start_s - 0.1).abs() < 1e-12);
    for file in [
        "timeseries.csv",
        "profile.csv",
        "repose.csv",
        "summary.json",
    ] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    // The gate was removed only after the settle stage: no bead beyond it while settling,
    // beads beyond it at the end.
    let frames = read_dump(&dir.join("traj.dump")).expect("dump");
    let gate = 0.04;
    let max_x = |f: &decks::Frame| {
        f.column("x")
            .unwrap()
            .iter()
            .fold(f64::MIN, |a, &b| a.max(b))
    };
    let settle_end = (settle.end_s / summary.dt_s).round() as u64;
    for f in frames.iter().filter(|f| f.step <= settle_end) {
        assert!(
            max_x(f) < gate,
            "{}: step {} beyond the gate",
            code.label(),
            f.step
        );
    }
    let end_max_x = max_x(frames.last().unwrap());
    assert!(end_max_x > gate + 0.005);
    let samples = &summary.repose_samples;
    Some(vec![
        ("particles", summary.n_particles as f64),
        ("settle end (s)", settle.end_s),
        ("collapse steps", collapse.steps as f64),
        (
            "fixed-time sample (s after stage start)",
            samples[0].time_after_start_s,
        ),
        ("wall height fixed time (m)", samples[0].wall_height_m),
        ("wall height stage end (m)", samples[1].wall_height_m),
        ("runout (m)", summary.runout_m.expect("runout")),
        ("max x at the end (m)", end_max_x),
    ])
}

#[test]
fn liggghts_runs_a_multi_stage_hertz_deck() {
    check(Code::Liggghts);
}

#[test]
fn lammps_runs_a_multi_stage_hertz_deck() {
    check(Code::Lammps);
}

/// Regression: after `unfix` and a `run pre no`, LAMMPS walks its old fix list, so without the
/// deck's zero-force pads the last wall fix acted twice (a normal impact on the end wall
/// rebounded with 0.366 instead of 0.49998); and a second setup re-applied the Tsuji
/// polynomial to the walls' damping (0.60055). One bead, no gravity, thrown at the end wall
/// after the gate (a wall fix defined before it) is removed: it must rebound as from one wall
/// set up once, as in LIGGGHTS (`tests/hertz_golden.rs`: 0.4999769 for this material). The
/// rebound is stored in `reference/golden/reference_stages.csv`; cgdem's run of the same
/// scene is compared with it always, the installed code (when there is one) too.
fn end_wall_rebound(code: Code) {
    const EXPECTED: f64 = 0.4999769;
    const CASE: &str = "end wall after unfix";
    let mut scene = scene();
    scene.gravity = cgdem_core::math::Vec3::ZERO;
    scene.repose = None;
    scene.output.timeseries_interval = 1e-3;
    scene.stages = vec![
        cgdem_core::scene::Stage {
            name: "before".into(),
            remove_walls: Vec::new(),
            end: cgdem_core::scene::StageEnd::Duration(1e-4),
        },
        cgdem_core::scene::Stage {
            name: "after".into(),
            remove_walls: vec!["gate".into()],
            end: cgdem_core::scene::StageEnd::Duration(6e-3),
        },
    ];
    let s = &scene.species[0];
    let mut particles = cgdem_core::particles::Particles::new(true);
    let r = s.radius();
    // 0.5 mm from the end wall at x = 0.15, moving into it at 1 m/s.
    particles.push(
        0,
        cgdem_core::math::Vec3::new(0.15 - r - 5e-4, 0.02, 0.06),
        r,
        s.mass(),
    );
    particles.velocity[0] = cgdem_core::math::Vec3::new(1.0, 0.0, 0.0);
    let dt = 1e-6;
    let name = code.label();
    let mut golden = GoldenFile::load(GOLDEN_FILE);
    if let Some(vx) = live_end_wall(code, &scene, &particles, dt) {
        golden.live(CASE, "rebound vx (m/s)", &key(code), vx);
    }
    golden.finish();
    let stored = -golden.get(CASE, "rebound vx (m/s)", &key(code));
    assert!(
        (stored - EXPECTED).abs() < 1e-4,
        "{name}: stored rebound {stored} m/s off the end wall after the gate's unfix (one wall, one setup: {EXPECTED})",
    );

    scene.time_step = cgdem_core::timestep::TimeStepRequest::Explicit(dt);
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("reference_stages")
        .join(format!("end_wall_cgdem_vs_{}", key(code)));
    let _ = std::fs::remove_dir_all(&out);
    let options = cgdem_core::run::RunOptions {
        out_dir: out,
        initial_state: Some(particles),
        keep_final_state: true,
        ..Default::default()
    };
    let run = cgdem_core::run::run(&scene, &options).expect("cgdem run");
    let cg = -run.final_state.expect("final state").velocity[0].x;
    println!("END WALL | {name} | cgdem {cg:.7} | stored {stored:.7}");
    assert!(
        (cg - stored).abs() < 1e-4,
        "cgdem rebound {cg} m/s off the end wall after the gate's removal vs {name}'s {stored}"
    );
}

/// The rebound's vx in the installed code; None when it is not installed.
fn live_end_wall(
    code: Code,
    scene: &Scene,
    particles: &cgdem_core::particles::Particles,
    dt: f64,
) -> Option<f64> {
    let found = match code {
        Code::Cgdem | Code::Lammps => lammps::find_lmp(),
        Code::Liggghts => liggghts::find_liggghts(),
    };
    if let Err(reason) = found {
        println!(
            "{} not run ({reason}): its stored numbers are used",
            code.label()
        );
        return None;
    }
    let deck = match code {
        Code::Cgdem | Code::Lammps => {
            lammps::write_deck(scene, particles, dt, lammps::WallModulus::installed())
        }
        Code::Liggghts => liggghts::write_deck(scene, particles, dt),
    }
    .expect("deck");
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("reference_stages")
        .join(format!("end_wall_{}", code.name()));
    let _ = std::fs::remove_dir_all(&dir);
    deck.write_to(&dir).expect("write deck");
    let options = RunnerOptions {
        np: None,
        stop: None,
        timeout: std::time::Duration::from_secs(60),
    };
    let status = match code {
        Code::Cgdem | Code::Lammps => lammps::run_deck(&dir, &options),
        Code::Liggghts => liggghts::run_deck(&dir, &options),
    };
    assert!(matches!(status, RunStatus::Completed { .. }), "{status:?}");
    let frames = read_dump(&dir.join("traj.dump")).expect("dump");
    Some(frames.last().unwrap().column("vx").unwrap()[0])
}

#[test]
fn lammps_applies_each_remaining_wall_once_after_an_unfix() {
    end_wall_rebound(Code::Lammps);
}

#[test]
fn liggghts_applies_each_remaining_wall_once_after_an_unfix() {
    end_wall_rebound(Code::Liggghts);
}
