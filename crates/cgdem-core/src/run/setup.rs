//! Setting a run up: the scene's particles as inserted, its bodies, walls, and the linearized
//! contacts that give its time step.

use crate::bodies::{fcc_sites_inside, Body, BodyShape, KinematicParticles, Motion};
use crate::contact::PairLaw;
use crate::geometry::{Aabb, Bvh, FastWindingNumber, FinitePlane, MeshSurface, SdfGrid};
use crate::insertion::{insert_random_where, lattice_sites};
use crate::math::{Real, Vec3};
use crate::particles::Particles;
use crate::scene::{BodyContact, InsertAmount, MeshSource, Scene};
use crate::timestep::LinearContact;
use crate::walls::{Wall, WallLaw, WallSet};

use super::laws::{with_laws, LawVisitor};
use super::RunError;

/// Linearized contacts of every species pair and every species against a wall.
pub fn linear_contacts<L: PairLaw, W: WallLaw>(
    scene: &Scene,
    law: &L,
    wall_law: &W,
) -> Vec<LinearContact> {
    let n = scene.species.len();
    let mut contacts = Vec::new();
    for (a, sa) in scene.species.iter().enumerate() {
        for (b, sb) in scene.species.iter().enumerate().skip(a) {
            // Two frozen particles never meet; against a frozen one, the mobile mass moves.
            let m_eff = match (sa.frozen, sb.frozen) {
                (true, true) => continue,
                (true, false) => sb.mass(),
                (false, true) => sa.mass(),
                (false, false) => sa.mass() * sb.mass() / (sa.mass() + sb.mass()),
            };
            let (k, gamma) = law.linearized(a * n + b, sa.radius(), sb.radius(), m_eff);
            contacts.push(LinearContact {
                label: format!("{}-{} particle", sa.name, sb.name),
                stiffness: k,
                damping: gamma,
                mass: m_eff,
            });
        }
        if sa.frozen {
            continue;
        }
        for material in wall_materials_in_use(scene) {
            let (k, gamma) = wall_law.linearized(a, material, sa.radius(), sa.mass());
            let label = match material {
                0 => format!("{}-wall", sa.name),
                k => format!(
                    "{}-wall {}",
                    sa.name,
                    scene.wall_contact.materials[k - 1].name
                ),
            };
            contacts.push(LinearContact {
                label,
                stiffness: k,
                damping: gamma,
                mass: sa.mass(),
            });
        }
    }
    contacts
}

/// The wall materials (0: the default) of the scene's walls and SDF bodies, each once, in
/// order.
fn wall_materials_in_use(scene: &Scene) -> Vec<usize> {
    let walls = scene.walls.iter().map(|w| w.material);
    // Bodies built of particles are material 0: they counted as walls before materials.
    let bodies = scene.bodies.iter().map(|b| b.material);
    let mut used: Vec<usize> = walls.chain(bodies).collect();
    used.sort_unstable();
    used.dedup();
    used
}

/// The scene's particles as inserted, before any step (the reference codes start from them);
/// none overlaps a body.
pub fn initial_particles(
    scene: &Scene,
    rotation: bool,
    bodies: &[Body],
) -> Result<Particles, RunError> {
    initial_particles_with_bodies(scene, rotation, bodies, &[]).map(|(p, _)| p)
}

/// The particles a run of the scene starts with, clear of its SDF bodies and with the
/// particles of bodies built of particles first (frozen): what the reference codes start from,
/// with their spins when the law rotates.
pub fn initial_particles_clear_of_bodies(scene: &Scene) -> Result<Particles, RunError> {
    // With a rotating law the spins given (insert omega, read_data, [[particle]]) go into
    // the deck's Velocities section.
    let rotation = matches!(scene.contact, crate::scene::ContactSettings::Hertz(_));
    if scene.bodies.is_empty() {
        return initial_particles(scene, rotation, &[]);
    }
    struct Bodies<'s>(&'s Scene);
    impl LawVisitor for Bodies<'_> {
        type Output = Result<(Vec<Body>, Vec<(usize, Vec<Vec3>)>), RunError>;
        fn visit<L: PairLaw, W: WallLaw>(self, _law: L, wall_law: W) -> Self::Output {
            build_bodies(self.0, &wall_law)
        }
    }
    let (bodies, sites) = with_laws(scene, Bodies(scene))??;
    initial_particles_with_bodies(scene, rotation, &bodies, &sites).map(|(p, _)| p)
}

/// As [`initial_particles`], with the particles of bodies built of particles first (`sites`:
/// per such body, its index in `bodies` and its lattice sites), frozen, and the record that
/// moves them with their bodies.
pub fn initial_particles_with_bodies(
    scene: &Scene,
    rotation: bool,
    bodies: &[Body],
    sites: &[(usize, Vec<Vec3>)],
) -> Result<(Particles, Vec<KinematicParticles>), RunError> {
    let file = scene.source.display().to_string();
    let mut particles = Particles::new(rotation);
    let mut kinematic = Vec::new();
    for (body, positions) in sites {
        let Some(bp) = &scene.bodies[*body].particles else {
            continue;
        };
        let species = &scene.species[bp.species];
        let first = particles.len();
        for &x in positions {
            particles.push(bp.species as u16, x, species.radius(), species.mass());
            particles.freeze(particles.len() - 1);
        }
        kinematic.push(KinematicParticles {
            body: *body,
            first_id: first as u32,
            reference: positions.clone(),
        });
    }
    for given in &scene.particles {
        let species = &scene.species[given.species];
        let k = particles.len();
        particles.push(
            given.species as u16,
            given.position,
            species.radius(),
            species.mass(),
        );
        particles.velocity[k] = given.velocity;
        if let Some(angular) = particles.angular.as_mut() {
            angular.omega[k] = given.omega;
        }
        if species.frozen {
            particles.freeze(k);
        }
    }
    for (index, ins) in scene.insertions.iter().enumerate() {
        let species = &scene.species[ins.species];
        let radius = species.radius();
        let count = match ins.amount {
            InsertAmount::Count(n) => Some(n),
            InsertAmount::SolidVolume(v) => Some(
                (v / (std::f64::consts::PI / 6.0 * species.diameter.powi(3)))
                    .round()
                    .max(1.0) as u64,
            ),
            InsertAmount::Lattice(_) => None,
        };
        let region = match &ins.mesh {
            None => None,
            Some(source) => Some(source.load().map_err(|message| RunError::Geometry {
                file: file.clone(),
                field: format!("insert[{index}].mesh"),
                message,
            })?),
        };
        let bvh = region.as_ref().map(Bvh::new);
        let winding = bvh.as_ref().map(FastWindingNumber::new);
        // Inside the region by at least one radius, and clear of every body.
        let accept = |p: Vec3| {
            if let (Some(bvh), Some(winding)) = (&bvh, &winding) {
                if !winding.is_inside(p) || bvh.nearest_within(p, radius).is_some() {
                    return false;
                }
            }
            bodies
                .iter()
                .all(|b| b.query(p, radius).is_none_or(|(d, _)| d > radius))
        };
        let first = particles.len();
        match (count, &ins.amount) {
            (Some(count), _) => insert_random_where(
                &mut particles,
                ins.species as u16,
                radius,
                species.mass(),
                ins.lo,
                ins.hi,
                count,
                ins.seed,
                ins.overlap,
                accept,
            )
            .map_err(|source| RunError::Insertion {
                file: file.clone(),
                index,
                source,
            })?,
            (None, InsertAmount::Lattice(lattice)) => {
                let sites = lattice_sites(lattice, ins.lo, ins.hi, radius);
                for p in sites.into_iter().filter(|&p| accept(p)) {
                    if let Some(k) = (0..first).find(|&k| {
                        (particles.position[k] - p).length() < particles.radius[k] + radius
                    }) {
                        return Err(RunError::LatticeOverlap {
                            file: file.clone(),
                            index,
                            site: p.to_array(),
                            id: particles.id[k],
                        });
                    }
                    particles.push(ins.species as u16, p, radius, species.mass());
                }
            }
            (None, _) => unreachable!("only a lattice has no count"),
        }
        for v in &mut particles.velocity[first..] {
            *v = ins.velocity;
        }
        if let Some(angular) = particles.angular.as_mut() {
            angular.omega[first..].fill(ins.omega);
        }
        if species.frozen {
            for k in first..particles.len() {
                particles.freeze(k);
            }
        }
    }
    Ok((particles, kinematic))
}

/// The scene's bodies as SDF grids, posed at t = 0; bodies without a start stage move from
/// the start.
///
/// A body built of particles gets no grid: its particles are the fcc sites inside its mesh
/// (nearest-neighbour distance = the species' diameter, one site on the body's axis point)
/// whose spheres are clear of every SDF body by the wall law's reach, returned with the
/// body's index.
#[allow(clippy::type_complexity)]
pub fn build_bodies<W: WallLaw>(
    scene: &Scene,
    wall_law: &W,
) -> Result<(Vec<Body>, Vec<(usize, Vec<Vec3>)>), RunError> {
    let file = scene.source.display().to_string();
    let mut bodies = Vec::new();
    let mut particle_meshes = Vec::new();
    for (k, b) in scene.bodies.iter().enumerate() {
        let error = |message: String| RunError::Geometry {
            file: file.clone(),
            field: format!("body[{k}]"),
            message,
        };
        let mesh = b.load_mesh().map_err(error)?;
        let motion = Motion::rotation_rpm(b.axis, b.point, b.rpm).with_velocity(b.velocity);
        if b.particles.is_some() {
            // Shape set below, once the SDF bodies exist.
            particle_meshes.push((k, mesh));
            let empty = Aabb {
                min: b.point,
                max: b.point,
            };
            let mut body = Body::new(b.name.clone(), BodyShape::Particles(empty), motion);
            if b.start_stage.is_none() {
                body.start(0.0);
            }
            bodies.push(body);
            continue;
        }
        if b.contact == BodyContact::Mesh {
            let surface = MeshSurface::new(&mesh).map_err(|e| {
                let file = match &b.mesh {
                    MeshSource::Stl(path) => format!("{}: ", path.display()),
                    _ => String::new(),
                };
                RunError::Geometry {
                    file: scene.source.display().to_string(),
                    field: format!("body[{k}].mesh"),
                    message: format!("{file}{e}"),
                }
            })?;
            let mut body = Body::new(b.name.clone(), BodyShape::Mesh(Box::new(surface)), motion);
            body.material = b.material;
            if b.start_stage.is_none() {
                body.start(0.0);
            }
            bodies.push(body);
            continue;
        }
        let padding = b
            .padding
            .unwrap_or(3.0 * b.cell_size + scene.max_diameter());
        let grid =
            SdfGrid::from_mesh(&mesh, b.cell_size, padding).map_err(|e| error(e.to_string()))?;
        let mut body = Body::new(b.name.clone(), BodyShape::Grid(grid), motion);
        body.material = b.material;
        if b.start_stage.is_none() {
            body.start(0.0);
        }
        bodies.push(body);
    }
    let mut sites = Vec::new();
    for (k, mesh) in particle_meshes {
        let b = &scene.bodies[k];
        let Some(bp) = &b.particles else { continue };
        let species = &scene.species[bp.species];
        let (radius, reach) = (
            species.radius(),
            wall_law.reach(bp.species, species.radius()),
        );
        let clear = |p: Vec3| {
            bodies
                .iter()
                .all(|o| o.query(p, reach).is_none_or(|(d, _)| d > radius.max(reach)))
        };
        let kept: Vec<Vec3> = fcc_sites_inside(&mesh, species.diameter, b.point)
            .into_iter()
            .filter(|&p| clear(p))
            .collect();
        if kept.is_empty() {
            return Err(RunError::Geometry {
                file: file.clone(),
                field: format!("body[{k}].particles"),
                message: format!(
                    "no fcc site of spacing {} m (the diameter of species `{}`) lies inside the mesh clear of the other bodies; use a smaller diameter",
                    species.diameter, species.name
                ),
            });
        }
        let mut bounds = Aabb {
            min: Vec3::splat(Real::INFINITY),
            max: Vec3::splat(Real::NEG_INFINITY),
        };
        for &p in &kept {
            bounds = bounds.grown(p);
        }
        let mut body = Body::new(
            b.name.clone(),
            BodyShape::Particles(bounds),
            bodies[k].motion,
        );
        if b.start_stage.is_none() {
            body.start(0.0);
        }
        bodies[k] = body;
        sites.push((k, kept));
    }
    Ok((bodies, sites))
}

/// The scene's walls as planes bounded by the box.
pub fn scene_walls(scene: &Scene) -> WallSet {
    // Scene walls are bounded by the box: half-extents of the box diagonal cover it.
    let half = scene.domain.length().length();
    WallSet {
        walls: scene
            .walls
            .iter()
            .map(|w| Wall {
                name: w.name.clone(),
                plane: FinitePlane::new(w.point, w.normal, half, half),
                active: true,
                material: w.material,
            })
            .collect(),
    }
}
