//! One impact of the benchmark: a sphere against a rigid plane (the plane `z = 0`) or against
//! a second sphere, run in-process by cgdem's own step under the scene's contact law, from
//! first touch until the surfaces have parted.

use std::path::Path;

use cgdem_core::contact::PairLaw;
use cgdem_core::math::{Real, Vec3};
use cgdem_core::particles::Particles;
use cgdem_core::run::{scene_walls, with_laws, LawVisitor};
use cgdem_core::scene::{apply_overrides, Scene};
use cgdem_core::simulation::{Decompose, NeighborSettings, World, WorldSetup};
use cgdem_core::walls::WallLaw;

/// An isotropic elastic material of the paper's Table 1 (or Kratos's inputs).
#[derive(Clone, Copy, Debug)]
pub struct Material {
    pub youngs_modulus: Real,
    pub poisson_ratio: Real,
    pub density: Real,
}

/// A sphere: its material, radius and initial state.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub material: Material,
    pub radius: Real,
    pub position: Vec3,
    pub velocity: Vec3,
    pub omega: Vec3,
}

/// An impact: one sphere on the plane `z = 0` (`partner` None), or two spheres.
#[derive(Clone, Copy, Debug)]
pub struct Impact {
    pub sphere: Sphere,
    pub partner: Option<Sphere>,
    pub restitution: Real,
    pub friction: Real,
}

/// What one impact gave: the spheres' final velocities and spins, and the contact's largest
/// overlap, largest normal force on the first sphere, and duration.
#[derive(Clone, Copy, Debug, Default)]
pub struct Outcome {
    pub velocity: [Vec3; 2],
    pub omega: [Vec3; 2],
    pub max_overlap: Real,
    pub max_force: Real,
    pub contact_time: Real,
    pub steps: u64,
}

/// A plane "rigid" to nine digits: the paper's plane does not deform.
const RIGID_MODULUS: Real = 1e20;

impl Impact {
    /// The overlap of the contact at the first sphere's position (negative when apart).
    fn overlap(&self, p: &[Vec3; 2]) -> Real {
        match &self.partner {
            None => self.sphere.radius - p[0].z,
            Some(b) => self.sphere.radius + b.radius - (p[1] - p[0]).length(),
        }
    }

    /// The impact's scene: materials, restitution, friction, the plane or the second
    /// species, time step `dt`; `set` are `KEY=VALUE` overrides (the law judged, planted
    /// faults).
    pub fn scene(&self, dt: Real, set: &[cgdem_core::scene::Override]) -> Result<Scene, String> {
        let a = &self.sphere;
        let m = a.material;
        let (mut lo, mut hi) = (Vec3::splat(-4.0 * a.radius), Vec3::splat(4.0 * a.radius));
        let mut species = format!(
            "[[species]]\nname = \"a\"\ndiameter = {:e}\ndensity = {:e}\n",
            2.0 * a.radius,
            m.density
        );
        let mut walls = String::new();
        match &self.partner {
            None => {
                lo.z = -0.5 * a.radius;
                walls = format!(
                    "[[wall]]\nname = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\
                     [wall_contact]\nrestitution = {e:e}\nfriction = {mu:e}\nyoungs_modulus = {RIGID_MODULUS:e}\npoisson_ratio = {nu:e}\n",
                    e = self.restitution,
                    mu = self.friction,
                    nu = m.poisson_ratio
                );
            }
            Some(b) => {
                let reach = b.position.length() + 2.0 * b.radius;
                lo = lo.min(Vec3::splat(-reach));
                hi = hi.max(Vec3::splat(reach));
                species += &format!(
                    "[[species]]\nname = \"b\"\ndiameter = {:e}\ndensity = {:e}\nyoungs_modulus = {:e}\npoisson_ratio = {:e}\n",
                    2.0 * b.radius,
                    b.material.density,
                    b.material.youngs_modulus,
                    b.material.poisson_ratio
                );
            }
        }
        let text = format!(
            "name = \"chung_ooi\"\ngravity = [0.0, 0.0, 0.0]\n\
             [domain]\nlo = [{:e}, {:e}, {:e}]\nhi = [{:e}, {:e}, {:e}]\nperiodic = [false, false, false]\n\
             {species}\
             [contact]\nmodel = \"hertz\"\nyoungs_modulus = {:e}\npoisson_ratio = {:e}\nrestitution = {:e}\nfriction = {:e}\n\
             [time]\ndt = {dt:e}\n[neighbor]\nskin_fraction = 0.1\nresort_every = 0\n\
             [[stage]]\nname = \"impact\"\nduration = {:e}\n[output]\ntimeseries_interval = {:e}\n{walls}",
            lo.x, lo.y, lo.z, hi.x, hi.y, hi.z,
            m.youngs_modulus, m.poisson_ratio, self.restitution, self.friction,
            1e3 * dt, 1e3 * dt,
        );
        let path = Path::new("chung_ooi.toml");
        let text = apply_overrides(&text, path, set).map_err(|e| e.to_string())?;
        Scene::parse(&text, path).map_err(|e| e.to_string())
    }

    /// Steps until the surfaces touch, at the initial closing speed.
    fn steps_to_touch(&self, dt: Real) -> u64 {
        let a = &self.sphere;
        let (gap, closing) = match &self.partner {
            None => (a.position.z - a.radius, -a.velocity.z),
            Some(b) => {
                let n = (b.position - a.position).normalize();
                (
                    (b.position - a.position).length() - a.radius - b.radius,
                    (a.velocity - b.velocity).dot(n),
                )
            }
        };
        (gap / closing / dt).ceil().max(0.0) as u64
    }

    /// Runs the impact under `scene`'s law at time step `dt`, for at most `contact_steps`
    /// steps after the surfaces first touch.
    pub fn run(&self, scene: &Scene, dt: Real, contact_steps: u64) -> Result<Outcome, String> {
        let max_steps = self.steps_to_touch(dt) + contact_steps;
        let mut p = Particles::new(true);
        for (k, s) in std::iter::once(&self.sphere)
            .chain(self.partner.iter())
            .enumerate()
        {
            let sp = &scene.species[k];
            p.push(k as u16, s.position, sp.radius(), sp.mass());
            p.velocity[k] = s.velocity;
            p.angular.as_mut().expect("rotation").omega[k] = s.omega;
        }
        with_laws(
            scene,
            Collide {
                impact: self,
                scene,
                particles: p,
                dt,
                max_steps,
            },
        )
        .map_err(|e| e.to_string())?
    }
}

struct Collide<'a> {
    impact: &'a Impact,
    scene: &'a Scene,
    particles: Particles,
    dt: Real,
    max_steps: u64,
}

impl LawVisitor for Collide<'_> {
    type Output = Result<Outcome, String>;

    fn visit<L: PairLaw, W: WallLaw>(self, law: L, wall_law: W) -> Self::Output {
        let neighbor = NeighborSettings {
            skin: 0.1 * self.scene.max_diameter(),
            resort_every: 0,
        };
        let mass = self.particles.mass[0];
        let mut setup = WorldSetup::new(
            self.particles,
            self.scene.domain.clone(),
            law,
            wall_law,
            self.scene.species.len(),
            Vec3::ZERO,
            self.dt,
            neighbor,
        );
        setup.walls = scene_walls(self.scene);
        let mut world = World::new(setup, &Decompose::default())?;
        let state = |world: &mut World<L, W>| {
            let p = world.synced_particles();
            let omega = &p.angular.as_ref().expect("rotation").omega;
            let (mut x, mut v, mut w) = ([Vec3::ZERO; 2], [Vec3::ZERO; 2], [Vec3::ZERO; 2]);
            for (k, (&id, &wk)) in p.id.iter().zip(omega).enumerate() {
                let i = id as usize;
                (x[i], v[i], w[i]) = (p.position[k], p.velocity[k], wk);
            }
            (x, v, w)
        };
        let mut out = Outcome::default();
        let (mut touched, mut t_in) = (false, 0.0);
        let (x, mut v_prev, _) = state(&mut world);
        let mut overlap_prev = self.impact.overlap(&x);
        for step in 1..=self.max_steps {
            world.step();
            let (x, v, w) = state(&mut world);
            let overlap = self.impact.overlap(&x);
            out.max_force = out
                .max_force
                .max(mass * (v[0] - v_prev[0]).length() / self.dt);
            out.max_overlap = out.max_overlap.max(overlap);
            // Start and end of the contact interpolated between steps.
            let crossing = |a: Real, b: Real| (step - 1) as Real + a / (a - b);
            if !touched && overlap > 0.0 {
                touched = true;
                t_in = crossing(overlap_prev, overlap) * self.dt;
            } else if touched && overlap <= 0.0 {
                out.contact_time = crossing(overlap_prev, overlap) * self.dt - t_in;
                out.velocity = v;
                out.omega = w;
                out.steps = step;
                return Ok(out);
            }
            overlap_prev = overlap;
            v_prev = v;
        }
        Err(format!(
            "the contact did not end within {} steps of {:e} s",
            self.max_steps, self.dt
        ))
    }
}
