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
//! - any other mesh body is refused, naming it.
//!
//! A union region keeps a piece's surface only where it does not lie inside another piece,
//! which is how the openings arise: the bore's upper half is inside the inlet chute, its
//! lower half inside the outlet box.

use std::fmt::Write as _;

use crate::decks::lines::g;
use crate::decks::DeckError;
use cgdem_core::geometry::screw_feeder::{hopper_inner_rect, ScrewFeederSpec};
use cgdem_core::geometry::silo::SiloSpec;
use cgdem_core::scene::{MeshSource, Scene, SiloPart};

/// The deck lines of the scene's bodies.
pub(crate) struct BodyLines {
    /// Groups, regions and the wall fix, before the first run.
    pub setup: String,
    /// The wall fix of the mesh bodies (`unfix` + `fix` again, before each later setup: LAMMPS
    /// re-applies its Tsuji polynomial to a wall fix's coefficient at every setup), if any.
    pub refix_walls: String,
    /// `(start stage, fix move lines)` of the turning bodies; `None`: from the first run.
    pub motions: Vec<(Option<String>, String)>,
    pub notes: Vec<String>,
}

/// Region name of the seed's casing and hopper.
const CASING_REGION: &str = "casing_hopper";

/// The lines for the scene's bodies: `integrated` is the group of the mobile atoms,
/// `wall_model` the `granular` sub-model arguments of the deck's walls.
pub(crate) fn body_lines(
    scene: &Scene,
    integrated: &str,
    wall_model: &str,
) -> Result<BodyLines, DeckError> {
    let unsupported = |reason: String| DeckError::unsupported(scene, reason);
    let mut out = BodyLines {
        setup: String::new(),
        refix_walls: String::new(),
        motions: Vec::new(),
        notes: Vec::new(),
    };
    let mut static_parts = Vec::new();
    let mut silos = Vec::new();
    for (k, b) in scene.bodies.iter().enumerate() {
        if let Some(bp) = &b.particles {
            // The body's atoms are its species' atoms: no other body or insertion may use it.
            let shared = scene.bodies.iter().enumerate().any(|(j, o)| {
                j != k && o.particles.as_ref().map(|p| p.species) == Some(bp.species)
            }) || scene.insertions.iter().any(|i| i.species == bp.species);
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
            continue;
        }
        match &b.mesh {
            MeshSource::ScrewFeeder(part)
                if (part == "casing" || part == "hopper")
                    && b.rpm == 0.0
                    && b.velocity.length() == 0.0 =>
            {
                static_parts.push(part.as_str());
            }
            MeshSource::Silo(SiloPart::Wall, spec) if b.rpm == 0.0 && b.velocity.length() == 0.0 => {
                silos.push((b.name.as_str(), spec));
            }
            _ => {
                return Err(unsupported(format!(
                    "body[{k}] `{}`: LAMMPS has no mesh walls; its decks take bodies built of particles, the fixed casing and hopper of Hirose's screw feeder (`screw-feeder:casing`, `screw-feeder:hopper`) and the fixed built-in silo (`silo:wall`) only",
                    b.name
                )))
            }
        }
    }
    if !static_parts.is_empty() {
        static_parts.sort_unstable();
        if static_parts != ["casing", "hopper"] {
            return Err(unsupported(format!(
                "bodies {static_parts:?}: the LAMMPS deck writes the screw feeder's casing and hopper together, as one region (each once)"
            )));
        }
        out.setup += &casing_and_hopper_region(&ScrewFeederSpec::default(), CASING_REGION);
        let fix = format!(
            "fix             w_{CASING_REGION} {integrated} wall/gran/region granular {wall_model} region {CASING_REGION}\n"
        );
        out.setup += &fix;
        out.refix_walls = format!("unfix           w_{CASING_REGION}\n{fix}");
        out.notes.push("LAMMPS: the casing and hopper are one union region of a cylinder, blocks and planes (the same dimensions as the STL meshes, whose bore is a 128-gon); below the outlet the region is a vertical box, above the casing's end open space, as in cgdem where grains fall freely".into());
    }
    if !static_parts.is_empty() && !silos.is_empty() || silos.len() > 1 {
        return Err(unsupported(
            "the LAMMPS deck writes one region wall: the casing and hopper of Hirose's screw feeder, or one silo"
                .into(),
        ));
    }
    if let Some((name, spec)) = silos.first() {
        let region = format!("silo_{name}");
        out.setup += &silo_region(spec, &region);
        let fix = format!(
            "fix             w_{region} {integrated} wall/gran/region granular {wall_model} region {region}\n"
        );
        out.setup += &fix;
        out.refix_walls = format!("unfix           w_{region}\n{fix}");
        out.notes.push(format!("LAMMPS: the silo is one union region of a cone (the hopper) and a cylinder, open at both ends, the same dimensions as cgdem's mesh (a {}-gon in cgdem, true circles here); it has no orifice lip: a grain whose centre has passed below the orifice plane no longer feels the rim, where cgdem's grains still touch the lip's edge", spec.segments));
    }
    Ok(out)
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
        let lines = body_lines(&scene, "all", "hertz/material").unwrap();
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
        let e = body_lines(&scene, "all", "hertz/material")
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("body[0] `screw`") && e.contains("no mesh walls"),
            "{e}"
        );
        scene.bodies.remove(0);
        scene.bodies.remove(1);
        let e = body_lines(&scene, "all", "hertz/material")
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("casing and hopper together"), "{e}");
    }
}
