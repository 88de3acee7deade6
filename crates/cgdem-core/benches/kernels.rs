//! Kernel benchmarks: the force loop per contact model, the neighbour-list build, the
//! integrator and the SDF query, each on a fixed configuration, so a change's effect shows
//! without running a whole case (`cargo bench --bench kernels`). Whole cases are compared
//! against LIGGGHTS and LAMMPS by `cgdem bench`.

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion};

use cgdem_core::contact::cohesion::NoCohesion;
use cgdem_core::contact::damping::HertzDamping;
use cgdem_core::contact::normal::{Hertz, Material, WcaCoefficients};
use cgdem_core::contact::rolling::Epsd2;
use cgdem_core::contact::tangential::Mindlin;
use cgdem_core::contact::{ContactLaw, PairLaw, SeedModel};
use cgdem_core::domain::Domain;
use cgdem_core::geometry::{sphere_mesh, SdfGrid};
use cgdem_core::insertion::insert_random_where;
use cgdem_core::integrate::kick_then_drift;
use cgdem_core::math::{Real, Vec3, TWO_POW_ONE_SIXTH};
use cgdem_core::particles::Particles;
use cgdem_core::simulation::{Decompose, NeighborSettings, World, WorldSetup};
use cgdem_core::walls::{HertzHistoryWall, WallLaw, WcaWall};

const DIAMETER: Real = 2e-3;
const DENSITY: Real = 2500.0;

/// 8000 spheres of 2 mm packed at random (overlapping by up to 2% of the diameter, so many
/// pairs touch) in a 4 cm periodic cube, at rest.
fn packed_bed(rotation: bool) -> (Particles, Domain) {
    let side = 0.04;
    let domain = Domain {
        lo: Vec3::ZERO,
        hi: Vec3::splat(side),
        periodic: [true; 3],
    };
    let mut particles = Particles::new(rotation);
    let mass = DENSITY * std::f64::consts::PI / 6.0 * DIAMETER.powi(3);
    let mut placed = Particles::new(rotation);
    // Half without overlap, half overlapping by up to 2%: a compressed bed, many pairs touch.
    for (seed, overlap) in [(7, 0.0), (8, 0.02)] {
        insert_random_where(
            &mut placed,
            0,
            0.5 * DIAMETER,
            mass,
            domain.lo,
            domain.hi,
            4000,
            seed,
            overlap,
            |_| true,
        )
        .unwrap();
    }
    for k in 0..placed.len() {
        particles.push(0, placed.position[k], 0.5 * DIAMETER, mass);
        particles.velocity[k] = Vec3::new(0.01, -0.02, 0.015) * ((k % 7) as Real - 3.0);
    }
    (particles, domain)
}

fn neighbor() -> NeighborSettings {
    NeighborSettings {
        skin: 0.25 * DIAMETER,
        resort_every: 1,
    }
}

fn hertz_law() -> ContactLaw<Hertz, HertzDamping, Mindlin, Epsd2, NoCohesion> {
    let m = Material {
        youngs_modulus: 5e6,
        poisson_ratio: 0.3,
    };
    let (y, g) = (Material::y_eff(m, m), Material::g_eff(m, m));
    ContactLaw::new(
        Hertz {
            y_eff: vec![y],
            characteristic_velocity: 1.0,
        },
        HertzDamping::from_restitution(&[0.5]),
        Mindlin {
            g_eff: vec![g],
            damping_factor: vec![cgdem_core::contact::damping::liggghts_damping_factor(0.5)],
            friction: vec![0.5],
        },
        Epsd2 {
            rolling_friction: vec![0.1],
            g_eff: vec![g],
        },
        NoCohesion,
    )
}

fn seed_law() -> SeedModel {
    // WCA scaled to 2 mm spheres with about the Hertz contact's softness.
    let wca = WcaCoefficients {
        epsilon: 2.85e-4,
        sigma: DIAMETER / TWO_POW_ONE_SIXTH,
    };
    SeedModel::seed(vec![wca], vec![0.065], vec![0.065])
}

fn world<L: PairLaw, W: WallLaw>(law: L, wall: W, rotation: bool) -> World<L, W> {
    let (particles, domain) = packed_bed(rotation);
    let gravity = Vec3::new(0.0, 0.0, -9.81);
    let setup = WorldSetup::new(particles, domain, law, wall, 1, gravity, 1e-5, neighbor());
    World::new(setup, &Decompose::default()).expect("the bed fits its box")
}

fn force_loop(c: &mut Criterion) {
    let mass = DENSITY * std::f64::consts::PI / 6.0 * DIAMETER.powi(3);
    let m = Material {
        youngs_modulus: 5e6,
        poisson_ratio: 0.3,
    };
    let moduli = [(Material::y_eff(m, m), Material::g_eff(m, m))];
    let mut hertz = world(
        hertz_law(),
        HertzHistoryWall::new(&moduli, 0.5, 0.5, 0.1, 1.0),
        true,
    );
    let mut seed = world(
        seed_law(),
        WcaWall::new(
            &[(
                WcaCoefficients {
                    epsilon: 2.85e-4,
                    sigma: DIAMETER / TWO_POW_ONE_SIXTH,
                },
                mass,
            )],
            0.5,
            0.4,
        ),
        false,
    );
    // A step is mostly its force loop (a list rebuild every few dozen steps at rest).
    let mut group = c.benchmark_group("step_8000_particles");
    group.bench_function("hertz_mindlin_epsd2", |b| b.iter(|| hertz.step()));
    group.bench_function("wca_seed", |b| b.iter(|| seed.step()));
    group.finish();
}

fn integrator(c: &mut Criterion) {
    let n = 100_000;
    let mut particles = Particles::new(false);
    for k in 0..n {
        particles.push(0, Vec3::ZERO, 1e-3, 1e-4);
        particles.velocity[k] = Vec3::X;
        particles.force[k] = Vec3::splat(k as Real * 1e-6);
    }
    let reference = particles.position.clone();
    c.bench_function("kick_then_drift_100k", |b| {
        b.iter_batched(
            || particles.clone(),
            |mut p| {
                let moved = kick_then_drift(
                    &mut p.position,
                    &mut p.velocity,
                    &p.force,
                    &p.inv_mass,
                    &reference,
                    1e-8,
                    1e-5,
                );
                black_box((p, moved))
            },
            BatchSize::LargeInput,
        )
    });
}

fn sdf_query(c: &mut Criterion) {
    let mesh = sphere_mesh(0.05, 4);
    let grid = SdfGrid::from_mesh(&mesh, 0.002, 0.01).unwrap();
    let points: Vec<Vec3> = (0..10_000)
        .map(|k| {
            let t = k as Real * 0.61803398875;
            Vec3::new(t.sin(), (1.7 * t).cos(), (2.3 * t).sin()) * 0.055
        })
        .collect();
    c.bench_function("sdf_query_10k_points", |b| {
        b.iter(|| {
            let mut hits = 0usize;
            for &p in &points {
                if grid.query(black_box(p)).is_some() {
                    hits += 1;
                }
            }
            hits
        })
    });
}

criterion_group!(benches, force_loop, integrator, sdf_query);
criterion_main!(benches);
