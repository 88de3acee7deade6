//! Laws for `[contact] model = "hertz"`: each slot built from the scene's settings, and the
//! short list of combinations that are compiled (each its own force loop).

use super::{execute, RunError, RunOptions, RunSummary};
use crate::contact::cohesion::{vdw_reach, NoCohesion, VanDerWaals};
use crate::contact::damping::{liggghts_damping_factor, HertzDamping, YangDamping};
use crate::contact::normal::{Hertz, Material};
use crate::contact::rolling::{ConstantTorque, Epsd2, NoRolling};
use crate::contact::tangential::{Mindlin, YangTangential};
use crate::contact::{CohesionModel, ContactLaw, DampingModel, RollingModel, TangentialModel};
use crate::math::Real;
use crate::scene::{
    CohesionKind, HertzDampingKind, HertzSettings, RollingKind, Scene, TangentialKind,
};
use crate::walls::{HertzHistoryWall, HertzWall};

/// A slot built from the scene (one material for all species, so every species-pair table
/// holds the same value).
pub trait FromScene: Sized {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self;
}

fn material(h: &HertzSettings) -> Material {
    Material {
        youngs_modulus: h.youngs_modulus,
        poisson_ratio: h.poisson_ratio,
    }
}

fn table(scene: &Scene, value: Real) -> Vec<Real> {
    vec![value; scene.species.len().pow(2)]
}

impl FromScene for Hertz {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        Hertz {
            y_eff: table(scene, Material::y_eff(material(h), material(h))),
            characteristic_velocity: h.characteristic_velocity,
        }
    }
}

impl FromScene for HertzDamping {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        HertzDamping::from_restitution(&table(scene, h.restitution))
    }
}

impl FromScene for YangDamping {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let HertzDampingKind::Yang { gamma_n } = h.damping else {
            unreachable!("dispatch pairs YangDamping with damping = \"yang\"")
        };
        YangDamping {
            gamma_n: table(scene, gamma_n),
        }
    }
}

impl FromScene for Mindlin {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        Mindlin {
            g_eff: table(scene, Material::g_eff(material(h), material(h))),
            damping_factor: table(scene, liggghts_damping_factor(h.restitution)),
            friction: table(scene, h.friction),
        }
    }
}

impl FromScene for YangTangential {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        YangTangential {
            friction: table(scene, h.friction),
            slip_factor: table(
                scene,
                YangTangential::slip_factor(h.friction, h.poisson_ratio),
            ),
        }
    }
}

impl FromScene for NoRolling {
    fn from_scene(_: &Scene, _: &HertzSettings) -> Self {
        NoRolling
    }
}

impl FromScene for ConstantTorque {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        ConstantTorque {
            rolling_friction: table(scene, h.rolling_friction),
        }
    }
}

impl FromScene for Epsd2 {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        Epsd2 {
            rolling_friction: table(scene, h.rolling_friction),
            g_eff: table(scene, Material::g_eff(material(h), material(h))),
        }
    }
}

impl FromScene for NoCohesion {
    fn from_scene(_: &Scene, _: &HertzSettings) -> Self {
        NoCohesion
    }
}

impl FromScene for VanDerWaals {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let CohesionKind::VanDerWaals {
            hamaker_constant,
            h_min,
            cutoff,
        } = h.cohesion
        else {
            unreachable!("dispatch pairs VanDerWaals with cohesion = \"vdw\"")
        };
        // Default reach: where the force of the widest-reaching species pair falls to 1e-3
        // of its value at h_min.
        let reach = cutoff.unwrap_or_else(|| {
            let mut reach: Real = 0.0;
            for a in &scene.species {
                for b in &scene.species {
                    reach = reach.max(vdw_reach(a.radius(), b.radius(), h_min, 1e-3));
                }
            }
            reach
        });
        VanDerWaals {
            hamaker_constant: table(scene, hamaker_constant),
            h_min,
            reach,
        }
    }
}

/// The particle law of a Hertz scene with slots `D, T, R, C`.
pub fn hertz_law<D, T, R, C>(scene: &Scene, h: &HertzSettings) -> ContactLaw<Hertz, D, T, R, C>
where
    D: DampingModel + FromScene,
    T: TangentialModel + FromScene,
    R: RollingModel + FromScene,
    C: CohesionModel + FromScene,
{
    ContactLaw::new(
        Hertz::from_scene(scene, h),
        D::from_scene(scene, h),
        T::from_scene(scene, h),
        R::from_scene(scene, h),
        C::from_scene(scene, h),
    )
}

/// The wall law of a Hertz scene: the wall's material (default: the particles'), the wall
/// restitution and friction of `[wall_contact]`.
pub fn hertz_wall(scene: &Scene, h: &HertzSettings) -> HertzWall {
    let w = &scene.wall_contact;
    let wall = Material {
        youngs_modulus: w.youngs_modulus.unwrap_or(h.youngs_modulus),
        poisson_ratio: w.poisson_ratio.unwrap_or(h.poisson_ratio),
    };
    let y_eff = vec![Material::y_eff(material(h), wall); scene.species.len()];
    HertzWall::new(
        &y_eff,
        w.restitution,
        w.friction,
        w.rolling_friction,
        h.characteristic_velocity,
    )
}

/// LIGGGHTS's wall for `tangential = "history"`: the pair law's springs with `R_eff = r`
/// (`walls::HertzHistoryWall`); epsd2 rolling when the particles have it.
pub fn hertz_history_wall(scene: &Scene, h: &HertzSettings) -> HertzHistoryWall {
    let w = &scene.wall_contact;
    let wall = Material {
        youngs_modulus: w.youngs_modulus.unwrap_or(h.youngs_modulus),
        poisson_ratio: w.poisson_ratio.unwrap_or(h.poisson_ratio),
    };
    let moduli = vec![
        (
            Material::y_eff(material(h), wall),
            Material::g_eff(material(h), wall)
        );
        scene.species.len()
    ];
    let rolling_friction = match h.rolling {
        RollingKind::Epsd2 => w.rolling_friction,
        _ => 0.0,
    };
    HertzHistoryWall::new(
        &moduli,
        w.restitution,
        w.friction,
        rolling_friction,
        h.characteristic_velocity,
    )
}

fn run_with<D, T, R, C>(
    scene: &Scene,
    h: &HertzSettings,
    options: &RunOptions,
) -> Result<RunSummary, RunError>
where
    D: DampingModel + FromScene,
    T: TangentialModel + FromScene,
    R: RollingModel + FromScene,
    C: CohesionModel + FromScene,
{
    execute(
        scene,
        hertz_law::<D, T, R, C>(scene, h),
        hertz_wall(scene, h),
        options,
    )
}

/// `run_with` for the LIGGGHTS keywords (`tangential = "history"`, rolling none or epsd2):
/// the walls are LIGGGHTS's, with the same springs (`hertz_history_wall`).
fn run_liggghts<R, C>(
    scene: &Scene,
    h: &HertzSettings,
    options: &RunOptions,
) -> Result<RunSummary, RunError>
where
    R: RollingModel + FromScene,
    C: CohesionModel + FromScene,
{
    execute(
        scene,
        hertz_law::<HertzDamping, Mindlin, R, C>(scene, h),
        hertz_history_wall(scene, h),
        options,
    )
}

/// The time step `run_hertz` takes for a scene with LIGGGHTS's keywords (`damping = "hertz"`,
/// `tangential = "history"`, rolling none or epsd2, no cohesion: the reference decks' scenes),
/// with its contact time scales. The rolling slot does not enter the linearized contacts.
pub fn time_step(
    scene: &Scene,
    h: &HertzSettings,
    force_dt: bool,
) -> Result<(Real, crate::timestep::Timescales, Option<String>), RunError> {
    match (h.damping, h.tangential, h.rolling, h.cohesion) {
        (
            HertzDampingKind::Restitution,
            TangentialKind::History,
            RollingKind::None | RollingKind::Epsd2,
            CohesionKind::None,
        ) => super::time_step_for(
            scene,
            &hertz_law::<HertzDamping, Mindlin, NoRolling, NoCohesion>(scene, h),
            &hertz_history_wall(scene, h),
            force_dt,
        ),
        (d, t, r, c) => Err(RunError::NotAvailable(format!(
            "{}: the time step is computed ahead of the run only for damping = \"hertz\", tangential = \"history\", rolling = \"none\" or \"epsd2\", no cohesion (the reference decks' keywords), not {d:?}/{t:?}/{r:?}/{c:?}",
            scene.source.display()
        ))),
    }
}

/// The compiled combinations, as (damping, tangential, rolling, cohesion) keywords.
pub const SUPPORTED: &[&str] = &[
    "hertz/history/none/none",
    "hertz/history/constant_torque/none",
    "hertz/history/constant_torque/vdw",
    "hertz/history/epsd2/none",
    "hertz/history/epsd2/vdw",
    "yang/yang/none/none",
    "yang/yang/constant_torque/vdw (paper B)",
];

/// Runs a Hertz scene with the one compiled law that matches its keywords.
pub fn run_hertz(
    scene: &Scene,
    h: &HertzSettings,
    options: &RunOptions,
) -> Result<RunSummary, RunError> {
    use CohesionKind::{None as NoVdw, VanDerWaals as Vdw};
    use HertzDampingKind::{Restitution, Yang};
    type K = TangentialKind;
    match (h.damping, h.tangential, h.rolling, h.cohesion) {
        (Restitution, K::History, RollingKind::None, NoVdw) => {
            run_liggghts::<NoRolling, NoCohesion>(scene, h, options)
        }
        (Restitution, K::History, RollingKind::ConstantTorque, NoVdw) => {
            run_with::<HertzDamping, Mindlin, ConstantTorque, NoCohesion>(scene, h, options)
        }
        (Restitution, K::History, RollingKind::ConstantTorque, Vdw { .. }) => {
            run_with::<HertzDamping, Mindlin, ConstantTorque, VanDerWaals>(scene, h, options)
        }
        (Restitution, K::History, RollingKind::Epsd2, NoVdw) => {
            run_liggghts::<Epsd2, NoCohesion>(scene, h, options)
        }
        (Restitution, K::History, RollingKind::Epsd2, Vdw { .. }) => {
            run_liggghts::<Epsd2, VanDerWaals>(scene, h, options)
        }
        (Yang { .. }, K::Yang, RollingKind::None, NoVdw) => {
            run_with::<YangDamping, YangTangential, NoRolling, NoCohesion>(scene, h, options)
        }
        (Yang { .. }, K::Yang, RollingKind::ConstantTorque, Vdw { .. }) => {
            run_with::<YangDamping, YangTangential, ConstantTorque, VanDerWaals>(scene, h, options)
        }
        (d, t, r, c) => Err(RunError::Unsupported {
            file: scene.source.display().to_string(),
            combination: format!("{d:?}/{t:?}/{r:?}/{c:?}"),
            supported: SUPPORTED.join(", "),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_uncompiled_combination_is_refused_with_the_supported_list() {
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("validation/cases/hertz_settle.toml");
        let mut scene = Scene::load(&path).unwrap();
        let crate::scene::ContactSettings::Hertz(h) = &mut scene.contact else {
            panic!("not hertz")
        };
        h.tangential = TangentialKind::Yang; // with the LIGGGHTS dashpot: not on the list
        let h = h.clone();
        let options = RunOptions {
            out_dir: std::env::temp_dir().join("cgdem-unsupported"),
            force_dt: false,
            keep_going: false,
            ..Default::default()
        };
        let message = run_hertz(&scene, &h, &options).unwrap_err().to_string();
        assert!(
            message.contains("not compiled") && message.contains("yang/yang/constant_torque/vdw"),
            "{message}"
        );
    }
}
