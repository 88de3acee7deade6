//! The solver guards: a deliberately unstable run is stopped with an error naming the guard,
//! the step, the particles, the likely cause and a stable step; what it wrote survives; and
//! `--keep-going` turns the stop into a warning. One regression test per guard.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use cgdem_core::guard::GuardKind;
use cgdem_core::math::Real;

use crate::common::{binary_collision, binary_collision_setup, build, collide, Coke};

fn cgdem_run(case: &str, dir: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cgdem"))
        .args(["run", case, "--quiet", "--threads", "1", "--out"])
        .arg(dir)
        .args(extra)
        .output()
        .unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cgdem-guard-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The run failed with the named guard's full message (with a stable time step, unless the
/// guard is one no time step cures), kept at least `rows` time-series rows
/// and wrote a summary that records the stop; returns stderr.
fn assert_stopped(out: &Output, dir: &Path, guard: &str, kind: &str, rows: usize) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for needle in [
        format!("guard `{guard}` fired at step"),
        "particles (id)".into(),
        "likely cause:".into(),
        "outputs written so far are kept".into(),
    ] {
        assert!(stderr.contains(&needle), "no `{needle}` in: {stderr}");
    }
    // Every guard a smaller step can cure names a stable one.
    if guard != "lost particles" {
        assert!(stderr.contains("a stable time step: dt <="), "{stderr}");
    }
    let series = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
    assert!(series.lines().count() > rows, "{series}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["stopped_by"]["kind"], kind, "{summary}");
    assert!(summary["stages"][0]["ended_by"]
        .as_str()
        .unwrap()
        .contains("stopped by"));
    stderr
}

#[test]
fn energy_guard_stops_a_forced_5x_time_step_and_keep_going_only_warns() {
    let dir = scratch("energy");
    let out = cgdem_run("validation/stability/dt_5x.toml", &dir, &["--force-dt"]);
    let stderr = assert_stopped(&out, &dir, "energy growth", "energy_growth", 2);
    assert!(
        stderr.contains("5.00 times the stable limit") && stderr.contains("dt <= 4.446e-6 s"),
        "{stderr}"
    );

    let dir_on = scratch("energy-keep-going");
    let out = cgdem_run(
        "validation/stability/dt_5x.toml",
        &dir_on,
        &["--force-dt", "--keep-going"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: --keep-going: guard `energy growth`"),
        "{stderr}"
    );
    let summary = std::fs::read_to_string(dir_on.join("summary.json")).unwrap();
    assert!(summary.contains("\"stopped_by\": null"), "{summary}");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&dir_on);
}

#[test]
fn overlap_guard_stops_a_50_m_s_impact_on_soft_hertz_beads() {
    let dir = scratch("overlap");
    let out = cgdem_run("validation/stability/impact_50ms_hertz.toml", &dir, &[]);
    let stderr = assert_stopped(&out, &dir, "overlap", "overlap", 1);
    assert!(
        stderr.contains("wall `floor` overlap") && stderr.contains("an impact at"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn overlap_guard_names_particles_placed_overlapping() {
    let dir = scratch("overlap-placed");
    let out = cgdem_run("validation/stability/dense_overlap.toml", &dir, &[]);
    let stderr = assert_stopped(&out, &dir, "overlap", "overlap", 0);
    assert!(stderr.contains("placed overlapping"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn lost_particle_guard_stops_a_run_whose_particle_leaves_the_box_and_warn_removes_it() {
    // Coke placed 5% overlapping: the WCA energy released throws a particle out at ~60 m/s.
    let dir = scratch("lost");
    let out = cgdem_run("validation/stability/dense_overlap_mild.toml", &dir, &[]);
    let stderr = assert_stopped(&out, &dir, "lost particles", "lost_particles", 0);
    assert!(
        stderr.contains("left the box through a bounded face")
            && stderr.contains("crossed zhi")
            && stderr.contains("placed overlapping")
            // a lost particle is no time-step matter: the message does not suggest one
            && !stderr.contains("a stable time step"),
        "{stderr}"
    );
    // Stopped before removing it: the summary counts no lost particle.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["lost_particles"], 0, "{summary}");

    let dir_warn = scratch("lost-warn");
    let out = cgdem_run(
        "validation/stability/dense_overlap_mild.toml",
        &dir_warn,
        &["--set", "domain.lost = \"warn\""],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("left the box through a bounded face and were removed"),
        "{stderr}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir_warn.join("summary.json")).unwrap())
            .unwrap();
    assert!(summary["lost_particles"].as_u64().unwrap() > 0, "{summary}");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&dir_warn);
}

#[test]
fn energy_guard_counts_the_elastic_energy_of_a_compressed_packing() {
    // Hertz beads placed overlapping by up to 10% of the radius expand: kinetic energy rises
    // far above the start's, yet below what the overlaps stored, so no guard may fire.
    let dir = scratch("energy-elastic");
    let out = cgdem_run("validation/stability/dense_overlap_hertz.toml", &dir, &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert!(summary["stopped_by"].is_null(), "{summary}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn non_finite_guard_stops_an_overflowing_contact_force() {
    let dir = scratch("non-finite");
    // The overflowing particle also leaves the box (at a finite 1e296 m first): lost
    // particles only warn here, so that this test isolates the non-finite guard.
    let out = cgdem_run(
        "tests/data/guard_non_finite.toml",
        &dir,
        &["--force-dt", "--set", "domain.lost = \"warn\""],
    );
    assert_stopped(&out, &dir, "non-finite state", "non_finite", 2);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn non_finite_velocity_trips_the_guard_in_the_step_it_appears_naming_the_particle() {
    let coke = Coke::at(8.0);
    let mut sane = binary_collision(&coke, 0.1, 0.0, 0.02 * coke.pair_period());
    sane.step();
    assert!(sane.take_guard_trip().is_none());
    let mut setup = binary_collision_setup(&coke, 0.1, 0.0, 0.02 * coke.pair_period());
    setup.particles.velocity[1].x = Real::NAN;
    let id = setup.particles.id[1];
    let mut world = build(setup);
    world.step();
    let trip = world.take_guard_trip().expect("the non-finite guard fires");
    assert_eq!(trip.kind, GuardKind::NonFinite);
    assert_eq!(trip.step, 1);
    assert!(trip.particles.contains(&id), "{trip}");
}

#[test]
fn a_resolved_binary_collision_trips_no_guard() {
    let coke = Coke::at(8.0);
    let mut world = binary_collision(&coke, 1.0, 0.3, 0.02 * coke.pair_period());
    collide(&mut world, coke.diameter());
    assert!(world.take_guard_trip().is_none());
    assert!(world.guard_peaks().overlap_fraction > 0.0);
}
