//! The stability suite's verdicts for cgdem: a 50 m/s impact with the seed's model runs to the
//! end within its energy and overlap bounds (stable); a time step forced to 5x the stable
//! limit is stopped by the energy guard before any particle is lost (detected). Both land in
//! summary.json, stability.csv and the report's "Stability" section. Also how `validate`
//! makes cgdem's runs: decomposed (`--grid`), several at a time (`--jobs`).

use std::process::Command;

#[test]
fn stability_suite_classifies_a_stable_and_a_detected_case() {
    let dir = std::env::temp_dir().join(format!("cgdem-stability-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let suite = dir.join("suite.toml");
    std::fs::write(
        &suite,
        format!(
            "name = \"stability-test\"\n\
             [[stability]]\nfile = \"{root}/validation/stability/impact_50ms_wca.toml\"\ncodes = [\"cgdem\"]\n\
             [[stability]]\nfile = \"{root}/validation/stability/dt_5x.toml\"\ncodes = [\"cgdem\"]\nforce_dt = true\n",
            root = env!("CARGO_MANIFEST_DIR")
        ),
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

/// `validate --grid`: every cgdem run of the suite (a case and a stability entry) is
/// decomposed as `cgdem run --grid` decomposes it, and `--reuse` without `--grid` does not
/// take the decomposed run for an undecomposed one.
#[test]
fn validate_grid_decomposes_cgdem_runs_and_reuse_tells_them_apart() {
    let dir = std::env::temp_dir().join(format!("cgdem-validate-grid-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let suite = dir.join("suite.toml");
    std::fs::write(
        &suite,
        format!(
            "name = \"grid-test\"\n\
             [[case]]\nfile = \"{root}/tests/data/tiny_drop.toml\"\ncodes = [\"cgdem\"]\nlambdas = [1]\nseeds = [1]\n\
             [[stability]]\nfile = \"{root}/validation/stability/impact_50ms_wca.toml\"\ncodes = [\"cgdem\"]\n",
            root = env!("CARGO_MANIFEST_DIR")
        ),
    )
    .unwrap();
    let report = dir.join("report");
    let validate = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_cgdem"))
            .args(["validate", "--quiet", "--threads", "2", "--suite"])
            .arg(&suite)
            .arg("--out")
            .arg(&report)
            .args(extra)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let summary_of = |run: &str| -> serde_json::Value {
        let path = report.join(run).join("summary.json");
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
    };
    let case_run = "runs/tiny_drop/cgdem-lambda1-seed1";
    let stability_run = "runs/stability/stab_impact_50ms_wca/cgdem";

    validate(&["--grid", "2x1x1", "--balance", "off"]);
    for run in [case_run, stability_run] {
        let d = &summary_of(run)["decomposition"];
        assert_eq!(d["grid"], serde_json::json!([2, 1, 1]), "{run}: {d}");
        assert!(d["balance_threshold"].is_null(), "{run}: {d}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["stability"][0]["verdict"], "stable", "{summary}");
    assert!(
        summary.to_string().contains("2x1x1, balance off"),
        "{summary}"
    );

    // Without --grid the runs are made again, on their scenes' own grids.
    validate(&["--reuse"]);
    for run in [case_run, stability_run] {
        let d = &summary_of(run)["decomposition"];
        assert_eq!(d["grid"], serde_json::json!([1, 1, 1]), "{run}: {d}");
        assert!(
            d["grid_reason"]
                .as_str()
                .unwrap()
                .starts_with("chosen from the scene"),
            "{d}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `validate --jobs` on an accuracy sweep: its runs are made side by side, each on its share
/// of the threads (summary.json says 1 thread under `--threads 2 --jobs 2`, where one run at
/// a time would say 2), with the same outputs and the same points, in the same order, as one
/// at a time on 1 thread.
#[test]
fn validate_jobs_runs_an_accuracy_sweep_side_by_side_with_the_same_points() {
    let dir = std::env::temp_dir().join(format!("cgdem-accuracy-jobs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let validate = |out: &str, threads: &str, jobs: &str| -> serde_json::Value {
        let out = dir.join(out);
        let o = Command::new(env!("CARGO_BIN_EXE_cgdem"))
            .args(["validate", "--quiet", "--suite"])
            .arg("tests/data/tiny_fidelity_suite.toml")
            .args(["--threads", threads, "--jobs", jobs, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
    };
    let one = validate("one", "1", "1");
    let two = validate("two", "2", "2");
    let points = |s: &serde_json::Value| -> Vec<serde_json::Value> {
        let points = s["accuracy"]["points"].as_array().unwrap().clone();
        points
            .into_iter()
            .map(|mut p| {
                // Where the run was made and how long it took differ by design.
                for key in ["dir", "wall_s"] {
                    p.as_object_mut().unwrap().remove(key);
                }
                p
            })
            .collect()
    };
    let (p1, p2) = (points(&one), points(&two));
    assert_eq!(p1.len(), 6, "{one}");
    assert!(p1.iter().all(|p| p["status"] == "ok"), "{one}");
    assert_eq!(p1, p2);
    for case in ["tiny_hertz_collapse-fidelity", "tiny_hertz_collapse-short"] {
        let runs = |root: &str| dir.join(root).join("runs").join(case).join("accuracy");
        for run in std::fs::read_dir(runs("two")).unwrap().flatten() {
            let name = run.file_name();
            let summary: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(run.path().join("summary.json")).unwrap(),
            )
            .unwrap();
            assert_eq!(summary["threads"], 1, "{name:?}");
            let series =
                |root: &str| std::fs::read(runs(root).join(&name).join("timeseries.csv")).unwrap();
            assert!(
                series("one") == series("two"),
                "{name:?}: time series differ"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
