//! State files: the particles a run starts from instead of the scene's insertions (as
//! LAMMPS `write_data` / `read_data`). `cgdem bench` writes its prepared state into one so
//! that `mpirun ... cgdem run --initial-state FILE` starts every rank from it.
//!
//! Layout: the restart file's 32-byte header with the magic `CGDEMPST`, then the
//! [`Particles`] in bincode.

use std::path::Path;

use super::restart::{decode, encode, frame, unframe};
use crate::particles::Particles;
use crate::scene::Scene;

const MAGIC: &[u8; 8] = b"CGDEMPST";
/// Bumped whenever the payload's layout changes.
pub const FORMAT_VERSION: u32 = 1;

/// Writes `particles` into `path` (written beside it, then renamed: never half a file).
pub fn write(path: &Path, particles: &Particles) -> std::io::Result<()> {
    crate::io::write_atomic(path, &frame(MAGIC, FORMAT_VERSION, &encode(particles)))
}

/// Reads a state file and checks it against `scene`: every array as long as the ids, each
/// species one of the scene's, radii and masses positive, positions finite and ids unique.
/// The error names the file and what is wrong.
pub fn read(path: &Path, scene: &Scene) -> Result<Particles, String> {
    let file = path.display();
    let bytes = std::fs::read(path).map_err(|e| format!("{file}: {e}"))?;
    let payload = unframe(MAGIC, FORMAT_VERSION, &bytes).map_err(|e| format!("{file}: {e}"))?;
    let p: Particles =
        decode(payload).map_err(|e| format!("{file}: payload does not decode: {e}"))?;
    check(&p, scene).map_err(|e| format!("{file}: {e}"))?;
    Ok(p)
}

fn check(p: &Particles, scene: &Scene) -> Result<(), String> {
    let n = p.id.len();
    let mut lengths = vec![
        ("species", p.species.len()),
        ("position", p.position.len()),
        ("velocity", p.velocity.len()),
        ("force", p.force.len()),
        ("radius", p.radius.len()),
        ("mass", p.mass.len()),
        ("inv_mass", p.inv_mass.len()),
    ];
    if let Some(a) = &p.angular {
        lengths.extend([
            ("omega", a.omega.len()),
            ("torque", a.torque.len()),
            ("inv_inertia", a.inv_inertia.len()),
        ]);
    }
    if let Some((name, len)) = lengths.iter().find(|(_, len)| *len != n) {
        return Err(format!("{n} particle ids but {len} values of {name}"));
    }
    let species = scene.species.len();
    for k in 0..n {
        if p.species[k] as usize >= species {
            return Err(format!(
                "particle {} has species {}, the scene {} has {species} species",
                p.id[k],
                p.species[k],
                scene.source.display()
            ));
        }
        if !(p.radius[k] > 0.0 && p.radius[k].is_finite() && p.mass[k] > 0.0) {
            return Err(format!(
                "particle {}: radius {} m and mass {} kg must be positive",
                p.id[k], p.radius[k], p.mass[k]
            ));
        }
        if !(p.position[k].is_finite() && p.velocity[k].is_finite()) {
            return Err(format!(
                "particle {}: non-finite position or velocity",
                p.id[k]
            ));
        }
    }
    let mut ids = p.id.clone();
    ids.sort_unstable();
    if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
        return Err(format!("particle id {} appears twice", w[0]));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn scene() -> Scene {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../validation/bench/heap.toml"
        );
        Scene::load(Path::new(path)).unwrap()
    }

    #[test]
    fn round_trip_and_bad_files_are_refused_by_name() {
        let dir = std::env::temp_dir().join(format!("cgdem-state-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("state.cgs");
        let mut p = Particles::new(true);
        p.push(0, Vec3::new(0.0, 0.0, 0.001), 1e-3, 1e-5);
        p.push(1, Vec3::new(0.0, 0.0, 0.003), 1e-3, 1e-5);
        p.velocity[1] = Vec3::new(0.1, 0.0, 0.0);
        write(&path, &p).unwrap();
        let back = read(&path, &scene()).unwrap();
        assert_eq!(back.id, p.id);
        assert_eq!(back.velocity, p.velocity);
        // A species the scene does not have.
        p.species[1] = 7;
        write(&path, &p).unwrap();
        let err = read(&path, &scene()).unwrap_err();
        assert!(
            err.contains("state.cgs") && err.contains("species 7"),
            "{err}"
        );
        // A truncated file.
        p.species[1] = 1;
        write(&path, &p).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 1]).unwrap();
        assert!(read(&path, &scene()).unwrap_err().contains("truncated"));
        // A restart file is not a state file.
        std::fs::write(&path, b"CGDEMRST and more bytes than a header has, surely").unwrap();
        assert!(read(&path, &scene()).unwrap_err().contains("CGDEMPST"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
