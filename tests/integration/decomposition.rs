//! Domain decomposition (`--grid`, issue 23): the same physics as the undecomposed run to
//! rounding, and bitwise the same run for any thread count.

use std::path::Path;

use cgdem_core::decomposition::{BalanceSpec, GridSpec};
use cgdem_core::math::Real;
use cgdem_core::particles::Particles;
use cgdem_core::run::{run, RunOptions, RunSummary};
use cgdem_core::scene::{Override, Scene};

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
    run_balanced(grid, BalanceSpec::Shift(1.0), threads, name)
}

fn run_balanced(
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
    pool.install(|| run(&scene(), &options)).expect("run")
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

#[test]
fn decomposed_runs_follow_the_undecomposed_trajectories_to_rounding() {
    let reference = run_with(None, 1, "none");
    let a = by_id(reference.final_state.as_ref().unwrap());
    let diameter = 1e-2;
    for (grid, name) in [
        (GridSpec::Given([2, 1, 1]), "2x1x1"),
        (GridSpec::Given([1, 2, 1]), "1x2x1"),
        (GridSpec::Given([2, 1, 2]), "2x1x2"),
    ] {
        let summary = run_with(Some(grid), 2, name);
        assert_eq!(summary.steps, reference.steps, "{name}");
        // These runs compare decompositions whose planes moved.
        let shifts = summary.decomposition.as_ref().unwrap().shifts;
        assert!(shifts > 0, "{name}: the planes never moved");
        assert_eq!(summary.lost_particles, reference.lost_particles, "{name}");
        let b = by_id(summary.final_state.as_ref().unwrap());
        assert_eq!(a.len(), b.len());
        let mut worst = [0.0 as Real; 3];
        for ((id_a, sa), (id_b, sb)) in a.iter().zip(&b) {
            assert_eq!(id_a, id_b);
            for c in 0..9 {
                worst[c / 3] = worst[c / 3].max((sa[c] - sb[c]).abs());
            }
        }
        // Rounding grows through the collisions: over this run a change of the Young's
        // modulus by one ulp moves positions by 4.7e-5 m (0.02 m/s, 3.4 rad/s), and a
        // decomposition that drops contact histories at a rebuild by 4e-2 m; the decomposed
        // runs stay within 1.1e-7 m, 3.2e-5 m/s and 7.5e-3 rad/s.
        assert!(
            worst[0] < 1e-4 * diameter && worst[1] < 1e-3 && worst[2] < 0.1,
            "{name}: largest differences {worst:?}"
        );
        let ke = |s: &RunSummary| s.final_state.as_ref().unwrap().kinetic_energy();
        let (e_a, e_b) = (ke(&reference), ke(&summary));
        assert!(
            (e_a - e_b).abs() <= 1e-4 * e_a,
            "{name}: kinetic energy {e_a} against {e_b}"
        );
    }
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
