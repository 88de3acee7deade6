//! Laws for `[contact] model = "hertz"`: each slot built from the scene's material and pair
//! tables (`scene::ContactTables`), and the short list of combinations that are compiled
//! (each its own force loop).

use super::LawVisitor;
use crate::contact::cohesion::{vdw_reach, NoCohesion, VanDerWaals};
use crate::contact::damping::{
    clamped_damping_factor, liggghts_damping_factor, HertzDamping, LimitForce, YangDamping,
};
use crate::contact::normal::Hertz;
use crate::contact::rolling::{ConstantTorque, Epsd2, NoRolling};
use crate::contact::tangential::{CoulombMindlin, Mindlin, MindlinSpring, YangTangential};
use crate::contact::{CohesionModel, ContactLaw, DampingModel, RollingModel, TangentialModel};
use crate::math::{Real, Vec3};
use crate::run::RunError;
use crate::scene::{
    CohesionKind, ContactTables, HertzDampingKind, HertzSettings, RollingKind, Scene,
    TangentialKind,
};
use crate::walls::{HertzHistoryWall, HertzWall};

/// A slot built from the scene: per species pair, from the scene's [`ContactTables`]
/// (materials and pair coefficients resolved).
pub trait FromScene: Sized {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self;
}

fn tables(scene: &Scene, h: &HertzSettings) -> ContactTables {
    ContactTables::of_hertz(scene, h)
}

impl FromScene for Hertz {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let t = tables(scene, h);
        Hertz {
            y_eff: t.pair_table(|a, b| t.y_eff(a, b)),
            characteristic_velocity: h.characteristic_velocity,
        }
    }
}

impl FromScene for HertzDamping {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let t = tables(scene, h);
        HertzDamping::from_restitution(&t.pair_table(|a, b| t.pair(a, b).restitution))
    }
}

/// The clamped dashpot with the coefficient that restitutes each pair's `e` when clamped.
impl FromScene for LimitForce<HertzDamping> {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let t = tables(scene, h);
        LimitForce(HertzDamping {
            factor: t.pair_table(|a, b| clamped_damping_factor(t.pair(a, b).restitution)),
        })
    }
}

/// The Mindlin dashpot's `2 sqrt(5/6) |beta(e)|` of restitution `e`, or 0 with
/// `tangential_damping = false` (the table is zeroed once, here; the force loop is the same).
fn tangential_damping_factor(h: &HertzSettings, restitution: Real) -> Real {
    if h.tangential_damping {
        liggghts_damping_factor(restitution)
    } else {
        0.0
    }
}

impl FromScene for YangDamping {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let HertzDampingKind::Yang { gamma_n } = h.damping else {
            unreachable!("dispatch pairs YangDamping with damping = \"yang\"")
        };
        YangDamping {
            gamma_n: vec![gamma_n; scene.species.len().pow(2)],
        }
    }
}

impl FromScene for Mindlin {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let t = tables(scene, h);
        Mindlin {
            g_eff: t.pair_table(|a, b| t.g_eff(a, b)),
            damping_factor: t
                .pair_table(|a, b| tangential_damping_factor(h, t.pair(a, b).restitution)),
            friction: t.pair_table(|a, b| t.pair(a, b).friction),
        }
    }
}

impl FromScene for CoulombMindlin {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        CoulombMindlin(Mindlin::from_scene(scene, h))
    }
}

impl FromScene for YangTangential {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let t = tables(scene, h);
        YangTangential {
            friction: t.pair_table(|a, b| t.pair(a, b).friction),
            slip_factor: t.pair_table(|a, b| {
                let (ma, mb) = (t.species[a], t.species[b]);
                let friction = t.pair(a, b).friction;
                if ma == mb {
                    YangTangential::slip_factor(friction, ma.poisson_ratio)
                } else {
                    YangTangential::slip_factor_of_pair(friction, t.y_eff(a, b), t.g_eff(a, b))
                }
            }),
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
        let t = tables(scene, h);
        ConstantTorque {
            rolling_friction: t.pair_table(|a, b| t.pair(a, b).rolling_friction),
        }
    }
}

impl FromScene for Epsd2 {
    fn from_scene(scene: &Scene, h: &HertzSettings) -> Self {
        let t = tables(scene, h);
        Epsd2 {
            rolling_friction: t.pair_table(|a, b| t.pair(a, b).rolling_friction),
            g_eff: t.pair_table(|a, b| t.g_eff(a, b)),
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
        let CohesionKind::VanDerWaals { h_min, cutoff, .. } = h.cohesion else {
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
        let t = tables(scene, h);
        VanDerWaals {
            hamaker_constant: t.pair_table(|a, b| t.pair(a, b).hamaker_constant),
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

/// The wall law of a Hertz scene for paper B's keywords: per species and wall material, the
/// materials' `Y*` and the pair's restitution, friction and rolling friction
/// ([`ContactTables`]).
pub fn hertz_wall(scene: &Scene, h: &HertzSettings) -> HertzWall {
    let t = tables(scene, h);
    HertzWall::from_tables(
        t.n_wall_materials(),
        t.wall_table(|a, k| t.wall_y_eff(a, k)),
        &t.wall_table(|a, k| t.wall_pair(a, k).restitution),
        t.wall_table(|a, k| t.wall_pair(a, k).friction),
        t.wall_table(|a, k| t.wall_pair(a, k).rolling_friction),
        h.characteristic_velocity,
    )
}

/// LIGGGHTS's wall for `tangential = "history"`: the pair law's springs with `R_eff = r`
/// (`walls::HertzHistoryWall`); epsd2 rolling when the particles have it.
pub fn hertz_history_wall(scene: &Scene, h: &HertzSettings) -> HertzHistoryWall<Mindlin> {
    history_wall(scene, h, |t| t)
}

/// `hertz_history_wall` with the normal force clamped at zero (`limit_force = true`).
pub fn hertz_history_wall_limited(
    scene: &Scene,
    h: &HertzSettings,
) -> HertzHistoryWall<Mindlin, true> {
    history_wall(scene, h, |t| t)
}

/// `hertz_coulomb_wall` with the normal force clamped at zero (`limit_force = true`).
pub fn hertz_coulomb_wall_limited(
    scene: &Scene,
    h: &HertzSettings,
) -> HertzHistoryWall<CoulombMindlin, true> {
    history_wall(scene, h, CoulombMindlin)
}

/// The wall for `tangential = "coulomb"`: `hertz_history_wall`'s springs with the pair law's
/// Coulomb bound on their sum.
pub fn hertz_coulomb_wall(scene: &Scene, h: &HertzSettings) -> HertzHistoryWall<CoulombMindlin> {
    history_wall(scene, h, CoulombMindlin)
}

/// The history wall with the tangential slot `slot` makes of the wall pairs' `Mindlin`.
fn history_wall<T: TangentialModel<History = Vec3> + MindlinSpring, const LIMIT_FORCE: bool>(
    scene: &Scene,
    h: &HertzSettings,
    slot: impl FnOnce(Mindlin) -> T,
) -> HertzHistoryWall<T, LIMIT_FORCE> {
    let t = tables(scene, h);
    let rolling_friction = match h.rolling {
        RollingKind::Epsd2 => t.wall_table(|a, k| t.wall_pair(a, k).rolling_friction),
        _ => vec![0.0; t.wall_pairs.len()],
    };
    let restitution = t.wall_table(|a, k| t.wall_pair(a, k).restitution);
    let tangential = Mindlin {
        g_eff: t.wall_table(|a, k| t.wall_g_eff(a, k)),
        damping_factor: restitution
            .iter()
            .map(|&e| tangential_damping_factor(h, e))
            .collect(),
        friction: t.wall_table(|a, k| t.wall_pair(a, k).friction),
    };
    let mut stateless = HertzWall::from_tables(
        t.n_wall_materials(),
        t.wall_table(|a, k| t.wall_y_eff(a, k)),
        &restitution,
        tangential.friction.clone(),
        vec![0.0; t.wall_pairs.len()],
        h.characteristic_velocity,
    );
    if LIMIT_FORCE {
        // The clamped wall contact restitutes e with its own coefficient, as pairs do.
        stateless.damping.factor = restitution
            .iter()
            .map(|&e| clamped_damping_factor(e))
            .collect();
    }
    HertzHistoryWall {
        stateless,
        tangential: slot(tangential),
        rolling_friction,
    }
}

/// The compiled combinations: each line is the keywords a scene gives (damping, tangential,
/// rolling, cohesion), the slots they compile to, the wall law (LIGGGHTS's history wall for
/// its keywords) and the name listed in errors. `SUPPORTED` and the dispatch are both made
/// from this one list.
macro_rules! compiled_hertz_laws {
    ($( ($d:pat, $l:pat, $t:pat, $r:pat, $c:pat) => <$D:ty, $T:ty, $R:ty, $C:ty>, $wall:ident, $name:literal; )*) => {
        /// The compiled combinations, as (damping, tangential, rolling, cohesion) keywords
        /// (`+limit_force` when the normal force is clamped).
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
            match (h.damping, h.limit_force, h.tangential, h.rolling, h.cohesion) {
                $( ($d, $l, $t, $r, $c) => Ok(visitor.visit(
                    hertz_law::<$D, $T, $R, $C>(scene, h),
                    $wall(scene, h),
                )), )*
                (d, l, t, r, c) => Err(RunError::Unsupported {
                    file: scene.source.display().to_string(),
                    combination: format!(
                        "{d:?}/{t:?}/{r:?}/{c:?}{}",
                        if l { "+limit_force" } else { "" }
                    ),
                    supported: SUPPORTED.join(", "),
                }),
            }
        }
    };
}

compiled_hertz_laws! {
    (Restitution, false, K::History, RollingKind::None, NoVdw)
        => <HertzDamping, Mindlin, NoRolling, NoCohesion>, hertz_history_wall, "hertz/history/none/none";
    (Restitution, false, K::History, RollingKind::ConstantTorque, NoVdw)
        => <HertzDamping, Mindlin, ConstantTorque, NoCohesion>, hertz_wall, "hertz/history/constant_torque/none";
    (Restitution, false, K::History, RollingKind::ConstantTorque, Vdw { .. })
        => <HertzDamping, Mindlin, ConstantTorque, VanDerWaals>, hertz_wall, "hertz/history/constant_torque/vdw";
    (Restitution, false, K::History, RollingKind::Epsd2, NoVdw)
        => <HertzDamping, Mindlin, Epsd2, NoCohesion>, hertz_history_wall, "hertz/history/epsd2/none";
    (Restitution, false, K::History, RollingKind::Epsd2, Vdw { .. })
        => <HertzDamping, Mindlin, Epsd2, VanDerWaals>, hertz_history_wall, "hertz/history/epsd2/vdw";
    (Restitution, false, K::Coulomb, RollingKind::None, NoVdw)
        => <HertzDamping, CoulombMindlin, NoRolling, NoCohesion>, hertz_coulomb_wall, "hertz/coulomb/none/none";
    (Restitution, false, K::Coulomb, RollingKind::Epsd2, NoVdw)
        => <HertzDamping, CoulombMindlin, Epsd2, NoCohesion>, hertz_coulomb_wall, "hertz/coulomb/epsd2/none";
    (Restitution, false, K::Coulomb, RollingKind::Epsd2, Vdw { .. })
        => <HertzDamping, CoulombMindlin, Epsd2, VanDerWaals>, hertz_coulomb_wall, "hertz/coulomb/epsd2/vdw";
    (Restitution, true, K::History, RollingKind::None, NoVdw)
        => <LimitForce<HertzDamping>, Mindlin, NoRolling, NoCohesion>, hertz_history_wall_limited, "hertz/history/none/none+limit_force";
    (Restitution, true, K::Coulomb, RollingKind::None, NoVdw)
        => <LimitForce<HertzDamping>, CoulombMindlin, NoRolling, NoCohesion>, hertz_coulomb_wall_limited, "hertz/coulomb/none/none+limit_force";
    // The Chung & Ooi preset on the Hertz collapse, whose beads roll with resistance.
    (Restitution, true, K::Coulomb, RollingKind::Epsd2, NoVdw)
        => <LimitForce<HertzDamping>, CoulombMindlin, Epsd2, NoCohesion>, hertz_coulomb_wall_limited, "hertz/coulomb/epsd2/none+limit_force";
    (Yang { .. }, false, K::Yang, RollingKind::None, NoVdw)
        => <YangDamping, YangTangential, NoRolling, NoCohesion>, hertz_wall, "yang/yang/none/none";
    (Yang { .. }, false, K::Yang, RollingKind::ConstantTorque, Vdw { .. })
        => <YangDamping, YangTangential, ConstantTorque, VanDerWaals>, hertz_wall, "yang/yang/constant_torque/vdw (paper B)";
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::RunOptions;

    #[test]
    fn tangential_damping_off_zeroes_the_dashpots_and_limit_force_recalibrates_the_walls() {
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("validation/cases/hertz_settle.toml");
        let mut scene = Scene::load(&path).unwrap();
        let crate::scene::ContactSettings::Hertz(h) = &mut scene.contact else {
            panic!("not hertz")
        };
        let mut h = h.clone();
        assert!(Mindlin::from_scene(&scene, &h)
            .damping_factor
            .iter()
            .all(|&f| f > 0.0));
        let plain = hertz_history_wall(&scene, &h);
        h.tangential_damping = false;
        h.limit_force = true;
        assert!(Mindlin::from_scene(&scene, &h)
            .damping_factor
            .iter()
            .all(|&f| f == 0.0));
        let wall = hertz_history_wall_limited(&scene, &h);
        assert!(wall.tangential.damping_factor.iter().all(|&f| f == 0.0));
        let e = scene.wall_contact.restitution;
        assert!(e < 1.0);
        for (clamped, free) in wall
            .stateless
            .damping
            .factor
            .iter()
            .zip(&plain.stateless.damping.factor)
        {
            assert_eq!(*clamped, clamped_damping_factor(e));
            assert!(clamped > free);
        }
    }

    #[test]
    fn without_its_dashpot_a_sticking_mindlin_contact_is_elastic() {
        // Load the spring by a slip and take it back: the force returns to zero (no energy
        // lost), and at any slip speed it is the spring's alone, -k_t u.
        let m = Mindlin {
            g_eff: vec![1e6],
            damping_factor: vec![0.0],
            friction: vec![0.5],
        };
        let mut c = crate::contact::tests::contact_at(1e-5, 5e-4);
        let k_t = 8.0 * 1e6 * (5e-4_f64 * 1e-5).sqrt();
        let mut u = Vec3::ZERO;
        c.tangential_velocity = Vec3::new(0.0, 1e-3, 0.0);
        let loaded = m.force(&c, 100.0, &mut u, 1e-3);
        assert!((loaded.y + k_t * 1e-6).abs() < 1e-12 * k_t);
        c.tangential_velocity = -c.tangential_velocity;
        let unloaded = m.force(&c, 100.0, &mut u, 1e-3);
        assert_eq!((unloaded, u), (Vec3::ZERO, Vec3::ZERO));
    }

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
