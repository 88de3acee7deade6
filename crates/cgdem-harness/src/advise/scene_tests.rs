//! The matrix from a scene alone: levels stop at the particle and opening minimums, rules
//! that give the scene the same parameters run once, the quantities a scene can measure.

use std::path::{Path, PathBuf};

use super::scene::*;
use super::AdviseError;
use crate::accuracy::Measure;
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::{Override, Scene};

fn case(name: &str) -> PathBuf {
    Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../validation/cases"
    ))
    .join(name)
}

fn load(name: &str, set: &[&str]) -> Scene {
    let path = case(name);
    let overrides: Vec<Override> = set
        .iter()
        .map(|o| Override::parse(o, Path::new("--set")).unwrap())
        .collect();
    Scene::load_with_overrides(&path, &overrides).unwrap()
}

/// The reduced silo (24 000 grains of 4 mm, orifice 40 mm): lambda 2 keeps 3000 grains and
/// 5 parcels across the orifice; lambda 4 would put 2.5 across, where the flow clogs.
#[test]
fn the_silo_stops_at_the_last_level_with_five_parcels_across_its_orifice() {
    let scene = load("silo_reduced.toml", &[]);
    let m = scene_matrix(
        &case("silo_reduced.toml"),
        scene,
        Measure::DischargeRate,
        0.05,
        &MatrixChoice::default(),
    )
    .unwrap();
    let levels: Vec<(u32, f64)> = m.levels.iter().map(|l| (l.lambda, l.particles)).collect();
    assert_eq!(levels, [(1, 24000.0), (2, 3000.0)]);
    assert_eq!(m.opening.as_ref().unwrap().diameter_m, 0.04);
    assert!((m.levels[1].across_opening.unwrap() - 5.0).abs() < 1e-9);
    let because = m.coarsest_because.as_deref().unwrap();
    assert!(
        because.contains("lambda = 4 puts 2.5 parcel diameters across the opening"),
        "{because}"
    );
    // Hertz without cohesion or rolling friction: the three rules give the same parameters.
    assert_eq!(m.rules, [CoarseGrainRule::RelativeOverlap]);
    assert_eq!(m.same_as.len(), 2);
    assert_eq!(m.seeds, DEFAULT_SEEDS);
    let d = m.sweep.discharge.as_ref().unwrap();
    assert_eq!(d.stage, "discharge");
    assert!((d.discard_s - 0.15).abs() < 1e-12 && d.blocks == 5);
    assert_eq!(m.sweep.targets.discharge_rate, 0.05);
    // The silo has no heap to measure.
    assert_eq!(measurable(&m.scene), [Measure::DischargeRate]);
}

/// The same silo given as an STL file: the orifice is found from the mesh's rim.
#[test]
fn the_opening_of_an_stl_hopper_is_its_rim_about_the_vertical_axis() {
    let scene = load("silo_reduced.toml", &[]);
    let cgdem_core::scene::MeshSource::Silo(_, spec) = &scene.bodies[0].mesh else {
        panic!("the reduced silo is built in")
    };
    let dir = std::env::temp_dir().join(format!("cgdem-advise-stl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let stl = dir.join("hopper.stl");
    let mesh = cgdem_core::geometry::silo::wall_mesh(spec);
    cgdem_core::geometry::write_stl_binary(&stl, &mesh).unwrap();
    let set = format!("body[0].mesh = {:?}", stl.display().to_string());
    let from_stl = load("silo_reduced.toml", &[&set]);
    let o = opening(&from_stl).unwrap();
    assert!((o.diameter_m - 0.04).abs() < 1e-6, "{o:?}");
    assert!(o.source.contains("hopper.stl"), "{o:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The seed's WCA collapse: both WCA rules, which give it different parameters; a quantity
/// it cannot measure is named with those it can.
#[test]
fn a_wca_scene_runs_both_its_rules_and_names_what_it_can_measure() {
    let path = case("aor_smoke.toml");
    let scene = Scene::load(&path).unwrap();
    let choice = MatrixChoice {
        lambdas: Some(vec![16, 8]),
        ..Default::default()
    };
    let m = scene_matrix(&path, scene.clone(), Measure::Angle, 2.0, &choice).unwrap();
    assert_eq!(
        m.rules,
        [
            CoarseGrainRule::RelativeOverlap,
            CoarseGrainRule::BulkViscosity
        ]
    );
    let lambdas: Vec<u32> = m.levels.iter().map(|l| l.lambda).collect();
    assert_eq!(lambdas, [8, 16], "sorted: the finest is the reference");
    assert_eq!(m.sweep.series.len(), 2);
    assert!(m.sweep.discharge.is_none() && m.opening.is_none());
    let e = scene_matrix(&path, scene.clone(), Measure::DischargeRate, 0.05, &choice)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("aor_smoke.toml")
            && e.contains("cannot measure discharge_rate")
            && e.contains("repose_angle, profile, t_half, front_history"),
        "{e}"
    );
    let one = MatrixChoice {
        lambdas: Some(vec![8, 8]),
        ..Default::default()
    };
    let e = scene_matrix(&path, scene.clone(), Measure::Angle, 2.0, &one).unwrap_err();
    assert!(matches!(e, AdviseError::Choice { .. }), "{e}");
    let hertz_rule = MatrixChoice {
        rules: Some(vec![CoarseGrainRule::ScaledParticle]),
        ..choice
    };
    let e = scene_matrix(&path, scene, Measure::Angle, 2.0, &hertz_rule)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--rules scaled-particle") && e.contains("wca"),
        "{e}"
    );
}
