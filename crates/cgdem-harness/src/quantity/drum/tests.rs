use super::measurement::{lacey_index, surface_angle, zone_counts, Grain, ZoneCounts};
use super::run::{parse_frame_time, read_frame};
use super::settings::parse_drum;

fn grain(x: f64, z: f64, large: bool) -> Grain {
    Grain {
        position: [x, 0.0, z],
        diameter: if large { 4e-3 } else { 2e-3 },
        large,
    }
}

#[test]
fn zones_are_mercurydpms_quadrants_by_species() {
    let grains = [
        grain(0.01, 0.01, false),   // zone 1, M1
        grain(0.02, 0.03, true),    // zone 1, M2
        grain(0.05, 0.001, true),   // zone 1, M2
        grain(-0.01, -0.01, false), // zone 2, M1
        grain(-0.01, -0.02, false), // zone 2, M1
        grain(-0.03, -0.05, true),  // zone 2, M2
        grain(0.01, -0.01, false),  // x > 0, z < 0: neither
        grain(-0.01, 0.01, true),   // x < 0, z > 0: neither
        grain(0.0, 0.01, false),    // on the axis x = 0: neither
    ];
    assert_eq!(
        zone_counts(&grains),
        ZoneCounts {
            zone1_m1: 1,
            zone1_m2: 2,
            zone2_m1: 2,
            zone2_m2: 1,
        }
    );
}

/// A surface of small grains laid on a line z = x tan(30 deg) - 0.02, with a buried grain under
/// every bin: the rule finds 30 degrees, R^2 = 1; the mirror image gives -30 degrees.
#[test]
fn surface_angle_reads_a_laid_slope() {
    let slope = 30f64.to_radians().tan();
    let w = 4e-3;
    let mut grains = Vec::new();
    for k in -20..20 {
        let x = (k as f64 + 0.5) * w;
        grains.push(grain(x, x * slope - 0.02 - 1e-3, false)); // top on the line
        grains.push(grain(x, x * slope - 0.05, true)); // buried
    }
    let line = surface_angle(&grains, w).unwrap();
    assert!((line.angle_deg - 30.0).abs() < 1e-9, "{line:?}");
    assert!((line.r2 - 1.0).abs() < 1e-12);
    // 40 bins: the centres between 20% and 80% of the span, 8 .. 32 exclusive of the ends
    assert_eq!(line.bins, 24);
    let mirrored: Vec<Grain> = grains
        .iter()
        .map(|g| Grain {
            position: [-g.position[0], g.position[1], g.position[2]],
            ..*g
        })
        .collect();
    let back = surface_angle(&mirrored, w).unwrap();
    assert!((back.angle_deg + 30.0).abs() < 1e-9, "{back:?}");
}

/// The wall's ends are left out: grains piled high at both ends (where the bed meets the
/// drum) do not tilt a flat surface.
#[test]
fn surface_angle_leaves_out_the_ends() {
    let w = 4e-3;
    let mut grains: Vec<Grain> = (0..50)
        .map(|k| grain((k as f64 + 0.5) * w, 0.0, false))
        .collect();
    for k in 0..5 {
        grains.push(grain((k as f64 + 0.5) * w, 0.05, false));
    }
    let line = surface_angle(&grains, w).unwrap();
    assert!(line.angle_deg.abs() < 1e-9, "{line:?}");
    assert!(surface_angle(&grains[..2], w).is_none());
}

fn cell_of(i: i64, n_small: usize, n_large: usize) -> Vec<Grain> {
    let x = (i as f64 + 0.5) * 0.01;
    let mut v: Vec<Grain> = (0..n_small).map(|_| grain(x, 0.005, false)).collect();
    v.extend((0..n_large).map(|_| grain(x, 0.005, true)));
    v
}

/// Two cells, one all small, one all large: segregated, M = 0. Two cells with the same
/// mixture: S^2 = 0, M = 1 / (1 - 1/n) (Lacey's index exceeds 1 when the cells are more
/// even than random sampling). A cell below the minimum count is left out.
#[test]
fn lacey_index_of_known_cells() {
    let mut seg = cell_of(0, 16, 0);
    seg.extend(cell_of(1, 0, 16));
    let m = lacey_index(&seg, 0.01, 10).unwrap();
    assert!(m.index.abs() < 1e-12, "{m:?}");
    assert_eq!(m.cells, 2);

    // 8 small and 1 large per cell: the large grain holds 8/16 = half the solid volume
    let mut even = cell_of(0, 8, 1);
    even.extend(cell_of(1, 8, 1));
    even.extend(cell_of(2, 3, 0)); // 3 grains: left out
    let m = lacey_index(&even, 0.01, 9).unwrap();
    let n = 9.0;
    assert!((m.index - 1.0 / (1.0 - 1.0 / n)).abs() < 1e-12, "{m:?}");
    assert_eq!(m.cells, 2);

    // one species only, or a single cell: no index
    assert!(lacey_index(&cell_of(0, 20, 0), 0.01, 10).is_none());
    let mut one = cell_of(0, 20, 0);
    one.extend(cell_of(1, 20, 0));
    assert!(lacey_index(&one, 0.01, 10).is_none());
}

/// Between segregated and even, by hand: cells of large-volume share 0.25 and 0.75 (equal
/// volumes) give p = 0.5, S^2 = 0.0625, S0^2 = 0.25, n = 18 grains a cell, so
/// M = 0.1875 / (0.25 - 0.25/18) = 0.794.
#[test]
fn lacey_index_between() {
    // 24 small (volume 24) + 1 large (volume 8): share 8/32 = 0.25; 8 small + 3 large: 24/32
    let mut g = cell_of(0, 24, 1);
    g.extend(cell_of(1, 8, 3));
    let m = lacey_index(&g, 0.01, 1).unwrap();
    let (s0, s2, n): (f64, f64, f64) = (0.25, 0.0625, (25.0 + 11.0) / 2.0);
    let expected = (s0 - s2) / (s0 - s0 / n);
    assert!((expected - 0.794).abs() < 1e-3);
    assert!((m.index - expected).abs() < 1e-12, "{m:?} {expected}");
}

#[test]
fn frames_time_from_cgdems_title() {
    let title = "LAMMPS data file written by cgdem 0.1.0: frame 3 of scene drum at t = 3.00000000000000044e-1 s";
    assert_eq!(parse_frame_time(title), Some(0.30000000000000004));
    assert_eq!(parse_frame_time("LAMMPS data file"), None);
}

#[test]
fn a_written_frame_is_read_by_type() {
    let dir = std::env::temp_dir().join(format!("cgdem-drum-frame-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("particles_000001.data");
    let text = "LAMMPS data file written by cgdem: frame 1 of scene drum at t = 2.5e-1 s\n\n\
        2 atoms\n2 atom types\n\n-0.1 0.1 xlo xhi\n-0.1 0.1 ylo yhi\n-0.1 0.1 zlo zhi\n\n\
        Atoms # sphere\n\n1 1 2e-3 2500 0.01 0.0 0.02\n2 2 4e-3 2000 -0.01 0.0 -0.02\n";
    std::fs::write(&path, text).unwrap();
    let frame = read_frame(&path, 2).unwrap();
    assert_eq!(frame.0, 0.25);
    assert_eq!(frame.1.len(), 2);
    assert!(!frame.1[0].large && frame.1[1].large);
    assert_eq!(zone_counts(&frame.1).as_array(), [1, 0, 0, 1]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn settings_are_checked() {
    let path = std::path::Path::new("suite.toml");
    let ok = parse_drum(
        toml::from_str("stage = \"rotate\"\nsteady_from = 1.0").unwrap(),
        "case[0]",
        path,
    );
    let ok = ok.unwrap();
    assert_eq!(ok.steady_from_s, 1.0);
    assert_eq!(
        (ok.count_tolerance, ok.angle_tolerance_deg),
        (
            super::settings::DEFAULT_COUNT_TOLERANCE,
            super::settings::DEFAULT_ANGLE_TOLERANCE_DEG
        )
    );
    let negative = parse_drum(
        toml::from_str("stage = \"rotate\"\nsteady_from = 1.0\ncount_tolerance = -0.1").unwrap(),
        "case[0]",
        path,
    );
    let message = negative.unwrap_err().to_string();
    assert!(
        message.contains("case[0].drum.count_tolerance"),
        "{message}"
    );
    let bad = parse_drum(
        toml::from_str("stage = \"rotate\"\nsteady_from = -1.0").unwrap(),
        "case[0]",
        path,
    );
    let message = bad.unwrap_err().to_string();
    assert!(message.contains("case[0].drum.steady_from"), "{message}");
    let empty = parse_drum(
        toml::from_str("stage = \"\"\nsteady_from = 1.0").unwrap(),
        "case[0]",
        path,
    );
    assert!(empty
        .unwrap_err()
        .to_string()
        .contains("case[0].drum.stage"));
}

/// A cgdem run directory made by hand (a summary whose rotation starts at 0.4 s, two
/// frames) is measured frame by frame with times from the rotation's start, its steady
/// means taken from `steady_from`, and the section writes the frames' CSV and figures.
#[test]
fn a_run_is_measured_from_its_frames_and_reported() {
    crate::at_repo_root();
    let dir = std::env::temp_dir().join(format!("cgdem-drum-run-{}", std::process::id()));
    let vtk = dir.join("run").join("vtk");
    std::fs::create_dir_all(&vtk).unwrap();
    let text = std::fs::read_to_string(
        "reports/silo/suite/runs/silo_reduced/cgdem-lambda1-seed1/summary.json",
    )
    .unwrap();
    let mut summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    summary["stages"][0]["name"] = "settle".into();
    summary["stages"][1]["name"] = "rotate".into();
    summary["stages"][1]["start_s"] = 0.4.into();
    std::fs::write(dir.join("run").join("summary.json"), summary.to_string()).unwrap();
    // Frame 0 (the settle): one M1 in zone 2; frame 1 (1.5 s of rotation): M1 and M2 in
    // zone 1, M2 in zone 2.
    let frame = |k: usize, t: f64, atoms: &str| {
        let body = format!(
            "LAMMPS data file written by cgdem: frame {k} of scene drum_reduced at t = {t:e} s\n\n\
             3 atoms\n2 atom types\n\n-0.1 0.1 xlo xhi\n-0.1 0.1 ylo yhi\n-0.1 0.1 zlo zhi\n\n\
             Atoms # sphere\n\n{atoms}"
        );
        std::fs::write(vtk.join(format!("particles_{k:06}.data")), body).unwrap();
    };
    frame(
        0,
        0.3,
        "1 1 2e-3 2500 -0.01 0 -0.01\n2 2 4e-3 2000 0.01 0 -0.01\n3 1 2e-3 2500 0.01 0 -0.02\n",
    );
    frame(
        1,
        1.9,
        "1 1 2e-3 2500 0.01 0 0.01\n2 2 4e-3 2000 0.02 0 0.01\n3 2 4e-3 2000 -0.01 0 -0.01\n",
    );
    let scene =
        cgdem_core::scene::Scene::load(std::path::Path::new("validation/cases/drum_reduced.toml"))
            .unwrap();
    let settings = super::DrumSettings {
        stage: "rotate".into(),
        steady_from_s: 1.0,
        count_tolerance: 0.03,
        angle_tolerance_deg: 1.0,
    };
    let record = crate::runs::RunRecord::ok(
        "drum_reduced".into(),
        crate::code::Code::Cgdem,
        1,
        cgdem_core::scene::CoarseGrainRule::RelativeOverlap,
        1,
        dir.join("run"),
    );
    let runs = super::measure_runs(&scene, &settings, &[record]);
    let run = &runs[0];
    assert!(run.problem.is_none(), "{:?}", run.problem);
    let times: Vec<f64> = run.frames.iter().map(|f| f.time_s).collect();
    assert!(
        (times[0] + 0.1).abs() < 1e-12 && (times[1] - 1.5).abs() < 1e-12,
        "{times:?}"
    );
    assert_eq!(run.frames[0].counts.as_array(), [0, 0, 1, 0]);
    assert_eq!(run.frames[1].counts.as_array(), [1, 1, 0, 1]);
    let means = run.steady_means(1.0).unwrap();
    assert_eq!((means.frames, means.counts), (1, [1.0, 1.0, 0.0, 1.0]));
    assert!(run.steady_means(2.0).is_none());

    let out = dir.join("report");
    let suite_file = std::path::PathBuf::from("validation/suites/drum.toml");
    let origin = crate::quantity::CaseOrigin {
        file: &suite_file,
        seeds: &[1],
        rpms: &[],
        keep_going: false,
    };
    let mut report = crate::report::Report::new("drum");
    super::write_drum_section(&mut report, &scene, &origin, &settings, &runs, None, &out).unwrap();
    let csv = std::fs::read_to_string(out.join("figures/drum_reduced/drum_frames.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 3, "{csv}");
    assert!(lines[2].starts_with("cgdem,1,1,1.500000,1,1,0,1,"), "{csv}");
    let runs_csv = std::fs::read_to_string(out.join("figures/drum_reduced/drum_runs.csv")).unwrap();
    // One steady frame: means, no swing.
    assert!(
        runs_csv
            .lines()
            .nth(1)
            .unwrap()
            .starts_with("cgdem,1,1,1,1.000000,1.000000,0.000000,1.000000,"),
        "{runs_csv}"
    );
    assert!(out
        .join("figures/drum_reduced/drum_zone1_counts.png")
        .exists());
    assert!(out
        .join("figures/drum_reduced/drum_zone2_counts.csv")
        .exists());

    // A reference code's run is read from its trajectory dump, which this one lacks.
    let other = crate::runs::RunRecord::ok(
        "drum_reduced".into(),
        crate::code::Code::Liggghts,
        1,
        cgdem_core::scene::CoarseGrainRule::RelativeOverlap,
        1,
        dir.join("run"),
    );
    let runs = super::measure_runs(&scene, &settings, &[other]);
    let problem = runs[0].problem.as_deref().unwrap();
    assert!(problem.contains("traj"), "{problem}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A reference code's trajectory dump: the frames at multiples of `every` steps are kept,
/// their grains typed as the data frames are.
#[test]
fn a_reference_dump_is_read_at_the_frame_period() {
    let dir = std::env::temp_dir().join(format!("cgdem-drum-dump-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("traj.dump");
    let mut text = String::new();
    for step in [0u64, 500, 1000] {
        text += &format!(
            "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n-0.1 0.1\n-0.1 0.1\n-0.1 0.1\n\
             ITEM: ATOMS id type x y z radius\n1 1 0.01 0 0.01 1e-3\n2 2 -0.01 0 -0.01 2e-3\n"
        );
    }
    std::fs::write(&path, text).unwrap();
    let frames = super::run::dump_frames(&path, 2, 1000).unwrap();
    assert_eq!(frames.iter().map(|f| f.0).collect::<Vec<_>>(), [0, 1000]);
    assert_eq!(zone_counts(&frames[1].1).as_array(), [1, 0, 0, 1]);
    assert_eq!(frames[1].1[1].diameter, 4e-3);
    std::fs::remove_dir_all(&dir).unwrap();
}
