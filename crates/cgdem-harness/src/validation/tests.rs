use std::path::Path;

use super::measurement::compare;
use super::*;
use crate::suite::Code;
use crate::verdict::Verdict;
use cgdem_core::coarse_graining::CoarseGrainRule;

/// A finished run of `code` and `seed` whose collapse front moves as `front(t)` and whose
/// final repose angle is `angle`, written to a temporary directory.
fn fake_run(
    root: &Path,
    code: Code,
    seed: u64,
    angle: f64,
    front: impl Fn(f64) -> f64,
) -> RunRecord {
    let dir = root.join(format!("{}-{seed}", code.name()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut csv = cgdem_core::io::CsvBuffer::new([
        "time_s",
        "stage",
        "front_m",
        "wall_height_m",
        "kinetic_energy_per_mass_j_kg",
    ]);
    for i in 0..=50 {
        let t = i as f64 * 0.01;
        let ke = (t * (0.6 - t)).max(1e-6);
        csv.row([
            (1.0 + t).to_string(),
            "collapse".into(),
            front(t).to_string(),
            (0.135 - 0.2 * (front(t) - 0.1)).to_string(),
            ke.to_string(),
        ]);
    }
    std::fs::write(dir.join("timeseries.csv"), csv.bytes().unwrap()).unwrap();
    let mut r = RunRecord::ok(
        "aor_hertz_smoke".into(),
        code,
        1,
        CoarseGrainRule::RelativeOverlap,
        seed,
        dir,
    );
    r.repose_angle_deg = Some(angle);
    r.reused = true;
    r
}

fn judge(extra: &str, lammps_front: f64, lammps_angle: f64) -> Vec<Comparison> {
    crate::at_repo_root();
    let root = std::env::temp_dir().join(format!(
        "cgdem-verdicts-{}-{}",
        std::process::id(),
        lammps_front.to_bits() ^ lammps_angle.to_bits()
    ));
    let text = format!(
        "name = \"t\"\n[[case]]\nfile = \"validation/cases/aor_hertz_smoke.toml\"\ncodes = [\"cgdem\", \"lammps\"]\nlambdas = [1]\nseeds = [1, 2]\nangle_tolerance_deg = 2.0\n{extra}"
    );
    let suite = Suite::parse(&text, Path::new("t.toml")).unwrap();
    let case = &suite.cases[0];
    let scene = case.load_scene().unwrap();
    // Fronts advancing 0.2 m in 0.5 s; seeds 0.005 m apart; the box is 0.5 m long.
    let runs = vec![
        fake_run(&root, Code::Cgdem, 1, 14.0, |t| 0.1 + 0.4 * t),
        fake_run(&root, Code::Cgdem, 2, 14.4, |t| 0.105 + 0.4 * t),
        fake_run(&root, Code::Lammps, 1, lammps_angle, move |t| {
            0.1 + 0.4 * t + lammps_front * t
        }),
        fake_run(&root, Code::Lammps, 2, lammps_angle + 0.4, move |t| {
            0.105 + 0.4 * t + lammps_front * t
        }),
    ];
    let out = compare(&scene, case, &runs);
    let _ = std::fs::remove_dir_all(&root);
    out
}

#[test]
fn the_same_runs_pass_and_a_shifted_front_fails_by_its_own_criterion() {
    let same = judge("", 0.0, 14.0);
    assert_eq!(same.len(), 2, "{same:?}");
    assert!(same.iter().all(|c| c.verdict == Verdict::Pass), "{same:?}");
    // The front runs 0.1 m further by the end: 0.2 of the box length.
    let moved = judge("", 0.2, 14.0);
    let dynamics = moved.iter().find(|c| c.part == "dynamics").unwrap();
    assert_eq!(dynamics.verdict, Verdict::Fail);
    let front = dynamics
        .criteria
        .iter()
        .find(|c| c.name == "front gap")
        .unwrap();
    assert!((front.value - 0.2).abs() < 1e-9, "{front:?}");
    // Seeds 0.005 m apart on both sides: noise sqrt(2 * 0.0025^2) / 0.5 of the box.
    assert!(
        (front.noise - 2f64.sqrt() * 0.0025 / 0.5).abs() < 1e-9,
        "{front:?}"
    );
    assert!(dynamics.decided_by == "front gap" || dynamics.decided_by == "wall height gap");
    let angle = moved.iter().find(|c| c.part == "final state").unwrap();
    assert_eq!(angle.verdict, Verdict::Pass);
}

#[test]
fn a_declared_difference_is_amber_in_its_band_and_red_outside() {
    let declared = "[[case.known_difference]]\ncomparison = \"cgdem vs lammps\"\ncriterion = \"repose angle\"\nreason = \"r\"\nevidence = \"reference/lammps/SEED_MODEL.md\"\nband = [5.0, 30.0]\n";
    let inside = judge(declared, 0.0, 29.0);
    let angle = inside.iter().find(|c| c.part == "final state").unwrap();
    assert_eq!(angle.verdict, Verdict::KnownDifference, "{angle:?}");
    assert!(angle.pass);
    let outside = judge(declared, 0.0, 50.0);
    let angle = outside.iter().find(|c| c.part == "final state").unwrap();
    assert_eq!(angle.verdict, Verdict::Fail, "{angle:?}");
    // Undeclared, 15 deg is a plain failure.
    let plain = judge("", 0.0, 29.0);
    assert_eq!(
        plain
            .iter()
            .find(|c| c.part == "final state")
            .unwrap()
            .verdict,
        Verdict::Fail
    );
}

#[test]
fn a_screw_flow_outside_its_band_turns_the_status_red_and_one_inside_green() {
    use crate::quantity::mass_flow::flow_verdicts;
    // One seed per code at 140 rpm (reports/screw_three_codes/NOTE.md: cgdem 5.938 +- 0.086,
    // LIGGGHTS 5.896 +- 0.146 kg/s), and cgdem's flow as a screw turning 0.8 times as fast.
    let screw_run = |code: Code, flow: f64, se: f64| {
        let mut r = RunRecord::ok(
            "screw_feeder_hertz".into(),
            code,
            1,
            CoarseGrainRule::RelativeOverlap,
            1,
            std::path::PathBuf::from("unused"),
        );
        r.rpm = Some(140.0);
        r.mass_flow_kg_s = Some(flow);
        r.mass_flow_std_error_kg_s = Some(se);
        r
    };
    let night = |cgdem_flow: f64| {
        let runs = vec![
            screw_run(Code::Cgdem, cgdem_flow, 0.086),
            screw_run(Code::Liggghts, 5.896, 0.146),
        ];
        let verdicts = flow_verdicts(&runs, None, 2, &[]);
        let mut summary = ValidationSummary {
            suite: "screw".into(),
            status: Status::Green,
            provenance: BTreeMap::new(),
            comparisons: screw_comparisons("screw_feeder_hertz", verdicts),
            runs,
            accuracy: None,
            stability: Vec::new(),
            chung_ooi: Vec::new(),
        };
        summary.status = Status::of(&summary);
        summary
    };
    let unchanged = night(5.938);
    assert_eq!(
        unchanged.status,
        Status::Green,
        "{:?}",
        unchanged.comparisons
    );
    let slowed = night(0.8 * 5.938);
    assert_eq!(slowed.status, Status::Red);
    assert_eq!(slowed.status.exit_code(), 1);
    // summary.json says which comparison and criterion, as for every other case.
    let json = serde_json::to_value(&slowed).unwrap();
    let c = &json["comparisons"][0];
    assert_eq!(c["what"], "cgdem vs liggghts, lambda = 1, 140 rpm", "{c}");
    assert_eq!(c["part"], "steady flow");
    assert_eq!(c["verdict"], "fail");
    assert_eq!(c["decided_by"], "mass flow");
    assert!(c["criteria"][0]["noise_rule"]
        .as_str()
        .unwrap()
        .contains("one seed per code"));
}
