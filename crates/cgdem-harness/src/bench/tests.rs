use std::path::Path;

use super::measurement::{medians, rank_ratios, ratios};
use super::runs::{check_ranks, ranks_command, run_order};
use super::suite::{with_duration, PreparedCase};
use super::*;
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
        threads,
        ranks,
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
    };
    let names = |w| -> Vec<(String, Code, Option<usize>)> {
        run_order(&cases, &options, w)
            .into_iter()
            .map(|(c, code, r)| (c.name.clone(), code, r))
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
            ("heap lammps".into(), 19.0 / 12.5),
        ]
    );
    assert_eq!(r[0].numerator, format!("{g} cgdem (2 ranks)"));
}
