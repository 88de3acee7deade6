//! Domain decomposition (`--grid`, issue 23): the same physics as the undecomposed run to
//! rounding, and bitwise the same run for any thread count.

use std::path::Path;

use cgdem_core::decomposition::{BalanceSpec, GridSpec};
use cgdem_core::math::Real;
use cgdem_core::particles::Particles;
use cgdem_core::run::{run, RunOptions, RunSummary};
use cgdem_core::scene::{ContactSettings, InsertAmount, Override, Scene};

/// The tiny Hertz collapse (Hertz-Mindlin, rolling friction, walls with history, a gate
/// removed, periodic y), shortened to 0.25 s (2384 steps).
fn scene() -> Scene {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tiny_hertz_collapse.toml");
    let overrides: Vec<Override> = [
        "stage[0].min_duration=0.15",
        "stage[0].max_duration=0.15",
        "stage[1].duration=0.1",
        "repose.at_times=[0.05]",
    ]
    .iter()
    .map(|o| Override::parse(o, Path::new("test")).unwrap())
    .collect();
    Scene::load_with_overrides(&file, &overrides).expect("scene")
}

/// Balanced at any imbalance (`--balance 1.0`): with 40 beads the planes move at most
/// rebuilds, so the histories travel to new owners as often as they can.
fn run_with(grid: Option<GridSpec>, threads: usize, name: &str) -> RunSummary {
    run_scene(&scene(), grid, BalanceSpec::Shift(1.0), threads, name)
}

fn run_balanced(
    grid: Option<GridSpec>,
    balance: BalanceSpec,
    threads: usize,
    name: &str,
) -> RunSummary {
    run_scene(&scene(), grid, balance, threads, name)
}

fn run_scene(
    scene: &Scene,
    grid: Option<GridSpec>,
    balance: BalanceSpec,
    threads: usize,
    name: &str,
) -> RunSummary {
    let out_dir = std::env::temp_dir().join(format!("cgdem-decomposition-{name}"));
    let options = RunOptions {
        out_dir,
        keep_final_state: true,
        grid,
        balance,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| run(scene, &options)).expect("run")
}

/// Particles by id: position, velocity, spin.
fn by_id(p: &Particles) -> Vec<(u32, [Real; 9])> {
    let mut v: Vec<(u32, [Real; 9])> = (0..p.len())
        .map(|k| {
            let (x, u) = (p.position[k], p.velocity[k]);
            let w = p.angular.as_ref().unwrap().omega[k];
            (p.id[k], [x.x, x.y, x.z, u.x, u.y, u.z, w.x, w.y, w.z])
        })
        .collect();
    v.sort_by_key(|e| e.0);
    v
}

/// The largest differences in position, velocity and spin between two final states of the
/// same particles.
fn largest_differences(a: &RunSummary, b: &RunSummary, name: &str) -> [Real; 3] {
    let (a, b) = (
        by_id(a.final_state.as_ref().unwrap()),
        by_id(b.final_state.as_ref().unwrap()),
    );
    assert_eq!(a.len(), b.len(), "{name}");
    let mut worst = [0.0 as Real; 3];
    for ((id_a, sa), (id_b, sb)) in a.iter().zip(&b) {
        assert_eq!(id_a, id_b, "{name}");
        for c in 0..9 {
            worst[c / 3] = worst[c / 3].max((sa[c] - sb[c]).abs());
        }
    }
    worst
}

/// A decomposed run against the undecomposed one: the same steps and removals, and the
/// trajectories within the bounds below.
fn assert_follows(reference: &RunSummary, summary: &RunSummary, name: &str) {
    let diameter = 1e-2;
    assert_eq!(summary.steps, reference.steps, "{name}");
    assert_eq!(summary.lost_particles, reference.lost_particles, "{name}");
    assert_eq!(
        summary.deleted_particles, reference.deleted_particles,
        "{name}"
    );
    let worst = largest_differences(reference, summary, name);
    // Rounding grows through the collisions: over this run a change of the Young's
    // modulus by one ulp moves positions by 4.7e-5 m (0.02 m/s, 3.4 rad/s), and a
    // decomposition that drops contact histories at a rebuild by 4e-2 m; the decomposed
    // runs stay within 1.1e-7 m, 3.2e-5 m/s and 7.5e-3 rad/s.
    assert!(
        worst[0] < 1e-4 * diameter && worst[1] < 1e-3 && worst[2] < 0.1,
        "{name}: largest differences {worst:?}"
    );
    let ke = |s: &RunSummary| s.final_state.as_ref().unwrap().kinetic_energy();
    let (e_a, e_b) = (ke(reference), ke(summary));
    assert!(
        (e_a - e_b).abs() <= 1e-4 * e_a,
        "{name}: kinetic energy {e_a} against {e_b}"
    );
}

#[test]
fn decomposed_runs_follow_the_undecomposed_trajectories_to_rounding() {
    let reference = run_with(None, 1, "none");
    for (grid, name) in [
        (GridSpec::Given([2, 1, 1]), "2x1x1"),
        (GridSpec::Given([1, 2, 1]), "1x2x1"),
        (GridSpec::Given([2, 1, 2]), "2x1x2"),
    ] {
        let summary = run_with(Some(grid), 2, name);
        // These runs compare decompositions whose planes moved.
        let shifts = summary.decomposition.as_ref().unwrap().shifts;
        assert!(shifts > 0, "{name}: the planes never moved");
        assert_follows(&reference, &summary, name);
    }
}

/// The tiny collapse with an outlet in the floor under the column, across the cut plane of
/// a 2x1x1 grid (the column spans x 0 to 0.04, cut near its middle): grains whose centre
/// reaches it are deleted as they come to the floor, in both subdomains, in both stages.
fn scene_with_outlet() -> Scene {
    let mut scene = scene();
    scene.deletions.push((
        cgdem_core::math::Vec3::new(0.012, -1.0, -1.0),
        cgdem_core::math::Vec3::new(0.03, 1.0, 0.0065),
    ));
    scene
}

#[test]
fn a_decomposed_run_deletes_the_grains_the_undecomposed_run_deletes() {
    let scene = scene_with_outlet();
    let reference = run_scene(&scene, None, BalanceSpec::Shift(1.0), 1, "outlet-none");
    // Enough deleted to mean something, and not the whole column.
    assert!(
        (5..30).contains(&reference.deleted_particles),
        "{} deleted",
        reference.deleted_particles
    );
    let grid = Some(GridSpec::Given([2, 1, 1]));
    let two = run_scene(&scene, grid, BalanceSpec::Shift(1.0), 2, "outlet-2x1x1");
    assert_follows(&reference, &two, "outlet 2x1x1");
    assert_eq!(two.deleted_mass_kg, reference.deleted_mass_kg);
    let one = run_scene(&scene, grid, BalanceSpec::Shift(1.0), 1, "outlet-2x1x1-t1");
    assert_eq!(
        by_id(one.final_state.as_ref().unwrap()),
        by_id(two.final_state.as_ref().unwrap())
    );
    assert_eq!(one.deleted_mass_kg.to_bits(), two.deleted_mass_kg.to_bits());
}

#[test]
fn a_decomposed_run_is_bitwise_the_same_on_one_and_two_threads() {
    let grid = Some(GridSpec::Given([2, 1, 1]));
    let one = run_with(grid, 1, "t1");
    let two = run_with(grid, 2, "t2");
    assert_eq!(
        by_id(one.final_state.as_ref().unwrap()),
        by_id(two.final_state.as_ref().unwrap())
    );
}

/// A thin periodic slab (a quasi-2D collapse): the periodic y axis, 0.023 m, is shorter than
/// two ghost layers (0.025 m) but longer than two contact distances (0.02 m). Subdomains then
/// list a partner through both images; the run still follows the undecomposed one.
#[test]
fn a_periodic_axis_shorter_than_two_ghost_layers_follows_the_undecomposed_run() {
    let mut slab = scene();
    slab.domain.hi.y = 0.023;
    slab.insertions[0].hi.y = 0.023;
    let run = |grid, name| run_scene(&slab, grid, BalanceSpec::Shift(1.0), 2, name);
    let reference = run(None, "slab-none");
    let split = run(Some(GridSpec::Given([2, 1, 1])), "slab-2x1x1");
    // Rounding grows faster in the slab, whose beads touch their own images' neighbours: the
    // bound is what one ulp of Young's modulus does to the undecomposed run.
    let mut nudged = slab.clone();
    if let ContactSettings::Hertz(h) = &mut nudged.contact {
        h.youngs_modulus = h.youngs_modulus.next_up();
    }
    let ulp = run_scene(&nudged, None, BalanceSpec::Shift(1.0), 1, "slab-ulp");
    let by_ulp = largest_differences(&reference, &ulp, "slab ulp");
    let by_split = largest_differences(&reference, &split, "slab 2x1x1");
    eprintln!("slab: one ulp {by_ulp:?}, 2x1x1 {by_split:?}");
    assert!(
        (0..3).all(|c| by_split[c] <= 10.0 * by_ulp[c]),
        "slab 2x1x1 {by_split:?} against one ulp {by_ulp:?}"
    );
    // Shorter than two contact distances: refused, as the undecomposed world refuses it.
    let mut thinner = scene();
    thinner.domain.hi.y = 0.0199;
    thinner.insertions[0].hi.y = 0.0199;
    thinner.insertions[0].amount = InsertAmount::Count(30);
    let options = RunOptions {
        out_dir: std::env::temp_dir().join("cgdem-decomposition-thinner"),
        grid: Some(GridSpec::Given([2, 1, 1])),
        ..Default::default()
    };
    let e = run_scene_err(&thinner, &options);
    assert!(
        e.contains("periodic y") && e.contains("twice the contact distance"),
        "{e}"
    );
}

fn run_scene_err(scene: &Scene, options: &RunOptions) -> String {
    run(scene, options).unwrap_err().to_string()
}

#[test]
fn a_grid_the_step_cannot_take_is_refused_with_the_reason() {
    // Ten subdomains along the 0.04 m periodic y: each thinner than the ghost layer.
    let options = RunOptions {
        out_dir: std::env::temp_dir().join("cgdem-decomposition-thin"),
        grid: Some(GridSpec::Given([1, 10, 1])),
        ..Default::default()
    };
    let e = run(&scene(), &options).unwrap_err().to_string();
    assert!(
        e.contains("--grid 1x10x1") && e.contains("thinner than the ghost layer"),
        "{e}"
    );
}

#[test]
fn balancing_moves_the_planes_after_the_collapse_and_the_static_split_stays_behind() {
    let grid = Some(GridSpec::Given([2, 1, 1]));
    // The collapse carries beads across the start's plane: 22 of the 40 on one side.
    let on = run_balanced(grid, BalanceSpec::Shift(1.05), 2, "balance-on");
    let off = run_balanced(grid, BalanceSpec::Off, 2, "balance-off");
    let (on, off) = (on.decomposition.unwrap(), off.decomposition.unwrap());
    assert_eq!(on.balance_threshold, Some(1.05));
    assert!(on.shifts > 0);
    // After a rebuild the subdomains are within the threshold: either the planes held it
    // or they moved.
    let worst = on.imbalance_max_after_first_shift.unwrap();
    assert!(worst <= 1.05 && on.imbalance <= 1.05, "{on:?}");
    // The start's planes would not have held it.
    assert!(on.static_imbalance_max > 1.05, "{on:?}");
    assert_eq!((off.balance_threshold, off.shifts), (None, 0));
    assert_eq!(off.imbalance_max_after_first_shift, None);
    assert!(off.static_imbalance_max > 1.05, "{off:?}");
}

#[test]
fn a_decomposed_pcvv_run_follows_the_undecomposed_one() {
    let mut scene = scene();
    scene.integrator = cgdem_core::integrate::Integrator::Pcvv;
    let reference = run_scene(&scene, None, BalanceSpec::Shift(1.0), 1, "pcvv-none");
    let grid = Some(GridSpec::Given([2, 1, 1]));
    let two = run_scene(&scene, grid, BalanceSpec::Shift(1.0), 2, "pcvv-2x1x1");
    assert_follows(&reference, &two, "pcvv 2x1x1");
    let one = run_scene(&scene, grid, BalanceSpec::Shift(1.0), 1, "pcvv-2x1x1-t1");
    assert_eq!(
        by_id(one.final_state.as_ref().unwrap()),
        by_id(two.final_state.as_ref().unwrap())
    );
}

/// The Hertz screw feeder (SDF casing and hopper; the screw an SDF body or built of
/// particles, turning at 300 rpm from the start of the second stage) cut to 300 grains and
/// 0.08 s, with coarser SDF cells: grains pre-filled around the screw meet it, the casing
/// and each other at once; the hopper is topped up twice while the screw turns.
fn short_screw(file: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let mut set = vec![
        "insert[0].count=150",
        "insert[1].count=150",
        "stage[0].duration=0.03",
        "stage[1].duration=0.05",
        "body[0].rpm=-300.0",
        "body[1].cell_size=0.01",
        "body[2].cell_size=0.01",
        "insert[0].refill.interval=0.02",
        "conveying.discard=0.01",
        "conveying.blocks=2",
        "output.vtk_interval=0.0",
    ];
    if !file.contains("particles") {
        set.push("body[0].cell_size=0.008");
    }
    let overrides: Vec<Override> = set
        .iter()
        .map(|o| Override::parse(o, Path::new("test")).unwrap())
        .collect();
    Scene::load_with_overrides(&path, &overrides).expect("scene")
}

/// Runs `scene` (guards only warn: grains wedged between flight and casing may pass the
/// overlap guard's threshold, as the case's header says); also returns the screw's axial
/// torque at each time-series row.
fn run_screw(
    scene: &Scene,
    grid: Option<GridSpec>,
    threads: usize,
    name: &str,
) -> (RunSummary, Vec<Real>) {
    let out_dir = std::env::temp_dir().join(format!("cgdem-decomposition-{name}"));
    let options = RunOptions {
        out_dir: out_dir.clone(),
        keep_final_state: true,
        keep_going: true,
        grid,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let summary = pool.install(|| run(scene, &options)).expect("run");
    let text = std::fs::read_to_string(out_dir.join("timeseries.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = header
        .iter()
        .position(|&h| h == "axial_torque_screw_nm")
        .expect("screw torque column");
    let torque = lines
        .map(|l| l.split(',').nth(column).unwrap().parse().unwrap())
        .collect();
    (summary, torque)
}

/// The screw's torque of a decomposed run against the undecomposed one, row by row; the
/// largest difference over the largest torque.
fn torque_difference(a: &[Real], b: &[Real]) -> Real {
    assert_eq!(a.len(), b.len());
    let largest = a.iter().fold(0.0 as Real, |m, t| m.max(t.abs()));
    assert!(largest > 0.0, "the grains load the screw");
    let worst = a
        .iter()
        .zip(b)
        .fold(0.0 as Real, |m, (x, y)| m.max((x - y).abs()));
    worst / largest
}

#[test]
fn decomposed_screw_feeders_follow_the_undecomposed_runs() {
    for file in [
        "validation/cases/screw_feeder_hertz.toml",
        "validation/cases/screw_feeder_hertz_particles.toml",
    ] {
        let scene = short_screw(file);
        let name = if file.contains("particles") {
            "particle-screw"
        } else {
            "sdf-screw"
        };
        let (reference, torque_a) = run_screw(&scene, None, 1, &format!("{name}-none"));
        let grid = Some(GridSpec::Given([2, 1, 1]));
        let (two, torque_b) = run_screw(&scene, grid, 2, &format!("{name}-2x1x1"));
        assert_follows(&reference, &two, name);
        let relative = torque_difference(&torque_a, &torque_b);
        eprintln!("{name}: screw torque within {relative:.2e} of its largest value");
        assert!(
            relative < 1e-3,
            "{name}: screw torque differs by {relative:.2e}"
        );
        // Bitwise the same on one thread: the body sums go over the subdomains in order.
        let (one, torque_c) = run_screw(&scene, grid, 1, &format!("{name}-2x1x1-t1"));
        assert_eq!(
            by_id(one.final_state.as_ref().unwrap()),
            by_id(two.final_state.as_ref().unwrap()),
            "{name}"
        );
        let bits = |t: &[Real]| t.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&torque_b), bits(&torque_c), "{name}");
    }
}
