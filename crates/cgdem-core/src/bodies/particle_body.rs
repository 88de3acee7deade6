//! Bodies built of particles (paper A sec. 4, Fig. 4): particles of a frozen species on an
//! fcc lattice fitted inside a closed mesh, moved each step with the body's prescribed motion
//! (position from the pose, velocity `omega x r + v`), so they meet the grains through the
//! scene's pair law.

use rayon::prelude::*;

use super::{Body, BodyLoad};
use crate::geometry::{Bvh, FastWindingNumber, TriMesh};
use crate::math::{Real, Vec3};
use crate::particles::Particles;

/// The sites of an fcc lattice with nearest-neighbour distance `spacing` (cube edge
/// `sqrt(2) spacing`), one site at `origin`, axes along x, y, z, whose points lie inside
/// `mesh` by the generalized winding number. Ordered by z, then y, then x, then basis site.
pub fn fcc_sites_inside(mesh: &TriMesh, spacing: Real, origin: Vec3) -> Vec<Vec3> {
    let bvh = Bvh::new(mesh);
    let winding = FastWindingNumber::new(&bvh);
    let bounds = mesh.bounding_box();
    let a = spacing * std::f64::consts::SQRT_2;
    let basis = [
        Vec3::ZERO,
        Vec3::new(0.5 * a, 0.5 * a, 0.0),
        Vec3::new(0.5 * a, 0.0, 0.5 * a),
        Vec3::new(0.0, 0.5 * a, 0.5 * a),
    ];
    let range = |lo: Real, hi: Real| ((lo / a).floor() as i64 - 1)..=((hi / a).ceil() as i64);
    let (lo, hi) = (bounds.min - origin, bounds.max - origin);
    let candidates: Vec<Vec3> = range(lo.z, hi.z)
        .flat_map(|k| range(lo.y, hi.y).map(move |j| (j, k)))
        .flat_map(|(j, k)| range(lo.x, hi.x).map(move |i| (i, j, k)))
        .flat_map(|(i, j, k)| {
            let corner = origin + a * Vec3::new(i as Real, j as Real, k as Real);
            basis.map(|b| corner + b)
        })
        .filter(|p| p.cmpge(bounds.min).all() && p.cmple(bounds.max).all())
        .collect();
    let inside: Vec<bool> = candidates
        .par_iter()
        .map(|&p| winding.is_inside(p))
        .collect();
    candidates
        .into_iter()
        .zip(inside)
        .filter_map(|(p, keep)| keep.then_some(p))
        .collect()
}

/// The particles that make up one body: particle ids `first_id .. first_id + reference.len()`
/// with their positions in the body frame (the world positions when the motion starts).
#[derive(Clone, Debug, PartialEq)]
pub struct KinematicParticles {
    /// Index of the driving body in the world's bodies.
    pub body: usize,
    pub first_id: u32,
    pub reference: Vec<Vec3>,
}

impl KinematicParticles {
    /// Body-frame position of the particle with `id`, if it belongs to this body.
    #[inline(always)]
    pub fn reference_of(&self, id: u32) -> Option<Vec3> {
        id.checked_sub(self.first_id)
            .and_then(|k| self.reference.get(k as usize))
            .copied()
    }

    /// The load of the grains on this body's particles among the first `n` of `p`, after a
    /// force evaluation: the contact force `F - m g` on each and its torque about `center`
    /// (the body's axis point), summed in index order.
    pub fn load(&self, p: &Particles, n: usize, gravity: Vec3, center: Vec3) -> BodyLoad {
        let mut load = BodyLoad::default();
        for k in 0..n {
            if self.reference_of(p.id[k]).is_some() {
                let f = p.force[k] - p.mass[k] * gravity;
                load.force += f;
                load.torque += (p.position[k] - center).cross(f);
            }
        }
        load
    }

    /// Moves this body's particles among the first `n` of `p` to `body`'s pose: position
    /// `c + R (q - point)`, velocity `omega x r + v` and, where particles spin, the body's
    /// angular velocity (the material of a rigid body turns with it, so a contact point on a
    /// body particle moves as the body's surface does; LAMMPS's `fix move rotate` does the
    /// same).
    pub fn drive(&self, body: &Body, p: &mut Particles, n: usize) {
        for k in 0..n {
            if let Some(q) = self.reference_of(p.id[k]) {
                let x = body.to_world(q);
                p.position[k] = x;
                p.velocity[k] = body.surface_velocity(x);
                if let Some(angular) = p.angular.as_mut() {
                    angular.omega[k] = body.angular_velocity();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{sphere_mesh, winding_number};

    fn cube_mesh(side: Real) -> TriMesh {
        let v: Vec<Vec3> = (0..8)
            .map(|k| {
                side * Vec3::new(
                    (k & 1) as Real,
                    ((k >> 1) & 1) as Real,
                    ((k >> 2) & 1) as Real,
                )
            })
            .collect();
        // Outward-oriented faces of the unit cube (vertex k = x + 2y + 4z).
        let t = vec![
            [0, 2, 1],
            [1, 2, 3], // z = 0
            [4, 5, 6],
            [5, 7, 6], // z = 1
            [0, 1, 4],
            [1, 5, 4], // y = 0
            [2, 6, 3],
            [3, 6, 7], // y = 1
            [0, 4, 2],
            [2, 4, 6], // x = 0
            [1, 3, 5],
            [3, 7, 5], // x = 1
        ];
        TriMesh::new(v, t)
    }

    #[test]
    fn fcc_in_a_cube_has_the_closed_form_count_and_nearest_neighbours_at_the_spacing() {
        // Cube edge a = sqrt(2) s, origin at the cube's corner shifted inside by a/4: in a
        // box of 4 x 4 x 4 cells there are 4 * 4^3 = 256 sites, none on the faces.
        let s = 1e-3;
        let a = s * std::f64::consts::SQRT_2;
        let mesh = cube_mesh(4.0 * a);
        let sites = fcc_sites_inside(&mesh, s, Vec3::splat(0.25 * a));
        assert_eq!(sites.len(), 256);
        let mut nearest = Real::INFINITY;
        for (k, p) in sites.iter().enumerate() {
            for q in &sites[k + 1..] {
                nearest = nearest.min((*p - *q).length());
            }
        }
        assert!((nearest - s).abs() < 1e-12, "{nearest}");
        // Twelve neighbours at the spacing for a site in the middle.
        let centre = sites
            .iter()
            .min_by(|p, q| {
                (**p - Vec3::splat(2.0 * a))
                    .length()
                    .total_cmp(&(**q - Vec3::splat(2.0 * a)).length())
            })
            .unwrap();
        let neighbours = sites
            .iter()
            .filter(|q| ((**q - *centre).length() - s).abs() < 1e-12)
            .count();
        assert_eq!(neighbours, 12);
    }

    use crate::bodies::{Body, BodyShape, Motion};
    use crate::contact::normal::WcaCoefficients;
    use crate::contact::SeedModel;
    use crate::domain::Domain;
    use crate::geometry::Aabb;
    use crate::particles::Particles;
    use crate::simulation::{Decompose, NeighborSettings, World, WorldSetup};
    use crate::walls::WcaWall;

    const R: Real = 0.675e-3;

    /// A ring of `n` frozen particles (species 1) of radius `R` at distance 0.01 m from the z
    /// axis, moved by a body turning at `rpm` about z, then `grains` (species 0, radius R);
    /// no gravity, step `dt`.
    /// A ring of `n` body particles of radius `R` turning about z at `rpm`, and free `grains`;
    /// `spin`: particles carry an angular velocity (as under Hertz-Mindlin).
    fn ring_world(
        n: usize,
        rpm: Real,
        grains: &[Vec3],
        dt: Real,
        spin: bool,
    ) -> World<SeedModel, WcaWall> {
        let wca = WcaCoefficients {
            epsilon: 9.434e-2,
            sigma: 1.203e-3,
        };
        let mass = 1370.0 * 4.0 / 3.0 * std::f64::consts::PI * R.powi(3);
        let law = SeedModel::seed(vec![wca; 4], vec![0.1257; 4], vec![0.1257; 4]);
        let wall = WcaWall::new(&[(wca, mass), (wca, mass)], 0.5, 0.4);
        let mut particles = Particles::new(spin);
        let reference: Vec<Vec3> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as Real / n as Real;
                0.01 * Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        for &q in &reference {
            particles.push(1, q, R, mass);
            particles.freeze(particles.len() - 1);
        }
        for &g in grains {
            particles.push(0, g, R, mass);
        }
        let domain = Domain {
            lo: Vec3::splat(-0.05),
            hi: Vec3::splat(0.05),
            periodic: [false; 3],
        };
        let neighbor = NeighborSettings {
            skin: 0.3 * 2.0 * R,
            resort_every: 1,
        };
        let bounds = Aabb {
            min: Vec3::new(-0.01, -0.01, 0.0),
            max: Vec3::new(0.01, 0.01, 0.0),
        };
        let mut body = Body::new(
            "screw",
            BodyShape::Particles(bounds),
            Motion::rotation_rpm(Vec3::Z, Vec3::ZERO, rpm),
        );
        body.start(0.0);
        let mut setup = WorldSetup::new(particles, domain, law, wall, 2, Vec3::ZERO, dt, neighbor);
        setup.bodies = vec![body];
        setup.kinematic = vec![KinematicParticles {
            body: 0,
            first_id: 0,
            reference,
        }];
        World::new(setup, &Decompose::default()).expect("the ring fits its box")
    }

    #[test]
    fn kinematic_particles_follow_the_prescribed_rotation_exactly() {
        // 600 rpm = 20 pi rad/s; 20,000 steps of 1 us = 0.02 s = 0.2 turns, through many
        // list rebuilds and re-sorts (tip speed 0.63 m/s, skin 0.4 mm).
        let n = 12;
        let mut world = ring_world(n, 600.0, &[], 1e-6, true);
        let omega = 600.0 * std::f64::consts::TAU / 60.0;
        for _ in 0..20_000 {
            world.step();
        }
        assert!(world.list_builds() > 10, "{}", world.list_builds());
        let t = world.time;
        world.sync_particles();
        let p = world.particles();
        assert_eq!(p.len(), n);
        for k in 0..n {
            let id = p.id[k] as usize;
            let a = std::f64::consts::TAU * id as Real / n as Real + omega * t;
            let expected = 0.01 * Vec3::new(a.cos(), a.sin(), 0.0);
            assert!((p.position[k] - expected).length() < 1e-12, "{id}");
            let v = Vec3::new(0.0, 0.0, omega).cross(expected);
            assert!((p.velocity[k] - v).length() < 1e-9, "{id}");
            // The material turns with the body: a contact point moves as its surface does.
            let spin = p.angular.as_ref().expect("spinning particles").omega[k];
            assert_eq!(spin, Vec3::new(0.0, 0.0, omega), "{id}");
            assert!(p.is_frozen(k));
        }
        // Nothing pushed on the ring: no load, no kinetic energy counted for it.
        assert_eq!(world.bodies()[0].axial_torque(), 0.0);
        assert_eq!(world.kinetic_energy(), 0.0);
    }

    #[test]
    fn the_load_on_a_particle_body_is_the_reaction_to_the_grains_with_its_torque() {
        // A grain pressed tangentially against ring particle 0 (at (0.01, 0, 0)), from +y.
        let grain = Vec3::new(0.01, 2.0 * R * 0.99, 0.0);
        let mut world = ring_world(6, 0.0, &[grain], 1e-9, false);
        world.step();
        world.sync_particles();
        let p = world.particles();
        let g = (0..p.len()).find(|&k| !p.is_frozen(k)).unwrap();
        let s = (0..p.len()).find(|&k| p.id[k] == 0).unwrap();
        let on_grain = p.force[g];
        assert!(on_grain.y > 0.0, "{on_grain:?}");
        let load = world.bodies()[0].load;
        assert!((load.force + on_grain).length() <= 1e-12 * on_grain.length());
        let torque = p.position[s].cross(-on_grain);
        assert!((load.torque - torque).length() <= 1e-12 * torque.length());
        // The grain pushes particle 0 toward -y: a torque about -z.
        assert!(world.bodies()[0].axial_torque() < 0.0);
    }

    #[test]
    fn particles_added_later_get_new_ids_after_a_resort() {
        let grains: Vec<Vec3> = (0..5)
            .map(|k| Vec3::new(-0.02 + 0.005 * k as Real, 0.02, 0.0))
            .collect();
        let mut world = ring_world(6, 60.0, &grains, 1e-6, false);
        for _ in 0..50 {
            world.step();
        }
        world.add_particles(0, &[Vec3::new(0.0, -0.03, 0.0)], R, 1e-6);
        let mut ids = world.particles().id.clone();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), 12);
        assert_eq!(*ids.last().unwrap(), 11);
    }

    #[test]
    fn the_seeds_screw_gets_fcc_sites_at_the_fcc_density_all_inside_its_mesh() {
        use crate::geometry::screw_feeder::{screw_mesh, ScrewFeederSpec};
        // r_s / r_p = 0.5 at lambda = 16: spacing 10.8 mm, a site on the axis.
        let mesh = screw_mesh(&ScrewFeederSpec::default());
        let s = 10.8e-3;
        let sites = fcc_sites_inside(&mesh, s, Vec3::ZERO);
        // sqrt(2) / s^3 sites per m^3 of the screw's volume (shaft + flight, 2.85e-3 m^3;
        // the mesh's signed volume counts the 2 mm root overlap twice, +0.4 %).
        // The 8 mm flight is thinner than one spacing, so which sites fall inside depends on
        // how the flight crosses the lattice: the count scatters by a few percent about the
        // density (here 2974 against 3157, -5.8 %; the Fig. 4 run at r_s / r_p = 0.5 used
        // these 2974).
        let expected = mesh.volume() * std::f64::consts::SQRT_2 / s.powi(3);
        let ratio = sites.len() as Real / expected;
        assert!(
            (ratio - 1.0).abs() < 0.08,
            "{} sites, {expected:.0} expected",
            sites.len()
        );
        assert_eq!(sites.len(), 2974);
        // Every centre inside by the exact winding number (one in 7, to keep the test fast).
        for p in sites.iter().step_by(7) {
            assert!(winding_number(&mesh, *p) > 0.5, "{p:?} outside");
        }
        // None beyond the screw's radius or its length.
        for p in &sites {
            assert!(p.y.hypot(p.z) <= 0.1025 + 1e-9 && p.x >= -0.015 - 1e-9 && p.x <= 0.698 + 1e-9);
        }
    }

    #[test]
    fn fcc_in_a_sphere_fills_it_at_the_fcc_density_with_every_centre_inside() {
        let (r, s) = (0.05, 0.004);
        let mesh = sphere_mesh(r, 4);
        let sites = fcc_sites_inside(&mesh, s, Vec3::ZERO);
        // fcc: 4 sites per cube of edge sqrt(2) s, i.e. sqrt(2) / s^3 sites per m^3.
        let expected = mesh.volume() * std::f64::consts::SQRT_2 / s.powi(3);
        assert!(
            (sites.len() as Real / expected - 1.0).abs() < 0.03,
            "{} vs {expected}",
            sites.len()
        );
        for p in &sites {
            assert!(winding_number(&mesh, *p) > 0.5, "{p:?} outside");
        }
    }
}
