//! Golden collisions of the seed model, cgdem against LAMMPS at the same time step.
//!
//! Each case is a tiny scene (two particles, or one particle and the floor) run through the
//! library (`World` with the scene's laws) and through the LAMMPS deck the harness writes for
//! the same scene and particles. Restitution, tangential velocity retained and contact time
//! are measured the same way from both trajectories (every step dumped): contact is
//! `r < r_c` for a pair (`h < r_c / 2` for the wall), its start and end interpolated
//! linearly between steps; `dt` is 1/200 of the linearized contact period. Both must agree
//! within 0.5%. LAMMPS's numbers are stored in `reference/golden/seed_collisions.csv`: cgdem
//! is compared with them always; an installed `lmp` is run too and must reproduce them
//! (`CGDEM_BLESS=1` rewrites them).

use std::path::{Path, PathBuf};

use cgdem_core::math::{Real, Vec3, TWO_POW_ONE_SIXTH};
use cgdem_core::particles::Particles;
use cgdem_core::run;
use cgdem_core::scene::{ContactSettings, Scene, StageEnd};
use cgdem_core::simulation::{Decompose, NeighborSettings, World, WorldSetup};
use cgdem_harness::decks::{self, lammps, RunStatus, RunnerOptions};

#[path = "support/golden.rs"]
mod golden;

const GOLDEN_FILE: &str = "seed_collisions.csv";

const SIGMA: Real = 1.203e-3;
const TOLERANCE: Real = 0.005;

/// Coke pair (paper A) in a closed box without gravity; `walls` adds [[wall]] tables.
/// Wall friction is 0: LAMMPS caps wall friction with the wall dashpot only, cgdem with WCA +
/// dashpot (SEED_MODEL.md claim 11), so only the frictionless wall law is comparable.
fn scene(lo: [Real; 3], walls: &str) -> Scene {
    let text = format!(
        r#"
name = "golden"
gravity = [0.0, 0.0, 0.0]
[domain]
lo = [{}, {}, {}]
hi = [0.01, 0.01, 0.01]
periodic = [false, false, false]
[[species]]
name = "coke"
diameter = 1.350e-3
density = 1370.0
[contact]
model = "wca"
epsilon = 9.434e-2
sigma = {SIGMA}
gamma_n = 0.1257
gamma_t = 0.1257
[wall_contact]
restitution = 0.5
friction = 0.0
[time]
dt_fraction = 0.005
[neighbor]
skin_fraction = 0.3
resort_every = 0
[[stage]]
name = "collide"
duration = 1.0
[output]
timeseries_interval = 1.0
{walls}
"#,
        lo[0], lo[1], lo[2]
    );
    Scene::parse(&text, Path::new("golden.toml")).expect("golden scene")
}

/// Positions and velocities per step, per particle (by id).
type Trajectory = Vec<Vec<(Vec3, Vec3)>>;

fn particles(scene: &Scene, states: &[(Vec3, Vec3)]) -> Particles {
    let s = &scene.species[0];
    let mut p = Particles::new(false);
    for (k, &(x, v)) in states.iter().enumerate() {
        p.push(0, x, s.radius(), s.mass());
        p.velocity[k] = v;
    }
    p
}

fn run_cgdem(scene: &Scene, initial: &Particles, dt: Real, steps: u64) -> Trajectory {
    let ContactSettings::Wca(wca) = &scene.contact else {
        panic!("the seed golden cases use the WCA model")
    };
    let (law, wall_law) = run::seed_laws(scene, wca);
    let neighbor = NeighborSettings {
        skin: scene.skin_fraction * scene.max_diameter(),
        resort_every: 0,
    };
    let mut setup = WorldSetup::new(
        initial.clone(),
        scene.domain.clone(),
        law,
        wall_law,
        1,
        scene.gravity,
        dt,
        neighbor,
    );
    setup.walls = run::scene_walls(scene);
    let mut world = World::new(setup, &Decompose::default()).expect("the case fits its box");
    let record = |world: &mut World<_, _>| {
        let p = world.synced_particles();
        let mut state = vec![(Vec3::ZERO, Vec3::ZERO); p.len()];
        for k in 0..p.len() {
            state[p.id[k] as usize] = (p.position[k], p.velocity[k]);
        }
        state
    };
    let mut trajectory = vec![record(&mut world)];
    for _ in 0..steps {
        world.step();
        trajectory.push(record(&mut world));
    }
    trajectory
}

/// None when `lmp` is absent (the stored numbers then stand in, with a message).
fn run_lammps(
    name: &str,
    scene: &Scene,
    initial: &Particles,
    dt: Real,
    steps: u64,
) -> Option<Trajectory> {
    if let Err(reason) = lammps::find_lmp() {
        println!(
            "lmp not run ({reason}): its stored numbers are used; install with `{}`",
            decks::INSTALL_HINT
        );
        return None;
    }
    let mut scene = scene.clone();
    scene.stages[0].end = StageEnd::Duration(steps as Real * dt);
    scene.output.timeseries_interval = dt;
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("lammps_golden")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let deck =
        lammps::write_deck(&scene, initial, dt, lammps::WallModulus::installed()).expect("deck");
    assert_eq!(deck.plan.dump_every, 1);
    deck.write_to(&dir).expect("write deck");
    let status = lammps::run_deck(&dir, &RunnerOptions::default());
    assert!(
        matches!(status, RunStatus::Completed { .. }),
        "{name}: {status:?}"
    );
    let frames = decks::read_dump(&dir.join(decks::TRAJECTORY_FILE)).expect("dump");
    assert_eq!(frames.len() as u64, steps + 1, "{name}: one frame per step");
    Some(
        frames
            .iter()
            .map(|f| {
                let col = |c: &str| f.column(c).unwrap();
                let (id, x, y, z, vx, vy, vz) = (
                    col("id"),
                    col("x"),
                    col("y"),
                    col("z"),
                    col("vx"),
                    col("vy"),
                    col("vz"),
                );
                let mut state = vec![(Vec3::ZERO, Vec3::ZERO); f.len()];
                for k in 0..f.len() {
                    state[id[k] as usize - 1] =
                        (Vec3::new(x[k], y[k], z[k]), Vec3::new(vx[k], vy[k], vz[k]));
                }
                state
            })
            .collect(),
    )
}

/// Contact time from a distance series: first and last crossing of `reach`, interpolated.
fn contact_time(distance: &[Real], reach: Real, dt: Real) -> Real {
    let start = distance
        .iter()
        .position(|&d| d < reach)
        .expect("no contact");
    let end = start
        + distance[start..]
            .iter()
            .position(|&d| d >= reach)
            .expect("contact never ends");
    let t_in = (start as Real - 1.0
        + (distance[start - 1] - reach) / (distance[start - 1] - distance[start]))
        * dt;
    let t_out = (end as Real - 1.0
        + (reach - distance[end - 1]) / (distance[end] - distance[end - 1]))
        * dt;
    t_out - t_in
}

#[derive(Debug)]
struct Collision {
    restitution: Real,
    tangential_retained: Option<Real>,
    contact_time: Real,
}

fn pair_collision(t: &Trajectory, dt: Real) -> Collision {
    let distance: Vec<Real> = t.iter().map(|s| (s[0].0 - s[1].0).length()).collect();
    let closest = (0..distance.len())
        .min_by(|&a, &b| distance[a].total_cmp(&distance[b]))
        .unwrap();
    let n = (t[closest][0].0 - t[closest][1].0).normalize();
    let (v_in, v_out) = (
        t[0][0].1 - t[0][1].1,
        t[t.len() - 1][0].1 - t[t.len() - 1][1].1,
    );
    let tangential = |v: Vec3| v - v.dot(n) * n;
    let t_in = tangential(v_in).length();
    Collision {
        restitution: -v_out.dot(n) / v_in.dot(n),
        tangential_retained: (t_in > 1e-3 * v_in.length())
            .then(|| tangential(v_out).length() / t_in),
        contact_time: contact_time(&distance, TWO_POW_ONE_SIXTH * SIGMA, dt),
    }
}

fn wall_collision(t: &Trajectory, dt: Real) -> Collision {
    let height: Vec<Real> = t.iter().map(|s| s[0].0.z).collect();
    let (v_in, v_out) = (t[0][0].1, t[t.len() - 1][0].1);
    Collision {
        restitution: -v_out.z / v_in.z,
        tangential_retained: Some(v_out.x / v_in.x),
        contact_time: contact_time(&height, 0.5 * TWO_POW_ONE_SIXTH * SIGMA, dt),
    }
}

/// The stored LAMMPS collision of case `name` (checked first against the live one, if any).
fn stored_lammps(name: &str, live: Option<Collision>) -> Collision {
    let mut stored = golden::GoldenFile::load(GOLDEN_FILE);
    if let Some(live) = &live {
        stored.live(name, "restitution", "lammps", live.restitution);
        stored.live(name, "contact time (s)", "lammps", live.contact_time);
        if let Some(t) = live.tangential_retained {
            stored.live(name, "tangential retained", "lammps", t);
        }
    }
    stored.finish();
    let with_tangential = stored.has(name, "tangential retained", "lammps");
    Collision {
        restitution: stored.get(name, "restitution", "lammps"),
        tangential_retained: with_tangential
            .then(|| stored.get(name, "tangential retained", "lammps")),
        contact_time: stored.get(name, "contact time (s)", "lammps"),
    }
}

fn compare(name: &str, cgdem: &Collision, lammps: &Collision) {
    let mut rows = vec![
        ("restitution", cgdem.restitution, lammps.restitution),
        ("contact time (s)", cgdem.contact_time, lammps.contact_time),
    ];
    match (cgdem.tangential_retained, lammps.tangential_retained) {
        (Some(a), Some(b)) => rows.push(("tangential retained", a, b)),
        (None, None) => {}
        (a, b) => panic!(
            "{name}: tangential retained measured by one code only: cgdem {a:?}, LAMMPS {b:?}"
        ),
    }
    for (quantity, a, b) in rows {
        let rel = (a - b).abs() / b.abs();
        println!("GOLDEN | {name} | {quantity} | {a:.9e} | {b:.9e} | {rel:.2e}");
        assert!(
            rel < TOLERANCE,
            "{name}: {quantity}: cgdem {a} vs LAMMPS {b} (rel. diff {rel:.3e})"
        );
    }
}

fn binary(name: &str, b: Real) {
    let scene = scene([-0.01, -0.01, -0.01], "");
    let (dt, _, _) = run::time_step(&scene, false).unwrap();
    let rc = TWO_POW_ONE_SIXTH * SIGMA;
    let gap = 1e-6;
    let second = Vec3::new((rc + gap) * (1.0 - b * b).sqrt(), (rc + gap) * b, 0.0);
    let initial = particles(
        &scene,
        &[
            (Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0)),
            (second, Vec3::new(-0.5, 0.0, 0.0)),
        ],
    );
    let steps = 400;
    let cg = pair_collision(&run_cgdem(&scene, &initial, dt, steps), dt);
    let live = run_lammps(name, &scene, &initial, dt, steps).map(|t| pair_collision(&t, dt));
    compare(name, &cg, &stored_lammps(name, live));
}

#[test]
fn head_on_binary_collision_matches_lammps() {
    binary("head-on", 0.0);
}

#[test]
fn oblique_binary_collision_matches_lammps() {
    binary("oblique b=0.5", 0.5);
}

#[test]
fn frictionless_wall_collision_matches_lammps() {
    let walls = "[[wall]]\nname = \"floor\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n";
    let scene = scene([-0.01, -0.01, 0.0], walls);
    let (dt, _, _) = run::time_step(&scene, false).unwrap();
    let z0 = 0.5 * TWO_POW_ONE_SIXTH * SIGMA + 1e-6;
    let initial = particles(
        &scene,
        &[(Vec3::new(0.0, 0.0, z0), Vec3::new(0.5, 0.0, -1.0))],
    );
    let steps = 300;
    let cg = wall_collision(&run_cgdem(&scene, &initial, dt, steps), dt);
    let live = run_lammps("wall", &scene, &initial, dt, steps).map(|t| wall_collision(&t, dt));
    compare(
        "wall (mu_w = 0)",
        &cg,
        &stored_lammps("wall (mu_w = 0)", live),
    );
}
