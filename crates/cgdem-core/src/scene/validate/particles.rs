//! Particles given one by one: `read_data` (a LAMMPS data file) and `[[particle]]` tables.
//! A species has one size and one density, so each given diameter and density must be its
//! species' (to 1e-6): a data file from another setup is refused rather than silently
//! resized.

use std::path::Path;

use super::super::raw::*;
use super::super::*;
use super::{names, Checker};
use crate::lammps_data::{parse_data, DataFileError};

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
        let text = std::fs::read_to_string(&path).map_err(|e| {
            c.invalid(
                "read_data",
                format!("\"{name}\""),
                format!(
                    "a readable LAMMPS data file, path relative to the scene file ({}: {e})",
                    path.display()
                ),
            )
        })?;
        out = given_particles_from_data(&text, &path, c.file, species, domain, rotates)?;
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

/// The particles of a LAMMPS data file's text (`file` and the `scene` that reads it named in
/// errors), in atom-ID order:
/// atom type `t` is species `t - 1` (the numbering of the decks cgdem writes); each
/// diameter and density must be its species', each position inside the domain, and spins
/// need a contact law that rotates (`rotates`).
pub fn given_particles_from_data(
    text: &str,
    file: &Path,
    scene: &Path,
    species: &[Species],
    domain: &Domain,
    rotates: bool,
) -> Result<Vec<GivenParticle>, SceneError> {
    let wrap = |source: DataFileError| SceneError::DataFile {
        scene: scene.to_path_buf(),
        source: Box::new(source),
    };
    let data = parse_data(text, file).map_err(wrap)?;
    let error = |line: usize, field: &str, value: String, allowed: String| {
        wrap(DataFileError {
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

#[cfg(test)]
mod tests {
    use super::super::super::*;
    use std::path::Path;

    /// Two species (`a`, `b` of 1 mm and 2 mm) in a 1 cm box, the Hertz law (or WCA with
    /// `wca`), and `extra` appended (tables) or `top` before the first table.
    fn scene(top: &str, extra: &str, wca: bool) -> Result<Scene, SceneError> {
        let contact = if wca {
            "model = \"wca\"\nepsilon = 1.0\nsigma = 8.908987e-4\ngamma_n = 0.0\ngamma_t = 0.0"
        } else {
            "model = \"hertz\"\nyoungs_modulus = 5e6\npoisson_ratio = 0.3\nrestitution = 0.5\nfriction = 0.5"
        };
        let text = format!(
            r#"name = "given"
{top}
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.01, 0.01, 0.01]
periodic = [false, true, false]
[[species]]
name = "a"
diameter = 1e-3
density = 2500.0
[[species]]
name = "b"
diameter = 2e-3
density = 1000.0
[contact]
{contact}
[time]
dt = 1e-7
[[stage]]
name = "s"
duration = 1e-6
{extra}
"#
        );
        // WCA: one sigma for all pairs, so one size.
        let text = if wca {
            text.replace("diameter = 2e-3", "diameter = 1e-3")
        } else {
            text
        };
        Scene::parse(&text, Path::new("given.toml"))
    }

    const DATA: &str = "title\n\n2 atoms\n3 atom types\n\n0 0.01 xlo xhi\n0 0.01 ylo yhi\n0 0.01 zlo zhi\n\nAtoms # sphere\n\n7 2 2e-3 1000 0.005 0.005 0.005\n3 1 1e-3 2500 0.001 0.002 0.003\n\nVelocities\n\n3 0.1 0 0 0 0 5\n7 0 0 -1 0 0 0\n";

    fn from_data(text: &str, rotates: bool) -> Result<Vec<GivenParticle>, SceneError> {
        let s = scene("", "", false).unwrap();
        given_particles_from_data(
            text,
            Path::new("start.data"),
            Path::new("given.toml"),
            &s.species,
            &s.domain,
            rotates,
        )
    }

    #[test]
    fn data_file_particles_come_in_atom_id_order_with_species_from_type() {
        let p = from_data(DATA, true).unwrap();
        assert_eq!(p.len(), 2);
        assert_eq!(p[0].species, 0);
        assert_eq!(p[0].position, Vec3::new(0.001, 0.002, 0.003));
        assert_eq!(p[0].velocity, Vec3::new(0.1, 0.0, 0.0));
        assert_eq!(p[0].omega, Vec3::new(0.0, 0.0, 5.0));
        assert_eq!(p[1].species, 1);
        assert_eq!(p[1].velocity, Vec3::new(0.0, 0.0, -1.0));
    }

    #[test]
    fn data_file_errors_name_scene_file_line_and_field() {
        let cases = [
            (
                DATA.replace("7 2 2e-3", "7 3 2e-3"),
                ":12: field `Atoms atom-type` = 3",
                "`a`, `b`",
            ),
            (
                DATA.replace("7 2 2e-3 1000", "7 2 2.1e-3 1000"),
                ":12: field `Atoms diameter`",
                "one size",
            ),
            (
                DATA.replace("7 2 2e-3 1000", "7 2 2e-3 1200"),
                ":12: field `Atoms density`",
                "1000",
            ),
            (
                DATA.replace("0.001 0.002 0.003", "0.001 0.002 0.013"),
                ":13: field `Atoms z` = 0.013",
                "[domain]",
            ),
            (
                DATA.replace("0.001 0.002 0.003", "0.001 0.01 0.003"),
                ":13: field `Atoms y` = 0.01",
                "inside",
            ),
        ];
        for (text, at, allowed) in cases {
            let m = from_data(&text, true).unwrap_err().to_string();
            assert!(
                m.starts_with("given.toml: read_data: start.data")
                    && m.contains(at)
                    && m.contains(allowed),
                "{m}"
            );
        }
        let m = from_data(DATA, false).unwrap_err().to_string();
        assert!(
            m.contains(":17: field `Velocities wx wy wz`") && m.contains("hertz"),
            "{m}"
        );
        let m = from_data(&DATA.replace("0 0 5\n", "0 0 0\n"), false);
        assert!(m.is_ok(), "zero spins are fine without rotation: {m:?}");
    }

    #[test]
    fn particle_tables_follow_the_data_file_and_are_checked() {
        let dir = std::env::temp_dir().join(format!("cgdem-given-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("start.data"), DATA).unwrap();
        let extra = "[[particle]]\nspecies = \"b\"\nposition = [0.008, 0.008, 0.008]\nvelocity = [0.0, 1.0, 0.0]\nomega = [1.0, 2.0, 3.0]\ndiameter = 2e-3\n";
        let s = {
            let base = scene("read_data = \"start.data\"", extra, false);
            // The data file is looked up beside the scene file: parse with a path in `dir`.
            assert!(base.is_err(), "given.toml has no start.data beside it");
            let m = base.unwrap_err().to_string();
            assert!(
                m.contains("field `read_data`") && m.contains("readable"),
                "{m}"
            );
            let text = format!(
                "name = \"given\"\nread_data = \"start.data\"\n{}",
                SCENE_TAIL.replace("{extra}", extra)
            );
            Scene::parse(&text, &dir.join("given.toml")).unwrap()
        };
        assert_eq!(s.particles.len(), 3);
        assert_eq!(s.particles[2].species, 1);
        assert_eq!(s.particles[2].omega, Vec3::new(1.0, 2.0, 3.0));
        let p = crate::run::initial_particles(&s, true, &[]).unwrap();
        assert_eq!(p.len(), 3);
        assert_eq!(p.position[0], Vec3::new(0.001, 0.002, 0.003));
        assert_eq!(p.radius[1], 1e-3);
        assert_eq!(p.velocity[2], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(
            p.angular.as_ref().unwrap().omega[0],
            Vec3::new(0.0, 0.0, 5.0)
        );
        assert_eq!(
            p.angular.as_ref().unwrap().omega[2],
            Vec3::new(1.0, 2.0, 3.0)
        );
        let m = crate::coarse_graining::coarse_grain(&s, 2)
            .unwrap_err()
            .to_string();
        assert!(m.contains("given particles"), "{m}");
        let _ = std::fs::remove_dir_all(&dir);

        for (extra, field, allowed) in [
            (
                "[[particle]]\nspecies = \"c\"\nposition = [0.0, 0.0, 0.0]",
                "particle[0].species",
                "`a`, `b`",
            ),
            (
                "[[particle]]\nspecies = \"a\"\nposition = [0.0, 0.0, nan]",
                "particle[0].position",
                "finite",
            ),
            (
                "[[particle]]\nspecies = \"a\"\nposition = [0.0, 0.0, 0.02]",
                "particle[0].position",
                "axis 2",
            ),
            (
                "[[particle]]\nspecies = \"a\"\nposition = [0.0, 0.0, 0.0]\ndiameter = 2e-3",
                "particle[0].diameter",
                "one size",
            ),
        ] {
            let m = scene("", extra, false).unwrap_err().to_string();
            assert!(
                m.starts_with("given.toml: field `") && m.contains(field) && m.contains(allowed),
                "{m}"
            );
        }
        let m = scene(
            "",
            "[[particle]]\nspecies = \"a\"\nposition = [0.0, 0.0, 0.0]\nomega = [0.0, 1.0, 0.0]",
            true,
        )
        .unwrap_err()
        .to_string();
        assert!(
            m.contains("particle[0].omega") && m.contains("hertz"),
            "{m}"
        );
    }

    const SCENE_TAIL: &str = r#"[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.01, 0.01, 0.01]
periodic = [false, true, false]
[[species]]
name = "a"
diameter = 1e-3
density = 2500.0
[[species]]
name = "b"
diameter = 2e-3
density = 1000.0
[contact]
model = "hertz"
youngs_modulus = 5e6
poisson_ratio = 0.3
restitution = 0.5
friction = 0.5
[time]
dt = 1e-7
[[stage]]
name = "s"
duration = 1e-6
{extra}
"#;
}
