//! The Hertz family as both reference codes take it: the settings a deck can express, the
//! particles' and walls' materials, axis-aligned walls, and the dump columns with spins.
//! Each code's own mapping is in its dialect's deck writer (`lammps::hertz`,
//! `liggghts::deck`).

use super::DeckError;
use cgdem_core::contact::normal::Material;
use cgdem_core::scene::{
    CohesionKind, ContactSettings, HertzDampingKind, HertzSettings, RollingKind, Scene,
    TangentialKind, WallSettings,
};

/// Dump columns of the Hertz decks (LAMMPS and LIGGGHTS): with spins.
pub(crate) const HERTZ_COLUMNS: &str = "id type x y z vx vy vz omegax omegay omegaz radius";

/// The Hertz settings a reference deck can express, or why not.
/// `bodies`: the code's deck writes the scene's bodies (checked there), else it refuses them.
pub(crate) fn hertz_settings<'a>(
    scene: &'a Scene,
    code: &str,
    bodies: bool,
) -> Result<&'a HertzSettings, DeckError> {
    let unsupported = |reason: String| DeckError::unsupported(scene, reason);
    let ContactSettings::Hertz(h) = &scene.contact else {
        return Err(unsupported(format!(
            "the {code} Hertz deck needs model = \"hertz\""
        )));
    };
    if h.damping != HertzDampingKind::Restitution
        || h.tangential != TangentialKind::History
        || h.cohesion != CohesionKind::None
        || h.rolling == RollingKind::ConstantTorque
    {
        return Err(unsupported(format!(
            "{code} decks are written for damping = \"hertz\", tangential = \"history\", rolling = \"none\" or \"epsd2\", cohesion = \"none\" only"
        )));
    }
    if !bodies && !scene.bodies.is_empty() {
        return Err(unsupported(format!(
            "{code} Hertz decks take planar walls only (no [[body]])"
        )));
    }
    Ok(h)
}

/// Axis (0, 1, 2) of an axis-aligned wall and whether its normal points to +axis.
pub(crate) fn wall_axis(scene: &Scene, w: &WallSettings) -> Result<(usize, bool), DeckError> {
    let n = w.normal;
    for (axis, c) in [n.x, n.y, n.z].into_iter().enumerate() {
        if (c.abs() - 1.0).abs() < 1e-12 {
            return Ok((axis, c > 0.0));
        }
    }
    Err(DeckError::Unsupported {
        file: scene.source.display().to_string(),
        reason: format!(
            "wall `{}`: only axis-aligned planes become primitive/zplane walls",
            w.name
        ),
    })
}

pub(crate) fn material(h: &HertzSettings) -> Material {
    Material {
        youngs_modulus: h.youngs_modulus,
        poisson_ratio: h.poisson_ratio,
    }
}

/// The wall's material: `[wall_contact]`'s, else the particles'.
pub(crate) fn wall_material(scene: &Scene, h: &HertzSettings) -> Material {
    Material {
        youngs_modulus: scene
            .wall_contact
            .youngs_modulus
            .unwrap_or(h.youngs_modulus),
        poisson_ratio: scene.wall_contact.poisson_ratio.unwrap_or(h.poisson_ratio),
    }
}

/// The deck of `validation/cases/aor_hertz.toml` with one particle, for the deck tests of
/// both codes.
#[cfg(test)]
pub(crate) fn collapse_scene_and_particle() -> (Scene, cgdem_core::particles::Particles) {
    let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("validation/cases/aor_hertz.toml");
    let scene = Scene::load(&path).unwrap();
    let mut particles = cgdem_core::particles::Particles::new(true);
    let s = &scene.species[0];
    particles.push(
        0,
        cgdem_core::math::Vec3::new(0.05, 0.025, 0.1),
        s.radius(),
        s.mass(),
    );
    (scene, particles)
}

/// Position of `needle` in `deck`, failing with the needle's text when it is absent.
#[cfg(test)]
pub(crate) fn at(deck: &str, needle: &str) -> usize {
    deck.find(needle)
        .unwrap_or_else(|| panic!("no `{needle}` in the deck:\n{deck}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decks::lines::g;

    /// Spins given in a scene (insert omega, `[[particle]]`) reach both reference codes through
    /// the data file's `Velocities` section (`wx wy wz`, which `read_data` takes for
    /// atom_style sphere / granular), and the data file reads back as the same particles.
    #[test]
    fn decks_carry_the_initial_spins_and_their_data_file_reads_back() {
        use cgdem_core::scene::{given_particles_from_data, Override};
        crate::at_repo_root();
        let path = std::path::Path::new("tests/data/tiny_hertz_collapse.toml");
        let overrides: Vec<Override> = ["insert[0].omega=[0.0, 30.0, -2.5]"]
            .iter()
            .map(|o| Override::parse(o, path).unwrap())
            .collect();
        let mut scene = Scene::load_with_overrides(path, &overrides).unwrap();
        scene.particles.push(cgdem_core::scene::GivenParticle {
            species: 0,
            position: cgdem_core::math::Vec3::new(0.1, 0.02, 0.05),
            velocity: cgdem_core::math::Vec3::new(-1.0, 0.0, 0.0),
            omega: cgdem_core::math::Vec3::new(0.0, 0.0, 7.0),
        });
        let particles = cgdem_core::run::initial_particles_clear_of_bodies(&scene).unwrap();
        let omega = &particles.angular.as_ref().expect("Hertz: spins").omega;
        assert_eq!(omega[0], cgdem_core::math::Vec3::new(0.0, 0.0, 7.0));
        assert!(omega[1..]
            .iter()
            .all(|&w| w == cgdem_core::math::Vec3::new(0.0, 30.0, -2.5)));
        for deck in [
            crate::decks::lammps::write_hertz_deck(&scene, &particles, 1e-5).unwrap(),
            crate::decks::liggghts::write_deck(&scene, &particles, 1e-5).unwrap(),
        ] {
            let velocities = &deck.data[deck.data.find("Velocities").unwrap()..];
            assert!(
                velocities.contains(&format!(
                    "\n1 {} {} {} {} {} {}\n",
                    g(-1.0),
                    g(0.0),
                    g(0.0),
                    g(0.0),
                    g(0.0),
                    g(7.0)
                )),
                "{velocities:.300}"
            );
            assert!(
                velocities.contains(&format!(
                    "\n2 {} {} {} {} {} {}\n",
                    g(0.0),
                    g(0.0),
                    g(0.0),
                    g(0.0),
                    g(30.0),
                    g(-2.5)
                )),
                "{velocities:.300}"
            );
            let back = given_particles_from_data(
                &deck.data,
                std::path::Path::new("particles.data"),
                path,
                &scene.species,
                &scene.domain,
                true,
            )
            .unwrap();
            assert_eq!(back.len(), particles.len());
            for (k, b) in back.iter().enumerate() {
                assert_eq!(b.position, particles.position[k]);
                assert_eq!(b.velocity, particles.velocity[k]);
                assert_eq!(b.omega, omega[k]);
            }
        }
    }
}
