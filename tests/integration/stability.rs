//! The stability suite's verdicts for cgdem: a 50 m/s impact with the seed's model runs to the
//! end within its energy and overlap bounds (stable); a time step forced to 5x the stable
//! limit is stopped by the energy guard before any particle is lost (detected). Both land in
//! summary.json, stability.csv and the report's "Stability" section.

use std::process::Command;

#[test]
fn stability_suite_classifies_a_stable_and_a_detected_case() {
    let dir = std::env::temp_dir().join(format!("cgdem-stability-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let suite = dir.join("suite.toml");
    std::fs::write(
        &suite,
        "name = \"stability-test\"\n\
         [[stability]]\nfile = \"validation/stability/impact_50ms_wca.toml\"\ncodes = [\"cgdem\"]\n\
         [[stability]]\nfile = \"validation/stability/dt_5x.toml\"\ncodes = [\"cgdem\"]\nforce_dt = true\n",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_cgdem"))
        .args(["validate", "--quiet", "--suite"])
        .arg(&suite)
        .arg("--out")
        .arg(dir.join("report"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report/summary.json")).unwrap())
            .unwrap();
    let records = summary["stability"].as_array().unwrap();
    assert_eq!(records.len(), 2, "{summary}");

    let stable = &records[0];
    assert_eq!(stable["case"], "stab_impact_50ms_wca");
    assert_eq!(stable["verdict"], "stable", "{stable}");
    let ev = &stable["evidence"];
    assert_eq!(ev["particles"], 20);
    assert_eq!(ev["particles_lost"], 0);
    assert!(ev["energy_rise"].as_f64().unwrap() < 0.05, "{ev}");
    // The contacts dissipate: the end holds less than the start.
    assert!(ev["dissipated_j"].as_f64().unwrap() > 0.0, "{ev}");
    assert!(ev["largest_overlap"].as_f64().unwrap() < 0.25, "{ev}");

    let detected = &records[1];
    assert_eq!(detected["verdict"], "detected", "{detected}");
    let message = detected["message"].as_str().unwrap();
    assert!(
        message.contains("guard `energy growth` fired") && message.contains("5.00 times"),
        "{message}"
    );
    assert_eq!(detected["evidence"]["particles_lost"], 0);

    let csv = std::fs::read_to_string(dir.join("report/stability.csv")).unwrap();
    assert!(csv.starts_with("case,code,verdict,"), "{csv}");
    assert!(csv.contains("stab_dt_5x,cgdem,detected,"), "{csv}");
    let html = std::fs::read_to_string(dir.join("report/index.html")).unwrap();
    assert!(html.contains("Stability") && html.contains("stab_impact_50ms_wca"));
    let _ = std::fs::remove_dir_all(&dir);
}
