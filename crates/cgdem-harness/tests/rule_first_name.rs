//! The coarse-graining rule `relative-overlap` was first called `seed`. Suite files,
//! `summary.json` matrices and nightly histories written under that name still load, and
//! load as `relative-overlap`, so that their runs, comparisons and trends match later ones.

use std::path::{Path, PathBuf};

use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_harness::advise::read_matrix;
use cgdem_harness::history::parse_history;
use cgdem_harness::suite::Suite;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn both_names_parse_to_the_same_rule() {
    for name in ["seed", "relative-overlap"] {
        assert_eq!(
            CoarseGrainRule::from_name(name),
            Some(CoarseGrainRule::RelativeOverlap)
        );
        let parsed: CoarseGrainRule = serde_json::from_str(&format!("\"{name}\"")).unwrap();
        assert_eq!(parsed, CoarseGrainRule::RelativeOverlap);
    }
    // Written under its new name only.
    assert_eq!(
        serde_json::to_string(&CoarseGrainRule::RelativeOverlap).unwrap(),
        "\"relative-overlap\""
    );
    assert_eq!(CoarseGrainRule::from_name("seeds"), None);
}

#[test]
fn a_suite_under_the_first_name_loads() {
    let evidence = repo().join("reports/cg_fidelity/NOTE.md");
    let text = format!(
        "name = \"old\"\n\
         [[case]]\nfile = \"validation/cases/aor_smoke.toml\"\ncodes = [\"cgdem\"]\n\
         lambdas = [8, 16]\nseeds = [1]\ncg_rules = [\"seed\", \"bulk-viscosity\"]\n\
         [[case.known_difference]]\ncomparison = \"cgdem lambda = 8 vs 16 (seed)\"\n\
         criterion = \"t_half ratio\"\nreason = \"slower coarse collapse\"\n\
         evidence = \"{}\"\nband = [1.0, 3.0]\n\
         [[accuracy]]\nfile = \"validation/cases/aor_smoke.toml\"\nvariant = \"a\"\n\
         cg_rule = \"seed\"\nreference = {{ lambda = 8 }}\n\
         [[accuracy.series]]\nknob = \"lambda\"\nvalues = [16]\ncg_rule = \"seed\"\n",
        evidence.display()
    );
    let suite = Suite::parse(&text, Path::new("old.toml")).unwrap();
    let case = &suite.cases[0];
    assert_eq!(
        case.cg_rules,
        [
            CoarseGrainRule::RelativeOverlap,
            CoarseGrainRule::BulkViscosity
        ]
    );
    let kd = &case.known_differences[0];
    assert_eq!(kd.comparison, "cgdem lambda = 8 vs 16 (relative-overlap)");
    assert!(kd.applies_to("cgdem lambda = 8 vs 16 (relative-overlap)", "t_half ratio"));
    assert_eq!(suite.accuracy[0].rule, CoarseGrainRule::RelativeOverlap);
    assert_eq!(
        suite.accuracy[0].series[0].rule,
        CoarseGrainRule::RelativeOverlap
    );
}

#[test]
fn the_stored_fidelity_matrix_loads_under_the_new_name() {
    let dir = repo().join("reports/cg_fidelity");
    let stored = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(
        stored.contains("\"cg_rule\": \"seed\""),
        "written before the rename"
    );
    let (_, points) = read_matrix(&dir).unwrap();
    assert!(points
        .iter()
        .any(|p| p.cg_rule == CoarseGrainRule::RelativeOverlap));
    assert!(points
        .iter()
        .any(|p| p.cg_rule == CoarseGrainRule::BulkViscosity));
}

#[test]
fn a_history_under_the_first_name_continues_its_trends() {
    let old = r#"[{"date": "d", "commit": "c", "report": "r", "runs": 1, "runs_failed": 0,
        "comparisons_failed": 0, "metrics": {"c cgdem lambda=8 seed: repose angle":
        {"quantity": "repose angle [deg]", "value": 30.0, "tolerance": 2.0, "relative": false}}}]"#;
    let nights = parse_history(old, Path::new("history.json")).unwrap();
    let names: Vec<&String> = nights[0].metrics.keys().collect();
    assert_eq!(names, ["c cgdem lambda=8 relative-overlap: repose angle"]);
}
