//! ParaView output: per frame, the particles (`particles_NNNNNN.vtu`), the bodies' meshes in
//! their pose (`bodies_NNNNNN.vtu`, when the scene has bodies) and, with
//! `[output] vtk_contact_network = true`, the pair contacts as lines
//! (`contacts_NNNNNN.vtu`); each kind indexed by its own `.pvd` (`particles.pvd`,
//! `bodies.pvd`, `contacts.pvd`).
//!
//! Three collections rather than three parts of one: ParaView opens a multi-part `.pvd` as
//! one multiblock data set, where a Glyph filter meant for the particles would also put
//! spheres on the mesh vertices; separate readers keep a pipeline per kind (Glyph, Surface,
//! Tube) and share the time axis. All files are `.vtu` (unstructured grids), which every VTK
//! reader takes (meshio reads `.vtu` but not `.vtp`).
//!
//! Particle arrays (LIGGGHTS `dump custom/vtk` names in brackets): `id` \[id\], `species`
//! (0-based, scene order) \[type - 1\], `radius` \[radius\], `velocity` \[v\], `force` (total,
//! gravity included) \[f\], `coordination_number` (particles it interacts with; for Hertz those it
//! overlaps) [`compute contact/atom`], and where the law rotates `omega` \[omega\] and `torque` \[tq\]. Body arrays:
//! `body` (index in scene order, per triangle) and `velocity` (of the body's surface, per
//! vertex). Contact arrays (`dump local` of `compute pair/gran/local`): `id` (the two
//! particles' ids), `normal_force` (N, positive pushes apart) and `overlap` (m), per line.
//!
//! With `[output] write_data = true` each frame's particles are also written as a LAMMPS data
//! file (`particles_NNNNNN.data`, see `lammps_data`), from which a scene can start.

mod appended;
mod series;

pub use appended::{VtkNumber, Vtu, VTK_LINE, VTK_TRIANGLE, VTK_VERTEX};
pub use series::PvdSeries;

use std::path::{Path, PathBuf};

use crate::contact::PairLaw;
use crate::geometry::TriMesh;
use crate::scene::Scene;
use crate::simulation::{ContactNetwork, World};
use crate::walls::WallLaw;

/// Bytes written for one frame, per file kind.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameBytes {
    pub particles: usize,
    pub bodies: usize,
    pub contacts: usize,
}

/// The series a run writes into one directory.
/// What a VTK output has written: the frame count and each series' frames.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct VtkState {
    pub frames: usize,
    pub particles: Vec<(f64, String)>,
    pub bodies: Option<Vec<(f64, String)>>,
    pub contacts: Option<Vec<(f64, String)>>,
}

pub struct VtkOutput {
    dir: PathBuf,
    frames: usize,
    particles: PvdSeries,
    /// Each body's mesh in its body frame (= world at t = 0), scene order.
    bodies: Option<(PvdSeries, Vec<TriMesh>)>,
    contacts: Option<PvdSeries>,
    /// With `output.write_data`: each frame's particles also as a LAMMPS data file.
    data: Option<DataFrames>,
}

/// What a frame's data file needs besides the particles: the scene's name, box and species.
struct DataFrames {
    scene: String,
    lo: crate::math::Vec3,
    hi: crate::math::Vec3,
    diameters: Vec<crate::math::Real>,
    densities: Vec<crate::math::Real>,
}

impl VtkOutput {
    /// `meshes`: one per body, in the order of the world's bodies (none: no body series).
    pub fn new(dir: &Path, meshes: Vec<TriMesh>, contact_network: bool) -> std::io::Result<Self> {
        std::fs::create_dir_all(dir)?;
        Ok(VtkOutput {
            dir: dir.to_path_buf(),
            frames: 0,
            particles: PvdSeries::new(dir.join("particles.pvd")),
            bodies: (!meshes.is_empty()).then(|| (PvdSeries::new(dir.join("bodies.pvd")), meshes)),
            contacts: contact_network.then(|| PvdSeries::new(dir.join("contacts.pvd"))),
            data: None,
        })
    }

    /// The series a scene asks for: its bodies' meshes and, with
    /// `output.vtk_contact_network`, the contacts.
    pub fn for_scene(dir: &Path, scene: &Scene) -> Result<Self, String> {
        let meshes = scene
            .bodies
            .iter()
            .enumerate()
            .map(|(k, b)| {
                b.mesh
                    .load()
                    .map_err(|e| format!("{}: body[{k}].mesh: {e}", scene.source.display()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut out = VtkOutput::new(dir, meshes, scene.output.vtk_contact_network)
            .map_err(|e| format!("{}: {e}", dir.display()))?;
        if scene.output.write_data {
            out.data = Some(DataFrames {
                scene: scene.name.clone(),
                lo: scene.domain.lo,
                hi: scene.domain.hi,
                diameters: scene.species.iter().map(|s| s.diameter).collect(),
                densities: scene.species.iter().map(|s| s.density).collect(),
            });
        }
        Ok(out)
    }

    /// The series' frames so far, for a restart file.
    pub fn state(&self) -> VtkState {
        VtkState {
            frames: self.frames,
            particles: self.particles.frames().to_vec(),
            bodies: self.bodies.as_ref().map(|(s, _)| s.frames().to_vec()),
            contacts: self.contacts.as_ref().map(|s| s.frames().to_vec()),
        }
    }

    /// Takes the frames of a [`VtkOutput::state`] and rewrites the `.pvd` indexes to them
    /// (frames a killed run wrote after its checkpoint are written again).
    pub fn restore(&mut self, state: VtkState) -> Result<(), String> {
        if state.bodies.is_some() != self.bodies.is_some()
            || state.contacts.is_some() != self.contacts.is_some()
        {
            return Err("the stored VTK series differ from the scene's".into());
        }
        self.frames = state.frames;
        let mut series: Vec<(&mut PvdSeries, Vec<(f64, String)>)> =
            vec![(&mut self.particles, state.particles)];
        if let (Some((s, _)), Some(f)) = (self.bodies.as_mut(), state.bodies) {
            series.push((s, f));
        }
        if let (Some(s), Some(f)) = (self.contacts.as_mut(), state.contacts) {
            series.push((s, f));
        }
        for (s, frames) in series {
            let path = s.path().to_path_buf();
            s.set_frames(frames)
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
        Ok(())
    }

    /// Frames written so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Writes the world's present state as the next frame of each series.
    pub fn write_frame<L: PairLaw, W: WallLaw>(
        &mut self,
        world: &World<L, W>,
    ) -> Result<FrameBytes, String> {
        let network = world.contact_network();
        let frame = self.frames;
        let time = world.time;
        let mut bytes = FrameBytes::default();
        let file = format!("particles_{frame:06}.vtu");
        let data = particles_vtu(world, &network);
        bytes.particles = total_len(&data);
        self.write(&file, &data)?;
        push(&mut self.particles, time, file)?;
        if let Some((series, meshes)) = &mut self.bodies {
            let file = format!("bodies_{frame:06}.vtu");
            let data = bodies_vtu(world, meshes);
            bytes.bodies = total_len(&data);
            write_frame_file(&self.dir.join(&file), &data)?;
            push(series, time, file)?;
        }
        if let Some(series) = &mut self.contacts {
            let file = format!("contacts_{frame:06}.vtu");
            let data = contacts_vtu(world, &network);
            bytes.contacts = total_len(&data);
            write_frame_file(&self.dir.join(&file), &data)?;
            push(series, time, file)?;
        }
        if let Some(d) = &self.data {
            // The frame's time in the title, to full precision: the data file and the .vtu
            // of one frame can be matched by a reader.
            let title = format!(
                "LAMMPS data file written by cgdem {}: frame {frame} of scene {} at t = {time:.17e} s",
                env!("CARGO_PKG_VERSION"),
                d.scene
            );
            let text = crate::lammps_data::data_text(
                &title,
                d.lo,
                d.hi,
                world.particles(),
                &d.diameters,
                &d.densities,
                d.diameters.len(),
            );
            write_frame_file(
                &self.dir.join(format!("particles_{frame:06}.data")),
                &[text.into_bytes()],
            )?;
        }
        self.frames += 1;
        Ok(bytes)
    }

    fn write(&self, file: &str, data: &[Vec<u8>]) -> Result<(), String> {
        write_frame_file(&self.dir.join(file), data)
    }
}

fn push(series: &mut PvdSeries, time: f64, file: String) -> Result<(), String> {
    let path = series.path().to_path_buf();
    series
        .push(time, file)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes a frame through a temporary file and a rename (a reader never sees half a frame),
/// without the fsync of `write_atomic`: a frame lost in a crash is rewritten by the next run,
/// and at 200,000 particles the fsync would cost more than the write.
fn write_frame_file(path: &Path, parts: &[Vec<u8>]) -> Result<(), String> {
    use std::io::Write;
    let tmp = path.with_extension("vtu.tmp");
    std::fs::File::create(&tmp)
        .and_then(|mut file| parts.iter().try_for_each(|part| file.write_all(part)))
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            // A full disk leaves no half frame behind, only the frames written before.
            let _ = std::fs::remove_file(&tmp);
            format!("{}: {e}", path.display())
        })
}

fn total_len(parts: &[Vec<u8>]) -> usize {
    parts.iter().map(Vec::len).sum()
}

/// The particles as vertices with their arrays.
pub fn particles_vtu<L: PairLaw, W: WallLaw>(
    world: &World<L, W>,
    network: &ContactNetwork,
) -> [Vec<u8>; 3] {
    let p = world.particles();
    let n = p.len();
    let spin = p.angular.as_ref();
    let per_particle = 8 * (3 + 1 + 3 + 3 + if spin.is_some() { 6 } else { 0 }) + 4 + 2 + 4 + 9;
    let mut vtu = Vtu::new(n, n, n * per_particle + 2048);
    vtu.point_array("id", 1, p.id.iter().copied());
    vtu.point_array("species", 1, p.species.iter().copied());
    vtu.point_array("radius", 1, p.radius.iter().copied());
    vtu.point_vectors("velocity", p.velocity.iter().copied());
    if let Some(a) = spin {
        vtu.point_vectors("omega", a.omega.iter().copied());
    }
    vtu.point_vectors("force", p.force.iter().copied());
    if let Some(a) = spin {
        vtu.point_vectors("torque", a.torque.iter().copied());
    }
    vtu.point_array(
        "coordination_number",
        1,
        network.coordination.iter().copied(),
    );
    vtu.points(p.position.iter().copied());
    vtu.vertex_cells();
    vtu.finish()
}

/// The bodies' meshes moved to the bodies' present pose, as triangles.
pub fn bodies_vtu<L: PairLaw, W: WallLaw>(world: &World<L, W>, meshes: &[TriMesh]) -> [Vec<u8>; 3] {
    let bodies = world.bodies();
    let n_points: usize = meshes.iter().map(|m| m.vertices.len()).sum();
    let n_cells: usize = meshes.iter().map(|m| m.triangles.len()).sum();
    let mut points = Vec::with_capacity(n_points);
    let mut velocity = Vec::with_capacity(n_points);
    let mut connectivity = Vec::with_capacity(3 * n_cells);
    let mut body_index = Vec::with_capacity(n_cells);
    for (k, (body, mesh)) in bodies.iter().zip(meshes).enumerate() {
        let first = points.len();
        for &q in &mesh.vertices {
            let x = body.to_world(q);
            points.push(x);
            velocity.push(body.surface_velocity(x));
        }
        for t in &mesh.triangles {
            connectivity.extend(t.iter().map(|&v| first + v as usize));
            body_index.push(k as u16);
        }
    }
    let offsets: Vec<usize> = (1..=body_index.len()).map(|c| 3 * c).collect();
    let types = vec![VTK_TRIANGLE; body_index.len()];
    let mut vtu = Vtu::new(points.len(), body_index.len(), 64 * n_points + 16 * n_cells);
    vtu.point_vectors("velocity", velocity.into_iter());
    vtu.cell_array("body", 1, body_index.into_iter());
    vtu.points(points.into_iter());
    vtu.cells(&connectivity, &offsets, &types);
    vtu.finish()
}

/// The pair contacts as lines from `i` to `j` (to the image `i` meets across a periodic
/// face, so no line spans the box).
pub fn contacts_vtu<L: PairLaw, W: WallLaw>(
    world: &World<L, W>,
    network: &ContactNetwork,
) -> [Vec<u8>; 3] {
    let p = world.particles();
    let pairs = &network.pairs;
    let m = pairs.len();
    let mut vtu = Vtu::new(2 * m, m, 72 * m + 1024);
    vtu.cell_array(
        "id",
        2,
        pairs
            .iter()
            .flat_map(|c| [p.id[c.i as usize], p.id[c.j as usize]]),
    );
    vtu.cell_array("normal_force", 1, pairs.iter().map(|c| c.normal_force));
    vtu.cell_array("overlap", 1, pairs.iter().map(|c| c.overlap));
    vtu.points(pairs.iter().flat_map(|c| {
        [
            p.position[c.i as usize],
            p.position[c.j as usize] + c.image_shift,
        ]
    }));
    let connectivity: Vec<usize> = (0..2 * m).collect();
    let offsets: Vec<usize> = (1..=m).map(|c| 2 * c).collect();
    vtu.cells(&connectivity, &offsets, &vec![VTK_LINE; m]);
    vtu.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Real, Vec3};
    use crate::simulation::network::tests::{hertz_world, R};

    /// Writing cost of a 200,000-particle frame (spinning Hertz particles on a cubic lattice
    /// at 1% overlap: six contacts each). Run by hand on a quiet machine:
    /// `cargo test --release -p cgdem-core vtk_frame_of_200k -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn vtk_frame_of_200k_particles_writes_in_under_a_second() {
        let side = 59; // 205,379 particles
        let spacing = 1.98 * R;
        let half = 0.5 * side as Real * spacing + 2.0 * R;
        let mut x = Vec::new();
        for a in 0..side {
            for b in 0..side {
                for c in 0..side {
                    x.push(
                        Vec3::new(a as Real, b as Real, c as Real) * spacing
                            - Vec3::splat(0.5 * (side - 1) as Real * spacing),
                    );
                }
            }
        }
        let v: Vec<Vec3> = (0..x.len())
            .map(|k| Vec3::new(1e-3 * (k % 7) as Real, 0.0, -1e-3))
            .collect();
        let world = hertz_world(&x, &v, half, false, 0.5);
        let n = world.particles().len() as Real;
        let contacts = world.contact_network().pairs.len() as Real;
        let mut medians = Vec::new();
        for network in [false, true] {
            let dir = std::env::temp_dir()
                .join(format!("cgdem-vtk-bench-{}-{network}", std::process::id()));
            let mut output = VtkOutput::new(&dir, Vec::new(), network).unwrap();
            let mut times = Vec::new();
            let mut bytes = FrameBytes::default();
            for _ in 0..5 {
                let start = std::time::Instant::now();
                bytes = output.write_frame(&world).unwrap();
                times.push(start.elapsed().as_secs_f64());
            }
            std::fs::remove_dir_all(&dir).ok();
            times.sort_by(f64::total_cmp);
            println!(
                "{n} particles, contact network {network}: frame written in {:.3} s (median of 5, min {:.3}, max {:.3}); particles file {} bytes = {:.1} bytes/particle; contacts file {} bytes = {:.1} bytes per contact ({contacts} contacts)",
                times[2],
                times[0],
                times[4],
                bytes.particles,
                bytes.particles as Real / n,
                bytes.contacts,
                bytes.contacts as Real / contacts,
            );
            medians.push(times[2]);
        }
        assert!(
            medians[0] < 1.0,
            "median particle frame time {} s",
            medians[0]
        );
    }
}
