//! A rotating drum as an accuracy quantity: the errors of a coarse level against the fine
//! run with the same seed, `cgdem advise` on the dynamic angle and the mixing period, the
//! sweep's `drum` table read, and the levels' table written.

use std::path::Path;

use super::tests::run;
use super::*;
use crate::advise::advise;

/// A drum run: `lambda`, `seed`, its angle, swing period, Lacey index and cost.
fn drum(lambda: u32, seed: u64, angle: f64, period: f64, lacey: f64) -> AccuracyPoint {
    let (series, setting, value) = if lambda == 1 {
        ("reference", "reference".to_string(), 1.0)
    } else {
        ("lambda", format!("lambda = {lambda}"), f64::from(lambda))
    };
    AccuracyPoint {
        case: "drum_reduced-fidelity".into(),
        series: series.into(),
        setting,
        lambda,
        repose_angle_deg: None,
        dynamic_angle_deg: Some(angle),
        mixing_period_s: Some(period),
        mixing_index: Some(lacey),
        large_share_zones: Some([0.1, 0.2]),
        ..run(series, value, seed, 0.0, 3.2e8 / f64::from(lambda).powi(4))
    }
}

fn matrix() -> Vec<AccuracyPoint> {
    let mut points = vec![
        drum(1, 1, 36.0, 1.50, 0.20),
        drum(1, 2, 36.4, 1.55, 0.22),
        drum(1, 3, 35.8, 1.45, 0.18),
        // lambda 2: the angle 1 deg steeper in every seed, the period 10% longer.
        drum(2, 1, 37.0, 1.65, 0.25),
        drum(2, 2, 37.4, 1.705, 0.27),
        drum(2, 3, 36.8, 1.595, 0.23),
    ];
    measure(&mut points);
    points
}

#[test]
fn a_coarse_levels_errors_are_against_the_fine_run_with_the_same_seed() {
    let points = matrix();
    let coarse: Vec<&AccuracyPoint> = points.iter().filter(|p| p.lambda == 2).collect();
    for p in &coarse {
        assert!(
            (p.dynamic_angle_error_deg.unwrap() - 1.0).abs() < 1e-9,
            "{p:?}"
        );
        assert!((p.mixing_period_error.unwrap() - 0.1).abs() < 1e-9, "{p:?}");
        assert!((p.mixing_index_error.unwrap() - 0.05).abs() < 1e-9, "{p:?}");
    }
}

#[test]
fn advise_answers_for_the_drums_dynamic_angle_and_mixing_period() {
    let points = matrix();
    let angle = Measure::from_quantity("dynamic_angle").unwrap();
    let a = advise(Path::new("m.json"), &points, "drum_reduced", angle, 2.0).unwrap();
    let l = a.advised.expect("lambda 2 is within 2 deg");
    assert_eq!(l.lambda, 2);
    assert!((l.error - 1.0).abs() < 1e-9, "{l:?}");
    assert!((l.saving_particle_steps - 16.0).abs() < 1e-9, "{l:?}");
    let period = Measure::from_quantity("mixing_period").unwrap();
    let a = advise(Path::new("m.json"), &points, "drum_reduced", period, 0.05).unwrap();
    assert!(a.advised.is_none());
    assert_eq!(a.best_reached.unwrap().lambda, 2);
    assert_eq!(
        Measure::from_quantity("mixing_index"),
        Some(Measure::MixingIndex)
    );
}

#[test]
fn an_accuracy_sweep_reads_its_drum_table_and_names_a_bad_field() {
    crate::at_repo_root();
    let sweep = |steady: f64| {
        format!(
            "name = \"s\"\ndescription = \"d\"\n[[accuracy]]\nfile = \"validation/cases/drum_reduced.toml\"\nvariant = \"fidelity\"\nmixing_period_target = 0.2\ndrum = {{ stage = \"rotate\", steady_from = {steady} }}\n[accuracy.reference]\nlambda = 1\n[[accuracy.series]]\nknob = \"lambda\"\nvalues = [2]\n"
        )
    };
    let suite = crate::suite::Suite::parse(&sweep(1.0), Path::new("s.toml")).unwrap();
    let a = &suite.accuracy[0];
    assert_eq!(a.drum.as_ref().unwrap().steady_from_s, 1.0);
    assert_eq!(a.targets.mixing_period, 0.2);
    assert_eq!(a.targets.dynamic_angle_deg, 2.0);
    let e = crate::suite::Suite::parse(&sweep(-1.0), Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("s.toml") && e.contains("accuracy[0].drum.steady_from"),
        "{e}"
    );
}

#[test]
fn the_levels_table_gives_each_levels_means_and_saving() {
    let points = matrix();
    let dir = std::env::temp_dir().join(format!("cgdem-drum-levels-{}", std::process::id()));
    let mut report = crate::report::Report::new("t");
    let section = report.section("s");
    super::drum::write_drum_table(section, &points, &dir).unwrap();
    let csv = std::fs::read_to_string(dir.join("drum_levels.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 3, "{csv}");
    assert!(
        rows[1].starts_with("reference,relative-overlap,1,3,3.606667e1,"),
        "{csv}"
    );
    assert!(
        rows[2].starts_with("lambda = 2,relative-overlap,2,3,3.706667e1,"),
        "{csv}"
    );
    assert!(rows[2].ends_with(",1.600000e1"), "{csv}");
    std::fs::remove_dir_all(&dir).unwrap();
}
