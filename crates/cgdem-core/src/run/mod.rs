//! Running a scene: build the world with the scene's laws, run its stages, measure and
//! write the outputs (summary.json, timeseries.csv, profile.csv, repose.csv, VTK series).

mod hertz;
mod progress;

pub use hertz::{hertz_history_wall, hertz_law, hertz_wall, run_hertz, FromScene, SUPPORTED};
pub use progress::{Progress, ProgressReporter, RunProgress};

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::analysis::conveying::{self, ConveyingSample, ConveyingSummary};
use crate::analysis::heap::{self, HeapProfile};
use crate::analysis::{measure_packing, PackingSummary};
use crate::bodies::{fcc_sites_inside, Body, BodyShape, KinematicParticles, Motion};
use crate::contact::normal::WcaCoefficients;
use crate::contact::{PairLaw, SeedModel};
use crate::geometry::{Aabb, Bvh, FastWindingNumber, FinitePlane, SdfGrid};
use crate::guard::{GuardKind, GuardPeaks, GuardSettings, GuardTrip};
use crate::insertion::{insert_random_where, lattice_sites, InsertionFailed};
use crate::io::{vtk::VtkSeries, write_atomic};
use crate::math::{Real, Vec3};
use crate::particles::Particles;
use crate::scene::{ContactSettings, InsertAmount, ReposeSettings, Scene, StageEnd};
use crate::simulation::{NeighborSettings, World};
use crate::timestep::{self, LinearContact, Timescales, UnstableTimeStep};
use crate::walls::{Wall, WallLaw, WallSet, WcaWall};

#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub out_dir: PathBuf,
    /// Where to report progress; `None` reports nothing.
    pub progress: Option<Progress>,
    pub force_dt: bool,
    /// A guard that fires only warns (once per guard) instead of stopping the run.
    pub keep_going: bool,
    /// Start from these particles instead of the scene's insertions (as LAMMPS `read_data`
    /// after `write_data`): the benchmark starts every code from one prepared state.
    pub initial_state: Option<Particles>,
    /// Keep the particles at the end of the run in [`RunSummary::final_state`].
    pub keep_final_state: bool,
    /// Split the box into these subdomains with ghost layers (`--grid`); None: one world.
    pub grid: Option<crate::decomposition::GridSpec>,
}

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    NotAvailable(String),
    #[error("{file}: time step: {source}")]
    TimeStep {
        file: String,
        source: UnstableTimeStep,
    },
    #[error("{file}: insert[{index}]: {source}")]
    Insertion {
        file: String,
        index: usize,
        source: InsertionFailed,
    },
    #[error("{file}: insert[{index}]: the lattice site {site:?} overlaps particle {id} of an earlier insertion; move the lattice's box or the other insertion")]
    LatticeOverlap {
        file: String,
        index: usize,
        site: [Real; 3],
        id: u32,
    },
    #[error("{file}: contact: the combination damping/tangential/rolling/cohesion = {combination} is not compiled; supported: {supported}")]
    Unsupported {
        file: String,
        combination: String,
        supported: String,
    },
    #[error("{file}: {field}: {message}")]
    Geometry {
        file: String,
        field: String,
        message: String,
    },
    #[error("cannot write {path}: {message}")]
    Output { path: PathBuf, message: String },
    #[error("{file}: run stopped: {trip}; the outputs written so far are kept in {}; pass --keep-going to only warn", out_dir.display())]
    Stopped {
        file: String,
        trip: Box<GuardTrip>,
        out_dir: PathBuf,
    },
}

fn output_error(path: &Path, e: impl std::fmt::Display) -> RunError {
    RunError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The angle measured at one time after the repose stage began.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct ReposeSample {
    pub time_after_start_s: Real,
    /// "fixed time" or "stage end" (the stage's own end condition).
    pub trigger: String,
    pub repose_angle_deg: Option<Real>,
    pub repose_fit_r2: Option<Real>,
    pub runout_m: Real,
    pub wall_height_m: Real,
}

impl ReposeSample {
    /// Measures a heap profile by the scene's repose rule (the same for every code).
    pub fn measure(
        profile: &HeapProfile,
        rule: &ReposeSettings,
        max_diameter: Real,
        time_after_start_s: Real,
        trigger: &str,
    ) -> ReposeSample {
        let fit = heap::repose_angle(
            profile,
            2.0 * max_diameter,
            rule.exclude_wall_fraction,
            rule.exclude_toe_fraction,
        );
        ReposeSample {
            time_after_start_s,
            trigger: trigger.to_string(),
            repose_angle_deg: fit.as_ref().map(|f| f.angle_deg),
            repose_fit_r2: fit.as_ref().map(|f| f.r_squared),
            runout_m: profile.front(2.0 * max_diameter) - profile.wall_x,
            wall_height_m: profile.wall_height(),
        }
    }
}

#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct StageRecord {
    pub name: String,
    pub start_s: Real,
    pub end_s: Real,
    pub steps: u64,
    pub ended_by: String,
}

/// Everything `summary.json` holds.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct RunSummary {
    pub case: String,
    pub code: String,
    pub lambda: u32,
    pub cg_rule: crate::coarse_graining::CoarseGrainRule,
    pub n_particles: usize,
    pub n_particles_inserted: usize,
    /// Particles added by top-ups (`[[insert]] refill`).
    pub n_particles_refilled: u64,
    /// Particles that make up bodies built of particles (frozen, counted in `n_particles`).
    pub n_body_particles: usize,
    pub lost_particles: u64,
    pub steps: u64,
    pub dt_s: Real,
    pub contact_period_s: Real,
    pub stable_dt_s: Real,
    pub simulated_s: Real,
    pub wall_s: Real,
    pub particle_steps: u64,
    pub particle_steps_per_s: Real,
    pub threads: usize,
    pub repose_angle_deg: Option<Real>,
    pub repose_fit_r2: Option<Real>,
    pub repose_rule: Option<String>,
    pub runout_m: Option<Real>,
    pub repose_samples: Vec<ReposeSample>,
    pub stages: Vec<StageRecord>,
    /// Particles deleted in `[[delete]]` regions, and their mass.
    pub deleted_particles: u64,
    pub deleted_mass_kg: Real,
    pub conveying: Option<ConveyingSummary>,
    /// Porosity and pore sizes of the bed (`[packing]`), measured when its stage ends.
    pub packing: Option<PackingSummary>,
    pub warnings: Vec<String>,
    /// The guard that stopped the run early, if one did.
    pub stopped_by: Option<GuardTrip>,
    /// How close the run came to the guards' thresholds (none for reference codes).
    pub guard_peaks: Option<GuardPeaks>,
    pub scene_file: String,
    /// `Scene::digest` of the (coarse-grained) scene this run simulated.
    pub scene_digest: String,
    pub cgdem_version: String,
    /// The particles at the end (with `RunOptions::keep_final_state`).
    #[serde(skip)]
    pub final_state: Option<Particles>,
    /// The solver's arrays at the end (none for reference codes).
    pub memory: Option<crate::simulation::MemoryUse>,
}

/// Runs a (possibly coarse-grained) scene and writes its outputs into `options.out_dir`.
pub fn run(scene: &Scene, options: &RunOptions) -> Result<RunSummary, RunError> {
    match &scene.contact {
        ContactSettings::Wca { .. } => {
            let (law, wall_law) = seed_laws(scene);
            execute(scene, law, wall_law, options)
        }
        ContactSettings::Hertz(h) => run_hertz(scene, h, options),
    }
}

/// The time step cgdem uses for a scene (for Hertz, the LIGGGHTS keyword combinations), with the contact time scales behind it
/// (the reference decks run at the same step).
pub fn time_step(
    scene: &Scene,
    force_dt: bool,
) -> Result<(Real, Timescales, Option<String>), RunError> {
    match &scene.contact {
        ContactSettings::Wca { .. } => {
            let (law, wall_law) = seed_laws(scene);
            time_step_for(scene, &law, &wall_law, force_dt)
        }
        ContactSettings::Hertz(h) => hertz::time_step(scene, h, force_dt),
    }
}

pub fn time_step_for<L: PairLaw, W: WallLaw>(
    scene: &Scene,
    law: &L,
    wall_law: &W,
    force_dt: bool,
) -> Result<(Real, Timescales, Option<String>), RunError> {
    let scales = Timescales::of(&linear_contacts(scene, law, wall_law));
    let (dt, warning) = timestep::choose(scene.time_step, &scales, force_dt).map_err(|source| {
        RunError::TimeStep {
            file: scene.source.display().to_string(),
            source,
        }
    })?;
    Ok((dt, scales, warning))
}

/// The seed's particle law and wall law for a scene with `ContactSettings::Wca`.
pub fn seed_laws(scene: &Scene) -> (SeedModel, WcaWall) {
    let ContactSettings::Wca {
        epsilon,
        sigma,
        gamma_n,
        gamma_t,
    } = scene.contact
    else {
        panic!("seed_laws needs a scene with model = \"wca\"");
    };
    let n = scene.species.len();
    // `sigma` belongs to the first mobile species; a pair of other diameters gets it scaled
    // by the mean diameter (Lorentz mixing), so the cut-off `2^(1/6) sigma_ab` stays at the
    // touching distance. Equal diameters: every pair is the scene's `sigma`.
    let reference = scene
        .species
        .iter()
        .find(|s| !s.frozen)
        .unwrap_or(&scene.species[0])
        .diameter;
    let pair = |a: usize, b: usize| WcaCoefficients {
        epsilon,
        sigma: if scene.species[a].diameter == reference && scene.species[b].diameter == reference {
            sigma
        } else {
            sigma * (scene.species[a].diameter + scene.species[b].diameter) / (2.0 * reference)
        },
    };
    let table: Vec<WcaCoefficients> = (0..n * n).map(|ab| pair(ab / n, ab % n)).collect();
    let law = SeedModel::seed(table, vec![gamma_n; n * n], vec![gamma_t; n * n]);
    let per_species: Vec<(WcaCoefficients, Real)> = scene
        .species
        .iter()
        .enumerate()
        .map(|(a, s)| (pair(a, a), s.mass()))
        .collect();
    let wall_law = WcaWall::new(
        &per_species,
        scene.wall_contact.restitution,
        scene.wall_contact.friction,
    );
    (law, wall_law)
}

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
        if !sa.frozen && (!scene.walls.is_empty() || !scene.bodies.is_empty()) {
            let (k, gamma) = wall_law.linearized(a, sa.radius(), sa.mass());
            contacts.push(LinearContact {
                label: format!("{}-wall", sa.name),
                stiffness: k,
                damping: gamma,
                mass: sa.mass(),
            });
        }
    }
    contacts
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
/// particles of bodies built of particles first (frozen): what the reference codes start from.
pub fn initial_particles_clear_of_bodies(scene: &Scene) -> Result<Particles, RunError> {
    if scene.bodies.is_empty() {
        return initial_particles(scene, false, &[]);
    }
    let (bodies, sites) = match &scene.contact {
        ContactSettings::Wca { .. } => build_bodies(scene, &seed_laws(scene).1)?,
        ContactSettings::Hertz(h) => build_bodies(scene, &hertz::hertz_wall(scene, h))?,
    };
    initial_particles_with_bodies(scene, false, &bodies, &sites).map(|(p, _)| p)
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
        let mesh = b.mesh.load().map_err(error)?;
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
        let padding = b
            .padding
            .unwrap_or(3.0 * b.cell_size + scene.max_diameter());
        let grid =
            SdfGrid::from_mesh(&mesh, b.cell_size, padding).map_err(|e| error(e.to_string()))?;
        let mut body = Body::new(b.name.clone(), BodyShape::Grid(grid), motion);
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
            })
            .collect(),
    }
}

fn execute<L: PairLaw, W: WallLaw>(
    scene: &Scene,
    law: L,
    wall_law: W,
    options: &RunOptions,
) -> Result<RunSummary, RunError> {
    let out = &options.out_dir;
    std::fs::create_dir_all(out).map_err(|e| output_error(out, e))?;
    let file = scene.source.display().to_string();
    let (dt, scales, warning) = time_step_for(scene, &law, &wall_law, options.force_dt)?;
    let mut warnings: Vec<String> = warning.into_iter().collect();
    for w in &warnings {
        eprintln!("warning: {w}");
    }

    let (bodies, body_sites) = build_bodies(scene, &wall_law)?;
    let (particles, kinematic) = match &options.initial_state {
        // A given state carries no particle-built bodies (the bench's heap has none).
        Some(_) if !body_sites.is_empty() => {
            return Err(RunError::NotAvailable(format!(
                "{}: starting from a given state is not supported with particle-built bodies",
                scene.source.display()
            )))
        }
        Some(state) => (state.clone(), Vec::new()),
        None => initial_particles_with_bodies(scene, L::NEEDS_ROTATION, &bodies, &body_sites)?,
    };
    let n_inserted = particles.len();
    let n_body_particles: usize = kinematic.iter().map(|k| k.reference.len()).sum();
    let neighbor = NeighborSettings {
        skin: scene.skin_fraction * scene.max_diameter(),
        resort_every: scene.resort_every,
    };
    let mut world = World::new(
        particles,
        scene.domain.clone(),
        scene_walls(scene),
        law,
        wall_law,
        scene.species.len(),
        scene.gravity,
        dt,
        neighbor,
    )
    .with_integrator(scene.integrator);
    world.set_guard_settings(GuardSettings {
        stable_dt: scales.stable_limit,
        // With --keep-going guards only warn: lost particles are removed, as with "warn".
        stop_on_lost: scene.stop_on_lost && !options.keep_going,
        ..GuardSettings::default()
    });
    let mut guard_counts: Vec<(GuardKind, u64)> = Vec::new();
    let mut stopped_by: Option<GuardTrip> = None;
    if !bodies.is_empty() {
        world.set_bodies(bodies);
        world.set_kinematic(kinematic);
    }
    world.set_delete_regions(
        scene
            .deletions
            .iter()
            .map(|&(min, max)| Aabb { min, max })
            .collect(),
    );
    if let Some(spec) = options.grid {
        world.set_grid(spec).map_err(|e| {
            RunError::NotAvailable(format!("{}: --grid {spec}: {e}", scene.source.display()))
        })?;
    }
    let body_columns: String = scene
        .bodies
        .iter()
        .map(|b| format!(",axial_torque_{}_nm", b.name))
        .collect();
    let conveying_body = scene.conveying.as_ref().and_then(|c| {
        scene
            .bodies
            .iter()
            .position(|b| b.name == c.body)
            .map(|k| (c, k))
    });
    let mut conveying_samples: Vec<ConveyingSample> = Vec::new();
    let (mut torque_sum, mut power_sum, mut torque_steps) = (0.0, 0.0, 0u64);
    let mut conveying_window: Option<(Real, Real)> = None;

    let timeseries_path = out.join("timeseries.csv");
    let mut timeseries = std::io::BufWriter::new(
        std::fs::File::create(&timeseries_path).map_err(|e| output_error(&timeseries_path, e))?,
    );
    writeln!(timeseries, "time_s,stage,kinetic_energy_j,kinetic_energy_per_mass_j_kg,n_particles,front_m,wall_height_m,deleted_mass_kg{body_columns}{},mechanical_energy_j", if conveying_body.is_some() { ",fill_ratio,bulk_density_kg_m3,passed_mass_kg" } else { "" }).map_err(|e| output_error(&timeseries_path, e))?;
    let mut vtk = if scene.output.vtk_interval > 0.0 {
        Some(
            VtkSeries::new(&out.join("vtk"), "particles")
                .map_err(|e| output_error(&out.join("vtk"), e))?,
        )
    } else {
        None
    };

    let max_diameter = scene.max_diameter();
    let floor_z = scene.domain.lo.z;
    let heap_profile = |world: &World<L, W>| -> Option<HeapProfile> {
        scene.repose.as_ref().map(|r| {
            heap::profile(
                &world.particles.position,
                &world.particles.radius,
                r.wall_x,
                scene.domain.hi.x,
                floor_z,
                r.bin_width_diameters * max_diameter,
            )
        })
    };
    let sample = |world: &World<L, W>,
                  time_after_start_s: Real,
                  trigger: &str|
     -> Option<(ReposeSample, HeapProfile)> {
        let rule = scene.repose.as_ref()?;
        let profile = heap_profile(world)?;
        Some((
            ReposeSample::measure(&profile, rule, max_diameter, time_after_start_s, trigger),
            profile,
        ))
    };

    let total_estimate: Real = scene
        .stages
        .iter()
        .map(|s| match s.end {
            StageEnd::Duration(d) => d,
            StageEnd::Settled { max_duration, .. } => max_duration,
        })
        .sum();
    let mut progress: Box<dyn RunProgress> = match &options.progress {
        Some(Progress(reporter)) => reporter.start((total_estimate / dt).ceil() as u64),
        None => Box::new(progress::Silent),
    };

    let refill_regions: Vec<(usize, RefillRegion)> = scene
        .insertions
        .iter()
        .enumerate()
        .filter(|(_, ins)| ins.refill.is_some())
        .map(|(k, ins)| RefillRegion::new(scene, k, ins).map(|r| (k, r)))
        .collect::<Result<_, _>>()?;
    let mut refilled: u64 = 0;
    let started = Instant::now();
    let mut particle_steps: u64 = 0;
    let mut stages = Vec::new();
    let mut samples = Vec::new();
    let mut next_row = 0.0;
    let mut next_frame = 0.0;
    let mut final_profile = None;
    let mut packing = None;
    'stages: for stage in &scene.stages {
        world.reset_energy_reference();
        for name in &stage.remove_walls {
            world.walls.remove(name);
        }
        for b in &scene.bodies {
            if b.start_stage.as_deref() == Some(stage.name.as_str()) {
                world.start_body(&b.name);
            }
        }
        progress.stage(&stage.name);
        let start = world.time;
        // Top-ups of this stage: (insertion, region, particles it held at the stage start,
        // top-ups so far).
        let mut refills: Vec<(usize, &RefillRegion, usize, u64)> = refill_regions
            .iter()
            .filter(|(k, _)| {
                scene.insertions[*k]
                    .refill
                    .as_ref()
                    .is_some_and(|r| r.stage == stage.name)
            })
            .map(|(k, region)| (*k, region, region.count(&world.particles), 0))
            .collect();
        let measuring = conveying_body.filter(|(c, _)| c.stage == stage.name);
        let start_steps = world.steps;
        let (duration, settle_threshold, min_duration) = match stage.end {
            StageEnd::Duration(d) => (d, None, d),
            StageEnd::Settled {
                kinetic_energy_per_mass,
                min_duration,
                max_duration,
            } => (max_duration, Some(kinetic_energy_per_mass), min_duration),
        };
        let stage_steps = (duration / dt).round() as u64;
        let repose_times: Vec<Real> = match &scene.repose {
            Some(r) if r.stage == stage.name => r.at_times.clone(),
            _ => Vec::new(),
        };
        let mut next_sample = 0;
        let mut ended_by = format!("duration {duration} s");
        for k in 1..=stage_steps {
            world.step();
            particle_steps += world.particles.len() as u64;
            if let Some(trip) = world.take_guard_trip() {
                if !options.keep_going {
                    stages.push(StageRecord {
                        name: stage.name.clone(),
                        start_s: start,
                        end_s: world.time,
                        steps: world.steps - start_steps,
                        ended_by: format!("stopped by the {} guard", trip.kind.name()),
                    });
                    stopped_by = Some(trip);
                    break 'stages;
                }
                // Warn once per guard; count the rest. A new energy reference, so the
                // energy guard judges what follows.
                world.reset_energy_reference();
                match guard_counts.iter_mut().find(|(kind, _)| *kind == trip.kind) {
                    Some((_, count)) => *count += 1,
                    None => {
                        let w = format!("--keep-going: {trip}");
                        eprintln!("warning: {w}");
                        warnings.push(w);
                        guard_counts.push((trip.kind, 1));
                    }
                }
            }
            for (index, region, target, done) in &mut refills {
                let ins = &scene.insertions[*index];
                let interval = ins.refill.as_ref().map_or(Real::INFINITY, |r| r.interval);
                if world.time - start + 0.5 * dt >= (*done + 1) as Real * interval {
                    *done += 1;
                    let seed = ins.seed.wrapping_add(1_000_003 * *done);
                    let added = region.top_up(&world.particles, world.bodies(), *target, seed);
                    let species = &scene.species[ins.species];
                    world.add_particles(
                        ins.species as u16,
                        &added,
                        species.radius(),
                        species.mass(),
                    );
                    refilled += added.len() as u64;
                }
            }
            if let Some((c, k)) = measuring {
                if world.time - start >= c.discard - 0.5 * dt {
                    let body = &world.bodies()[k];
                    torque_sum -= body.axial_torque();
                    power_sum += body.drive_power();
                    torque_steps += 1;
                }
            }
            if k % 256 == 0 {
                progress.advance(256);
            }
            let elapsed = world.time - start;
            if world.time + 0.5 * dt >= next_row {
                next_row += scene.output.timeseries_interval;
                let ke = world.kinetic_energy();
                let mass = world.particles.mobile_mass();
                let profile = heap_profile(&world);
                let front = profile.as_ref().map(|p| p.front(2.0 * max_diameter));
                let wall_height = profile.as_ref().map(|p| p.wall_height());
                let opt = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6e}"));
                let mut extra = format!(",{:.9e}", world.deleted_mass);
                for body in world.bodies() {
                    extra += &format!(",{:.6e}", body.axial_torque());
                }
                if let Some((c, k)) = conveying_body {
                    let body = &world.bodies()[k];
                    // The grains only: a body's own (frozen) particles are not material.
                    let p = &world.particles;
                    let mobile: Vec<usize> = (0..p.len()).filter(|&k| !p.is_frozen(k)).collect();
                    let position: Vec<Vec3> = mobile.iter().map(|&k| p.position[k]).collect();
                    let radius: Vec<Real> = mobile.iter().map(|&k| p.radius[k]).collect();
                    let mass: Vec<Real> = mobile.iter().map(|&k| p.mass[k]).collect();
                    let sample = ConveyingSample {
                        time: world.time,
                        passed_mass: conveying::passed_mass(
                            c,
                            body.motion.axis,
                            body.motion.point,
                            &position,
                            &mass,
                            world.deleted_mass,
                        ),
                        fill_ratio: conveying::fill_ratio(
                            c,
                            body.motion.axis,
                            body.motion.point,
                            &position,
                            &radius,
                        ),
                        bulk_density: conveying::bulk_density(c, &position, &mass),
                    };
                    extra += &format!(
                        ",{:.6e},{:.6e},{:.9e}",
                        sample.fill_ratio, sample.bulk_density, sample.passed_mass
                    );
                    if measuring.is_some() {
                        conveying_samples.push(sample);
                    }
                }
                // Kinetic plus gravitational energy, for the stability suite's energy balance.
                extra += &format!(",{:.9e}", world.mechanical_energy());
                writeln!(
                    timeseries,
                    "{:.9e},{},{:.9e},{:.9e},{},{},{}{extra}",
                    world.time,
                    stage.name,
                    ke,
                    ke / mass.max(Real::MIN_POSITIVE),
                    world.particles.len(),
                    opt(front),
                    opt(wall_height)
                )
                .map_err(|e| output_error(&timeseries_path, e))?;
                timeseries
                    .flush()
                    .map_err(|e| output_error(&timeseries_path, e))?;
                if let Some(threshold) = settle_threshold {
                    if elapsed >= min_duration && ke / mass < threshold {
                        ended_by = format!(
                            "kinetic energy per mass {:.3e} J/kg < {threshold:.3e} J/kg",
                            ke / mass
                        );
                        break;
                    }
                }
            }
            if let Some(series) = &mut vtk {
                if world.time + 0.5 * dt >= next_frame {
                    next_frame += scene.output.vtk_interval;
                    series
                        .write_frame(&world.particles, world.time)
                        .map_err(|e| output_error(&out.join("vtk"), e))?;
                }
            }
            if next_sample < repose_times.len() && elapsed + 0.5 * dt >= repose_times[next_sample] {
                if let Some((s, profile)) = sample(&world, repose_times[next_sample], "fixed time")
                {
                    samples.push(s);
                    write_measurements(out, &samples, &profile)?;
                    final_profile = Some(profile);
                }
                next_sample += 1;
            }
        }
        let measures_at_end = scene
            .repose
            .as_ref()
            .is_some_and(|r| r.stage == stage.name && r.at_stage_end);
        if measures_at_end {
            if let Some((s, profile)) = sample(&world, world.time - start, "stage end") {
                samples.push(s);
                write_measurements(out, &samples, &profile)?;
                final_profile = Some(profile);
            }
        }
        if settle_threshold.is_some() && ended_by.starts_with("duration") {
            let w = format!(
                "stage `{}` did not settle within max_duration {duration} s",
                stage.name
            );
            eprintln!("warning: {w}");
            warnings.push(w);
        }
        if let Some((c, _)) = measuring {
            conveying_window = Some((start + c.discard, world.time));
        }
        if let Some(pk) = scene.packing.as_ref().filter(|p| p.stage == stage.name) {
            let (lo, hi) = (scene.domain.lo, scene.domain.hi);
            match measure_packing(
                &world.particles.position,
                &world.particles.radius,
                [lo.x, lo.y],
                [hi.x, hi.y],
                floor_z,
                &pk.rule,
                pk.voxels_per_diameter,
                pk.bin_width_diameters,
            ) {
                Ok(m) => {
                    let path = out.join("pore_size.csv");
                    let mut csv = Vec::new();
                    m.pore_sizes
                        .write_csv(&mut csv)
                        .map_err(|e| output_error(&path, e))?;
                    write_atomic(&path, &csv).map_err(|e| output_error(&path, e))?;
                    packing = Some(m.summary);
                }
                Err(e) => {
                    let w = format!(
                        "packing: not measured at the end of stage `{}`: {e}",
                        stage.name
                    );
                    eprintln!("warning: {w}");
                    warnings.push(w);
                }
            }
        }
        stages.push(StageRecord {
            name: stage.name.clone(),
            start_s: start,
            end_s: world.time,
            steps: world.steps - start_steps,
            ended_by,
        });
    }
    progress.finish();
    for (kind, count) in guard_counts.iter().filter(|(_, count)| *count > 1) {
        let w = format!(
            "--keep-going: the {} guard fired in {count} steps",
            kind.name()
        );
        eprintln!("warning: {w}");
        warnings.push(w);
    }
    let wall_s = started.elapsed().as_secs_f64();
    if world.lost > 0 {
        let w = format!(
            "{} particles left the box through a bounded face and were removed",
            world.lost
        );
        eprintln!("warning: {w}");
        warnings.push(w);
    }

    let conveying_summary = match (conveying_body, conveying_window) {
        (Some((c, k)), Some((t0, t1))) => {
            let n = torque_steps.max(1) as Real;
            let summary = conveying::summarize(
                c,
                scene.bodies[k].rpm,
                scene.species[0].density,
                &conveying_samples,
                t0,
                t1,
                torque_sum / n,
                power_sum / n,
            );
            if summary.is_none() {
                let w = format!("conveying: too few time-series samples after the discarded {} s for {} blocks; shorten output.timeseries_interval or run longer", c.discard, c.blocks);
                eprintln!("warning: {w}");
                warnings.push(w);
            }
            summary
        }
        _ => None,
    };
    if final_profile.is_none() && stopped_by.is_none() {
        if let Some(profile) = heap_profile(&world) {
            write_measurements(out, &samples, &profile)?;
        }
    }
    let headline = headline_sample(&samples);
    let summary = RunSummary {
        case: scene.name.clone(),
        code: "cgdem".into(),
        lambda: scene.lambda,
        cg_rule: scene.cg_rule,
        n_particles: world.particles.len(),
        n_particles_inserted: n_inserted,
        n_particles_refilled: refilled,
        n_body_particles,
        lost_particles: world.lost,
        steps: world.steps,
        dt_s: dt,
        contact_period_s: scales.shortest_period,
        stable_dt_s: scales.stable_limit,
        simulated_s: world.time,
        wall_s,
        particle_steps,
        particle_steps_per_s: particle_steps as Real / wall_s.max(1e-9),
        threads: rayon::current_num_threads(),
        repose_angle_deg: headline.and_then(|s| s.repose_angle_deg),
        repose_fit_r2: headline.and_then(|s| s.repose_fit_r2),
        repose_rule: scene.repose.as_ref().map(|r| {
            let when = if r.at_stage_end {
                let end = scene.stages.iter().find(|s| s.name == r.stage).map(|s| describe_end(&s.end)).unwrap_or_default();
                format!("at the end of stage `{}` ({end})", r.stage)
            } else {
                format!("{} s after stage `{}` began", r.at_times.last().copied().unwrap_or(0.0), r.stage)
            };
            format!(
                "least-squares line through the surface profile (bins of {} diameters) between {}% of the run-out from the wall and {}% before the front (deposit >= 2 diameters deep), measured {when}",
                r.bin_width_diameters,
                r.exclude_wall_fraction * 100.0,
                r.exclude_toe_fraction * 100.0,
            )
        }),
        runout_m: headline.map(|s| s.runout_m),
        repose_samples: samples,
        stages,
        deleted_particles: world.deleted,
        deleted_mass_kg: world.deleted_mass,
        conveying: conveying_summary,
        packing,
        warnings,
        stopped_by: stopped_by.clone(),
        guard_peaks: Some(world.guard_peaks()),
        scene_file: file.clone(),
        scene_digest: scene.digest(),
        cgdem_version: env!("CARGO_PKG_VERSION").into(),
        final_state: options.keep_final_state.then(|| world.particles.clone()),
        memory: Some(world.memory_use()),
    };
    let path = out.join("summary.json");
    let json = serde_json::to_string_pretty(&summary).map_err(|e| output_error(&path, e))?;
    write_atomic(&path, json.as_bytes()).map_err(|e| output_error(&path, e))?;
    match stopped_by {
        Some(trip) => Err(RunError::Stopped {
            file,
            trip: Box::new(trip),
            out_dir: out.clone(),
        }),
        None => Ok(summary),
    }
}

/// How a stage ends, in words for the summary.
fn describe_end(end: &StageEnd) -> String {
    match end {
        StageEnd::Duration(d) => format!("after {d} s"),
        StageEnd::Settled {
            kinetic_energy_per_mass,
            min_duration,
            max_duration,
        } => format!("kinetic energy per mass below {kinetic_energy_per_mass:e} J/kg, after at least {min_duration} s and at most {max_duration} s"),
    }
}

/// `profile.csv`: the heap surface height per bin.
pub fn profile_csv(profile: &HeapProfile) -> String {
    let mut csv = String::from("x_m,height_m\n");
    for (k, h) in profile.heights.iter().enumerate() {
        csv += &format!("{:.6e},{:.6e}\n", profile.bin_centre(k), h);
    }
    csv
}

/// `repose.csv`: the angle at each measurement.
pub fn repose_csv(samples: &[ReposeSample]) -> String {
    let mut csv = String::from(
        "time_after_start_s,trigger,repose_angle_deg,repose_fit_r2,runout_m,wall_height_m\n",
    );
    let opt = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6}"));
    for s in samples {
        csv += &format!(
            "{},{},{},{},{:.6e},{:.6e}\n",
            s.time_after_start_s,
            s.trigger,
            opt(s.repose_angle_deg),
            opt(s.repose_fit_r2),
            s.runout_m,
            s.wall_height_m
        );
    }
    csv
}

/// The headline measurement: the stage-end sample when the scene asks for one, else the last
/// fixed time.
pub fn headline_sample(samples: &[ReposeSample]) -> Option<&ReposeSample> {
    samples
        .iter()
        .rev()
        .find(|s| s.trigger == "stage end")
        .or(samples.last())
}

/// Writes `repose.csv` (all samples so far) and `profile.csv` (the latest profile) as soon as
/// a measurement is taken, so a run stopped later keeps them.
fn write_measurements(
    out: &Path,
    samples: &[ReposeSample],
    profile: &HeapProfile,
) -> Result<(), RunError> {
    let path = out.join("profile.csv");
    write_atomic(&path, profile_csv(profile).as_bytes()).map_err(|e| output_error(&path, e))?;
    if !samples.is_empty() {
        let path = out.join("repose.csv");
        write_atomic(&path, repose_csv(samples).as_bytes()).map_err(|e| output_error(&path, e))?;
    }
    Ok(())
}

/// The region of an insertion with `refill`: its box (and mesh), where it is topped up.
struct RefillRegion {
    species: u16,
    radius: Real,
    lo: Vec3,
    hi: Vec3,
    bvh: Option<Bvh>,
    overlap: Real,
}

impl RefillRegion {
    fn new(scene: &Scene, index: usize, ins: &crate::scene::Insertion) -> Result<Self, RunError> {
        let bvh = match &ins.mesh {
            None => None,
            Some(source) => Some(Bvh::new(&source.load().map_err(|message| {
                RunError::Geometry {
                    file: scene.source.display().to_string(),
                    field: format!("insert[{index}].mesh"),
                    message,
                }
            })?)),
        };
        Ok(RefillRegion {
            species: ins.species as u16,
            radius: scene.species[ins.species].radius(),
            lo: ins.lo,
            hi: ins.hi,
            bvh,
            overlap: ins.overlap,
        })
    }

    /// Whether a centre lies in the region (box, and inside the mesh if there is one).
    fn contains(&self, winding: Option<&FastWindingNumber>, p: Vec3) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all() && winding.is_none_or(|w| w.is_inside(p))
    }

    /// Mobile particles of the species with centres in the region.
    fn count(&self, particles: &Particles) -> usize {
        let winding = self.bvh.as_ref().map(FastWindingNumber::new);
        (0..particles.len())
            .filter(|&k| {
                particles.species[k] == self.species
                    && !particles.is_frozen(k)
                    && self.contains(winding.as_ref(), particles.position[k])
            })
            .count()
    }

    /// Positions for as many new particles (up to `target` in the region) as random
    /// sequential addition places without overlap, inside the mesh by one radius and clear of
    /// the bodies, as the first insertion did. New particles start at rest.
    fn top_up(
        &self,
        particles: &Particles,
        bodies: &[Body],
        target: usize,
        seed: u64,
    ) -> Vec<Vec3> {
        let missing = target.saturating_sub(self.count(particles));
        if missing == 0 {
            return Vec::new();
        }
        let winding = self.bvh.as_ref().map(FastWindingNumber::new);
        let radius = self.radius;
        let accept = |p: Vec3| {
            if let (Some(bvh), Some(winding)) = (&self.bvh, &winding) {
                if !winding.is_inside(p) || bvh.nearest_within(p, radius).is_some() {
                    return false;
                }
            }
            bodies
                .iter()
                .all(|b| b.query(p, radius).is_none_or(|(d, _)| d > radius))
        };
        let mut trial = particles.clone();
        let before = trial.len();
        // Fewer than `missing` when the region has no more room: the rest next time.
        let _ = insert_random_where(
            &mut trial,
            self.species,
            radius,
            1.0,
            self.lo,
            self.hi,
            missing as u64,
            seed,
            self.overlap,
            accept,
        );
        trial.position[before..].to_vec()
    }
}

#[cfg(test)]
mod refill_tests {
    use super::*;

    #[test]
    fn top_up_restores_the_count_in_the_region_without_overlap() {
        let (r, m) = (1e-3, 1e-6);
        let region = RefillRegion {
            species: 0,
            radius: r,
            lo: Vec3::ZERO,
            hi: Vec3::splat(0.02),
            bvh: None,
            overlap: 0.0,
        };
        let mut particles = Particles::new(false);
        insert_random_where(
            &mut particles,
            0,
            r,
            m,
            region.lo,
            region.hi,
            60,
            7,
            0.0,
            |_| true,
        )
        .unwrap();
        // One outside the region (not counted) and a frozen one inside (not counted).
        particles.push(0, Vec3::splat(0.03), r, m);
        particles.push(0, Vec3::splat(0.0105), r, m);
        particles.freeze(particles.len() - 1);
        assert_eq!(region.count(&particles), 60);
        // Drain 25 of them, as the screw would.
        let keep: Vec<bool> = (0..particles.len()).map(|k| k >= 25).collect();
        particles.retain(&keep);
        assert_eq!(region.count(&particles), 35);
        let added = region.top_up(&particles, &[], 60, 11);
        assert_eq!(added.len(), 25);
        for (k, a) in added.iter().enumerate() {
            assert!(a.cmpge(region.lo).all() && a.cmple(region.hi).all());
            for b in particles.position.iter().chain(&added[..k]) {
                assert!((*a - *b).length() >= 2.0 * r * (1.0 - 1e-12));
            }
        }
        for &a in &added {
            particles.push(0, a, r, m);
        }
        assert_eq!(region.count(&particles), 60);
        // Full: nothing more.
        assert!(region.top_up(&particles, &[], 60, 12).is_empty());
    }
}
