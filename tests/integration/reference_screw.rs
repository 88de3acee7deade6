//! The particle-built screw feeder in LAMMPS: the screw's atoms turn as one rigid body from
//! the conveying stage on, the grains stay inside the casing-and-hopper region except where
//! they fall out of the outlet, the hopper is topped up, and the post-processing measures a
//! mass flow. What LAMMPS measured is stored in `reference/golden/reference_screw.csv` and
//! checked always: its screw is cgdem's (the deck's atoms are cgdem's body sites), so cgdem's
//! build of the same scene must give the stored atom count; an installed `lmp` is run too and
//! must reproduce the stored numbers. (cgdem's own run of this short version is not compared:
//! it takes minutes here.)

use std::path::Path;

use cgdem_core::geometry::screw_feeder::ScrewFeederSpec;
use cgdem_core::scene::{Override, Scene};
use cgdem_harness::code::Code;
use cgdem_harness::decks::{self, read_dump};

use crate::common::completed_reference_run;
use crate::golden::GoldenFile;

const CASE: &str = "short particle screw";

#[test]
fn lammps_turns_a_particle_screw_and_conveys_grains_inside_its_casing() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("validation/cases/screw_feeder_hertz_particles.toml");
    // A short run: 0.05 s of settling, half a turn at 100 rpm with two top-ups.
    let overrides: Vec<Override> = [
        "stage[0].duration=0.05",
        "stage[1].duration=0.3",
        "conveying.discard=0.1",
    ]
    .iter()
    .map(|o| Override::parse(o, Path::new("test")).unwrap())
    .collect();
    let scene = Scene::load_with_overrides(&file, &overrides).expect("scene");
    let mut golden = GoldenFile::load("reference_screw.csv");
    if let Some(measured) = live_check(&scene) {
        for (quantity, value) in measured {
            golden.live(CASE, quantity, "lammps", value);
        }
    }
    golden.finish();
    let stored = |quantity: &str| golden.get(CASE, quantity, "lammps");
    assert!(stored("mass flow (kg/s)") > 0.0);
    assert!(
        stored("grains refilled") > 0.0,
        "no top-up deposited a grain"
    );
    assert!(stored("screw atoms") > 1000.0);

    // cgdem builds the same screw (no step taken: both stages shorter than dt).
    let mut built = scene.clone();
    for stage in &mut built.stages {
        stage.end = cgdem_core::scene::StageEnd::Duration(1e-9);
    }
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("reference_screw_cgdem");
    let _ = std::fs::remove_dir_all(&out);
    let options = cgdem_core::run::RunOptions {
        out_dir: out,
        ..Default::default()
    };
    let cg = cgdem_core::run::run(&built, &options).expect("cgdem build of the screw");
    assert_eq!(cg.n_body_particles as f64, stored("screw atoms"));
    assert_eq!(
        (cg.n_particles - cg.n_body_particles) as f64,
        stored("grains at the start")
    );
}

/// The LAMMPS run with its checks; its numbers for the golden file. None without `lmp`.
fn live_check(scene: &Scene) -> Option<Vec<(&'static str, f64)>> {
    let (run, dir) = completed_reference_run(Code::Lammps, scene, "reference_screw", 300)?;
    let summary = run.summary.expect("summary");
    let conveying = summary.conveying.clone().expect("conveying summary");
    assert!(
        conveying.mass_flow_kg_s.is_finite() && conveying.mass_flow_kg_s > 0.0,
        "{conveying:?}"
    );
    assert!(
        summary.n_body_particles > 1000,
        "{}",
        summary.n_body_particles
    );
    assert!(
        summary.n_particles_refilled > 0,
        "no top-up deposited a grain"
    );

    let frames = read_dump(&dir.join("traj.dump")).expect("dump");
    let convey_start = summary.stages[1].start_s;
    let screw_type = 2.0;
    let atoms = |f: &decks::Frame, screw: bool| -> Vec<(i64, [f64; 3])> {
        let (id, ty) = (f.column("id").unwrap(), f.column("type").unwrap());
        let (x, y, z) = (
            f.column("x").unwrap(),
            f.column("y").unwrap(),
            f.column("z").unwrap(),
        );
        (0..f.len())
            .filter(|&k| (ty[k] == screw_type) == screw)
            .map(|k| (id[k] as i64, [x[k], y[k], z[k]]))
            .collect()
    };

    // The screw: every atom keeps its x and its distance from the axis and has turned by
    // 2 pi rpm/60 t (rpm = -100: about -x) since the conveying stage began.
    let (first, last) = (&frames[0], frames.last().unwrap());
    let t = last.step as f64 * summary.dt_s - convey_start;
    let expected = 2.0 * std::f64::consts::PI * -100.0 / 60.0 * t;
    let before: std::collections::HashMap<i64, [f64; 3]> = atoms(first, true).into_iter().collect();
    let after = atoms(last, true);
    assert_eq!(after.len(), before.len());
    let wrap = |a: f64| {
        (a + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
    };
    for (id, p) in &after {
        let q = before[id];
        let (r0, r1) = (q[1].hypot(q[2]), p[1].hypot(p[2]));
        assert!(
            (p[0] - q[0]).abs() < 1e-9 && (r1 - r0).abs() < 1e-9,
            "atom {id}"
        );
        if r0 > 0.01 {
            let turned = wrap(p[2].atan2(p[1]) - q[2].atan2(q[1]));
            assert!(
                (turned - wrap(expected)).abs() < 1e-6,
                "atom {id}: {turned} vs {expected}"
            );
        }
    }

    // The grains: none behind the end plate, none outside the bore below the axis except
    // under the outlet or past the casing's open end.
    let layout = ScrewFeederSpec::default().layout();
    let d = scene.species[0].diameter;
    for f in &frames {
        for (id, [x, y, z]) in atoms(f, false) {
            assert!(
                x > layout.end_plate_x[1] - 0.1 * d,
                "step {}: grain {id} behind the end plate at x = {x}",
                f.step
            );
            let outside = z < 0.0 && y.hypot(z) > layout.bore_radius + 0.1 * d;
            let falling_out =
                (x > layout.outlet_x[0] && x < layout.outlet_x[1]) || x > layout.casing_end_x;
            assert!(
                !outside || falling_out,
                "step {}: grain {id} leaked at ({x}, {y}, {z})",
                f.step
            );
        }
    }
    let grains_at_start = atoms(first, false).len();
    Some(vec![
        ("screw atoms", summary.n_body_particles as f64),
        ("grains at the start", grains_at_start as f64),
        ("grains refilled", summary.n_particles_refilled as f64),
        ("mass flow (kg/s)", conveying.mass_flow_kg_s),
    ])
}
