//! A scene's bodies in a LAMMPS Hertz deck. LAMMPS (29 Sep 2021) has no mesh walls, so:
//!
//! - a body built of particles (`[[body]] particles = ...`) is its frozen species' atoms, the
//!   same lattice sites cgdem places, turned by `fix move rotate` from the body's start stage
//!   (LAMMPS then also sets their spin to the body's, as cgdem does);
//! - the seed's casing and hopper (`screw-feeder:casing` and `screw-feeder:hopper`, both
//!   fixed) are one union region of analytic pieces from the same `ScrewFeederSpec`, felt
//!   through `fix wall/gran/region` with the deck's wall model ([`casing_and_hopper_region`]);
//! - the built-in silo's wall (`silo:wall`, fixed) is a union region of a cone (the hopper)
//!   and a cylinder above it, both with open ends, from the same `SiloSpec`
//!   ([`silo_region`]);
//! - a mesh body whose triangles form a closed cylinder about its axis along x, y or z (a
//!   drum: [`super::cylinder`]) is a `region cylinder ... side in`, turning about its axis
//!   with `rotate v_theta` when the body turns ([`cylinder_lines`]);
//! - any other mesh body is refused, naming it.
//!
//! A union region keeps a piece's surface only where it does not lie inside another piece,
//! which is how the openings arise: the bore's upper half is inside the inlet chute, its
//! lower half inside the outlet box.

use std::fmt::Write as _;

use super::cylinder::{closed_cylinder, Cylinder};
use crate::decks::lines::g;
use crate::decks::DeckError;
use cgdem_core::geometry::screw_feeder::{hopper_inner_rect, ScrewFeederSpec};
use cgdem_core::geometry::silo::SiloSpec;
use cgdem_core::math::Real;
use cgdem_core::scene::{BodyParticles, BodySettings, MeshSource, Scene, SiloPart};

/// The deck lines of the scene's bodies.
pub(crate) struct BodyLines {
    /// Groups, regions and the wall fix, before the first run.
    pub setup: String,
    /// The wall fix of the mesh bodies (`unfix` + `fix` again, before each later setup: LAMMPS
    /// re-applies its Tsuji polynomial to a wall fix's coefficient at every setup), if any.
    pub refix_walls: String,
    /// `(start stage, fix move lines)` of the turning bodies; `None`: from the first run.
    pub motions: Vec<(Option<String>, String)>,
    /// `(stage, lines)` issued at a stage's start that need no new setup: a turning region's
    /// angle starts counting.
    pub turns: Vec<(String, String)>,
    pub notes: Vec<String>,
}

/// The `fix wall/gran/region` lines of a region (given its name and the wall material of
/// the body), one per group of grains the deck's wall model takes.
pub(crate) type RegionFixes<'a> = &'a dyn Fn(&str, usize) -> Result<String, DeckError>;

/// Region name of the seed's casing and hopper.
const CASING_REGION: &str = "casing_hopper";

/// What LAMMPS decks take as mesh bodies, for the refusals.
const TAKEN: &str = "LAMMPS has no mesh walls; its decks take bodies built of particles, a closed cylinder about its axis along x, y or z (a drum: lateral faces at one radius, two flat end caps), the fixed casing and hopper of Hirose's screw feeder (`screw-feeder:casing`, `screw-feeder:hopper`) and the fixed built-in silo (`silo:wall`) only";

/// A mesh body the deck writes as a region.
enum RegionBody<'a> {
    ScrewPart(&'a str),
    Silo(&'a str, &'a SiloSpec, usize),
    Cylinder(&'a BodySettings, Cylinder),
}

/// The lines for the scene's bodies: `dt` is the time step, `fixes` writes the wall fixes
/// of a region body.
pub(crate) fn body_lines(
    scene: &Scene,
    dt: Real,
    fixes: RegionFixes,
) -> Result<BodyLines, DeckError> {
    let unsupported = |reason: String| DeckError::unsupported(scene, reason);
    let mut out = BodyLines {
        setup: String::new(),
        refix_walls: String::new(),
        motions: Vec::new(),
        turns: Vec::new(),
        notes: Vec::new(),
    };
    let mut regions = Vec::new();
    for (k, b) in scene.bodies.iter().enumerate() {
        if let Some(bp) = &b.particles {
            particle_body(scene, k, bp, &mut out)?;
        } else {
            regions.push(region_body(scene, k)?);
        }
    }
    let mut static_parts: Vec<&str> = regions
        .iter()
        .filter_map(|r| match r {
            RegionBody::ScrewPart(p) => Some(*p),
            _ => None,
        })
        .collect();
    let others = regions.len() - static_parts.len();
    if !static_parts.is_empty() {
        static_parts.sort_unstable();
        if static_parts != ["casing", "hopper"] {
            return Err(unsupported(format!(
                "bodies {static_parts:?}: the LAMMPS deck writes the screw feeder's casing and hopper together, as one region (each once)"
            )));
        }
    }
    if !static_parts.is_empty() && others > 0 || others > 1 {
        return Err(unsupported(
            "the LAMMPS deck writes one region wall: the casing and hopper of Hirose's screw feeder, one silo or one cylinder"
                .into(),
        ));
    }
    let fix = match regions.first() {
        None => return Ok(out),
        Some(RegionBody::ScrewPart(_)) => {
            out.setup += &casing_and_hopper_region(&ScrewFeederSpec::default(), CASING_REGION);
            out.notes.push("LAMMPS: the casing and hopper are one union region of a cylinder, blocks and planes (the same dimensions as the STL meshes, whose bore is a 128-gon); below the outlet the region is a vertical box, above the casing's end open space, as in cgdem where grains fall freely".into());
            fixes(CASING_REGION, 0)?
        }
        Some(RegionBody::Silo(name, spec, material)) => {
            let region = format!("silo_{name}");
            out.setup += &silo_region(spec, &region);
            out.notes.push(format!("LAMMPS: the silo is one union region of a cone (the hopper) and a cylinder, open at both ends, the same dimensions as cgdem's mesh (a {}-gon in cgdem, true circles here); it has no orifice lip: a grain whose centre has passed below the orifice plane no longer feels the rim, where cgdem's grains still touch the lip's edge", spec.segments));
            fixes(&region, *material)?
        }
        Some(RegionBody::Cylinder(b, c)) => {
            let region = format!("cylinder_{}", b.name);
            cylinder_lines(scene, b, c, &region, dt, &mut out);
            fixes(&region, b.material)?
        }
    };
    out.setup += &fix;
    out.refix_walls = refix(&fix);
    Ok(out)
}

/// `unfix` of every fix in `fixes`, then `fixes` again.
fn refix(fixes: &str) -> String {
    let mut d = String::new();
    for name in fixes.lines().filter_map(|l| l.split_whitespace().nth(1)) {
        let _ = writeln!(d, "unfix           {name}");
    }
    d + fixes
}

/// A body built of particles: its group and, when it turns, its `fix move` from its stage.
fn particle_body(
    scene: &Scene,
    k: usize,
    bp: &BodyParticles,
    out: &mut BodyLines,
) -> Result<(), DeckError> {
    let unsupported = |reason: String| DeckError::unsupported(scene, reason);
    let b = &scene.bodies[k];
    // The body's atoms are its species' atoms: no other body or insertion may use it.
    let shared = scene
        .bodies
        .iter()
        .enumerate()
        .any(|(j, o)| j != k && o.particles.as_ref().map(|p| p.species) == Some(bp.species))
        || scene.insertions.iter().any(|i| i.species == bp.species);
    if shared {
        return Err(unsupported(format!(
            "body[{k}] `{}`: its species `{}` is used elsewhere too; the LAMMPS deck groups a particle body by its atom type",
            b.name, scene.species[bp.species].name
        )));
    }
    let _ = writeln!(
        out.setup,
        "group           body_{} type {}",
        b.name,
        bp.species + 1
    );
    if b.velocity.length() > 0.0 {
        return Err(unsupported(format!(
            "body[{k}] `{}` translates; LAMMPS decks rotate bodies only",
            b.name
        )));
    }
    if b.rpm != 0.0 {
        // `fix move rotate` turns counter-clockwise about its axis once per period;
        // a negative rpm turns about the reversed axis.
        let axis = if b.rpm < 0.0 { -b.axis } else { b.axis };
        let line = format!(
            "fix             move_{0} body_{0} move rotate {1} {2} {3} {4} {5} {6} {7}\n",
            b.name,
            g(b.point.x),
            g(b.point.y),
            g(b.point.z),
            g(axis.x),
            g(axis.y),
            g(axis.z),
            g(60.0 / b.rpm.abs())
        );
        out.motions.push((b.start_stage.clone(), line));
    }
    Ok(())
}

/// What region a mesh body becomes, or the refusal naming it.
fn region_body(scene: &Scene, k: usize) -> Result<RegionBody<'_>, DeckError> {
    let b = &scene.bodies[k];
    let still = b.rpm == 0.0 && b.velocity.length() == 0.0;
    let refuse = |why: String| {
        DeckError::unsupported(scene, format!("body[{k}] `{}`: {why}; {TAKEN}", b.name))
    };
    match &b.mesh {
        MeshSource::ScrewFeeder(part) if (part == "casing" || part == "hopper") && still => {
            Ok(RegionBody::ScrewPart(part.as_str()))
        }
        MeshSource::Silo(SiloPart::Wall, spec) if still => {
            Ok(RegionBody::Silo(b.name.as_str(), spec, b.material))
        }
        _ => {
            let mesh = b
                .load_mesh()
                .map_err(|e| refuse(format!("its mesh cannot be read ({e})")))?;
            let c = closed_cylinder(&mesh, b.point, b.axis)
                .map_err(|e| refuse(format!("not a closed cylinder: {e}")))?;
            if b.velocity.length() > 0.0 {
                return Err(refuse(
                    "it translates; LAMMPS decks rotate cylinders only".into(),
                ));
            }
            Ok(RegionBody::Cylinder(b, c))
        }
    }
}

/// A closed cylinder body as `region NAME cylinder ... side in` (both ends closed), turning
/// about its axis through the body's point from its start stage with `rotate v_theta`:
/// theta is 0 until the stage begins, then the body's angular speed times the time since
/// (the step at the stage's start captured with an immediate `$(step)`). The region's shape
/// does not change as it turns; `fix wall/gran/region` takes the wall's velocity at each
/// contact from the region's rotation (its angle's change per step, about the given axis
/// vector, which is why the axis is written as a unit vector), so the wall drags the grains.
fn cylinder_lines(
    scene: &Scene,
    b: &BodySettings,
    c: &Cylinder,
    region: &str,
    dt: Real,
    out: &mut BodyLines,
) {
    let mut rotate = String::new();
    if b.rpm != 0.0 {
        let (theta, start) = (format!("theta_{}", b.name), format!("start_{}", b.name));
        let axis = b.axis / b.axis.length();
        // cgdem's rpm is right-handed about `axis`, as LAMMPS's region rotation for a
        // positive angle; a negative rpm gives a negative angle.
        let per_step = b.rpm * std::f64::consts::TAU / 60.0 * dt;
        let stage = b
            .start_stage
            .clone()
            .or_else(|| scene.stages.first().map(|s| s.name.clone()));
        let count = format!(
            "variable        {start} equal $(step)\nvariable        {theta} equal {}*(step-v_{start})\n",
            g(per_step)
        );
        match stage {
            Some(stage) => {
                let _ = writeln!(out.setup, "variable        {theta} equal 0.0");
                out.turns.push((stage, count));
            }
            None => out.setup += &count,
        }
        rotate = format!(
            " rotate v_{theta} {} {} {} {} {} {}",
            g(b.point.x),
            g(b.point.y),
            g(b.point.z),
            g(axis.x),
            g(axis.y),
            g(axis.z)
        );
    }
    let _ = writeln!(
        out.setup,
        "region          {region} cylinder {} {} {} {} {} {} side in{rotate}",
        c.dim_name(),
        g(c.centre[0]),
        g(c.centre[1]),
        g(c.radius),
        g(c.lo),
        g(c.hi)
    );
    out.notes.push(format!(
        "LAMMPS: the body `{}` is a cylinder region about {} of radius {:.6} m from {:.6} to {:.6} m, closed at both ends: a true circle where the mesh is a {}-gon. The radius is the {}-gon's corners' (the circle its vertices were placed on, so the nominal radius of a drum drawn as an N-gon on it, as the drum's STL and MercuryDPM's triangles are); its faces lie up to {:.2e} m closer to the axis (apothem {:.6} m). The smooth circle drags the grains by friction alone, where the polygon's corners also push them; and LAMMPS's region contact takes the wall's curvature (R* = 2 r R/(2 R - r) for a grain of radius r), where the flat faces give R* = r",
        b.name,
        c.dim_name(),
        c.radius,
        c.lo,
        c.hi,
        c.sides,
        c.sides,
        c.radius - c.apothem,
        c.apothem
    ));
    if b.rpm != 0.0 {
        out.notes.push(format!(
            "LAMMPS: the cylinder `{}` turns as a rotating region (`region ... rotate v_theta`, theta counted in steps from the start of its stage), so its wall velocity at a contact is omega x r; the wall fix is not defined anew when it starts",
            b.name
        ));
    }
}

/// The built-in silo's inside as one LAMMPS region named `name` (inside = where grains may
/// be): the hopper, a cone from the orifice (radius r0) to the hopper's top (radius R), and
/// the cylinder from there to the rim, each with its end faces open, so the orifice and the
/// top are open and the two pieces join without a face between them. Below the orifice a
/// grain is outside the region and feels no wall (`fix wall/gran/region` skips it).
pub(crate) fn silo_region(spec: &SiloSpec, name: &str) -> String {
    let l = spec.layout();
    let mut d = String::new();
    let _ = writeln!(
        d,
        "# The built-in silo (SiloSpec, reference/silo/SOURCE.md) as a union region."
    );
    let _ = writeln!(
        d,
        "region          {name}_hopper cone z 0.0 0.0 {} {} {} {} side in open 1 open 2",
        g(l.orifice_radius),
        g(l.radius),
        g(l.orifice_z),
        g(l.hopper_top_z)
    );
    let _ = writeln!(
        d,
        "region          {name}_cylinder cylinder z 0.0 0.0 {} {} {} side in open 1 open 2",
        g(l.radius),
        g(l.hopper_top_z),
        g(l.rim_z)
    );
    let _ = writeln!(
        d,
        "region          {name} union 2 {name}_hopper {name}_cylinder side in"
    );
    d
}

/// The seed's casing and hopper as one LAMMPS region named `name` (inside = where grains may
/// be): the bore (a cylinder about x from the end plate's inner face to the tube's end), the
/// inlet chute (a block over the inlet from the axis up into the hopper), the outlet (a block
/// under the outlet opening down to the box's floor, across the box in y), what lies beyond
/// the tube's end, and the hopper (four sloping planes through the inner rims of its bottom
/// and top openings, cut below at half the chute's height, where its pieces lie inside the
/// chute: uncut, its planes would continue into the bore).
pub(crate) fn casing_and_hopper_region(spec: &ScrewFeederSpec, name: &str) -> String {
    let l = spec.layout();
    let ri = l.bore_radius;
    let (z0, z1) = (l.hopper_bottom_z, l.hopper_top_z);
    let (bottom, top) = (hopper_inner_rect(spec, z0), hopper_inner_rect(spec, z1));
    let h = z1 - z0;
    let mut d = String::new();
    let _ = writeln!(
        d,
        "# The seed's casing and hopper (ScrewFeederSpec, reference/SCREW_GEOMETRY.md) as a union region."
    );
    let _ = writeln!(
        d,
        "region          {name}_bore cylinder x 0.0 0.0 {} {} {} side in",
        g(ri),
        g(l.end_plate_x[1]),
        g(l.casing_end_x)
    );
    let _ = writeln!(
        d,
        "region          {name}_chute block {} {} {} {} 0.0 {} side in",
        g(l.inlet_x[0]),
        g(l.inlet_x[1]),
        g(-ri),
        g(ri),
        g(z0 + 0.5 * h)
    );
    let _ = writeln!(
        d,
        "region          {name}_outlet block {} {} EDGE EDGE EDGE 0.0 side in",
        g(l.outlet_x[0]),
        g(l.outlet_x[1])
    );
    // Starting a hair inside the tube, so that the bore's end cap lies inside this piece.
    let _ = writeln!(
        d,
        "region          {name}_beyond block {} EDGE EDGE EDGE EDGE EDGE side in",
        g(l.casing_end_x - 1e-6)
    );
    // Each wall through its bottom rim, inward normal (into the hopper), tilted up by the
    // outward slope of the wall.
    let planes = [
        (bottom[0], top[0], [h, 0.0, bottom[0] - top[0]], 0),
        (bottom[1], top[1], [-h, 0.0, top[1] - bottom[1]], 0),
        (bottom[2], top[2], [0.0, h, bottom[2] - top[2]], 1),
        (bottom[3], top[3], [0.0, -h, top[3] - bottom[3]], 1),
    ];
    for (k, (at, _, n, axis)) in planes.iter().enumerate() {
        let mut p = [0.0, 0.0, z0];
        p[*axis] = *at;
        let _ = writeln!(
            d,
            "region          {name}_wall{k} plane {} {} {} {} {} {} side in",
            g(p[0]),
            g(p[1]),
            g(p[2]),
            g(n[0]),
            g(n[1]),
            g(n[2])
        );
    }
    let _ = writeln!(
        d,
        "region          {name}_cut plane 0.0 0.0 {} 0.0 0.0 1.0 side in",
        g(0.5 * z0)
    );
    let _ = writeln!(
        d,
        "region          {name}_hopper intersect 5 {name}_wall0 {name}_wall1 {name}_wall2 {name}_wall3 {name}_cut side in"
    );
    let _ = writeln!(
        d,
        "region          {name} union 5 {name}_bore {name}_chute {name}_outlet {name}_beyond {name}_hopper side in"
    );
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The uniform deck's one wall fix of a region, on all atoms.
    fn one_fix(region: &str, _material: usize) -> Result<String, DeckError> {
        Ok(format!(
            "fix             w_{region} all wall/gran/region granular hertz/material region {region}\n"
        ))
    }

    /// Parses `region NAME plane px py pz nx ny nz` lines of a deck.
    fn planes(deck: &str) -> Vec<([f64; 3], [f64; 3])> {
        deck.lines()
            .filter(|l| l.contains(" plane "))
            .map(|l| {
                let v: Vec<f64> = l
                    .split_whitespace()
                    .skip(3)
                    .take(6)
                    .map(|w| w.parse().unwrap())
                    .collect();
                ([v[0], v[1], v[2]], [v[3], v[4], v[5]])
            })
            .collect()
    }

    #[test]
    fn hopper_planes_pass_through_both_rims_of_the_hopper_mesh_and_face_inward() {
        let spec = ScrewFeederSpec::default();
        let l = spec.layout();
        let d = casing_and_hopper_region(&spec, "c");
        let planes = planes(&d);
        assert_eq!(planes.len(), 5);
        let side = |(p, n): &([f64; 3], [f64; 3]), q: [f64; 3]| {
            (0..3).map(|k| (q[k] - p[k]) * n[k]).sum::<f64>()
        };
        // The hopper mesh's inner corners at the bottom and the top lie on the planes.
        for z in [l.hopper_bottom_z, l.hopper_top_z] {
            let r = hopper_inner_rect(&spec, z);
            for (k, plane) in planes[..4].iter().enumerate() {
                let corner = match k {
                    0 => [r[0], 0.0, z],
                    1 => [r[1], 0.0, z],
                    2 => [0.0, r[2], z],
                    _ => [0.0, r[3], z],
                };
                assert!(side(plane, corner).abs() < 1e-12, "wall {k} at z = {z}");
            }
        }
        // The hopper's centre is inside every plane; a point under the cut is not.
        let centre = [0.159, 0.0, 0.5 * (l.hopper_bottom_z + l.hopper_top_z)];
        assert!(planes.iter().all(|p| side(p, centre) > 0.0));
        assert!(side(&planes[4], [0.159, 0.0, 0.0]) < 0.0);
        // The bore from the end plate's inner face to the tube's end.
        assert!(d.contains(&format!(
            "region          c_bore cylinder x 0.0 0.0 {} {} {} side in",
            g(l.bore_radius),
            g(l.end_plate_x[1]),
            g(l.casing_end_x)
        )));
        assert!(d.contains(
            "region          c union 5 c_bore c_chute c_outlet c_beyond c_hopper side in"
        ));
    }

    /// The numbers of the region line `region NAME STYLE ...` (after the style's axis).
    fn region_numbers(deck: &str, name: &str) -> Vec<f64> {
        let line = deck
            .lines()
            .find(|l| l.split_whitespace().nth(1) == Some(name))
            .unwrap_or_else(|| panic!("no region {name} in\n{deck}"));
        line.split_whitespace()
            .skip(4)
            .map_while(|w| w.parse().ok())
            .collect()
    }

    #[test]
    fn the_silo_region_is_the_cases_hopper_and_cylinder_through_the_meshs_inner_rims() {
        crate::at_repo_root();
        let scene = Scene::load_with_overrides(
            std::path::Path::new("validation/cases/silo_reduced.toml"),
            &[cgdem_core::scene::Override::parse(
                "silo.orifice_diameter=0.06",
                std::path::Path::new("test"),
            )
            .unwrap()],
        )
        .unwrap();
        let lines = body_lines(&scene, 1e-4, &one_fix).unwrap();
        let MeshSource::Silo(SiloPart::Wall, spec) = &scene.bodies[0].mesh else {
            panic!("{:?}", scene.bodies[0].mesh)
        };
        // cone: c1 c2 radlo radhi lo hi; cylinder: c1 c2 radius lo hi.
        let cone = region_numbers(&lines.setup, "silo_silo_hopper");
        let cylinder = region_numbers(&lines.setup, "silo_silo_cylinder");
        let near = |a: &[f64], b: &[f64]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-15)
        };
        assert!(near(&cone, &[0.0, 0.0, 0.03, 0.1, 0.0, 0.07]), "{cone:?}");
        assert!(
            near(&cylinder, &[0.0, 0.0, 0.1, 0.07, 0.19]),
            "{cylinder:?}"
        );
        // Every vertex of the mesh below the rim and off the orifice's lip lies on the cone or
        // the cylinder (its inner surface: the 96-gon's corners lie on the circles) or the
        // wall's thickness outside it.
        let mesh = cgdem_core::geometry::silo::wall_mesh(spec);
        let mut inner = 0;
        for v in &mesh.vertices {
            let r = v.x.hypot(v.y);
            let lip = v.z.abs() < 1e-12
                && r > cone[2] + 1e-12
                && r < cone[2] + spec.wall_thickness - 1e-12;
            if v.z > cylinder[4] - 1e-12 || lip {
                continue;
            }
            let surface = if v.z <= cone[5] {
                cone[2] + (v.z - cone[4]) * (cone[3] - cone[2]) / (cone[5] - cone[4])
            } else {
                cylinder[2]
            };
            if (r - surface).abs() < 1e-12 {
                inner += 1;
            } else {
                assert!(
                    (r - surface - spec.wall_thickness).abs() < 1e-12,
                    "vertex {v:?} (r = {r})"
                );
            }
        }
        assert!(inner > 1000, "{inner}");
        assert!(lines.setup.contains(
            "region          silo_silo union 2 silo_silo_hopper silo_silo_cylinder side in"
        ));
        assert!(lines
            .setup
            .contains("wall/gran/region granular hertz/material region silo_silo"));
        assert!(lines
            .refix_walls
            .starts_with("unfix           w_silo_silo\n"));
    }

    #[test]
    fn a_mesh_body_other_than_the_seeds_casing_and_hopper_is_refused_by_name() {
        crate::at_repo_root();
        let mut scene = Scene::load(std::path::Path::new(
            "validation/cases/screw_feeder_hertz.toml",
        ))
        .unwrap();
        let e = body_lines(&scene, 1e-4, &one_fix)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("body[0] `screw`: not a closed cylinder")
                && e.contains("no mesh walls")
                && e.contains("a closed cylinder about its axis"),
            "{e}"
        );
        scene.bodies.remove(0);
        scene.bodies.remove(1);
        let e = body_lines(&scene, 1e-4, &one_fix)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("casing and hopper together"), "{e}");
    }

    /// The reduced drum's scene, both species at 5e6 Pa as in the drum suite's `e5` variant.
    fn drum_e5() -> Scene {
        crate::at_repo_root();
        let set = [
            "species[0].youngs_modulus=5e6",
            "species[1].youngs_modulus=5e6",
            "contact.youngs_modulus=5e6",
            "time.dt=5e-5",
        ];
        let overrides: Vec<_> = set
            .iter()
            .map(|s| cgdem_core::scene::Override::parse(s, std::path::Path::new("test")).unwrap())
            .collect();
        Scene::load_with_overrides(
            std::path::Path::new("validation/cases/drum_reduced.toml"),
            &overrides,
        )
        .unwrap()
    }

    #[test]
    fn the_drum_mesh_is_a_y_cylinder_region_turning_from_its_stage() {
        let scene = drum_e5();
        let lines = body_lines(&scene, 5e-5, &one_fix).unwrap();
        // cylinder: c1 c2 radius lo hi, then `side in rotate v_theta_drum P A`.
        let c = region_numbers(&lines.setup, "cylinder_drum");
        let want = [0.0, 0.0, 0.1, -0.0075, 0.0075];
        assert!(
            c.len() == 5 && c.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-7),
            "{c:?}\n{}",
            lines.setup
        );
        let region = lines
            .setup
            .lines()
            .find(|l| l.contains("region          cylinder_drum cylinder y "))
            .unwrap();
        let rotate: Vec<f64> = region
            .split(" rotate v_theta_drum ")
            .nth(1)
            .unwrap()
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect();
        assert_eq!(rotate, [0.0, 0.0, 0.0, 0.0, -1.0, 0.0], "{region}");
        assert!(region.contains(" side in rotate "), "{region}");
        // Still until `rotate`; then 2 rad/s x 5e-5 s per step since the stage's first step.
        let still = lines
            .setup
            .find("variable        theta_drum equal 0.0")
            .unwrap();
        assert!(still < lines.setup.find(region).unwrap());
        assert_eq!(lines.turns.len(), 1);
        let (stage, turn) = &lines.turns[0];
        assert_eq!(stage, "rotate");
        let mut turn_lines = turn.lines();
        assert_eq!(
            turn_lines.next(),
            Some("variable        start_drum equal $(step)")
        );
        let theta = turn_lines.next().unwrap();
        let per_step: f64 = theta
            .strip_prefix("variable        theta_drum equal ")
            .and_then(|t| t.strip_suffix("*(step-v_start_drum)"))
            .unwrap()
            .parse()
            .unwrap();
        assert!((per_step - 2.0 * 5e-5).abs() < 1e-15, "{theta}");
        assert!(lines.motions.is_empty());
        assert!(lines
            .refix_walls
            .starts_with("unfix           w_cylinder_drum\n"));
        assert!(lines.notes[0].contains("a true circle where the mesh is a 100-gon"));
    }

    #[test]
    fn the_drum_deck_gives_each_species_its_wall_fix_on_the_region_and_starts_the_angle_with_its_stage(
    ) {
        let scene = drum_e5();
        let particles = cgdem_core::run::initial_particles_clear_of_bodies(&scene).unwrap();
        let deck = super::super::write_hertz_deck(&scene, &particles, 5e-5).unwrap();
        let d = &deck.input;
        let at = |s: &str| d.find(s).unwrap_or_else(|| panic!("no `{s}` in\n{d}"));
        let region = at("region          cylinder_drum cylinder y");
        for t in [1, 2] {
            let fix = at(&format!(
                "fix             w_cylinder_drum_{t} grains_{t} wall/gran/region granular hertz/material"
            ));
            assert!(region < fix && at(&format!("group           grains_{t} type {t}")) < fix);
        }
        // M1 and M2 against steel: restitution 0.4 alike, friction 0.2 alike, own modulus.
        let fixes: Vec<&str> = d
            .lines()
            .filter(|l| l.contains("wall/gran/region"))
            .collect();
        assert_eq!(fixes.len(), 2, "{fixes:?}");
        let start = at("variable        start_drum equal $(step)");
        assert!(at("CGDEM_STAGE settle end") < start && start < at("CGDEM_STAGE rotate start"));
        // The turn needs no new setup: no `run 0` and no refix between the stages.
        let between = &d[at("CGDEM_STAGE settle end")..at("CGDEM_STAGE rotate start")];
        assert!(
            !between.contains("run ") && !between.contains("unfix"),
            "{between}"
        );
    }
}
