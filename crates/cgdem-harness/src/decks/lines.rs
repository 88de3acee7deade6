//! The deck lines LAMMPS and LIGGGHTS take alike (a dialect gives the words that differ):
//! header, preamble, neighbour list, frozen species, regions and the data file.

use std::fmt::Write as _;

use super::{Dialect, DATA_FILE};
use cgdem_core::math::{Real, Vec3};
use cgdem_core::particles::Particles;
use cgdem_core::scene::Scene;

/// The `boundary` line (LAMMPS and LIGGGHTS alike): `p` on periodic axes, `f` elsewhere.
pub(crate) fn boundary_line(scene: &Scene) -> String {
    let flag = |axis: usize| {
        if scene.domain.periodic[axis] {
            "p"
        } else {
            "f"
        }
    };
    format!("boundary        {} {} {}\n", flag(0), flag(1), flag(2))
}

/// The first words of a deck's header comment: `# LAMMPS input written by cgdem 0.1.0 from
/// case.toml (scene `name``; the caller closes it.
pub(crate) fn written_by(dialect: &Dialect, scene: &Scene) -> String {
    format!(
        "# {} input written by cgdem {} from {} (scene `{}`",
        dialect.code.label(),
        env!("CARGO_PKG_VERSION"),
        scene.source.display(),
        scene.name
    )
}

/// The set-up every deck starts with, after its header: SI units, spheres with a diameter
/// (`sphere` in LAMMPS, `granular` in LIGGGHTS), the boundary, `newton off` with ghost
/// velocities communicated, and the data file.
pub(crate) fn preamble(dialect: &Dialect, scene: &Scene) -> String {
    let mut d = format!(
        "units           si\natom_style      {}\natom_modify     map array\n",
        dialect.atom_style
    );
    d += &boundary_line(scene);
    let _ = writeln!(d, "newton          off\n{}", dialect.ghost_velocities);
    let _ = writeln!(d, "read_data       {DATA_FILE}");
    d
}

/// The neighbour list: a skin of `skin_fraction` largest diameters, rebuilt when needed
/// (LIGGGHTS checks every step by default and takes only the delay).
pub(crate) fn neighbor_lines(dialect: &Dialect, scene: &Scene) -> String {
    format!(
        "neighbor        {} bin\n{}\n",
        g(scene.skin_fraction * scene.max_diameter()),
        dialect.neigh_modify
    )
}

/// Frozen species (LAMMPS and LIGGGHTS alike): the `nve/sphere` fix's group, and the lines
/// that freeze the rest (`fix freeze`, which also makes pair styles use the mobile partner's
/// mass as the effective mass) and exclude frozen-frozen pairs from the neighbour list, as
/// cgdem does. Without frozen species: `all` and nothing.
pub(crate) fn frozen_lines(scene: &Scene) -> (&'static str, String) {
    let frozen: Vec<usize> = (0..scene.species.len())
        .filter(|&k| scene.species[k].frozen)
        .map(|k| k + 1)
        .collect();
    if frozen.is_empty() {
        return ("all", String::new());
    }
    let types: Vec<String> = frozen.iter().map(|t| t.to_string()).collect();
    let mut lines = format!(
        "group           frozen type {}
",
        types.join(" ")
    );
    lines += "group           mobile subtract all frozen
";
    for (k, a) in frozen.iter().enumerate() {
        for b in &frozen[k..] {
            lines += &format!("neigh_modify    exclude type {a} {b}\n");
        }
    }
    lines += "fix             freeze frozen freeze\n";
    ("mobile", lines)
}

pub(crate) fn g(x: Real) -> String {
    format!("{x:.17e}")
}

/// Removes the wall fix `w_NAME` of a Hertz deck (LAMMPS and LIGGGHTS name them alike).
pub(crate) fn unfix_wall(name: &str) -> String {
    format!("unfix           w_{name}\n")
}

/// `region NAME block xlo xhi ylo yhi zlo zhi` for the box `lo..hi` (LAMMPS and LIGGGHTS).
pub(crate) fn block_region(name: &str, lo: Vec3, hi: Vec3) -> String {
    format!(
        "region          {name} block {} {} {} {} {} {}\n",
        g(lo.x),
        g(hi.x),
        g(lo.y),
        g(hi.y),
        g(lo.z),
        g(hi.z)
    )
}

/// A `read_data` file for `atom_style sphere` (LAMMPS) or `granular` (LIGGGHTS, same columns):
/// `n_types` atom types (at least one per species; LIGGGHTS walls take one more), per
/// species the diameter and density given, the particles' positions, velocities and
/// spins (zero without angular state). Ids are `id + 1`, types `species + 1`.
pub fn data_file(
    scene: &Scene,
    particles: &Particles,
    diameters: &[Real],
    densities: &[Real],
    n_types: usize,
) -> String {
    let title = format!(
        "LAMMPS data file written by cgdem {} for scene {} (lambda = {})",
        env!("CARGO_PKG_VERSION"),
        scene.name,
        scene.lambda
    );
    cgdem_core::lammps_data::data_text(
        &title,
        scene.domain.lo,
        scene.domain.hi,
        particles,
        diameters,
        densities,
        n_types,
    )
}
