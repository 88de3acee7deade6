//! The multi-stage Hertz decks in LIGGGHTS and LAMMPS (when installed): a tiny collapse
//! settles until at rest, loses its gate (`unfix`), runs a timed stage with a repose sample,
//! and goes through the post-processing cgdem's own runs share.

use std::path::{Path, PathBuf};

use cgdem_core::run::SampleTrigger;
use cgdem_core::scene::Scene;
use cgdem_harness::lammps::{self, read_dump, ReferenceCode, RunStatus, RunnerOptions};
use cgdem_harness::liggghts;

use crate::common::completed_reference_run;

fn scene() -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tiny_hertz_collapse.toml"))
        .expect("scene")
}

fn check(code: ReferenceCode) {
    let dir = format!("reference_stages/{}", code.name().to_lowercase());
    let Some((run, dir)) = completed_reference_run(code, &scene(), &dir, 120) else {
        return;
    };
    let summary = run.summary.expect("summary");
    assert_eq!(summary.code, code.name().to_lowercase());
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
    let max_x = |f: &lammps::Frame| {
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
            code.name(),
            f.step
        );
    }
    assert!(max_x(frames.last().unwrap()) > gate + 0.005);
}

#[test]
fn liggghts_runs_a_multi_stage_hertz_deck() {
    check(ReferenceCode::Liggghts);
}

#[test]
fn lammps_runs_a_multi_stage_hertz_deck() {
    check(ReferenceCode::Lammps);
}

/// Regression: after `unfix` and a `run pre no`, LAMMPS walks its old fix list, so without the
/// deck's zero-force pads the last wall fix acted twice (a normal impact on the end wall
/// rebounded with 0.366 instead of 0.49998); and a second setup re-applied the Tsuji
/// polynomial to the walls' damping (0.60055). One bead, no gravity, thrown at the end wall
/// after the gate (a wall fix defined before it) is removed: it must rebound as from one wall
/// set up once, as in LIGGGHTS (`tests/hertz_golden.rs`: 0.4999769 for this material).
fn end_wall_rebound(code: ReferenceCode) {
    let found = match code {
        ReferenceCode::Lammps => lammps::find_lmp(),
        ReferenceCode::Liggghts => liggghts::find_liggghts(),
    };
    if let Err(reason) = found {
        println!("skipped {}: {reason}", code.name());
        return;
    }
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
    let mut particles = cgdem_core::particles::Particles::new(false);
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
    let deck = match code {
        ReferenceCode::Lammps => lammps::write_deck(&scene, &particles, dt),
        ReferenceCode::Liggghts => liggghts::write_deck(&scene, &particles, dt),
    }
    .expect("deck");
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("reference_stages")
        .join(format!("end_wall_{}", code.name().to_lowercase()));
    let _ = std::fs::remove_dir_all(&dir);
    deck.write_to(&dir).expect("write deck");
    let options = RunnerOptions {
        np: None,
        timeout: std::time::Duration::from_secs(60),
    };
    let status = match code {
        ReferenceCode::Lammps => lammps::run_deck(&dir, &options),
        ReferenceCode::Liggghts => liggghts::run_deck(&dir, &options),
    };
    assert!(matches!(status, RunStatus::Completed { .. }), "{status:?}");
    let frames = read_dump(&dir.join("traj.dump")).expect("dump");
    let vx = frames.last().unwrap().column("vx").unwrap()[0];
    assert!(
        (-vx - 0.4999769).abs() < 1e-4,
        "{}: rebound {} m/s off the end wall after the gate's unfix (one wall, one setup: 0.4999769)",
        code.name(),
        -vx
    );
}

#[test]
fn lammps_applies_each_remaining_wall_once_after_an_unfix() {
    end_wall_rebound(ReferenceCode::Lammps);
}

#[test]
fn liggghts_applies_each_remaining_wall_once_after_an_unfix() {
    end_wall_rebound(ReferenceCode::Liggghts);
}
