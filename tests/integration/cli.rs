//! The command line: errors are messages with a non-zero exit, never panics; outputs land
//! where asked.

use std::process::Command;

use cgdem_harness::csv_table::CsvTable;

fn cgdem() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cgdem"))
}

#[test]
fn a_missing_scene_file_is_an_error_naming_it() {
    let out = cgdem()
        .args(["run", "no/such/case.toml", "--quiet"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("no/such/case.toml") && stderr.contains("cannot read"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));
}

/// A reference run asked for by name whose code is not installed is not reported as done:
/// exit status 3, the reason on stderr, and the deck left in the output directory.
#[test]
fn a_reference_run_without_its_code_exits_3_and_keeps_the_deck() {
    let out_dir = std::env::temp_dir().join(format!("cgdem-ref-missing-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out_dir);
    let case = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/validation/cases/aor_hertz_smoke.toml"
    );
    let out = cgdem()
        .args(["reference", "liggghts", case, "--out"])
        .arg(&out_dir)
        .env("CGDEM_LIGGGHTS", "/no/such/liggghts")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("not installed") && stderr.contains("/no/such/liggghts"),
        "{stderr}"
    );
    assert!(out_dir.join("deck.in").is_file(), "the deck is kept");
    let _ = std::fs::remove_dir_all(&out_dir);
}

/// A sweep's runs are not decomposed: `--grid` with `--sweep` is refused rather than ignored.
#[test]
fn grid_with_a_sweep_is_refused_not_ignored() {
    let out = cgdem()
        .args([
            "run",
            "tests/data/tiny_drop.toml",
            "--sweep",
            "rpm=140",
            "--grid",
            "2x1x1",
            "--quiet",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--grid")
            && stderr.contains("--sweep")
            && stderr.contains("cannot be used with"),
        "{stderr}"
    );
}

#[test]
fn lambda_must_be_a_power_of_two() {
    let out = cgdem()
        .args([
            "run",
            "validation/cases/aor_collapse.toml",
            "--lambda",
            "3",
            "--quiet",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("power of two"), "{stderr}");
}

#[test]
fn a_time_step_above_the_limit_is_refused_with_the_limit_unless_forced() {
    let dir = std::env::temp_dir().join(format!("cgdem-cli-dt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = std::fs::read_to_string("tests/data/tiny_drop.toml")
        .unwrap()
        .replace("dt_fraction = 0.05", "dt = 1e-3");
    let case = dir.join("too_big_dt.toml");
    std::fs::write(&case, scene).unwrap();
    let out = cgdem()
        .args(["run", case.to_str().unwrap(), "--quiet", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("exceeds the stable limit") && stderr.contains("--force-dt"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_small_run_writes_summary_timeseries_profile_and_a_vtk_series() {
    let dir = std::env::temp_dir().join(format!("cgdem-cli-run-{}", std::process::id()));
    let out = cgdem()
        .args([
            "run",
            "tests/data/tiny_drop.toml",
            "--quiet",
            "--threads",
            "2",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    for key in [
        "case",
        "lambda",
        "n_particles",
        "steps",
        "dt_s",
        "wall_s",
        "particle_steps_per_s",
        "repose_angle_deg",
        "repose_fit_r2",
    ] {
        assert!(summary.get(key).is_some(), "summary.json lacks `{key}`");
    }
    assert_eq!(summary["n_particles"], summary["n_particles_inserted"]);
    let series = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
    assert!(series.starts_with("time_s,stage,kinetic_energy_j"));
    assert!(series.lines().count() > 5);
    assert!(std::fs::read_to_string(dir.join("profile.csv"))
        .unwrap()
        .starts_with("x_m,height_m"));
    let pvd = std::fs::read_to_string(dir.join("vtk/particles.pvd")).unwrap();
    let frames = pvd.matches("<DataSet").count();
    assert!(frames >= 2, "{pvd}");
    // Appended raw binary: not UTF-8 past the XML header.
    let first = std::fs::read(dir.join("vtk/particles_000000.vtu")).unwrap();
    let first = String::from_utf8_lossy(&first);
    assert!(
        first.contains("UnstructuredGrid")
            && first.contains("radius")
            && first.contains("velocity")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn geometry_commands_write_the_screw_feeder_meshes_and_the_sdf_study() {
    let dir = std::env::temp_dir().join(format!("cgdem-geometry-{}", std::process::id()));
    let out = cgdem()
        .args(["geometry", "screw-feeder", "--out"])
        .arg(dir.join("feeder"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("outlet_x"));
    for name in ["screw.stl", "casing.stl", "hopper.stl", "insertion.stl"] {
        // The casing and the insertion region are unions of closed pieces that touch or
        // overlap (see screw_feeder.rs), so the strict reader's manifold check is skipped.
        let (mesh, _) =
            cgdem_core::geometry::read_stl_unchecked(&dir.join("feeder").join(name)).unwrap();
        assert!(!mesh.triangles.is_empty(), "{name}");
    }
    let out = cgdem()
        .args([
            "geometry",
            "sdf-accuracy",
            "--cells",
            "0.04,0.02",
            "--samples",
            "200",
            "--out",
        ])
        .arg(dir.join("sdf"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("sdf").join("sdf_accuracy.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 * 2, "{csv}");
    for stem in ["sdf_error", "sdf_memory", "sdf_build_time"] {
        assert!(dir.join("sdf").join(format!("{stem}.png")).exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_sweeps_are_errors_naming_the_key_and_value_not_panics() {
    let cases: [(&str, &str, &[&str]); 4] = [
        (
            "validation/cases/packing_vdw.toml",
            "size=1e-6",
            &["--sweep", "unknown key `size`", "diameter"],
        ),
        (
            "validation/cases/packing_vdw.toml",
            "diameter=1e-6,-1e-5",
            &["--sweep diameter", "`-1e-5`", "> 0"],
        ),
        (
            "validation/cases/aor_collapse.toml",
            "diameter=1e-4",
            &["aor_collapse.toml", "[packing]"],
        ),
        (
            "validation/cases/packing_vdw.toml",
            "rpm=20",
            &["packing_vdw.toml", "[conveying]"],
        ),
    ];
    for (case, sweep, expected) in cases {
        let out = cgdem()
            .args(["run", case, "--quiet", "--sweep", sweep, "--out"])
            .arg(std::env::temp_dir().join(format!("cgdem-cli-sweep-{}", std::process::id())))
            .output()
            .unwrap();
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        for e in expected {
            assert!(stderr.contains(e), "{sweep}: {stderr}");
        }
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

/// A small bed (300 spheres of 1 mm in a 5 d period, where gravity beats van der Waals) poured
/// by the diameter sweep: a coarse random packing, porosity 0.35 .. 0.45, with its pore sizes
/// and the sweep's table and plots written.
#[test]
fn a_small_diameter_sweep_packs_a_coarse_bed_and_writes_its_tables() {
    let dir = std::env::temp_dir().join(format!("cgdem-cli-packing-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = std::fs::read_to_string("validation/cases/packing_vdw.toml")
        .unwrap()
        .replace(
            "hi = [1.0e-3, 1.0e-3, 9.0e-3]",
            "hi = [5.0e-4, 5.0e-4, 1.1e-2]",
        )
        .replace(
            "hi = [1.0e-3, 1.0e-3, 8.72665e-3]",
            "hi = [5.0e-4, 5.0e-4, 1.0472e-2]", // start porosity 0.94 again
        )
        .replace("count = 1000", "count = 300")
        .replace("min_duration = 0.045", "min_duration = 0.05");
    let case = dir.join("small_packing.toml");
    std::fs::write(&case, scene).unwrap();
    let out = cgdem()
        .args(["run", case.to_str().unwrap(), "--quiet", "--threads", "1"])
        .args(["--sweep", "diameter=1e-3", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let table = CsvTable::read(&dir.join("out/porosity_vs_diameter.csv")).unwrap();
    let row = table.rows().next().unwrap();
    let column = |name: &str| row.text(table.column(name).unwrap()).unwrap();
    let porosity: f64 = column("porosity").parse().unwrap();
    assert!((0.35..0.45).contains(&porosity), "porosity {porosity}");
    assert_eq!(column("settled"), "true");
    assert_eq!(column("published_porosity"), "0.36");
    for file in [
        "d1000um/summary.json",
        "d1000um/pore_size.csv",
        "pore_size_vs_diameter.csv",
        "porosity_vs_diameter_plot.png",
        "porosity_vs_diameter_plot.svg",
        "pore_size_distribution_plot.png",
    ] {
        assert!(dir.join("out").join(file).exists(), "{file} missing");
    }
}

/// A scene asking for 1e10 particles is refused before anything is allocated, at once, with
/// the estimate and the machine's available memory.
#[test]
fn a_scene_needing_more_memory_than_the_machine_has_is_refused_at_once() {
    let started = std::time::Instant::now();
    let out = cgdem()
        .args([
            "run",
            "tests/data/tiny_hertz_collapse.toml",
            "--quiet",
            "--set",
            "insert[0].count=10000000000",
            "--out",
        ])
        .arg(std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("memory_refused"))
        .output()
        .unwrap();
    let elapsed = started.elapsed();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("tiny_hertz_collapse.toml")
            && stderr.contains("1.000e10 particles")
            && stderr.contains("GB")
            && stderr.contains("MemAvailable"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(elapsed < std::time::Duration::from_secs(1), "{elapsed:?}");
}

/// `--strict` refuses what the rule cannot keep, naming the rule and the parameter; a rule
/// not defined for the model is refused with the ones that are. Both before any step.
#[test]
fn strict_names_the_rule_and_the_parameter_it_cannot_keep() {
    let run = |rule: &str| {
        cgdem()
            .args([
                "run",
                "validation/cases/packing_vdw.toml",
                "--lambda",
                "4",
                "--cg-rule",
                rule,
                "--strict",
                "--quiet",
                "--out",
                std::env::temp_dir()
                    .join(format!("cgdem-strict-{}-{rule}", std::process::id()))
                    .to_str()
                    .unwrap(),
            ])
            .output()
            .unwrap()
    };
    let out = run("seed");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--strict: the relative-overlap rule")
            && stderr.contains("hamaker_constant")
            && stderr.contains("Bond number"),
        "{stderr}"
    );
    let out = run("scaled-particle");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && stderr.contains("the scaled-particle rule")
            && stderr.contains("gamma_n_yang"),
        "{stderr}"
    );
    let out = run("bulk-viscosity");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("\"hertz\"") && stderr.contains("liggghts-pfm"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));
}

/// `cgdem ... | head -1`: when the reader of stdout has gone, the command ends without a
/// panic's "Broken pipe" message (SIGPIPE at its default, as C tools). The pipe's read end is
/// closed before the command starts, so its first line of output meets a closed pipe.
#[test]
fn a_closed_stdout_ends_the_command_quietly_not_with_a_panic() {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = cgdem()
        .args([
            "advise",
            "packing_vdw",
            "--quantity",
            "porosity",
            "--target",
            "0.02",
            "--matrix",
            "reports/cg_fidelity",
            "--json",
        ])
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    use std::os::unix::process::ExitStatusExt;
    const SIGPIPE: i32 = 13; // Linux; the tests do not link libc
    assert_eq!(out.status.signal(), Some(SIGPIPE), "{:?}", out.status);
}

/// `cgdem advise --run`: the case's missing points are made into the matrix's runs (those
/// already there reused), its own report goes to MATRIX/advise/CASE/, the answer is read
/// from it; the suite's other case is not run and the matrix's own report is not touched.
#[test]
fn advise_run_makes_the_missing_points_of_one_case_and_answers_from_them() {
    let matrix = std::env::temp_dir().join(format!("cgdem-advise-run-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&matrix);
    std::fs::create_dir_all(&matrix).unwrap();
    // A matrix report of another suite, which --run must leave as it is.
    std::fs::write(matrix.join("index.html"), "the matrix's report").unwrap();
    // The question every call asks, of one case.
    let ask = |case: &str| {
        let mut c = cgdem();
        c.args([
            "advise",
            case,
            "--quantity",
            "repose_angle",
            "--target",
            "5",
        ]);
        c
    };
    let advise = |case: &str| {
        let out = ask(case)
            .args(["--run", "--suite", "tests/data/tiny_fidelity_suite.toml"])
            .args(["--threads", "1", "--matrix"])
            .arg(&matrix)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(!stderr.contains("panicked"), "{stderr}");
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        // Answered: exit 0 when a setting meets the target, 1 when the answer is "none".
        let none = stdout.contains(": none;");
        let answered = out.status.code() == Some(if none { 1 } else { 0 });
        (answered && !stdout.is_empty(), stdout, stderr)
    };
    let case = "tiny_hertz_collapse-fidelity";
    // The answer up to its savings: the wall time of a run made again differs.
    let answer = |text: &str| {
        text.split(" fewer particle-steps")
            .next()
            .unwrap()
            .to_string()
    };
    let (ok, first, stderr) = advise(case);
    assert!(ok, "{stderr}");
    assert!(
        first.starts_with(&format!("{case}: repose_angle within")),
        "{first}"
    );
    let runs = matrix.join("runs").join(case).join("accuracy");
    let made: Vec<String> = std::fs::read_dir(&runs)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    assert_eq!(made.len(), 4, "{made:?}");
    assert!(!matrix.join("runs/tiny_hertz_collapse-short").exists());
    assert_eq!(
        std::fs::read_to_string(matrix.join("index.html")).unwrap(),
        "the matrix's report"
    );
    assert!(!matrix.join("summary.json").exists());
    let report = matrix.join("advise").join(case);
    // The case's report says where its runs are.
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(
        html.contains(&format!("under {}", matrix.join("runs").display())),
        "{html}"
    );

    // One point lost: only it is made again, and the answer is the same.
    std::fs::remove_dir_all(runs.join("cgdem-lambda-2-seed2")).unwrap();
    let (ok, second, stderr) = advise(case);
    assert!(ok, "{stderr}");
    assert_eq!(answer(&first), answer(&second));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("summary.json")).unwrap())
            .unwrap();
    let made_again: Vec<&str> = summary["accuracy"]["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["reused"] == false)
        .map(|p| p["setting"].as_str().unwrap())
        .collect();
    assert_eq!(made_again, ["lambda = 2"], "{summary}");
    // Without --run the answer from the case's report is the same.
    let out = ask(case).arg("--matrix").arg(&report).output().unwrap();
    assert_eq!(String::from_utf8_lossy(&out.stdout), second);

    // A case the suite has no sweep of is an error naming the cases it has; a scene name
    // two of its variants share is one naming those variants; nothing runs.
    for (asked, says) in [
        (
            "no_such_case",
            "`no_such_case` is not one of its accuracy sweeps",
        ),
        (
            "tiny_hertz_collapse",
            "`tiny_hertz_collapse` names several cases",
        ),
    ] {
        let (ok, _, stderr) = advise(asked);
        assert!(
            !ok && stderr.contains(says)
                && stderr.contains("tiny_hertz_collapse-fidelity, tiny_hertz_collapse-short"),
            "{stderr}"
        );
    }
    assert!(!matrix.join("runs/tiny_hertz_collapse-short").exists());
    let _ = std::fs::remove_dir_all(&matrix);
}

/// An open surface (a plate of two triangles, as a CAD export of a sheet gives it) cannot be
/// an SDF grid: the run is refused naming the scene, the body and the STL file once, and
/// pointing to `contact = "mesh"`, under which the same file runs, as it does with neither
/// `contact` nor `cell_size` (a body given no grid spacing is met on its triangles).
#[test]
fn an_open_stl_is_refused_as_a_grid_and_met_on_its_triangles_as_a_mesh() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("open_stl_body");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("plate.stl"),
        "solid plate\n\
         facet normal 0 0 1\nouter loop\nvertex -0.05 -0.05 0\nvertex 0.05 -0.05 0\nvertex 0.05 0.05 0\nendloop\nendfacet\n\
         facet normal 0 0 1\nouter loop\nvertex -0.05 -0.05 0\nvertex 0.05 0.05 0\nvertex -0.05 0.05 0\nendloop\nendfacet\n\
         endsolid plate\n",
    )
    .unwrap();
    let scene = std::fs::read_to_string("tests/data/tiny_hertz_collapse.toml").unwrap();
    let run = |name: &str, body: &str| {
        let file = dir.join(format!("{name}.toml"));
        std::fs::write(
            &file,
            format!("{scene}\n[[body]]\nname = \"plate\"\nmesh = \"plate.stl\"\n{body}\n"),
        )
        .unwrap();
        cgdem()
            .arg("run")
            .arg(&file)
            .args([
                "--quiet",
                "--threads",
                "1",
                "--set",
                "stage[0].max_duration=0.001",
            ])
            .args(["--set", "stage[0].min_duration=0.001", "--out"])
            .arg(dir.join(name))
            .output()
            .unwrap()
    };
    let out = run("grid", "cell_size = 0.005");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("grid.toml")
            && stderr.contains("body[0]")
            && stderr.matches("plate.stl").count() == 1
            && stderr.contains("not closed")
            && stderr.contains("contact = \"mesh\""),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    // Named, or by default for a body given no grid spacing.
    for (name, body) in [("mesh", "contact = \"mesh\""), ("default", "")] {
        let out = run(name, body);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
