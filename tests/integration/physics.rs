//! The seed's model against closed forms: energy, restitution, Newton's third law, walls,
//! coarse-graining invariants, determinism.

use crate::common::*;
use cgdem_core::decomposition::GridSpec;
use cgdem_core::domain::Domain;
use cgdem_core::geometry::FinitePlane;
use cgdem_core::math::{Real, Vec3};
use cgdem_core::particles::Particles;
use cgdem_core::walls::{restitution_damping_ratio, Wall, WallSet};
use rand::{Rng, SeedableRng};

fn linear_restitution(zeta: Real) -> Real {
    (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp()
}

#[test]
fn undamped_binary_collision_conserves_energy_to_1e6_with_second_order_convergence() {
    let mut coke = Coke::at(1.0);
    coke.gamma_n = 0.0;
    coke.gamma_t = 0.0;
    // Velocity Verlet leaves an O(dt^2) energy error where the WCA stiffness jumps to zero at
    // the cut-off; halving dt must quarter it, and a fine step must bring it below 1e-6.
    let energy_error = |steps_per_period: Real| {
        let dt = coke.pair_period() / steps_per_period;
        let mut world = binary_collision(&coke, 1.0, 0.3, dt);
        let before = world.kinetic_energy();
        collide(&mut world, coke.diameter());
        ((world.kinetic_energy() - before) / before).abs()
    };
    let coarse = energy_error(250.0);
    let fine = energy_error(500.0);
    let order = (coarse / fine).log2();
    assert!(
        (order - 2.0).abs() < 0.3,
        "convergence order {order} ({coarse:e} -> {fine:e})"
    );
    let finest = energy_error(4000.0);
    assert!(finest < 1e-6, "relative energy change {finest:e}");
}

#[test]
fn binary_restitution_matches_the_linearized_damping_ratio() {
    let coke = Coke::at(1.0);
    let m_eff = 0.5 * coke.mass();
    let zeta = coke.gamma_n / (2.0 * (coke.wca.contact_stiffness() * m_eff).sqrt());
    let predicted = linear_restitution(zeta);
    let dt = coke.pair_period() / 200.0;
    // Slow enough that the WCA stays in its linear range (overlap ~ 1e-5 of the diameter).
    let mut world = binary_collision(&coke, 0.1, 0.0, dt);
    let (steps, relative) = collide(&mut world, coke.diameter());
    let e = -relative.x / 0.1;
    assert!(
        (e / predicted - 1.0).abs() < 2e-3,
        "e = {e}, predicted {predicted}"
    );
    // Paper A (derived): e about 0.9, contact about half the period (1.5 us).
    assert!((e - 0.9).abs() < 0.01);
    let contact_time = steps as Real * dt;
    assert!(
        (contact_time / (0.5 * coke.pair_period()) - 1.0).abs() < 0.03,
        "contact {contact_time}"
    );
}

#[test]
fn restitution_and_tangential_loss_are_unchanged_under_coarse_graining() {
    let reference = {
        let coke = Coke::at(1.0);
        let dt = coke.pair_period() / 100.0;
        let mut world = binary_collision(&coke, 1.0, 0.5, dt);
        let (steps, v) = collide(&mut world, coke.diameter());
        (steps, v)
    };
    for lambda in [2.0, 4.0, 8.0] {
        let coke = Coke::at(lambda);
        let dt = Coke::at(1.0).pair_period() / 100.0 * lambda; // dt' = lambda dt
        let mut world = binary_collision(&coke, 1.0, 0.5, dt);
        let (steps, v) = collide(&mut world, coke.diameter());
        // The scaled dynamics are the same trajectory in time units of lambda: same
        // number of steps in contact, same outgoing relative velocity.
        assert_eq!(steps, reference.0, "lambda {lambda}");
        assert!(
            (v - reference.1).length() < 1e-9 * reference.1.length(),
            "lambda {lambda}: {v} vs {}",
            reference.1
        );
    }
}

#[test]
fn pair_forces_obey_newtons_third_law_in_a_dense_random_packing() {
    let coke = Coke::at(1.0);
    let d = coke.diameter();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let mut particles = Particles::new(false);
    for _ in 0..400 {
        let p = Vec3::new(
            rng.gen_range(0.0..8.0),
            rng.gen_range(0.0..8.0),
            rng.gen_range(0.0..8.0),
        ) * d;
        particles.push(0, p, 0.5 * d, coke.mass());
        let v = Vec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        *particles.velocity.last_mut().unwrap() = v;
    }
    let domain = Domain {
        lo: Vec3::ZERO,
        hi: Vec3::splat(8.0 * d),
        periodic: [true; 3],
    };
    let mut world = world(
        &coke,
        particles,
        domain,
        WallSet::default(),
        coke.wall_law(0.5, 0.0),
        Vec3::ZERO,
        coke.pair_period() / 50.0,
    );
    let momentum =
        |p: &Particles| -> Vec3 { p.velocity.iter().zip(&p.mass).map(|(v, m)| *m * *v).sum() };
    let p0 = momentum(world.particles());
    let mut largest_force: Real = 0.0;
    for _ in 0..200 {
        world.step();
        let p = world.synced_particles();
        let net: Vec3 = p.force.iter().copied().sum();
        largest_force = p
            .force
            .iter()
            .map(|f| f.length())
            .fold(largest_force, Real::max);
        assert!(
            net.length() <= 1e-12 * largest_force * p.len() as Real,
            "net force {net}"
        );
    }
    assert!(largest_force > 0.0, "no contact happened");
    let p = world.particles();
    let momentum_scale: Real = p
        .velocity
        .iter()
        .zip(&p.mass)
        .map(|(v, m)| m * v.length())
        .sum();
    let drift = (momentum(p) - p0).length();
    assert!(
        drift < 1e-12 * momentum_scale,
        "momentum drift {drift:e} of {momentum_scale:e}"
    );
}

#[test]
fn wall_rebounds_with_the_restitution_it_was_given() {
    let coke = Coke::at(1.0);
    let d = coke.diameter();
    for e in [0.3, 0.5, 0.9] {
        let mut particles = Particles::new(false);
        particles.push(
            0,
            Vec3::new(0.0, 0.0, 0.5 * d * 1.001),
            0.5 * d,
            coke.mass(),
        );
        particles.velocity[0] = Vec3::new(0.0, 0.0, -0.1);
        let walls = WallSet {
            walls: vec![Wall {
                name: "floor".into(),
                plane: FinitePlane::new(Vec3::ZERO, Vec3::Z, 1.0, 1.0),
                active: true,
            }],
        };
        let law = coke.wall_law(e, 0.0);
        let period = 2.0
            * std::f64::consts::PI
            * (coke.mass() / (4.0 * coke.wca.contact_stiffness())).sqrt();
        let mut world = world(
            &coke,
            particles,
            open_box(10.0 * d),
            walls,
            law,
            Vec3::ZERO,
            period / 200.0,
        );
        while world.synced_particles().position[0].z < 0.5 * d * 1.01 {
            world.step();
        }
        let rebound = world.synced_particles().velocity[0].z / 0.1;
        assert!(
            (rebound / e - 1.0).abs() < 5e-3,
            "e = {e}: rebound {rebound}"
        );
        assert!(
            (restitution_damping_ratio(e)
                - (-e.ln() / (std::f64::consts::PI.powi(2) + e.ln().powi(2)).sqrt()))
            .abs()
                < 1e-15
        );
    }
}

#[test]
fn wall_friction_stops_a_sliding_particle_at_mu_g_without_chatter() {
    let coke = Coke::at(1.0);
    let d = coke.diameter();
    let mu = 0.413;
    let g = 9.81;
    let v0 = 0.05;
    let mut particles = Particles::new(false);
    // Resting on the floor at its equilibrium height under gravity (found by settling).
    particles.push(0, Vec3::new(0.0, 0.0, 0.5 * d), 0.5 * d, coke.mass());
    let walls = WallSet {
        walls: vec![Wall {
            name: "floor".into(),
            plane: FinitePlane::new(Vec3::ZERO, Vec3::Z, 1.0, 1.0),
            active: true,
        }],
    };
    let dt = coke.pair_period() / 50.0;
    let on_floor = |particles: Particles| {
        world(
            &coke,
            particles,
            open_box(0.5),
            walls.clone(),
            coke.wall_law(0.5, mu),
            Vec3::new(0.0, 0.0, -g),
            dt,
        )
    };
    let mut settling = on_floor(particles);
    for _ in 0..20_000 {
        settling.step();
    }
    // Settled: set sliding from there.
    let mut settled = settling.synced_particles().clone();
    settled.velocity[0] = Vec3::new(v0, 0.0, 0.0);
    let start_x = settled.position[0].x;
    let mut world = on_floor(settled);
    let expected_stop = v0 / (mu * g);
    let steps = (1.5 * expected_stop / dt) as usize;
    let mut stopped_at = None;
    let mut sign_changes = 0;
    let mut last_vx = v0;
    for k in 0..steps {
        world.step();
        let vx = world.synced_particles().velocity[0].x;
        if vx * last_vx < 0.0 {
            sign_changes += 1;
        }
        last_vx = vx;
        if stopped_at.is_none() && vx.abs() < 1e-6 {
            stopped_at = Some(k as Real * dt);
        }
    }
    let t = stopped_at.expect("the particle never stopped");
    assert!(
        (t / expected_stop - 1.0).abs() < 0.02,
        "stopped after {t} s, Coulomb predicts {expected_stop} s"
    );
    let distance = world.particles().position[0].x - start_x;
    let expected_distance = v0 * v0 / (2.0 * mu * g);
    assert!(
        (distance / expected_distance - 1.0).abs() < 0.02,
        "slid {distance} m, predicted {expected_distance}"
    );
    assert_eq!(
        sign_changes, 0,
        "friction reversed the sliding velocity (chatter)"
    );
    assert!(world.particles().velocity[0].x.abs() < 1e-6);
}

#[test]
fn one_and_two_threads_give_bitwise_identical_positions() {
    let run = |threads: usize| -> Vec<Vec3> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let coke = Coke::at(4.0);
            let d = coke.diameter();
            let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
            let mut particles = Particles::new(false);
            let mut attempts = 0;
            while particles.len() < 3000 && attempts < 1_000_000 {
                attempts += 1;
                let p = Vec3::new(
                    rng.gen_range(0.5..19.5),
                    rng.gen_range(0.0..20.0),
                    rng.gen_range(0.5..40.0),
                ) * d;
                // Apart also across the periodic y faces (nearest image): placed
                // overlapping there, pairs would explode at the first step.
                let apart = |q: &Vec3| {
                    let mut gap = *q - p;
                    gap.y -= 20.0 * d * (gap.y / (20.0 * d)).round();
                    gap.length() > d
                };
                if particles.position.iter().all(apart) {
                    particles.push(0, p, 0.5 * d, coke.mass());
                    // Random motion, so that the short run collides, rebuilds and re-sorts.
                    *particles.velocity.last_mut().unwrap() = Vec3::new(
                        rng.gen_range(-2.0..2.0),
                        rng.gen_range(-2.0..2.0),
                        rng.gen_range(-2.0..2.0),
                    );
                }
            }
            let domain = Domain {
                lo: Vec3::ZERO,
                hi: Vec3::new(20.0, 20.0, 60.0) * d,
                periodic: [false, true, false],
            };
            let plane = |name: &str, point: Vec3, normal: Vec3| Wall {
                name: name.into(),
                plane: FinitePlane::new(point, normal, 1.0, 1.0),
                active: true,
            };
            let walls = WallSet {
                walls: vec![
                    plane("floor", Vec3::ZERO, Vec3::Z),
                    plane("left", Vec3::ZERO, Vec3::X),
                    plane("right", Vec3::X * 20.0 * d, -Vec3::X),
                ],
            };
            // Four subdomains (the scene alone would run as one), stepped by one thread or
            // two.
            let column = setup(
                &coke,
                particles,
                domain,
                walls,
                coke.wall_law(0.5, 0.413),
                Vec3::new(0.0, 0.0, -9.81),
                coke.pair_period() / 20.0,
            );
            let mut world = build_on(column, GridSpec::Auto(4));
            for _ in 0..4000 {
                world.step();
                if let Some(trip) = world.take_guard_trip() {
                    panic!("the test must run a sane state: {trip:?}");
                }
            }
            assert!(
                world.list_builds() > 6,
                "the test must cover list rebuilds and re-sorts (every 5th build)"
            );
            let p = world.synced_particles();
            let mut by_id: Vec<(u32, Vec3)> =
                p.id.iter()
                    .copied()
                    .zip(p.position.iter().copied())
                    .collect();
            by_id.sort_by_key(|(id, _)| *id);
            by_id.into_iter().map(|(_, p)| p).collect()
        })
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one.len(), two.len());
    for (a, b) in one.iter().zip(&two) {
        assert_eq!(
            a.to_array().map(f64::to_bits),
            b.to_array().map(f64::to_bits)
        );
    }
}

#[test]
fn a_frozen_particle_stays_put_and_acts_with_infinite_mass() {
    // Against a frozen partner the contact's effective mass is the mobile particle's mass
    // (LIGGGHTS/LAMMPS `fix freeze`), so the damping ratio is gamma / (2 sqrt(k m)).
    let coke = Coke::at(1.0);
    let m_eff = coke.mass();
    let zeta = coke.gamma_n / (2.0 * (coke.wca.contact_stiffness() * m_eff).sqrt());
    let predicted = linear_restitution(zeta);
    let dt = coke.pair_period() / 200.0;
    let mut setup = binary_collision_setup(&coke, 0.1, 0.0, dt);
    setup.particles.freeze(1);
    setup.particles.velocity[0] = Vec3::new(0.1, 0.0, 0.0);
    let frozen_at = setup.particles.position[1];
    let mut world = build(setup);
    let (_, relative) = collide(&mut world, coke.diameter());
    let e = -relative.x / 0.1;
    assert!(
        (e / predicted - 1.0).abs() < 2e-3,
        "e = {e}, predicted {predicted}"
    );
    let p = world.particles();
    let k = p.id.iter().position(|&id| id == 1).unwrap();
    assert_eq!(p.position[k], frozen_at);
    assert_eq!(p.velocity[k], Vec3::ZERO);
    // Two frozen particles are never listed, touching or not.
    let mut both = binary_collision_setup(&coke, 0.1, 0.0, dt);
    both.particles.freeze(0);
    both.particles.freeze(1);
    assert_eq!(build(both).listed_pairs(), 0);
    assert_eq!(binary_collision(&coke, 0.1, 0.0, dt).listed_pairs(), 1);
}
