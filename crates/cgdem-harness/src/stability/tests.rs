use super::measurement::{classify, LogFindings};
use super::*;

#[test]
fn a_lost_atoms_error_counts_the_atoms_and_a_nan_row_is_non_finite() {
    let log = "Step Time Atoms c_ke v_kepm\n0 0 40 1.5 0.2\n100 1e-3 40 -nan nan\nERROR: Lost atoms: original 40 current 37 (src/thermo.cpp:481)\n";
    let f = LogFindings::of(log);
    assert_eq!(f.lost_atoms, 3);
    assert!(f.non_finite);
    assert!(f.error.unwrap().starts_with("ERROR: Lost atoms"));
    let liggghts =
        LogFindings::of("ERROR: Lost atoms: original 79 current 79 (./src/thermo.cpp:445)\n");
    assert_eq!(liggghts.lost_atoms, 1);
    let clean = LogFindings::of("Step Time\n0 0 40 1.5 0.2\nLoop time of 1.0 on 1 procs\n");
    assert_eq!(clean, LogFindings::default());
}

#[test]
fn a_suite_without_stability_cases_adds_no_section_and_no_csv() {
    let dir = std::env::temp_dir().join(format!("cgdem-stability-none-{}", std::process::id()));
    let mut report = Report::new("t");
    let options = ValidateOptions {
        out: dir.clone(),
        quiet: true,
        ..Default::default()
    };
    let records = run_stability(&[], &options, &mut report).unwrap();
    assert!(records.is_empty());
    assert!(!dir.join("stability.csv").exists());
    assert!(!report.render(&dir).contains("Stability"));
}

fn case() -> StabilityCase {
    StabilityCase {
        file: "x.toml".into(),
        codes: vec![Code::Cgdem],
        lambda: 1,
        force_dt: false,
        energy_tolerance: 0.05,
        conserves_energy: true,
        energy_not_judged: None,
        max_overlap: 0.25,
        overrides: Vec::new(),
        set: Vec::new(),
        variant: None,
    }
}

#[test]
fn a_stop_is_detected_only_before_loss_and_a_run_to_the_end_is_judged_on_energy() {
    let ev = Evidence {
        energy_rise: Some(0.01),
        energy_drift: Some(-0.01),
        largest_overlap: Some(0.1),
        ..Evidence::default()
    };
    assert_eq!(classify(&case(), &ev, None, None).0, Verdict::Stable);
    let stop = Some("guard".to_string());
    assert_eq!(
        classify(&case(), &ev, stop.clone(), None).0,
        Verdict::Detected
    );
    let lost = Evidence {
        particles_lost: 2,
        ..ev.clone()
    };
    assert_eq!(classify(&case(), &lost, stop, None).0, Verdict::Failed);
    let drift = Evidence {
        energy_drift: Some(-0.2),
        ..ev.clone()
    };
    assert_eq!(classify(&case(), &drift, None, None).0, Verdict::Failed);
    let crash = Some("exit 139".to_string());
    assert_eq!(classify(&case(), &ev, None, crash).0, Verdict::Failed);
}
