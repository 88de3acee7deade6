//! Golden collisions of the Hertz-Mindlin law with epsd2 rolling friction: cgdem against
//! LIGGGHTS 3.8 (`model hertz tangential history rolling_friction epsd2`) and LAMMPS
//! (`granular hertz/material ... damping tsuji tangential mindlin ... rolling sds`), at the
//! same time step, every step dumped.
//!
//! One scene (TOML, below) defines each case; the decks for both codes are written from it by
//! the harness (`harness::liggghts::write_deck`, `harness::lammps::write_hertz_deck`), so no
//! parameter is kept twice. Measured the same way from each trajectory: effective restitution
//! (normal relative velocity out / in, the normal at closest approach), rebound velocity
//! (normal and tangential parts of particle 1's centre velocity), rebound spin, and contact
//! duration (`distance < r_i + r_j`, resp. `h < r`, start and end interpolated between steps).
//! LIGGGHTS is the reference (cgdem's keywords promise its model); a code "agrees" when every
//! quantity is within 1% of LIGGGHTS's. The quantities that cannot agree, and why, are listed
//! per case (`known`) and explained in `reference/MAPPING.md`; they are printed, not asserted.
//! The reference numbers are stored in `reference/golden/hertz_collisions.csv`: cgdem is
//! compared with them always; an installed LIGGGHTS or LAMMPS is run too and must reproduce
//! its stored numbers (`CGDEM_BLESS=1` rewrites them).

use std::path::{Path, PathBuf};

use cgdem_core::contact::cohesion::NoCohesion;
use cgdem_core::contact::damping::HertzDamping;
use cgdem_core::contact::rolling::Epsd2;
use cgdem_core::contact::tangential::Mindlin;
use cgdem_core::math::{Real, Vec3};
use cgdem_core::particles::Particles;
use cgdem_core::run::{hertz_history_wall, hertz_law};
use cgdem_core::scene::{ContactSettings, Scene};
use cgdem_core::simulation::{Decompose, NeighborSettings, World, WorldSetup};
use cgdem_harness::code::Code;
use cgdem_harness::decks::{self, lammps, liggghts, Deck, RunStatus, RunnerOptions};

#[path = "support/bead_scene.rs"]
mod bead_scene;
#[path = "support/golden.rs"]
mod golden;

use bead_scene::{every_step, BEAD_CONTACT, BEAD_WALL_CONTACT};

const GOLDEN_FILE: &str = "hertz_collisions.csv";

const TOLERANCE: Real = 0.01;
const DT: Real = 1e-7;
const STEPS: u64 = 4000;
const DIAMETER: Real = 2e-3;

/// Glass-like beads, d = 2 mm, E = 5e6 Pa (the smallest LIGGGHTS takes), e = 0.5, mu = 0.5,
/// mu_r = 0.1, no gravity; `walls` adds [[wall]] tables.
fn scene(lo_z: Real, walls: &str) -> Scene {
    let text = format!(
        r#"
name = "hertz_golden"
gravity = [0.0, 0.0, 0.0]
[domain]
lo = [-0.01, -0.01, {lo_z}]
hi = [0.01, 0.01, 0.01]
periodic = [false, false, false]
[[species]]
name = "bead"
diameter = {DIAMETER}
density = 2500.0
{BEAD_CONTACT}{BEAD_WALL_CONTACT}{run}{walls}
"#,
        run = every_step(STEPS as Real * DT, DT)
    );
    Scene::parse(&text, Path::new("hertz_golden.toml")).expect("golden scene")
}

/// Position, velocity, spin per step, per particle (by id).
type Trajectory = Vec<Vec<[Vec3; 3]>>;

fn particles(scene: &Scene, states: &[[Vec3; 3]]) -> Particles {
    particles_of(scene, &vec![0; states.len()], states)
}

/// Particle k of species `species[k]`.
fn particles_of(scene: &Scene, species: &[usize], states: &[[Vec3; 3]]) -> Particles {
    let mut p = Particles::new(true);
    for (k, &[x, v, w]) in states.iter().enumerate() {
        let s = &scene.species[species[k]];
        p.push(species[k] as u16, x, s.radius(), s.mass());
        p.velocity[k] = v;
        p.angular.as_mut().unwrap().omega[k] = w;
    }
    p
}

fn run_cgdem(scene: &Scene, initial: &Particles) -> Trajectory {
    let ContactSettings::Hertz(h) = &scene.contact else {
        unreachable!()
    };
    let law = hertz_law::<HertzDamping, Mindlin, Epsd2, NoCohesion>(scene, h);
    let neighbor = NeighborSettings {
        skin: scene.skin_fraction * scene.max_diameter(),
        resort_every: 0,
    };
    let mut setup = WorldSetup::new(
        initial.clone(),
        scene.domain.clone(),
        law,
        hertz_history_wall(scene, h),
        scene.species.len(),
        scene.gravity,
        DT,
        neighbor,
    );
    setup.walls = cgdem_core::run::scene_walls(scene);
    let mut world = World::new(setup, &Decompose::default()).expect("the case fits its box");
    let record = |world: &mut World<_, _>| {
        let p = world.synced_particles();
        let omega = &p.angular.as_ref().unwrap().omega;
        let mut state = vec![[Vec3::ZERO; 3]; p.len()];
        for k in 0..p.len() {
            state[p.id[k] as usize] = [p.position[k], p.velocity[k], omega[k]];
        }
        state
    };
    let mut trajectory = vec![record(&mut world)];
    for _ in 0..STEPS {
        world.step();
        trajectory.push(record(&mut world));
    }
    trajectory
}

/// None when the code's binary is absent (its stored numbers stand in, with a message).
fn run_reference(code: Code, case: &str, scene: &Scene, initial: &Particles) -> Option<Trajectory> {
    let found = match code {
        Code::Liggghts => liggghts::find_liggghts(),
        Code::Lammps => lammps::find_lmp(),
        Code::Cgdem => unreachable!("cgdem runs in-process"),
    };
    if let Err(reason) = found {
        println!(
            "{code:?} not run ({reason}): its stored numbers are used; install with `{}`",
            decks::INSTALL_HINT
        );
        return None;
    }
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("hertz_golden")
        .join(case)
        .join(format!("{code:?}").to_lowercase());
    let _ = std::fs::remove_dir_all(&dir);
    // Both deck writers take the scene's material tables (reference/MAPPING.md).
    let deck: Deck = match code {
        Code::Liggghts => liggghts::write_deck(scene, initial, DT),
        _ => lammps::write_hertz_deck_for(scene, initial, DT, lammps::WallModulus::installed()),
    }
    .expect("deck");
    assert_eq!(deck.plan.dump_every, 1);
    deck.write_to(&dir).expect("write deck");
    let options = RunnerOptions {
        np: None,
        stop: None,
        timeout: std::time::Duration::from_secs(120),
    };
    let status = match code {
        Code::Liggghts => liggghts::run_deck(&dir, &options),
        _ => lammps::run_deck(&dir, &options),
    };
    assert!(
        matches!(status, RunStatus::Completed { .. }),
        "{case} {code:?}: {status:?}"
    );
    let frames = decks::read_dump(&dir.join("traj.dump")).expect("dump");
    assert_eq!(frames.len() as u64, STEPS + 1, "{case}: one frame per step");
    Some(
        frames
            .iter()
            .map(|f| {
                let col = |c: &str| f.column(c).unwrap();
                let v3 = |a: &str, b: &str, c: &str, k: usize| {
                    Vec3::new(col(a)[k], col(b)[k], col(c)[k])
                };
                let id = col("id");
                let mut state = vec![[Vec3::ZERO; 3]; f.len()];
                for k in 0..f.len() {
                    state[id[k] as usize - 1] = [
                        v3("x", "y", "z", k),
                        v3("vx", "vy", "vz", k),
                        v3("omegax", "omegay", "omegaz", k),
                    ];
                }
                state
            })
            .collect(),
    )
}

/// Contact time from a distance series: first and last crossing of `reach`, interpolated.
fn contact_time(distance: &[Real], reach: Real) -> Real {
    let start = distance
        .iter()
        .position(|&d| d < reach)
        .expect("no contact");
    let end = start
        + distance[start..]
            .iter()
            .position(|&d| d >= reach)
            .expect("contact never ends");
    let t_in = start as Real - 1.0
        + (distance[start - 1] - reach) / (distance[start - 1] - distance[start]);
    let t_out =
        end as Real - 1.0 + (reach - distance[end - 1]) / (distance[end] - distance[end - 1]);
    (t_out - t_in) * DT
}

/// (quantity, value) rows of one trajectory.
type Measures = Vec<(&'static str, Real)>;

/// Pair: normal at closest approach, tangent = the in-plane direction of particle 1's
/// incoming tangential velocity (x-y plane), spins about z.
fn pair_measures(t: &Trajectory) -> Measures {
    pair_measures_touching_at(t, DIAMETER)
}

/// `pair_measures` for a pair touching at centre distance `reach`.
fn pair_measures_touching_at(t: &Trajectory, reach: Real) -> Measures {
    let distance: Vec<Real> = t.iter().map(|s| (s[1][0] - s[0][0]).length()).collect();
    let closest = (0..distance.len())
        .min_by(|&a, &b| distance[a].total_cmp(&distance[b]))
        .unwrap();
    let n = (t[closest][1][0] - t[closest][0][0]).normalize(); // from 1 to 2
    let tangent = Vec3::Z.cross(n);
    let (first, last) = (&t[0], &t[t.len() - 1]);
    let (v_in, v_out) = (first[0][1] - first[1][1], last[0][1] - last[1][1]);
    vec![
        ("restitution", -v_out.dot(n) / v_in.dot(n)),
        ("contact time (s)", contact_time(&distance, reach)),
        ("v1 normal out (m/s)", last[0][1].dot(n)),
        ("v1 tangential out (m/s)", last[0][1].dot(tangent)),
        ("spin1 z out (rad/s)", last[0][2].z),
        ("spin2 z out (rad/s)", last[1][2].z),
    ]
}

fn wall_measures(t: &Trajectory) -> Measures {
    wall_measures_of_radius(t, 0.5 * DIAMETER)
}

/// `wall_measures` for a particle of radius `radius`.
fn wall_measures_of_radius(t: &Trajectory, radius: Real) -> Measures {
    let height: Vec<Real> = t.iter().map(|s| s[0][0].z).collect();
    let (first, last) = (&t[0][0], &t[t.len() - 1][0]);
    vec![
        ("restitution", -last[1].z / first[1].z),
        ("contact time (s)", contact_time(&height, radius)),
        ("vz out (m/s)", last[1].z),
        ("vx out (m/s)", last[1].x),
        ("spin y out (rad/s)", last[2].y),
    ]
}

/// Quantities a code is known not to reproduce, with the reason (MAPPING.md).
type Known = &'static [(Code, &'static str, &'static str)];

/// Runs one case in cgdem and in the installed reference codes, checks the live reference
/// numbers against the stored ones, prints the table and asserts agreement with LIGGGHTS's
/// stored numbers (within `TOLERANCE`).
fn golden(
    case: &str,
    scene: &Scene,
    initial: &Particles,
    measure: &dyn Fn(&Trajectory) -> Measures,
    known: Known,
) {
    golden_within(case, scene, initial, measure, known, TOLERANCE)
}

/// `golden` with cgdem held to `cgdem_tolerance` of LIGGGHTS (LAMMPS to `TOLERANCE`).
fn golden_within(
    case: &str,
    scene: &Scene,
    initial: &Particles,
    measure: &dyn Fn(&Trajectory) -> Measures,
    known: Known,
    cgdem_tolerance: Real,
) {
    let cg = measure(&run_cgdem(scene, initial));
    let mut stored = golden::GoldenFile::load(GOLDEN_FILE);
    for code in [Code::Liggghts, Code::Lammps] {
        if let Some(t) = run_reference(code, case, scene, initial) {
            for (quantity, value) in measure(&t) {
                stored.live(case, quantity, code.name(), value);
            }
        }
    }
    stored.finish();
    let mut failures = Vec::new();
    for &(quantity, c) in &cg {
        let reference = stored.get(case, quantity, Code::Liggghts.name());
        let l = stored.get(case, quantity, Code::Lammps.name());
        let rel = |x: Real| {
            if x == reference {
                0.0
            } else {
                (x - reference).abs() / reference.abs().max(1e-300)
            }
        };
        let (r_c, r_l) = (rel(c), rel(l));
        println!(
            "GOLDEN | {case} | {quantity} | {c:.6e} | {reference:.6e} | {l:.6e} | {r_c:.2e} | {r_l:.2e}"
        );
        for (code, value, r, tolerance) in [
            (Code::Cgdem, c, r_c, cgdem_tolerance),
            (Code::Lammps, l, r_l, TOLERANCE),
        ] {
            if r < tolerance {
                continue;
            }
            match known.iter().find(|(kc, kq, _)| *kc == code && *kq == quantity) {
                Some((_, _, why)) => println!("  known: {code:?} {quantity}: {why}"),
                None => failures.push(format!(
                    "{case}: {quantity}: {code:?} {value:.9e} vs LIGGGHTS {reference:.9e} (rel. diff {r:.3e})"
                )),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn pair_case(case: &str, b: Real, spin: Real, known: Known) {
    let scene = scene(-0.01, "");
    let gap = 1e-6;
    let dir = Vec3::new((1.0 - b * b).sqrt(), b, 0.0);
    let initial = particles(
        &scene,
        &[
            [
                -0.5 * (DIAMETER + gap) * dir,
                Vec3::new(0.5, 0.0, 0.0),
                Vec3::new(0.0, 0.0, spin),
            ],
            [
                0.5 * (DIAMETER + gap) * dir,
                Vec3::new(-0.5, 0.0, 0.0),
                Vec3::ZERO,
            ],
        ],
    );
    golden(case, &scene, &initial, &pair_measures, known);
}

fn wall_case(case: &str, angle_deg: Real, spin: Real, known: Known) {
    let walls = "[[wall]]\nname = \"floor\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n";
    let scene = scene(0.0, walls);
    let a = angle_deg.to_radians();
    let initial = particles(
        &scene,
        &[[
            Vec3::new(0.0, 0.0, 0.5 * DIAMETER + 1e-6),
            Vec3::new(a.sin(), 0.0, -a.cos()),
            Vec3::new(0.0, spin, 0.0),
        ]],
    );
    golden(case, &scene, &initial, &wall_measures, known);
}

#[test]
fn head_on_pair() {
    pair_case("pair head-on", 0.0, 0.0, &[]);
}

/// LAMMPS's `mindlin` is not LIGGGHTS's `tangential history` (contact-point velocity with the
/// full radii, Coulomb cap on spring + dashpot) and `rolling sds` has a constant stiffness;
/// runs with rolling or friction switched off put the gap in the tangential law (MAPPING.md).
const LAMMPS_SPIN: &str =
    "LAMMPS mindlin / rolling sds are other laws than tangential history / epsd2 (MAPPING.md)";

#[test]
fn oblique_pair_with_spin() {
    pair_case(
        "pair oblique b=0.5 spin",
        0.5,
        300.0,
        &[
            (Code::Lammps, "spin1 z out (rad/s)", LAMMPS_SPIN),
            (Code::Lammps, "spin2 z out (rad/s)", LAMMPS_SPIN),
        ],
    );
}

#[test]
fn normal_wall_impact_with_spin() {
    wall_case(
        "wall normal spin",
        0.0,
        300.0,
        &[
            (Code::Lammps, "vx out (m/s)", LAMMPS_SPIN),
            (Code::Lammps, "spin y out (rad/s)", LAMMPS_SPIN),
        ],
    );
}

#[test]
fn wall_impact_at_45_degrees_with_spin() {
    wall_case(
        "wall 45deg spin",
        45.0,
        -300.0,
        &[
            (Code::Lammps, "vx out (m/s)", LAMMPS_SPIN),
            (Code::Lammps, "spin y out (rad/s)", LAMMPS_SPIN),
        ],
    );
}

/// Two materials and a plate (issue 40): a soft bead (2 mm, E = 5e6 Pa, nu = 0.3) and a hard,
/// smaller, lighter grain (1.5 mm, E = 5e7 Pa, nu = 0.2); each pair its own restitution,
/// friction and rolling friction, the floor a `[[wall_material]]` of its own (E = 1e8 Pa,
/// nu = 0.25) with the grain's coefficients against it in `[[wall_contact.pair]]`.
fn unlike_scene(lo_z: Real, walls: &str) -> Scene {
    let text = format!(
        r#"
name = "hertz_golden_unlike"
gravity = [0.0, 0.0, 0.0]
[domain]
lo = [-0.01, -0.01, {lo_z}]
hi = [0.01, 0.01, 0.01]
periodic = [false, false, false]
[[species]]
name = "bead"
diameter = {DIAMETER}
density = 2500.0
[[species]]
name = "grain"
diameter = 1.5e-3
density = 1200.0
youngs_modulus = 5.0e7
poisson_ratio = 0.2
{BEAD_CONTACT}[[contact.pair]]
species = ["grain", "bead"]
restitution = 0.35
friction = 0.3
rolling_friction = 0.05
[[contact.pair]]
species = ["grain", "grain"]
restitution = 0.8
friction = 0.2
rolling_friction = 0.02
[[wall_material]]
name = "plate"
youngs_modulus = 1.0e8
poisson_ratio = 0.25
{BEAD_WALL_CONTACT}[[wall_contact.pair]]
species = "grain"
material = "plate"
restitution = 0.6
friction = 0.4
rolling_friction = 0.03
{run}{walls}
"#,
        run = every_step(STEPS as Real * DT, DT)
    );
    Scene::parse(&text, Path::new("hertz_golden_unlike.toml")).expect("golden scene")
}

/// cgdem against LIGGGHTS for unlike materials: the same law, so to round-off.
const UNLIKE_TOLERANCE: Real = 1e-12;

/// A bead (species 0) and a grain (species 1): the bead at +0.5 m/s with spin `spin` about
/// z, the grain at -0.5 m/s, impact parameter `b` of the contact distance.
fn unlike_pair_case(case: &str, b: Real, spin: Real, known: Known) {
    let scene = unlike_scene(-0.01, "");
    let reach = scene.species[0].radius() + scene.species[1].radius();
    let gap = 1e-6;
    let dir = Vec3::new((1.0 - b * b).sqrt(), b, 0.0);
    let initial = particles_of(
        &scene,
        &[0, 1],
        &[
            [
                -0.5 * (reach + gap) * dir,
                Vec3::new(0.5, 0.0, 0.0),
                Vec3::new(0.0, 0.0, spin),
            ],
            [
                0.5 * (reach + gap) * dir,
                Vec3::new(-0.5, 0.0, 0.0),
                Vec3::ZERO,
            ],
        ],
    );
    let measure = move |t: &Trajectory| pair_measures_touching_at(t, reach);
    golden_within(case, &scene, &initial, &measure, known, UNLIKE_TOLERANCE);
}

#[test]
fn unlike_materials_head_on_pair() {
    unlike_pair_case("unlike pair head-on", 0.0, 0.0, &[]);
}

#[test]
fn unlike_materials_oblique_pair_with_spin() {
    unlike_pair_case(
        "unlike pair oblique b=0.5 spin",
        0.5,
        300.0,
        &[
            (Code::Lammps, "v1 tangential out (m/s)", LAMMPS_SPIN),
            (Code::Lammps, "spin1 z out (rad/s)", LAMMPS_SPIN),
            (Code::Lammps, "spin2 z out (rad/s)", LAMMPS_SPIN),
        ],
    );
}

/// The grain (species 1) on the plate at 45 degrees with spin. A frozen bead rests far from
/// it and the floor: LIGGGHTS refuses a granular run whose atom types do not start at 1, and
/// frozen, the bead leaves the grain the one species the walls meet (one LAMMPS wall fix).
#[test]
fn unlike_materials_wall_impact_at_45_degrees_with_spin() {
    let walls = "[[wall]]\nname = \"floor\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nmaterial = \"plate\"\n";
    let mut scene = unlike_scene(0.0, walls);
    scene.species[0].frozen = true;
    let radius = scene.species[1].radius();
    let a = 45f64.to_radians();
    let initial = particles_of(
        &scene,
        &[1, 0],
        &[
            [
                Vec3::new(0.0, 0.0, radius + 1e-6),
                Vec3::new(a.sin(), 0.0, -a.cos()),
                Vec3::new(0.0, -300.0, 0.0),
            ],
            [Vec3::new(-0.008, -0.008, 0.008), Vec3::ZERO, Vec3::ZERO],
        ],
    );
    let measure = move |t: &Trajectory| wall_measures_of_radius(t, radius);
    golden_within(
        "unlike wall 45deg spin",
        &scene,
        &initial,
        &measure,
        &[
            (Code::Lammps, "vx out (m/s)", LAMMPS_SPIN),
            (Code::Lammps, "spin y out (rad/s)", LAMMPS_SPIN),
        ],
        UNLIKE_TOLERANCE,
    );
}
