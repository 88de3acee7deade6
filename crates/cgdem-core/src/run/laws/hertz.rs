//! Laws for `[contact] model = "hertz"`: each slot built from the scene's settings, and the
//! short list of combinations that are compiled (each its own force loop).

use super::LawVisitor;
use crate::contact::cohesion::{vdw_reach, NoCohesion, VanDerWaals};
use crate::contact::damping::{liggghts_damping_factor, HertzDamping, YangDamping};
use crate::contact::normal::{Hertz, Material};
use crate::contact::rolling::{ConstantTorque, Epsd2, NoRolling};
use crate::contact::tangential::{Mindlin, YangTangential};
use crate::contact::{CohesionModel, ContactLaw, DampingModel, RollingModel, TangentialModel};
use crate::math::Real;
use crate::run::RunError;
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

/// The compiled combinations: each line is the keywords a scene gives (damping, tangential,
/// rolling, cohesion), the slots they compile to, the wall law (LIGGGHTS's history wall for
/// its keywords) and the name listed in errors. `SUPPORTED` and the dispatch are both made
/// from this one list.
macro_rules! compiled_hertz_laws {
    ($( ($d:pat, $t:pat, $r:pat, $c:pat) => <$D:ty, $T:ty, $R:ty, $C:ty>, $wall:ident, $name:literal; )*) => {
        /// The compiled combinations, as (damping, tangential, rolling, cohesion) keywords.
        pub const SUPPORTED: &[&str] = &[$($name),*];

        /// Calls `visitor` with the one compiled law that matches the scene's keywords.
        pub(super) fn with_hertz_laws<V: LawVisitor>(
            scene: &Scene,
            h: &HertzSettings,
            visitor: V,
        ) -> Result<V::Output, RunError> {
            #[allow(unused_imports)]
            use CohesionKind::{None as NoVdw, VanDerWaals as Vdw};
            #[allow(unused_imports)]
            use HertzDampingKind::{Restitution, Yang};
            type K = TangentialKind;
            match (h.damping, h.tangential, h.rolling, h.cohesion) {
                $( ($d, $t, $r, $c) => Ok(visitor.visit(
                    hertz_law::<$D, $T, $R, $C>(scene, h),
                    $wall(scene, h),
                )), )*
                (d, t, r, c) => Err(RunError::Unsupported {
                    file: scene.source.display().to_string(),
                    combination: format!("{d:?}/{t:?}/{r:?}/{c:?}"),
                    supported: SUPPORTED.join(", "),
                }),
            }
        }
    };
}

compiled_hertz_laws! {
    (Restitution, K::History, RollingKind::None, NoVdw)
        => <HertzDamping, Mindlin, NoRolling, NoCohesion>, hertz_history_wall, "hertz/history/none/none";
    (Restitution, K::History, RollingKind::ConstantTorque, NoVdw)
        => <HertzDamping, Mindlin, ConstantTorque, NoCohesion>, hertz_wall, "hertz/history/constant_torque/none";
    (Restitution, K::History, RollingKind::ConstantTorque, Vdw { .. })
        => <HertzDamping, Mindlin, ConstantTorque, VanDerWaals>, hertz_wall, "hertz/history/constant_torque/vdw";
    (Restitution, K::History, RollingKind::Epsd2, NoVdw)
        => <HertzDamping, Mindlin, Epsd2, NoCohesion>, hertz_history_wall, "hertz/history/epsd2/none";
    (Restitution, K::History, RollingKind::Epsd2, Vdw { .. })
        => <HertzDamping, Mindlin, Epsd2, VanDerWaals>, hertz_history_wall, "hertz/history/epsd2/vdw";
    (Yang { .. }, K::Yang, RollingKind::None, NoVdw)
        => <YangDamping, YangTangential, NoRolling, NoCohesion>, hertz_wall, "yang/yang/none/none";
    (Yang { .. }, K::Yang, RollingKind::ConstantTorque, Vdw { .. })
        => <YangDamping, YangTangential, ConstantTorque, VanDerWaals>, hertz_wall, "yang/yang/constant_torque/vdw (paper B)";
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::RunOptions;

    #[test]
    fn an_uncompiled_combination_is_refused_with_the_supported_list() {
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("validation/cases/hertz_settle.toml");
        let mut scene = Scene::load(&path).unwrap();
        let crate::scene::ContactSettings::Hertz(h) = &mut scene.contact else {
            panic!("not hertz")
        };
        h.tangential = TangentialKind::Yang; // with the LIGGGHTS dashpot: not on the list
        let options = RunOptions {
            out_dir: std::env::temp_dir().join("cgdem-unsupported"),
            force_dt: false,
            keep_going: false,
            ..Default::default()
        };
        let message = crate::run::run(&scene, &options).unwrap_err().to_string();
        assert!(
            message.contains("not compiled") && message.contains("yang/yang/constant_torque/vdw"),
            "{message}"
        );
    }
}
