//! The discharge rate as an accuracy quantity: a synthetic silo run with a known rate, the
//! parcel's mass, a clog, the error against the fine run and `cgdem advise` on silo rows.

use std::path::{Path, PathBuf};

use super::discharge::measure_discharge;
use super::*;
use crate::advise::advise;
use crate::code::Code;
use crate::quantity::discharge::DischargeSettings;
use crate::runs::RunRecord;
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::Scene;

/// The reduced silo's grain: d = 4 mm, 2500 kg/m3.
fn grain_mass() -> f64 {
    2500.0 * std::f64::consts::PI / 6.0 * 0.004f64.powi(3)
}

fn settings() -> DischargeSettings {
    DischargeSettings {
        stage: "discharge".into(),
        orifice_diameter_m: 0.04,
        discard_s: 0.1,
        blocks: 5,
        bulk_lo: [-0.028, -0.028, 0.03],
        bulk_hi: [0.028, 0.028, 0.07],
    }
}

/// The reduced silo without its fill's data file (no bulk density to read).
fn silo() -> Scene {
    crate::at_repo_root();
    let mut scene = Scene::load(Path::new("validation/cases/silo_reduced.toml")).unwrap();
    scene.output.data_at_stage_ends.clear();
    scene
}

/// A run directory of a cgdem silo run at `lambda`: the gate opens at 0.30 s, then
/// `per_sample` particles leave every 0.01 s until `until` s after the gate (the end: 0.35 s).
fn run_dir(name: &str, lambda: u32, per_sample: u64, until: f64) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cgdem-acc-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let n0 = 24_000 / u64::from(lambda).pow(3);
    let mut csv = String::from("time_s,stage,n_particles\n0.29,fill,");
    csv += &format!("{n0}\n0.30,fill,{n0}\n");
    for k in 1..=35u64 {
        let t = 0.01 * k as f64;
        let gone = per_sample * (k.min((until / 0.01).round() as u64));
        csv += &format!("{:.2},discharge,{}\n", 0.30 + t, n0 - gone);
    }
    std::fs::write(dir.join("timeseries.csv"), csv).unwrap();
    let stage = |name: &str, start: f64, end: f64| serde_json::json!({"name": name, "start_s": start, "end_s": end, "steps": 1, "ended_by": "duration"});
    let summary = serde_json::json!({
        "case": "silo_reduced", "code": "cgdem", "lambda": lambda, "cg_rule": "seed",
        "n_particles": n0, "n_particles_inserted": n0, "n_particles_refilled": 0,
        "n_body_particles": 0, "lost_particles": 0, "steps": 1, "dt_s": 1.25e-5 * lambda as f64,
        "contact_period_s": 1e-3, "stable_dt_s": 1e-4, "simulated_s": 0.65, "wall_s": 1.0,
        "particle_steps": 1, "particle_steps_per_s": 1.0, "threads": 1,
        "repose_angle_deg": null, "repose_fit_r2": null, "repose_rule": null, "runout_m": null,
        "repose_samples": [], "stages": [stage("fill", 0.0, 0.3), stage("discharge", 0.3, 0.65)],
        "deleted_particles": 0, "deleted_mass_kg": 0.0, "conveying": null, "packing": null,
        "warnings": [], "stopped_by": null, "guard_peaks": null, "scene_file": "s",
        "scene_digest": "d", "cgdem_version": "v", "memory": null
    });
    std::fs::write(dir.join("summary.json"), summary.to_string()).unwrap();
    dir
}

fn measured(lambda: u32, per_sample: u64, until: f64, name: &str) -> AccuracyPoint {
    let dir = run_dir(name, lambda, per_sample, until);
    let record = RunRecord::ok(
        "silo".into(),
        Code::Cgdem,
        lambda,
        CoarseGrainRule::RelativeOverlap,
        1,
        dir.clone(),
    );
    let mut point = AccuracyPoint {
        repose_angle_deg: None,
        lambda,
        ..super::tests::run("lambda", lambda as f64, 1, 0.0, 1e6)
    };
    measure_discharge(&silo(), &settings(), &record, &mut point).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    point
}

#[test]
fn a_silo_run_gives_its_known_rate_with_each_parcel_carrying_lambda_cubed_grains() {
    // 10 grains per 0.01 s at lambda 1: 1000 grains/s.
    let fine = measured(1, 10, 1.0, "fine");
    let w = 1000.0 * grain_mass();
    assert!(
        (fine.discharge_rate_kg_s.unwrap() / w - 1.0).abs() < 1e-9,
        "{fine:?}"
    );
    assert!(fine.discharge_rate_std_error_kg_s.unwrap() < 1e-9 * w);
    assert_eq!(fine.particle_diameter_m, Some(0.004));
    assert_eq!(fine.flow_stopped_at_s, None);
    // The same count of parcels at lambda 2 is 8 times the mass.
    let coarse = measured(2, 10, 1.0, "coarse");
    assert!((coarse.discharge_rate_kg_s.unwrap() / (8.0 * w) - 1.0).abs() < 1e-9);
    assert_eq!(coarse.particle_diameter_m, Some(0.008));
}

#[test]
fn a_discharge_that_stops_is_measured_as_a_clog_with_its_time() {
    // Parcels leave until 0.15 s after the gate, then none to the end (0.35 s).
    let p = measured(4, 1, 0.15, "clog");
    let t = p.flow_stopped_at_s.expect("the flow stopped");
    assert!((t - 0.15).abs() < 1e-9, "{t}");
    // A flow that still runs in the last blocks did not stop.
    assert_eq!(measured(4, 1, 0.30, "late").flow_stopped_at_s, None);
}

#[test]
fn a_run_of_another_orifice_than_the_suites_is_refused_with_both_diameters() {
    let dir = run_dir("orifice", 1, 10, 1.0);
    let record = RunRecord::ok(
        "silo".into(),
        Code::Cgdem,
        1,
        CoarseGrainRule::RelativeOverlap,
        1,
        dir.clone(),
    );
    let wide = DischargeSettings {
        orifice_diameter_m: 0.06,
        ..settings()
    };
    let mut point = super::tests::run("reference", 1.0, 1, 0.0, 1e6);
    let e = measure_discharge(&silo(), &wide, &record, &mut point).unwrap_err();
    assert!(e.contains("0.04") && e.contains("0.06"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A silo matrix: fine rate 2.0 kg/s (seeds 1-3 a little apart), lambda 2 within 2-3%,
/// lambda 4 at half the rate.
fn silo_matrix() -> Vec<AccuracyPoint> {
    let mut points = Vec::new();
    for seed in 1..=3u64 {
        let noise = [0.0, 0.01, -0.01][seed as usize - 1];
        for (series, lambda, ratio) in [
            ("reference", 1u32, 1.0),
            ("lambda", 2, 0.975 + noise / 2.0),
            ("lambda", 4, 0.5 + noise),
        ] {
            let steps = 1e9 / f64::from(lambda).powi(4);
            points.push(AccuracyPoint {
                case: "silo_reduced-fidelity-d60".into(),
                setting: format!("lambda = {lambda}"),
                lambda,
                repose_angle_deg: None,
                discharge_rate_kg_s: Some(2.0 * (1.0 + noise) * ratio),
                ..super::tests::run(series, lambda as f64, seed, 0.0, steps)
            });
        }
    }
    measure(&mut points);
    points
}

#[test]
fn the_error_is_against_the_fine_run_of_the_same_seed() {
    let points = silo_matrix();
    let e: Vec<f64> = points
        .iter()
        .filter(|p| p.lambda == 4)
        .map(|p| p.discharge_rate_error.unwrap())
        .collect();
    for (e, noise) in e.iter().zip([0.0, 0.01, -0.01]) {
        assert!((e - (0.5 - noise)).abs() < 1e-12, "{e}");
    }
    let reference = points.iter().find(|p| p.series == "reference").unwrap();
    assert_eq!(reference.discharge_rate_error, Some(0.0));
}

#[test]
fn advise_answers_for_the_silos_discharge_rate() {
    let m = Measure::from_quantity("discharge_rate").unwrap();
    assert_eq!(m, Measure::DischargeRate);
    let points = silo_matrix();
    let a = advise(Path::new("m.json"), &points, "silo_reduced", m, 0.05).unwrap();
    let l = a.advised.expect("lambda 2 is within 5%");
    assert_eq!(l.lambda, 2);
    assert!((l.error - 0.025).abs() < 1e-9 && l.reach() < 0.05, "{l:?}");
    assert!((l.saving_particle_steps - 16.0).abs() < 1e-9);
    // Within 1%: none; the closest is lambda 2.
    let a = advise(Path::new("m.json"), &points, "silo_reduced", m, 0.01).unwrap();
    assert!(a.advised.is_none());
    assert_eq!(a.best_reached.unwrap().lambda, 2);
}

#[test]
fn an_accuracy_sweep_reads_its_discharge_table_and_names_a_bad_field() {
    crate::at_repo_root();
    let sweep = |blocks: u32| {
        format!(
            "name = \"s\"\ndescription = \"d\"\n[[accuracy]]\nfile = \"validation/cases/silo_reduced.toml\"\nvariant = \"fidelity\"\ndischarge_rate_target = 0.03\ndischarge = {{ stage = \"discharge\", orifice_diameter = 0.04, discard = 0.1, blocks = {blocks}, bulk_lo = [-0.028, -0.028, 0.03], bulk_hi = [0.028, 0.028, 0.07] }}\n[accuracy.reference]\nlambda = 1\n[[accuracy.series]]\nknob = \"lambda\"\nvalues = [2, 4]\n"
        )
    };
    let suite = crate::suite::Suite::parse(&sweep(5), Path::new("s.toml")).unwrap();
    let a = &suite.accuracy[0];
    assert_eq!(a.discharge.as_ref().unwrap().blocks, 5);
    assert_eq!(a.targets.discharge_rate, 0.03);
    let e = crate::suite::Suite::parse(&sweep(1), Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("s.toml") && e.contains("accuracy[0].discharge.blocks"),
        "{e}"
    );
}

/// The silo (restitution dashpot, no cohesion, no rolling friction) gets the same parameters
/// under every Hertz rule, so the fidelity suites run it under one (the seed's).
#[test]
fn the_hertz_rules_give_the_silo_the_same_parameters() {
    use cgdem_core::coarse_graining::coarse_grain_by;
    let scene = silo();
    for lambda in [2, 4] {
        let seed = coarse_grain_by(&scene, lambda, CoarseGrainRule::RelativeOverlap).unwrap();
        for rule in [
            CoarseGrainRule::ScaledParticle,
            CoarseGrainRule::LiggghtsPfm,
        ] {
            let other = coarse_grain_by(&scene, lambda, rule).unwrap();
            assert_eq!(other.contact, seed.contact, "{}", rule.name());
            assert_eq!(other.wall_contact, seed.wall_contact);
            assert_eq!(other.species, seed.species);
            assert_eq!(other.time_step, seed.time_step);
            assert_eq!(other.insertions, seed.insertions);
        }
    }
}

/// Each level holds the fine fill's solid mass: 24 000 grains are 3000 parcels at lambda 2
/// and 375 at lambda 4 (the count falls as lambda^3, exactly here).
#[test]
fn every_level_of_the_silo_inserts_the_same_solid_mass() {
    use cgdem_core::coarse_graining::coarse_grain_by;
    use cgdem_core::scene::InsertAmount;
    let scene = silo();
    let mass = |s: &Scene| match s.insertions[0].amount {
        InsertAmount::Count(n) => n as f64 * s.species[0].mass(),
        _ => panic!("the silo inserts a count"),
    };
    let fine = mass(&scene);
    for lambda in [2, 4] {
        let coarse = coarse_grain_by(&scene, lambda, CoarseGrainRule::RelativeOverlap).unwrap();
        assert!(
            (mass(&coarse) / fine - 1.0).abs() < 1e-12,
            "lambda {lambda}"
        );
    }
}
