//! Small worlds for the tests.

use cgdem_core::contact::normal::WcaCoefficients;
use cgdem_core::contact::{PairLaw, SeedModel};
use cgdem_core::decomposition::GridSpec;
use cgdem_core::domain::Domain;
use cgdem_core::math::{Real, Vec3, TWO_POW_ONE_SIXTH};
use cgdem_core::particles::Particles;
use cgdem_core::scene::Scene;
use cgdem_core::simulation::{Decompose, NeighborSettings, World, WorldSetup};
use cgdem_core::walls::{WallLaw, WallSet, WcaWall};
use cgdem_harness::code::Code;
use cgdem_harness::decks::{
    self, lammps, liggghts, run_reference, ReferenceOptions, ReferenceRun, RunStatus, RunnerOptions,
};

/// The seed's coke parameters (paper A sec. 3), coarse-grained by `lambda`.
pub struct Coke {
    pub wca: WcaCoefficients,
    pub gamma_n: Real,
    pub gamma_t: Real,
    pub density: Real,
}

impl Coke {
    pub fn at(lambda: Real) -> Coke {
        Coke {
            wca: WcaCoefficients {
                epsilon: 9.434e-2 * lambda.powi(3),
                sigma: 1.203e-3 * lambda,
            },
            gamma_n: 0.1257 * lambda * lambda,
            gamma_t: 0.1257 * lambda * lambda,
            density: 1370.0,
        }
    }

    pub fn diameter(&self) -> Real {
        TWO_POW_ONE_SIXTH * self.wca.sigma
    }

    pub fn mass(&self) -> Real {
        self.density * std::f64::consts::PI / 6.0 * self.diameter().powi(3)
    }

    /// Linearized pair period `2 pi sqrt(m_eff / k)`.
    pub fn pair_period(&self) -> Real {
        2.0 * std::f64::consts::PI * (0.5 * self.mass() / self.wca.contact_stiffness()).sqrt()
    }

    pub fn law(&self) -> SeedModel {
        SeedModel::seed(vec![self.wca], vec![self.gamma_n], vec![self.gamma_t])
    }

    pub fn wall_law(&self, restitution: Real, friction: Real) -> WcaWall {
        WcaWall::new(&[(self.wca, self.mass())], restitution, friction)
    }
}

pub fn open_box(half: Real) -> Domain {
    Domain {
        lo: Vec3::splat(-half),
        hi: Vec3::splat(half),
        periodic: [false; 3],
    }
}

/// The setup of a world of coke particles (the seed's law).
pub fn setup(
    coke: &Coke,
    particles: Particles,
    domain: Domain,
    walls: WallSet,
    wall_law: WcaWall,
    gravity: Vec3,
    dt: Real,
) -> WorldSetup<SeedModel, WcaWall> {
    let neighbor = NeighborSettings {
        skin: 0.3 * coke.diameter(),
        resort_every: 5,
    };
    let mut setup = WorldSetup::new(
        particles,
        domain,
        coke.law(),
        wall_law,
        1,
        gravity,
        dt,
        neighbor,
    );
    setup.walls = walls;
    setup
}

/// The world of `setup`, on the grid the scene gives.
pub fn build<L: PairLaw, W: WallLaw>(setup: WorldSetup<L, W>) -> World<L, W> {
    World::new(setup, &Decompose::default()).expect("the test world fits its box")
}

/// The world of `setup` on `grid`.
pub fn build_on<L: PairLaw, W: WallLaw>(setup: WorldSetup<L, W>, grid: GridSpec) -> World<L, W> {
    let decompose = Decompose {
        grid: Some(grid),
        ..Decompose::default()
    };
    World::new(setup, &decompose).expect("the test world fits its grid")
}

/// The world of [`setup`].
pub fn world(
    coke: &Coke,
    particles: Particles,
    domain: Domain,
    walls: WallSet,
    wall_law: WcaWall,
    gravity: Vec3,
    dt: Real,
) -> World<SeedModel, WcaWall> {
    build(setup(coke, particles, domain, walls, wall_law, gravity, dt))
}

/// Two coke particles approaching head-on (or offset by `impact_parameter` diameters) with
/// relative speed `speed`, just out of contact.
pub fn binary_collision(
    coke: &Coke,
    speed: Real,
    impact_parameter: Real,
    dt: Real,
) -> World<SeedModel, WcaWall> {
    build(binary_collision_setup(coke, speed, impact_parameter, dt))
}

/// The setup of [`binary_collision`], for tests that change its particles first.
pub fn binary_collision_setup(
    coke: &Coke,
    speed: Real,
    impact_parameter: Real,
    dt: Real,
) -> WorldSetup<SeedModel, WcaWall> {
    let d = coke.diameter();
    let mut particles = Particles::new(false);
    let b = impact_parameter * d;
    let gap = (d * d - b * b).sqrt() * 1.001;
    particles.push(
        0,
        Vec3::new(-0.5 * gap, -0.5 * b, 0.0),
        0.5 * d,
        coke.mass(),
    );
    particles.push(0, Vec3::new(0.5 * gap, 0.5 * b, 0.0), 0.5 * d, coke.mass());
    particles.velocity[0] = Vec3::new(0.5 * speed, 0.0, 0.0);
    particles.velocity[1] = Vec3::new(-0.5 * speed, 0.0, 0.0);
    setup(
        coke,
        particles,
        open_box(20.0 * d),
        WallSet::default(),
        coke.wall_law(0.5, 0.0),
        Vec3::ZERO,
        dt,
    )
}

/// Runs until the pair separates again; returns (steps in contact, relative velocity after).
pub fn collide(world: &mut World<SeedModel, WcaWall>, contact_distance: Real) -> (u64, Vec3) {
    let distance = |w: &mut World<SeedModel, WcaWall>| {
        let p = w.synced_particles();
        (p.position[0] - p.position[1]).length()
    };
    let mut in_contact = 0;
    let mut touched = false;
    for _ in 0..10_000_000 {
        world.step();
        if distance(world) < contact_distance {
            touched = true;
            in_contact += 1;
        } else if touched {
            break;
        }
    }
    assert!(touched, "the particles never met");
    // Index order may have been re-sorted; the relative velocity's sign follows the ids.
    let p = world.particles();
    let (a, b) = if p.id[0] == 0 { (0, 1) } else { (1, 0) };
    (in_contact, p.velocity[a] - p.velocity[b])
}

/// Runs `scene` in a reference code into a fresh `dir` under the tests' temporary directory;
/// None (after saying so) when the code is not installed. The run must complete; returns it
/// with its directory.
pub fn completed_reference_run(
    code: Code,
    scene: &Scene,
    dir: &str,
    timeout_s: u64,
) -> Option<(ReferenceRun, std::path::PathBuf)> {
    let found = match code {
        Code::Cgdem | Code::Lammps => lammps::find_lmp(),
        Code::Liggghts => liggghts::find_liggghts(),
    };
    if let Err(reason) = found {
        println!(
            "skipped {}: {reason}; install with `{}`",
            code.name(),
            decks::INSTALL_HINT
        );
        return None;
    }
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(dir);
    let _ = std::fs::remove_dir_all(&dir);
    let options = ReferenceOptions {
        code,
        runner: RunnerOptions {
            np: None,
            stop: None,
            timeout: std::time::Duration::from_secs(timeout_s),
        },
        ..ReferenceOptions::default()
    };
    let run = run_reference(scene, &dir, &options).expect("deck, run and post-processing");
    assert!(
        matches!(run.status, RunStatus::Completed { .. }),
        "{}: {:?}",
        code.name(),
        run.status
    );
    Some((run, dir))
}
