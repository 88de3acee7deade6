//! Particles given one by one: `read_data` (a LAMMPS data file) and `[[particle]]` tables.
//! A species has one size and one density, so each given diameter and density must be its
//! species' (to 1e-6): a data file from another setup is refused rather than silently
//! resized.

use std::path::Path;

use super::super::raw::*;
use super::super::*;
use super::{names, Checker};
use crate::io::lammps_data::{parse_data, DataFileError};

/// Relative tolerance of a given diameter or density against its species'.
const MATCH: Real = 1e-6;

fn matches(given: Real, species: Real) -> bool {
    (given - species).abs() <= MATCH * species.abs()
}

pub(super) fn given_particles(
    c: &Checker,
    raw: &RawScene,
    domain: &Domain,
    species: &[Species],
) -> Result<Vec<GivenParticle>, SceneError> {
    let rotates = raw.contact.model == "hertz";
    let mut out = Vec::new();
    if let Some(name) = &raw.read_data {
        let path = c.file.parent().unwrap_or(Path::new(".")).join(name);
        let text = std::fs::read_to_string(&path).map_err(|source| SceneError::Unreadable {
            file: path.clone(),
            source,
        })?;
        out = given_particles_from_data(&text, &path, species, domain, rotates)?;
    }
    for (k, p) in raw.particles.iter().enumerate() {
        let field = |f: &str| format!("particle[{k}].{f}");
        let s = species
            .iter()
            .position(|s| s.name == p.species)
            .ok_or_else(|| {
                c.invalid(
                    field("species"),
                    &p.species,
                    format!(
                        "one of the species: {}",
                        names(species.iter().map(|s| &s.name))
                    ),
                )
            })?;
        let position = c.vector(&field("position"), p.position)?;
        if let Some(axis) = outside(domain, position) {
            return Err(c.invalid(
                field("position"),
                format!("{:?}", p.position),
                format!(
                    "inside the domain, {} .. {} along axis {axis}",
                    domain.lo[axis], domain.hi[axis]
                ),
            ));
        }
        if let Some(d) = p.diameter {
            if !matches(d, species[s].diameter) {
                return Err(c.invalid(
                    field("diameter"),
                    d,
                    format!(
                        "the diameter of species `{}`, {} m (a species has one size: give another size its own species)",
                        species[s].name, species[s].diameter
                    ),
                ));
            }
        }
        let omega = match p.omega {
            None => Vec3::ZERO,
            Some(w) if !rotates => {
                return Err(c.invalid(
                    field("omega"),
                    format!("{w:?}"),
                    "no omega: the contact law does not rotate particles; an initial angular velocity needs contact.model = \"hertz\"",
                ))
            }
            Some(w) => c.vector(&field("omega"), w)?,
        };
        out.push(GivenParticle {
            species: s,
            position,
            velocity: c.vector(&field("velocity"), p.velocity.unwrap_or([0.0; 3]))?,
            omega,
        });
    }
    Ok(out)
}

/// The first axis along which `x` lies outside the domain (a periodic side is half-open).
fn outside(domain: &Domain, x: Vec3) -> Option<usize> {
    (0..3).find(|&a| {
        x[a] < domain.lo[a] || x[a] > domain.hi[a] || (domain.periodic[a] && x[a] >= domain.hi[a])
    })
}

/// The particles of a LAMMPS data file's text (`file` named in errors), in atom-ID order:
/// atom type `t` is species `t - 1` (the numbering of the decks cgdem writes); each
/// diameter and density must be its species', each position inside the domain, and spins
/// need a contact law that rotates (`rotates`).
pub fn given_particles_from_data(
    text: &str,
    file: &Path,
    species: &[Species],
    domain: &Domain,
    rotates: bool,
) -> Result<Vec<GivenParticle>, SceneError> {
    let data = parse_data(text, file)?;
    let error = |line: usize, field: &str, value: String, allowed: String| {
        SceneError::DataFile(DataFileError {
            file: file.to_path_buf(),
            line: Some(line),
            field: field.into(),
            value,
            allowed,
        })
    };
    let mut order: Vec<usize> = (0..data.atoms.len()).collect();
    order.sort_by_key(|&k| data.atoms[k].id);
    let mut out = Vec::with_capacity(order.len());
    for k in order {
        let a = &data.atoms[k];
        let Some(s) = species.get(a.atom_type as usize - 1) else {
            return Err(error(
                a.line,
                "Atoms atom-type",
                a.atom_type.to_string(),
                format!(
                    "1 to {}: atom type t is the scene's t-th species ({})",
                    species.len(),
                    names(species.iter().map(|s| &s.name))
                ),
            ));
        };
        if !matches(a.diameter, s.diameter) {
            return Err(error(
                a.line,
                "Atoms diameter",
                a.diameter.to_string(),
                format!(
                    "the diameter of species `{}` (atom type {}), {} m: a species has one size, give another size its own species",
                    s.name, a.atom_type, s.diameter
                ),
            ));
        }
        if !matches(a.density, s.density) {
            return Err(error(
                a.line,
                "Atoms density",
                a.density.to_string(),
                format!(
                    "the density of species `{}` (atom type {}), {} kg/m^3: the scene's species set the material",
                    s.name, a.atom_type, s.density
                ),
            ));
        }
        if let Some(axis) = outside(domain, a.position) {
            let name = ["x", "y", "z"][axis];
            return Err(error(
                a.line,
                &format!("Atoms {name}"),
                a.position[axis].to_string(),
                format!(
                    "inside the scene's domain, {} .. {} (the header's box is not used: [domain] sets it)",
                    domain.lo[axis], domain.hi[axis]
                ),
            ));
        }
        let (velocity, omega) = match &data.velocities {
            None => (Vec3::ZERO, Vec3::ZERO),
            Some(v) => {
                let v = &v[k];
                if !rotates && v.omega != Vec3::ZERO {
                    return Err(error(
                        v.line,
                        "Velocities wx wy wz",
                        format!("{:?}", v.omega.to_array()),
                        "zero: the contact law does not rotate particles; spins need contact.model = \"hertz\"".into(),
                    ));
                }
                (v.velocity, v.omega)
            }
        };
        out.push(GivenParticle {
            species: a.atom_type as usize - 1,
            position: a.position,
            velocity,
            omega,
        });
    }
    Ok(out)
}
