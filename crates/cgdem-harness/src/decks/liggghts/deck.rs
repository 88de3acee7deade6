//! The LIGGGHTS input for a Hertz scene, written from the scene alone: `pair_style gran model
//! hertz tangential history [rolling_friction epsd2]`, the keywords cgdem's Hertz slots are
//! named after, so no mapping is needed; walls are `fix wall/gran` primitives (axis-aligned
//! planes) and meshes; each wall material in use is an atom type after the species'
//! (`n_species + 1`, ...). The `peratomtype` and `peratomtypepair` tables are written from
//! the scene's resolved tables (`scene::ContactTables`: a species' own material,
//! `[[contact.pair]]`, `[[wall_material]]`, `[[wall_contact.pair]]`, defaults `[contact]` and
//! `[wall_contact]`), which LIGGGHTS mixes as cgdem does (`Y*`, `G*`).
//!
//! LIGGGHTS needs `newton off`, `communicate single vel yes`, Young's modulus >= 5e6 Pa in SI
//! units (it refuses softer materials), and an explicit dump format (default: 6 digits).
//! Supported: the Hertz settings of `decks::hertz`; stages, wall removal (`unfix w_NAME`) and
//! repose samples come from `decks::stages`, the same lines as the LAMMPS decks (LIGGGHTS
//! takes LAMMPS's loop, if, print and write_dump commands), so both go through one
//! post-processing.

use std::fmt::Write as _;

use super::DIALECT;
use crate::decks::hertz::{hertz_settings, wall_axis, HERTZ_COLUMNS};
use crate::decks::lines::{
    block_region, data_file, frozen_lines, g, neighbor_lines, preamble, unfix_wall, written_by,
};
use crate::decks::stages::{run_without_setup, stage_lines, trajectory_lines, StageHooks};
use crate::decks::{Deck, DeckError, DeckPlan};
use cgdem_core::contact::normal::Material;
use cgdem_core::math::Real;
use cgdem_core::particles::Particles;
use cgdem_core::scene::{ContactTables, HertzSettings, PairProperties, RollingKind, Scene};
use cgdem_core::simulation::DELETE_EVERY;

/// LIGGGHTS 3.8 rejects a Young's modulus below this in SI units.
pub const MIN_YOUNGS_MODULUS: Real = 5e6;

/// The deck for a Hertz `scene` starting from `particles`, stepping `dt`, one frame every
/// time-series interval (id type x y z vx vy vz omegax omegay omegaz radius).
pub fn write_deck(scene: &Scene, particles: &Particles, dt: Real) -> Result<Deck, DeckError> {
    let h = hertz_settings(scene, "LIGGGHTS", true)?;
    let types = AtomTypes::of(scene, h);
    for (what, e) in types.youngs_moduli(scene) {
        if e < MIN_YOUNGS_MODULUS {
            return Err(DeckError::Unsupported {
                file: scene.source.display().to_string(),
                reason: format!("{what} = {e} Pa: LIGGGHTS refuses E < 5e6 Pa in SI units"),
            });
        }
    }
    let dump_every = ((scene.output.timeseries_interval / dt).round() as u64).max(1);

    let diameters: Vec<Real> = scene.species.iter().map(|s| s.diameter).collect();
    let densities: Vec<Real> = scene.species.iter().map(|s| s.density).collect();
    let data = data_file(scene, particles, &diameters, &densities, types.count());

    let mut d = written_by(&DIALECT, scene);
    d += ").\n";
    d += &preamble(&DIALECT, scene);
    d += &neighbor_lines(&DIALECT, scene);
    let (integrated, freeze) = frozen_lines(scene);
    d += &freeze;
    let (materials, rolling) = material_lines(h, &types);
    d += &materials;
    let _ = writeln!(
        d,
        "pair_style      gran model hertz tangential history{rolling}"
    );
    d += "pair_coeff      * *\n";
    let _ = writeln!(d, "timestep        {}", g(dt));
    let _ = writeln!(d, "fix             integ {integrated} nve/sphere");
    if scene.gravity.length() > 0.0 {
        let dir = scene.gravity / scene.gravity.length();
        let _ = writeln!(
            d,
            "fix             grav all gravity {} vector {} {} {}",
            g(scene.gravity.length()),
            g(dir.x),
            g(dir.y),
            g(dir.z)
        );
    }
    d += &wall_lines(scene, &types, rolling)?;
    let meshes = mesh_lines(scene, &types, rolling)?;
    d += &meshes.setup;
    // LIGGGHTS's dump_modify format is one C format for the whole line (default: 6 digits).
    let modify = format!("sort id format \"%d %d{}\"", " %.17g".repeat(10));
    let dumps = trajectory_lines(&mut d, dump_every, true, HERTZ_COLUMNS, &modify);
    let begin = |stage: &str| stage_start_lines(scene, &meshes.pieces, stage, dt);
    // With a mesh wall, a `run pre no` right after an `unfix` stops LIGGGHTS with "internal
    // error (fix_contact_history_mesh.cpp:479)" (measured on the silo, reference/silo/PLAN.md
    // C): such a removal sets the run up once more (LIGGGHTS re-applies nothing in a setup).
    let unfix = |name: &str| {
        let mut lines = unfix_wall(name);
        if !scene.bodies.is_empty() {
            lines += "run             0 post no\n";
        }
        lines
    };
    d += &deletion_regions(scene);
    let run = |n: u64| run_lines(scene, n);
    let repose_dumps = stage_lines(
        &mut d,
        scene,
        dt,
        dump_every,
        &dumps,
        &StageHooks {
            unfix: &unfix,
            begin: &begin,
            periodic: &|_| None,
            run: &run,
        },
    );
    Ok(Deck {
        input: d,
        data,
        plan: DeckPlan {
            code: DIALECT.code.name(),
            log_file: DIALECT.log_file,
            notes: meshes.notes,
            dt,
            dump_every,
            repose_dumps,
        },
        files: meshes.files,
    })
}

/// LIGGGHTS's atom types: one per species, then one per wall material that a wall or mesh
/// uses (walls pair with particles only), with the scene's resolved tables.
struct AtomTypes {
    tables: ContactTables,
    /// The wall materials in use (`ContactTables::wall_materials` indices), in order: wall
    /// material `wall_materials[j]` is atom type `n_species + 1 + j`.
    wall_materials: Vec<usize>,
}

impl AtomTypes {
    fn of(scene: &Scene, h: &HertzSettings) -> AtomTypes {
        let mut wall_materials: Vec<usize> = (scene.walls.iter().map(|w| w.material))
            .chain(scene.bodies.iter().map(|b| b.material))
            .collect();
        wall_materials.sort_unstable();
        wall_materials.dedup();
        AtomTypes {
            tables: ContactTables::of_hertz(scene, h),
            wall_materials,
        }
    }

    fn particles(&self) -> usize {
        self.tables.n_species()
    }

    fn count(&self) -> usize {
        self.particles() + self.wall_materials.len()
    }

    /// The atom type (from 1) of walls of wall material `material`.
    fn wall_type(&self, material: usize) -> usize {
        let j = self.wall_materials.iter().position(|&k| k == material);
        self.particles() + 1 + j.expect("every wall's material is in use")
    }

    /// The material of atom type `t` (from 0).
    fn material(&self, t: usize) -> Material {
        match t.checked_sub(self.particles()) {
            None => self.tables.species[t],
            Some(j) => self.tables.wall_materials[self.wall_materials[j]],
        }
    }

    /// Each type's Young's modulus and the field it comes from.
    fn youngs_moduli(&self, scene: &Scene) -> Vec<(String, Real)> {
        let species = scene.species.iter().enumerate().map(|(a, s)| {
            let field = match s.youngs_modulus {
                Some(_) => format!("species[{a}].youngs_modulus"),
                None => "contact.youngs_modulus".into(),
            };
            (field, self.tables.species[a].youngs_modulus)
        });
        let walls = self.wall_materials.iter().map(|&k| {
            let field = match k {
                0 => "wall_contact.youngs_modulus".into(),
                k => format!("wall_material[{}].youngs_modulus", k - 1),
            };
            (field, self.tables.wall_materials[k].youngs_modulus)
        });
        species.chain(walls).collect()
    }

    /// A `peratomtype` table of `f` of each type's material.
    fn per_type(&self, f: impl Fn(Material) -> Real) -> String {
        let v: Vec<String> = (0..self.count()).map(|t| g(f(self.material(t)))).collect();
        v.join(" ")
    }

    /// A `peratomtypepair` table of `f` of each pair's coefficients: species pairs from
    /// `[[contact.pair]]`, a species and a wall material from `[[wall_contact.pair]]`. Walls
    /// never meet walls: their pairs take the first species' value against the later wall
    /// material (any valid value, but LIGGGHTS wants the matrix symmetric).
    fn per_pair(&self, f: impl Fn(&PairProperties) -> Real) -> String {
        let (n, n_types) = (self.particles(), self.count());
        let t = &self.tables;
        let mut v = Vec::new();
        for a in 0..n_types {
            for b in 0..n_types {
                let p = match (a.checked_sub(n), b.checked_sub(n)) {
                    (None, None) => t.pair(a, b),
                    (None, Some(j)) => t.wall_pair(a, self.wall_materials[j]),
                    (Some(j), None) => t.wall_pair(b, self.wall_materials[j]),
                    (Some(j), Some(k)) => t.wall_pair(0, self.wall_materials[j.max(k)]),
                };
                v.push(g(f(p)));
            }
        }
        format!("{n_types} {}", v.join(" "))
    }
}

/// The material tables (`fix property/global`), and the `pair_style` suffix for rolling
/// friction (empty without it).
fn material_lines(h: &HertzSettings, types: &AtomTypes) -> (String, &'static str) {
    let mut d = String::new();
    // LIGGGHTS refuses E > 1e9 Pa in SI units unless told the particles are hard (steel).
    if (0..types.count()).any(|t| types.material(t).youngs_modulus > 1e9) {
        d += "hard_particles  yes\n";
    }
    for (fix, property, table) in [
        (
            "m1",
            "youngsModulus peratomtype",
            types.per_type(|m| m.youngs_modulus),
        ),
        (
            "m2",
            "poissonsRatio peratomtype",
            types.per_type(|m| m.poisson_ratio),
        ),
        (
            "m3",
            "coefficientRestitution peratomtypepair",
            types.per_pair(|p| p.restitution),
        ),
        (
            "m4",
            "coefficientFriction peratomtypepair",
            types.per_pair(|p| p.friction),
        ),
    ] {
        let _ = writeln!(
            d,
            "fix             {fix} all property/global {property} {table}"
        );
    }
    let rolling = if h.rolling == RollingKind::Epsd2 {
        let _ = writeln!(
            d,
            "fix             m5 all property/global coefficientRollingFriction peratomtypepair {}",
            types.per_pair(|p| p.rolling_friction)
        );
        " rolling_friction epsd2"
    } else {
        ""
    };
    (d, rolling)
}

/// One `fix wall/gran ... primitive` per planar wall, of its wall material's atom type.
fn wall_lines(scene: &Scene, types: &AtomTypes, rolling: &str) -> Result<String, DeckError> {
    let mut d = String::new();
    for wall in &scene.walls {
        let (axis, _) = wall_axis(scene, wall)?;
        let at = [wall.point.x, wall.point.y, wall.point.z][axis];
        let _ = writeln!(
            d,
            "fix             w_{} all wall/gran model hertz tangential history{rolling} primitive type {} {}plane {}",
            wall.name,
            types.wall_type(wall.material),
            ["x", "y", "z"][axis],
            g(at)
        );
    }
    Ok(d)
}

/// The deck lines of the scene's bodies: one `fix mesh/surface` per body from an ASCII STL
/// of the same triangles cgdem builds its SDF from (metres), all in one `fix wall/gran ...
/// mesh`; the STL files; and notes on what differs from cgdem.
struct MeshLines {
    setup: String,
    /// Per body, the names of its pieces (`b_NAME` is the mesh fix).
    pieces: Vec<Vec<String>>,
    files: Vec<(String, Vec<u8>)>,
    notes: Vec<String>,
}

fn mesh_lines(scene: &Scene, types: &AtomTypes, rolling: &str) -> Result<MeshLines, DeckError> {
    let unsupported = |reason: String| DeckError::unsupported(scene, reason);
    let mut out = MeshLines {
        setup: String::new(),
        pieces: Vec::new(),
        files: Vec::new(),
        notes: Vec::new(),
    };
    if scene.bodies.is_empty() {
        return Ok(out);
    }
    let mut names = Vec::new();
    let mut body_pieces = Vec::new();
    for (k, b) in scene.bodies.iter().enumerate() {
        let mut pieces = Vec::new();
        let wall_type = types.wall_type(b.material);
        if b.particles.is_some() {
            return Err(unsupported(format!(
                "body[{k}] `{}` is built of particles; LIGGGHTS decks take mesh bodies",
                b.name
            )));
        }
        if b.velocity.length() > 0.0 && b.rpm != 0.0 {
            return Err(unsupported(format!(
                "body[{k}] `{}` both turns and translates; LIGGGHTS decks take one motion per body",
                b.name
            )));
        }
        let mesh = b
            .load_mesh()
            .map_err(|e| unsupported(format!("body[{k}].mesh: {e}")))?;
        // One mesh fix per separate solid of the body (see `TriMesh::components`).
        for (j, piece) in mesh.components().into_iter().enumerate() {
            let (piece, dropped, area) = without_slivers(piece);
            if dropped > 0 {
                out.notes.push(format!(
                    "body `{}` piece {j}: {dropped} sliver triangle(s) (smallest angle < {SLIVER_ANGLE_DEG} deg, {area:.1e} m2 in all) left out of the LIGGGHTS mesh, which refuses them",
                    b.name
                ));
            }
            let piece = &piece;
            let name = format!("{}_{j}", b.name);
            let file = format!("{name}.stl");
            let text = cgdem_core::geometry::stl::stl_ascii(piece, &name);
            out.files.push((file.clone(), text.into_bytes()));
            let _ = writeln!(
                out.setup,
                "fix             b_{name} all mesh/surface file {file} type {wall_type} curvature {:e}",
                cgdem_core::geometry::mesh_surface::CURVATURE_DEG
            );
            names.push(format!("b_{name}"));
            pieces.push(name);
        }
        body_pieces.push(pieces);
    }
    for (b, pieces) in scene.bodies.iter().zip(&body_pieces) {
        if b.start_stage.is_none() {
            out.setup += &move_lines(b, pieces);
        }
    }
    out.pieces = body_pieces;
    let _ = writeln!(
        out.setup,
        "fix             bodies all wall/gran model hertz tangential history{rolling} mesh n_meshes {} meshes {}",
        names.len(),
        names.join(" ")
    );
    Ok(out)
}

/// The `[[delete]]` boxes as regions `delete_K`.
fn deletion_regions(scene: &Scene) -> String {
    (scene.deletions.iter().enumerate())
        .map(|(k, (lo, hi))| block_region(&format!("delete_{k}"), *lo, *hi))
        .collect()
}

/// The line that runs `n` steps of a stage. LIGGGHTS 3.8 has no `fix evaporate`: with
/// `[[delete]]` boxes, the run goes in chunks of cgdem's [`DELETE_EVERY`] steps (counted from
/// the run's start; cgdem counts from the first step, a phase that changes nothing), each
/// followed by `delete_atoms region delete_K compress no` (ids kept, so the post-processing
/// counts the grains that vanished as deleted). Deleting atoms invalidates the neighbour
/// lists, so every chunk is set up again (`pre yes`): measured on the hopper check,
/// reference/MAPPING.md. Without boxes, `run n pre no post no`.
fn run_lines(scene: &Scene, n: u64) -> String {
    if scene.deletions.is_empty() {
        return run_without_setup(n);
    }
    let deletes: Vec<String> = (0..scene.deletions.len())
        .map(|k| format!("\"delete_atoms region delete_{k} compress no\""))
        .collect();
    format!(
        "run             {n} pre yes post no every {DELETE_EVERY} {}\n",
        deletes.join(" ")
    )
}

/// `fix move/mesh ... rotate` for each piece of a turning body: LIGGGHTS turns
/// counter-clockwise about `axis` once per `period`; a negative rpm turns about the reversed
/// axis. `fix move/mesh ... linear` for each piece of a translating one.
fn move_lines(b: &cgdem_core::scene::BodySettings, pieces: &[String]) -> String {
    if b.rpm == 0.0 {
        if b.velocity.length() == 0.0 {
            return String::new();
        }
        let v = b.velocity;
        return pieces
            .iter()
            .map(|name| {
                format!(
                    "fix             move_{name} all move/mesh mesh b_{name} linear {} {} {}\n",
                    g(v.x),
                    g(v.y),
                    g(v.z)
                )
            })
            .collect();
    }
    let axis = if b.rpm < 0.0 { -b.axis } else { b.axis };
    let mut d = String::new();
    for name in pieces {
        let _ = writeln!(
            d,
            "fix             move_{name} all move/mesh mesh b_{name} rotate origin {} {} {} axis {} {} {} period {}",
            g(b.point.x),
            g(b.point.y),
            g(b.point.z),
            g(axis.x),
            g(axis.y),
            g(axis.z),
            g(60.0 / b.rpm.abs())
        );
    }
    d
}

/// LIGGGHTS 3.8 aborts on a mesh element whose smallest angle is below about 0.01 deg
/// (measured: the casing's gables, fan-triangulated, have two at 0.0093 deg).
const SLIVER_ANGLE_DEG: Real = 0.02;

/// The mesh without its sliver triangles: the mesh, how many were dropped and their area (a
/// sliver's area is tiny, so the surface grains meet is the same).
fn without_slivers(
    mut mesh: cgdem_core::geometry::TriMesh,
) -> (cgdem_core::geometry::TriMesh, usize, Real) {
    let smallest_angle = |[a, b, c]: [cgdem_core::math::Vec3; 3]| {
        [(a, b, c), (b, c, a), (c, a, b)]
            .iter()
            .map(|&(p, q, r)| (q - p).angle_between(r - p))
            .fold(Real::INFINITY, Real::min)
    };
    let n = mesh.triangles.len();
    let mut area = 0.0;
    let keep: Vec<bool> = (0..n)
        .map(|t| {
            let tri = mesh.triangle(t);
            let sliver = smallest_angle(tri).to_degrees() < SLIVER_ANGLE_DEG;
            if sliver {
                area += 0.5 * (tri[1] - tri[0]).cross(tri[2] - tri[0]).length();
            }
            !sliver
        })
        .collect();
    let mut k = 0;
    mesh.triangles.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    let dropped = n - mesh.triangles.len();
    (mesh, dropped, area)
}

/// What starts with `stage`: the motion of the bodies that start then, and the top-ups of the
/// insertions refilled during it (`fix insert/pack ... particles_in_region N`, N the count in
/// the insertion box when the stage begins, first after one interval, as cgdem does). A
/// `run 0` sets the new fixes up.
fn stage_start_lines(scene: &Scene, pieces: &[Vec<String>], stage: &str, dt: Real) -> String {
    let mut d = String::new();
    for (b, pieces) in scene.bodies.iter().zip(pieces) {
        if b.start_stage.as_deref() == Some(stage) {
            d += &move_lines(b, pieces);
        }
    }
    for (k, ins) in scene.insertions.iter().enumerate() {
        let Some(refill) = ins.refill.as_ref().filter(|r| r.stage == stage) else {
            continue;
        };
        let species = &scene.species[ins.species];
        let every = ((refill.interval / dt).round() as u64).max(1);
        d += &block_region(&format!("top_{k}"), ins.lo, ins.hi);
        let _ = writeln!(
            d,
            "fix             pts_{k} all particletemplate/sphere {} atom_type {} density constant {} radius constant {}",
            PRIMES[(2 * k) % PRIMES.len()],
            ins.species + 1,
            g(species.density),
            g(species.radius())
        );
        let _ = writeln!(
            d,
            "fix             pdd_{k} all particledistribution/discrete {} 1 pts_{k} 1.0",
            PRIMES[(2 * k + 1) % PRIMES.len()]
        );
        let _ = writeln!(d, "variable        top_n_{k} equal count(all,top_{k})");
        let _ = writeln!(
            d,
            "fix             top_{k} all insert/pack seed {} distributiontemplate pdd_{k} maxattempt 200 insert_every {every} start $(step+{every}) overlapcheck yes all_in no particles_in_region ${{top_n_{k}}} region top_{k}",
            PRIMES[(2 * k + 2) % PRIMES.len()]
        );
    }
    if !d.is_empty() {
        d += "run             0 post no\n";
    }
    d
}

/// Primes above 10000 for LIGGGHTS's random seeds.
const PRIMES: [u64; 6] = [15485863, 32452843, 49979687, 67867967, 86028121, 104395301];

#[cfg(test)]
mod tests {
    use super::super::LOG_FILE;
    use super::*;
    use crate::decks::hertz::{at, collapse_scene_and_particle};

    #[test]
    fn collapse_deck_settles_then_unfixes_the_gate_then_samples_the_collapse() {
        let (scene, particles) = collapse_scene_and_particle();
        let deck = write_deck(&scene, &particles, 5e-5).unwrap();
        let d = &deck.input;
        assert_eq!((deck.plan.code, deck.plan.log_file), ("liggghts", LOG_FILE));
        // Walls are primitives of the extra atom type 2, each removable on its own.
        let gate = at(d, "fix             w_gate all wall/gran model hertz tangential history rolling_friction epsd2 primitive type 2 xplane 1.00000000000000006e-1");
        let settle = at(d, "variable        chunk0 loop 200");
        let settle_end = at(d, "label           end_stage0");
        let unfix = at(d, "unfix           w_gate");
        assert!(!d.contains("unfix           w_floor"));
        let collapse = at(d, "CGDEM_STAGE collapse start");
        assert!(gate < settle && settle < settle_end && settle_end < unfix && unfix < collapse);
        at(d, "variable        kepm equal (c_ke+c_rke)/mass(all)");
        // LIGGGHTS takes one C format per line; inside an `if`, in single quotes.
        let format = format!("format '%d %d{}'", " %.17g".repeat(10));
        let sample = at(d, &format!("if              \"${{chunk1}} == 25\" then \"write_dump all custom repose_0.dump id type x y z vx vy vz omegax omegay omegaz radius modify sort id {format}\""));
        assert!(collapse < sample);
        assert_eq!(deck.plan.repose_dumps.len(), 3);
    }

    #[test]
    fn screw_deck_turns_the_screw_mesh_from_the_conveying_stage_and_tops_up_the_hopper() {
        crate::at_repo_root();
        let scene = Scene::load(std::path::Path::new(
            "validation/cases/screw_feeder_hertz.toml",
        ))
        .unwrap();
        let deck = write_deck(&scene, &Particles::new(true), 6e-5).unwrap();
        let d = &deck.input;
        // Meshes of the same triangles cgdem builds its SDF from, one fix per solid, as walls.
        at(
            d,
            "fix             b_screw_0 all mesh/surface file screw_0.stl type 2",
        );
        at(
            d,
            "fix             b_hopper_0 all mesh/surface file hopper_0.stl type 2",
        );
        let walls = at(d, "fix             bodies all wall/gran model hertz tangential history mesh n_meshes 12 meshes b_screw_0 b_screw_1 b_casing_0");
        assert!(deck.files.iter().any(|(name, text)| name == "casing_0.stl"
            && String::from_utf8_lossy(text).starts_with("solid casing_0")));
        // rpm -100 about +x: counter-clockwise about -x, 0.6 s per turn, from `convey` on.
        let settle = at(d, "CGDEM_STAGE settle start");
        let turn = at(d, "fix             move_screw_0 all move/mesh mesh b_screw_0 rotate origin 0.00000000000000000e0 0.00000000000000000e0 0.00000000000000000e0 axis -1.00000000000000000e0");
        assert!(d[turn..].contains("period 5.99999999999999978e-1"));
        let top_up = at(d, "fix             top_0 all insert/pack seed");
        assert!(d[top_up..].contains("insert_every 1667 start $(step+1667) overlapcheck yes all_in no particles_in_region ${top_n_0} region top_0"));
        let convey = at(d, "CGDEM_STAGE convey start");
        assert!(walls < settle && settle < turn && turn < top_up && top_up < convey);
        assert!(!d.contains("move_casing"));
        at(d, "dump            traj all custom");
        // The outlet's [[delete]] box is emptied every 100 steps, not left out with a note.
        assert!(d[convey..].contains("every 100 \"delete_atoms region delete_0 compress no\""));
        assert!(deck.plan.notes.iter().all(|n| !n.contains("evaporate")));
    }

    /// tests/data/tiny_two_material_collapse.toml: species bead (type 1) and grit (2), the
    /// default wall material (3: the back, gate and end walls) and steel (4: the floor); each
    /// table entry is the scene's pair value, both ways round.
    #[test]
    fn material_tables_are_written_per_atom_type_from_the_scene() {
        crate::at_repo_root();
        let scene = Scene::load(std::path::Path::new(
            "tests/data/tiny_two_material_collapse.toml",
        ))
        .unwrap();
        let particles = cgdem_core::run::initial_particles_clear_of_bodies(&scene).unwrap();
        let deck = write_deck(&scene, &particles, 1e-5).unwrap();
        let d = &deck.input;
        let row = |v: &[Real]| v.iter().map(|&x| g(x)).collect::<Vec<_>>().join(" ");
        at(
            d,
            &format!(
                "fix             m1 all property/global youngsModulus peratomtype {}\n",
                row(&[5e6, 2e7, 5e6, 2e8])
            ),
        );
        at(
            d,
            &format!(
                "fix             m2 all property/global poissonsRatio peratomtype {}\n",
                row(&[0.3, 0.25, 0.3, 0.3])
            ),
        );
        // Rows by type: bead, grit, default wall, steel (wall-wall pairs: any valid value).
        let e = [
            [0.5, 0.4, 0.5, 0.5],
            [0.4, 0.3, 0.5, 0.6],
            [0.5, 0.5, 0.5, 0.5],
            [0.5, 0.6, 0.5, 0.5],
        ];
        at(
            d,
            &format!(
                "coefficientRestitution peratomtypepair 4 {}\n",
                row(e.as_flattened())
            ),
        );
        let mu = [
            [0.5, 0.6, 0.5, 0.4],
            [0.6, 0.7, 0.5, 0.3],
            [0.5, 0.5, 0.5, 0.4],
            [0.4, 0.3, 0.4, 0.4],
        ];
        at(
            d,
            &format!(
                "coefficientFriction peratomtypepair 4 {}\n",
                row(mu.as_flattened())
            ),
        );
        let mu_r = [
            [0.1, 0.15, 0.1, 0.1],
            [0.15, 0.1, 0.1, 0.1],
            [0.1, 0.1, 0.1, 0.1],
            [0.1, 0.1, 0.1, 0.1],
        ];
        at(
            d,
            &format!(
                "coefficientRollingFriction peratomtypepair 4 {}\n",
                row(mu_r.as_flattened())
            ),
        );
        at(d, "fix             w_floor all wall/gran model hertz tangential history rolling_friction epsd2 primitive type 4 zplane");
        for wall in ["back", "gate", "end"] {
            at(d, &format!("fix             w_{wall} all wall/gran model hertz tangential history rolling_friction epsd2 primitive type 3 xplane"));
        }
        assert!(deck.data.contains("\n4 atom types\n"), "{:.400}", deck.data);
    }

    #[test]
    fn the_silo_deck_sets_up_again_after_the_gate_is_removed() {
        crate::at_repo_root();
        let scene =
            Scene::load(std::path::Path::new("validation/cases/silo_reduced.toml")).unwrap();
        let deck = write_deck(&scene, &Particles::new(true), 1.25e-5).unwrap();
        let d = &deck.input;
        let mesh = at(d, "fix             bodies all wall/gran model hertz tangential history mesh n_meshes 1 meshes b_silo_0");
        let unfix = at(d, "unfix           w_gate\nrun             0 post no\n");
        let discharge = at(d, "CGDEM_STAGE discharge start");
        assert!(mesh < unfix && unfix < discharge);
    }

    /// LIGGGHTS 3.8 has no `fix evaporate`: a [[delete]] box is a region emptied with
    /// `delete_atoms` (ids kept) after every 100 steps of every stage run, each chunk set up
    /// again; a deck without boxes runs its stages without a new setup.
    #[test]
    fn a_delete_box_is_emptied_between_run_chunks_at_cgdems_cadence() {
        crate::at_repo_root();
        let scene =
            Scene::load(std::path::Path::new("validation/cases/silo_reduced.toml")).unwrap();
        let deck = write_deck(&scene, &Particles::new(true), 1.25e-5).unwrap();
        let d = &deck.input;
        at(d, "region          delete_0 block");
        let chunk = format!(
            "pre yes post no every {DELETE_EVERY} \"delete_atoms region delete_0 compress no\"\n"
        );
        // The fill's settle loop (one output interval, 800 steps) and the 0.6 s discharge.
        at(d, &format!("run             800 {chunk}"));
        at(d, &format!("run             48000 {chunk}"));
        let stage_runs: Vec<&str> = d.lines().filter(|l| l.starts_with("run ")).collect();
        assert!(
            stage_runs
                .iter()
                .all(|l| l.ends_with(&chunk[..chunk.len() - 1]) || l.contains(" 0 post no")),
            "{stage_runs:?}"
        );
        assert!(deck.plan.notes.iter().all(|n| !n.contains("[[delete]]")));

        let (scene, particles) = collapse_scene_and_particle();
        assert!(scene.deletions.is_empty());
        let d = write_deck(&scene, &particles, 5e-5).unwrap().input;
        assert!(
            d.contains(" pre no post no\n") && !d.contains("delete_atoms"),
            "{d}"
        );
    }

    #[test]
    fn a_soft_material_is_refused_with_the_field_named() {
        let (mut scene, particles) = collapse_scene_and_particle();
        if let cgdem_core::scene::ContactSettings::Hertz(h) = &mut scene.contact {
            h.youngs_modulus = 1e6;
        }
        let e = write_deck(&scene, &particles, 5e-5)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("aor_hertz.toml") && e.contains("contact.youngs_modulus = 1000000 Pa"),
            "{e}"
        );
    }
}
