//! `[contact]` (one function per model and per Hertz sub-model), `[wall_contact]` and
//! `[[wall]]`.

use super::super::raw::*;
use super::super::*;
use super::{materials, Checker};
use crate::math::TWO_POW_ONE_SIXTH;

/// `[contact]`: `model = "wca"` or `"hertz"`.
pub(super) fn contact(
    c: &Checker,
    rc: &RawContact,
    species: &[Species],
) -> Result<ContactSettings, SceneError> {
    match rc.model.as_str() {
        "hertz" => Ok(ContactSettings::Hertz(hertz_contact(c, rc, species)?)),
        "wca" => wca_contact(c, rc, species),
        other => Err(c.invalid(
            "contact.model",
            format!("\"{other}\""),
            "\"wca\" (the WCA model of Hirose) or \"hertz\"",
        )),
    }
}

/// `[contact] model = "wca"`: the seed's WCA repulsion with viscous damping.
fn wca_contact(
    c: &Checker,
    rc: &RawContact,
    species: &[Species],
) -> Result<ContactSettings, SceneError> {
    for (field, set) in [
        ("youngs_modulus", rc.youngs_modulus.is_some()),
        ("poisson_ratio", rc.poisson_ratio.is_some()),
        ("restitution", rc.restitution.is_some()),
        ("friction", rc.friction.is_some()),
        ("rolling_friction", rc.rolling_friction.is_some()),
        ("damping", rc.damping.is_some()),
        ("gamma_n_yang", rc.gamma_n_yang.is_some()),
        ("tangential", rc.tangential.is_some()),
        ("limit_force", rc.limit_force.is_some()),
        ("tangential_damping", rc.tangential_damping.is_some()),
        ("preset", rc.preset.is_some()),
        ("rolling", rc.rolling.is_some()),
        ("cohesion", rc.cohesion.is_some()),
        ("hamaker_constant", rc.hamaker_constant.is_some()),
        ("h_min", rc.h_min.is_some()),
        ("cohesion_cutoff", rc.cohesion_cutoff.is_some()),
        (
            "characteristic_velocity",
            rc.characteristic_velocity.is_some(),
        ),
        ("pair", !rc.pairs.is_empty()),
    ] {
        if set {
            return Err(c.invalid(
                format!("contact.{field}"),
                "set",
                "only with model = \"hertz\"; the wca model takes epsilon, sigma, gamma_n, gamma_t",
            ));
        }
    }
    let epsilon = c.positive(
        "contact.epsilon",
        c.required("contact.epsilon", rc.epsilon, "the WCA energy, J")?,
    )?;
    let sigma = c.positive(
        "contact.sigma",
        c.required("contact.sigma", rc.sigma, "the WCA length, m")?,
    )?;
    let gamma_n = c.non_negative(
        "contact.gamma_n",
        c.required("contact.gamma_n", rc.gamma_n, "the normal dashpot, kg/s")?,
    )?;
    let gamma_t = c.non_negative(
        "contact.gamma_t",
        c.required(
            "contact.gamma_t",
            rc.gamma_t,
            "the tangential dashpot, kg/s",
        )?,
    )?;
    // The WCA cut-off 2^(1/6) sigma is the particle diameter (paper A); a mismatch
    // would make particles touch before or after they repel. Frozen species (e.g. a
    // body's particles) get sigma mixed by the mean diameter of each pair instead.
    for s in species.iter().filter(|s| !s.frozen) {
        let rc = TWO_POW_ONE_SIXTH * sigma;
        if (rc / s.diameter - 1.0).abs() > 0.01 {
            return Err(c.invalid("contact.sigma", sigma, format!("2^(1/6) sigma within 1% of the diameter of species `{}` ({} m), i.e. sigma near {:.6e}", s.name, s.diameter, s.diameter / TWO_POW_ONE_SIXTH)));
        }
    }
    Ok(ContactSettings::Wca(WcaSettings {
        epsilon,
        sigma,
        gamma_n,
        gamma_t,
    }))
}

pub(super) fn poisson(c: &Checker, field: &str, nu: f64) -> Result<f64, SceneError> {
    if nu.is_finite() && (-1.0..0.5).contains(&nu) {
        Ok(nu)
    } else {
        Err(c.invalid(field, nu, "-1 <= poisson_ratio < 0.5"))
    }
}

/// `[contact] model = "hertz"`: keywords as in LIGGGHTS/LAMMPS; `[[contact.pair]]` for the
/// species pairs whose coefficients are not these.
fn hertz_contact(
    c: &Checker,
    rc: &RawContact,
    species: &[Species],
) -> Result<HertzSettings, SceneError> {
    for (field, set) in [
        ("epsilon", rc.epsilon.is_some()),
        ("sigma", rc.sigma.is_some()),
        ("gamma_n", rc.gamma_n.is_some()),
        ("gamma_t", rc.gamma_t.is_some()),
    ] {
        if set {
            return Err(c.invalid(
                format!("contact.{field}"),
                "set",
                "only with model = \"wca\"; for Yang damping use gamma_n_yang",
            ));
        }
    }
    let youngs_modulus = c.positive(
        "contact.youngs_modulus",
        c.required(
            "contact.youngs_modulus",
            rc.youngs_modulus,
            "Young's modulus of the particles, Pa",
        )?,
    )?;
    let poisson_ratio = poisson(
        c,
        "contact.poisson_ratio",
        c.required(
            "contact.poisson_ratio",
            rc.poisson_ratio,
            "Poisson's ratio of the particles",
        )?,
    )?;
    let friction = c.non_negative(
        "contact.friction",
        c.required(
            "contact.friction",
            rc.friction,
            "the Coulomb friction coefficient",
        )?,
    )?;
    let rolling_friction = c.non_negative(
        "contact.rolling_friction",
        rc.rolling_friction.unwrap_or(0.0),
    )?;
    let (damping, restitution) = hertz_damping(c, rc)?;
    let preset = preset(c, rc)?;
    let tangential = tangential(c, rc, &preset)?;
    let (limit_force, tangential_damping) = mindlin_options(c, rc, &preset, damping, tangential)?;
    let rolling = rolling(c, rc)?;
    let cohesion = cohesion(c, rc)?;
    let mut h = HertzSettings {
        youngs_modulus,
        poisson_ratio,
        restitution,
        friction,
        rolling_friction,
        damping,
        tangential,
        rolling,
        cohesion,
        characteristic_velocity: c.positive(
            "contact.characteristic_velocity",
            rc.characteristic_velocity.unwrap_or(1.0),
        )?,
        limit_force,
        tangential_damping,
        pairs: Vec::new(),
    };
    h.pairs = materials::contact_pairs(c, &rc.pairs, species, &h)?;
    materials::check_rolling_friction(c, rc.rolling_friction, &h, species)?;
    Ok(h)
}

/// `damping = "hertz" | "yang"` and the restitution that goes (only) with the first.
fn hertz_damping(c: &Checker, rc: &RawContact) -> Result<(HertzDampingKind, Real), SceneError> {
    let damping = match rc.damping.as_deref().unwrap_or("hertz") {
        "hertz" => {
            if rc.gamma_n_yang.is_some() {
                return Err(c.invalid(
                    "contact.gamma_n_yang",
                    "set",
                    "only with damping = \"yang\"",
                ));
            }
            HertzDampingKind::Restitution
        }
        "yang" => HertzDampingKind::Yang {
            gamma_n: c.non_negative(
                "contact.gamma_n_yang",
                c.required(
                    "contact.gamma_n_yang",
                    rc.gamma_n_yang,
                    "the Yang damping time gamma_n, s",
                )?,
            )?,
        },
        other => {
            return Err(c.invalid(
                "contact.damping",
                format!("\"{other}\""),
                "\"hertz\" (LIGGGHTS restitution-based, default) or \"yang\" (paper B Eq. 4)",
            ))
        }
    };
    let restitution = match (damping, rc.restitution) {
        (HertzDampingKind::Restitution, None) => {
            return Err(c.invalid(
                "contact.restitution",
                "missing",
                "the coefficient of restitution, 0 < e <= 1",
            ))
        }
        (_, Some(e)) if !(e > 0.0 && e <= 1.0) => {
            return Err(c.invalid("contact.restitution", e, "0 < e <= 1"))
        }
        (HertzDampingKind::Yang { .. }, Some(_)) => {
            return Err(c.invalid(
                "contact.restitution",
                "set",
                "not with damping = \"yang\" (its damping is gamma_n_yang)",
            ))
        }
        (_, e) => e.unwrap_or(1.0),
    };
    Ok((damping, restitution))
}

/// What a `[contact] preset` sets: the values it gives the keys it names, which the scene
/// may repeat but not contradict.
#[derive(Default)]
struct Preset {
    name: Option<&'static str>,
    tangential: Option<&'static str>,
    limit_force: Option<bool>,
}

/// The presets and what each sets, as the guide's physics chapter names them.
const PRESETS: &[(&str, &str, bool)] = &[
    // The law that passes every criterion of the Chung & Ooi (2011) benchmark: Coulomb's
    // bound on spring plus dashpot, and no dashpot pull at the end of a contact.
    ("chung-ooi", "coulomb", true),
];

/// `preset = "chung-ooi"`: a named combination of `tangential` and `limit_force`.
fn preset(c: &Checker, rc: &RawContact) -> Result<Preset, SceneError> {
    let Some(name) = rc.preset.as_deref() else {
        return Ok(Preset::default());
    };
    let Some(&(name, tangential, limit_force)) = PRESETS.iter().find(|p| p.0 == name) else {
        return Err(c.invalid(
            "contact.preset",
            format!("\"{name}\""),
            "\"chung-ooi\" (tangential = \"coulomb\" with limit_force = true: the law that passes the Chung & Ooi (2011) benchmark)",
        ));
    };
    let contradiction = |field: &str, given: String, preset_value: String| {
        c.invalid(
            format!("contact.{field}"),
            given,
            format!(
                "{preset_value} or left out: preset = \"{name}\" sets tangential = \"{tangential}\" and limit_force = {limit_force}"
            ),
        )
    };
    if let Some(t) = rc.tangential.as_deref() {
        if t != tangential {
            return Err(contradiction(
                "tangential",
                format!("\"{t}\""),
                format!("\"{tangential}\""),
            ));
        }
    }
    if let Some(l) = rc.limit_force {
        if l != limit_force {
            return Err(contradiction(
                "limit_force",
                l.to_string(),
                limit_force.to_string(),
            ));
        }
    }
    Ok(Preset {
        name: Some(name),
        tangential: Some(tangential),
        limit_force: Some(limit_force),
    })
}

/// `tangential = "history" | "coulomb" | "yang"` (or the preset's).
fn tangential(c: &Checker, rc: &RawContact, preset: &Preset) -> Result<TangentialKind, SceneError> {
    let given = rc.tangential.as_deref().or(preset.tangential);
    match given.unwrap_or("history") {
        "history" => Ok(TangentialKind::History),
        "coulomb" => Ok(TangentialKind::Coulomb),
        "yang" => Ok(TangentialKind::Yang),
        other => Err(c.invalid(
            "contact.tangential",
            format!("\"{other}\""),
            "\"history\" (LIGGGHTS tangential history, default), \"coulomb\" (the same spring and dashpot, their sum capped at mu max(F_n, 0)) or \"yang\" (paper B Eq. 5)",
        )),
    }
}

/// `limit_force` and `tangential_damping` (LIGGGHTS `limitForce`, `tangential_damping`): options
/// of the restitution dashpot and of the Mindlin spring, so only with `damping = "hertz"` and
/// `tangential = "history"` or `"coulomb"`.
fn mindlin_options(
    c: &Checker,
    rc: &RawContact,
    preset: &Preset,
    damping: HertzDampingKind,
    tangential: TangentialKind,
) -> Result<(bool, bool), SceneError> {
    let mindlin = damping == HertzDampingKind::Restitution
        && matches!(
            tangential,
            TangentialKind::History | TangentialKind::Coulomb
        );
    let limit_force = rc.limit_force.or(preset.limit_force).unwrap_or(false);
    let tangential_damping = rc.tangential_damping.unwrap_or(true);
    if let (Some(name), false) = (preset.name, mindlin) {
        return Err(c.invalid(
            "contact.preset",
            format!("\"{name}\""),
            "only with damping = \"hertz\" (its options are those of the restitution dashpot and the Mindlin spring)",
        ));
    }
    for (field, non_default, value) in [
        ("limit_force", limit_force, "true"),
        ("tangential_damping", !tangential_damping, "false"),
    ] {
        if non_default && !mindlin {
            return Err(c.invalid(
                format!("contact.{field}"),
                value,
                "only with damping = \"hertz\" and tangential = \"history\" or \"coulomb\"",
            ));
        }
    }
    Ok((limit_force, tangential_damping))
}

/// `rolling = "none" | "constant_torque" | "epsd2"` (its friction is checked with the pairs).
fn rolling(c: &Checker, rc: &RawContact) -> Result<RollingKind, SceneError> {
    let rolling = match rc.rolling.as_deref().unwrap_or("none") {
        "none" => RollingKind::None,
        "constant_torque" => RollingKind::ConstantTorque,
        "epsd2" => RollingKind::Epsd2,
        other => return Err(c.invalid(
            "contact.rolling",
            format!("\"{other}\""),
            "\"none\", \"constant_torque\" (paper B Eq. 10) or \"epsd2\" (LIGGGHTS rolling spring)",
        )),
    };
    Ok(rolling)
}

/// `cohesion = "none" | "vdw"` with the van der Waals parameters only for the second.
fn cohesion(c: &Checker, rc: &RawContact) -> Result<CohesionKind, SceneError> {
    match rc.cohesion.as_deref().unwrap_or("none") {
        "none" => {
            for (field, set) in [
                ("hamaker_constant", rc.hamaker_constant.is_some()),
                ("h_min", rc.h_min.is_some()),
                ("cohesion_cutoff", rc.cohesion_cutoff.is_some()),
            ] {
                if set {
                    return Err(c.invalid(
                        format!("contact.{field}"),
                        "set",
                        "only with cohesion = \"vdw\"",
                    ));
                }
            }
            Ok(CohesionKind::None)
        }
        "vdw" => {
            let h_min = c.positive(
                "contact.h_min",
                c.required(
                    "contact.h_min",
                    rc.h_min,
                    "the van der Waals cut-off gap, m (e.g. 4e-10)",
                )?,
            )?;
            let cutoff = match rc.cohesion_cutoff {
                Some(x) if x.is_finite() && x > h_min => Some(x),
                Some(x) => {
                    return Err(c.invalid(
                        "contact.cohesion_cutoff",
                        x,
                        format!("a gap > h_min = {h_min} m"),
                    ))
                }
                None => None,
            };
            Ok(CohesionKind::VanDerWaals {
                hamaker_constant: c.positive(
                    "contact.hamaker_constant",
                    c.required(
                        "contact.hamaker_constant",
                        rc.hamaker_constant,
                        "the Hamaker constant, J",
                    )?,
                )?,
                h_min,
                cutoff,
            })
        }
        other => Err(c.invalid(
            "contact.cohesion",
            format!("\"{other}\""),
            "\"none\" or \"vdw\" (van der Waals, paper B Eq. 7-8)",
        )),
    }
}

/// `[wall_contact]`: required when the scene has walls; inert defaults otherwise. With the
/// `[[wall_material]]` tables and its `[[wall_contact.pair]]` (Hertz scenes).
pub(super) fn wall_contact(
    c: &Checker,
    raw: &RawScene,
    species: &[Species],
    hertz: bool,
) -> Result<WallContactSettings, SceneError> {
    let materials = materials::wall_materials(c, &raw.wall_materials, hertz)?;
    let mut settings = wall_contact_defaults(c, raw.wall_contact.as_ref(), !raw.walls.is_empty())?;
    if let Some(w) = &raw.wall_contact {
        settings.pairs = materials::wall_pairs(c, &w.pairs, species, &materials, hertz)?;
    }
    settings.materials = materials;
    Ok(settings)
}

/// `[wall_contact]`'s own values.
fn wall_contact_defaults(
    c: &Checker,
    raw: Option<&RawWallContact>,
    has_walls: bool,
) -> Result<WallContactSettings, SceneError> {
    match raw {
        Some(w) => {
            if !(w.restitution > 0.0 && w.restitution <= 1.0) {
                return Err(c.invalid("wall_contact.restitution", w.restitution, "0 < e <= 1"));
            }
            let youngs_modulus = match w.youngs_modulus {
                Some(y) => Some(c.positive("wall_contact.youngs_modulus", y)?),
                None => None,
            };
            let poisson_ratio = match w.poisson_ratio {
                Some(nu) => Some(poisson(c, "wall_contact.poisson_ratio", nu)?),
                None => None,
            };
            Ok(WallContactSettings {
                restitution: w.restitution,
                friction: c.non_negative("wall_contact.friction", w.friction)?,
                youngs_modulus,
                poisson_ratio,
                rolling_friction: c.non_negative(
                    "wall_contact.rolling_friction",
                    w.rolling_friction.unwrap_or(0.0),
                )?,
                materials: Vec::new(),
                pairs: Vec::new(),
            })
        }
        None if !has_walls => Ok(WallContactSettings {
            restitution: 1.0,
            friction: 0.0,
            youngs_modulus: None,
            poisson_ratio: None,
            rolling_friction: 0.0,
            materials: Vec::new(),
            pairs: Vec::new(),
        }),
        None => Err(c.invalid(
            "wall_contact",
            "missing",
            "a [wall_contact] table with restitution and friction when the scene has walls",
        )),
    }
}

/// `[[wall]]`: planes by a point and a non-zero normal, names unique, each of a known wall
/// material (`materials`; Hertz scenes only).
pub(super) fn walls(
    c: &Checker,
    raw: &[RawWall],
    materials: &[WallMaterial],
    hertz: bool,
) -> Result<Vec<WallSettings>, SceneError> {
    let mut walls = Vec::new();
    for (k, w) in raw.iter().enumerate() {
        let point = c.vector(&format!("wall[{k}].point"), w.point)?;
        let normal = c.vector(&format!("wall[{k}].normal"), w.normal)?;
        if normal.length() == 0.0 {
            return Err(c.invalid(
                format!("wall[{k}].normal"),
                format!("{:?}", w.normal),
                "a non-zero vector",
            ));
        }
        if walls.iter().any(|x: &WallSettings| x.name == w.name) {
            return Err(c.invalid(
                format!("wall[{k}].name"),
                &w.name,
                "a name not used by another wall",
            ));
        }
        if w.material.is_some() && !hertz {
            return Err(c.invalid(
                format!("wall[{k}].material"),
                "set",
                "only with contact.model = \"hertz\"",
            ));
        }
        walls.push(WallSettings {
            name: w.name.clone(),
            point,
            normal: normal.normalize(),
            material: materials::material_index(
                c,
                &format!("wall[{k}].material"),
                w.material.as_deref(),
                materials,
            )?,
        });
    }
    Ok(walls)
}

#[cfg(test)]
mod tests {
    use super::super::super::*;
    use std::path::Path;

    /// A one-species Hertz scene whose `[contact]` ends with `extra`.
    fn scene(extra: &str) -> Result<Scene, SceneError> {
        let text = format!(
            r#"name = "preset"
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.01, 0.01, 0.01]
[[species]]
name = "a"
diameter = 1e-3
density = 2500.0
[contact]
model = "hertz"
youngs_modulus = 5e6
poisson_ratio = 0.3
friction = 0.5
{extra}
[time]
dt = 1e-7
[[stage]]
name = "s"
duration = 1e-6
"#
        );
        Scene::parse(&text, Path::new("preset.toml"))
    }

    fn hertz(scene: Scene) -> HertzSettings {
        match scene.contact {
            ContactSettings::Hertz(h) => h,
            other => panic!("not a Hertz scene: {other:?}"),
        }
    }

    #[test]
    fn the_chung_ooi_preset_is_coulomb_with_the_normal_force_clamped() {
        let by_preset = hertz(scene("restitution = 0.5\npreset = \"chung-ooi\"").unwrap());
        let by_hand = hertz(
            scene("restitution = 0.5\ntangential = \"coulomb\"\nlimit_force = true").unwrap(),
        );
        assert_eq!(by_preset.tangential, TangentialKind::Coulomb);
        assert!(by_preset.limit_force && by_preset.tangential_damping);
        assert_eq!(by_preset, by_hand);
        // Repeating what the preset sets is allowed.
        let repeated = "restitution = 0.5\npreset = \"chung-ooi\"\ntangential = \"coulomb\"";
        assert_eq!(hertz(scene(repeated).unwrap()), by_hand);
    }

    #[test]
    fn a_preset_that_is_unknown_contradicted_or_out_of_place_is_refused_by_name() {
        for (extra, field, allowed) in [
            (
                "restitution = 0.5\npreset = \"kratos\"",
                "contact.preset",
                "\"chung-ooi\"",
            ),
            (
                "restitution = 0.5\npreset = \"chung-ooi\"\ntangential = \"history\"",
                "contact.tangential",
                "sets tangential = \"coulomb\"",
            ),
            (
                "restitution = 0.5\npreset = \"chung-ooi\"\nlimit_force = false",
                "contact.limit_force",
                "limit_force = true",
            ),
            (
                "damping = \"yang\"\ngamma_n_yang = 1e-5\npreset = \"chung-ooi\"",
                "contact.preset",
                "only with damping = \"hertz\"",
            ),
        ] {
            let message = scene(extra).unwrap_err().to_string();
            assert!(
                message.contains(field) && message.contains(allowed),
                "{extra:?}: {message}"
            );
        }
    }
}
