//! Which concrete laws a scene gets, chosen once: `with_laws` hands the scene's particle law
//! and wall law to a [`LawVisitor`] (the run, the time step, the bodies), so the choice is
//! written in one place and every force loop is compiled for its own combination. The
//! Hertz-Mindlin slots (`hertz`) are chosen below it.

pub(super) mod hertz;

use crate::contact::normal::WcaCoefficients;
use crate::contact::{PairLaw, SeedModel};
use crate::math::Real;
use crate::scene::{ContactSettings, Scene, WcaSettings};
use crate::walls::{WallLaw, WcaWall};

use super::RunError;

/// Something done with a scene's concrete particle and wall laws.
pub trait LawVisitor {
    type Output;
    fn visit<L: PairLaw, W: WallLaw>(self, law: L, wall_law: W) -> Self::Output;
}

/// Calls `visitor` with the scene's laws; an uncompiled combination of Hertz slots is an
/// error naming the supported ones ([`hertz::SUPPORTED`]).
pub fn with_laws<V: LawVisitor>(scene: &Scene, visitor: V) -> Result<V::Output, RunError> {
    match &scene.contact {
        ContactSettings::Wca(wca) => {
            let (law, wall_law) = seed_laws(scene, wca);
            Ok(visitor.visit(law, wall_law))
        }
        ContactSettings::Hertz(h) => hertz::with_hertz_laws(scene, h, visitor),
    }
}

/// The seed's particle law and wall law for a scene with `ContactSettings::Wca`.
pub fn seed_laws(scene: &Scene, wca: &WcaSettings) -> (SeedModel, WcaWall) {
    let sigma = wca.sigma;
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
        epsilon: wca.epsilon,
        sigma: if scene.species[a].diameter == reference && scene.species[b].diameter == reference {
            sigma
        } else {
            sigma * (scene.species[a].diameter + scene.species[b].diameter) / (2.0 * reference)
        },
    };
    let table: Vec<WcaCoefficients> = (0..n * n).map(|ab| pair(ab / n, ab % n)).collect();
    let law = SeedModel::seed(table, vec![wca.gamma_n; n * n], vec![wca.gamma_t; n * n]);
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
