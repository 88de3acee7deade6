//! Materials and pair coefficients (Hertz scenes): a species' own material, `[[contact.pair]]`,
//! `[[wall_material]]`, `[[wall_contact.pair]]` and the material a wall or body names. Each
//! pair at most once, every name known, every value in its range; the defaults are `[contact]`'s
//! and `[wall_contact]`'s (`scene::ContactTables` resolves them).

use super::super::raw::*;
use super::super::*;
use super::contact::poisson;
use super::{names, Checker};

/// What a field of the material tables needs when the scene's model is not Hertz.
const HERTZ_ONLY: &str =
    "only with contact.model = \"hertz\": the wca model has one law for all pairs";

/// A species' own `youngs_modulus` and `poisson_ratio`, checked for range (`hertz` says
/// whether the model has materials at all).
pub(super) fn species_material(
    c: &Checker,
    k: usize,
    s: &RawSpecies,
    hertz: bool,
) -> Result<(Option<Real>, Option<Real>), SceneError> {
    let field = |f: &str| format!("species[{k}].{f}");
    if !hertz {
        for (f, set) in [
            ("youngs_modulus", s.youngs_modulus.is_some()),
            ("poisson_ratio", s.poisson_ratio.is_some()),
        ] {
            if set {
                return Err(c.invalid(field(f), "set", HERTZ_ONLY));
            }
        }
    }
    let youngs_modulus = s
        .youngs_modulus
        .map(|e| c.positive(&field("youngs_modulus"), e))
        .transpose()?;
    let poisson_ratio = s
        .poisson_ratio
        .map(|nu| poisson(c, &field("poisson_ratio"), nu))
        .transpose()?;
    Ok((youngs_modulus, poisson_ratio))
}

/// The index of species `name`, or an error at `field` listing the species.
fn species_index(
    c: &Checker,
    field: &str,
    name: &str,
    species: &[Species],
) -> Result<usize, SceneError> {
    species.iter().position(|s| s.name == name).ok_or_else(|| {
        c.invalid(
            field,
            format!("\"{name}\""),
            format!(
                "one of the species: {}",
                names(species.iter().map(|s| &s.name))
            ),
        )
    })
}

/// `[[contact.pair]]` of a Hertz scene whose settings (the defaults) are `h`.
pub(super) fn contact_pairs(
    c: &Checker,
    raw: &[RawContactPair],
    species: &[Species],
    h: &HertzSettings,
) -> Result<Vec<SpeciesPair>, SceneError> {
    let mut pairs: Vec<SpeciesPair> = Vec::new();
    for (k, p) in raw.iter().enumerate() {
        let field = |f: &str| format!("contact.pair[{k}].{f}");
        let [a, b] = p.species.as_slice() else {
            return Err(c.invalid(
                field("species"),
                format!("{:?}", p.species),
                "two species names, e.g. [\"grain\", \"base\"] (the same name twice for a species with itself)",
            ));
        };
        let (a, b) = (
            species_index(c, &field("species"), a, species)?,
            species_index(c, &field("species"), b, species)?,
        );
        if let Some(j) = pairs
            .iter()
            .position(|q| q.species == [a, b] || q.species == [b, a])
        {
            return Err(c.invalid(
                field("species"),
                format!("{:?}", p.species),
                format!("a species pair given once: contact.pair[{j}] gives it already"),
            ));
        }
        if p.restitution.is_none()
            && p.friction.is_none()
            && p.rolling_friction.is_none()
            && p.hamaker_constant.is_none()
        {
            return Err(c.invalid(
                format!("contact.pair[{k}]"),
                "no coefficient",
                "at least one of restitution, friction, rolling_friction, hamaker_constant",
            ));
        }
        let restitution = match p.restitution {
            None => None,
            Some(_) if matches!(h.damping, HertzDampingKind::Yang { .. }) => {
                return Err(c.invalid(
                    field("restitution"),
                    "set",
                    "not with damping = \"yang\" (its damping is gamma_n_yang)",
                ))
            }
            Some(e) if e > 0.0 && e <= 1.0 => Some(e),
            Some(e) => return Err(c.invalid(field("restitution"), e, "0 < e <= 1")),
        };
        let friction = p
            .friction
            .map(|mu| c.non_negative(&field("friction"), mu))
            .transpose()?;
        let rolling_friction = match p.rolling_friction {
            Some(_) if h.rolling == RollingKind::None => {
                return Err(c.invalid(
                    field("rolling_friction"),
                    "set",
                    "only with rolling = \"constant_torque\" or \"epsd2\"",
                ))
            }
            r => r
                .map(|r| c.non_negative(&field("rolling_friction"), r))
                .transpose()?,
        };
        let hamaker_constant = match p.hamaker_constant {
            Some(_) if h.cohesion == CohesionKind::None => {
                return Err(c.invalid(
                    field("hamaker_constant"),
                    "set",
                    "only with cohesion = \"vdw\"",
                ))
            }
            x => x
                .map(|x| c.positive(&field("hamaker_constant"), x))
                .transpose()?,
        };
        pairs.push(SpeciesPair {
            species: [a, b],
            restitution,
            friction,
            rolling_friction,
            hamaker_constant,
        });
    }
    Ok(pairs)
}

/// A rolling model needs a rolling friction for every species pair that meets (two frozen
/// particles never do): from its `[[contact.pair]]` or the `[contact]` default (`given`).
pub(super) fn check_rolling_friction(
    c: &Checker,
    given: Option<Real>,
    h: &HertzSettings,
    species: &[Species],
) -> Result<(), SceneError> {
    if h.rolling == RollingKind::None {
        return Ok(());
    }
    let from_pairs = h.pairs.iter().any(|p| p.rolling_friction.is_some());
    match given {
        Some(r) if r > 0.0 => return Ok(()),
        None if from_pairs => {}
        _ => {
            return Err(c.invalid(
                "contact.rolling_friction",
                h.rolling_friction,
                "> 0 when rolling is not \"none\" (or one per species pair in [[contact.pair]])",
            ))
        }
    }
    let n = species.len();
    for (a, b) in (0..n).flat_map(|a| (a..n).map(move |b| (a, b))) {
        let meet = !(species[a].frozen && species[b].frozen);
        let has = h
            .pairs
            .iter()
            .any(|p| (p.species == [a, b] || p.species == [b, a]) && p.rolling_friction.is_some());
        if meet && !has {
            return Err(c.invalid(
                "contact.pair",
                format!(
                    "no rolling_friction for the species pair (`{}`, `{}`)",
                    species[a].name, species[b].name
                ),
                "a [[contact.pair]] with rolling_friction for every species pair, or a default rolling_friction in [contact]",
            ));
        }
    }
    Ok(())
}

/// `[[wall_material]]`: names unique, Young's modulus > 0, Poisson's ratio in range.
pub(super) fn wall_materials(
    c: &Checker,
    raw: &[RawWallMaterial],
    hertz: bool,
) -> Result<Vec<WallMaterial>, SceneError> {
    let mut materials: Vec<WallMaterial> = Vec::new();
    for (k, m) in raw.iter().enumerate() {
        let field = |f: &str| format!("wall_material[{k}].{f}");
        if !hertz {
            return Err(c.invalid(format!("wall_material[{k}]"), &m.name, HERTZ_ONLY));
        }
        if m.name.trim().is_empty() || materials.iter().any(|o| o.name == m.name) {
            return Err(c.invalid(
                field("name"),
                format!("\"{}\"", m.name),
                "a non-empty name used by no other wall material",
            ));
        }
        materials.push(WallMaterial {
            name: m.name.clone(),
            youngs_modulus: c.positive(&field("youngs_modulus"), m.youngs_modulus)?,
            poisson_ratio: poisson(c, &field("poisson_ratio"), m.poisson_ratio)?,
        });
    }
    Ok(materials)
}

/// The material a wall, body or wall pair names at `field`: 0 (the `[wall_contact]` default)
/// when none, else `k + 1` for `[[wall_material]]` k.
pub(super) fn material_index(
    c: &Checker,
    field: &str,
    name: Option<&str>,
    materials: &[WallMaterial],
) -> Result<usize, SceneError> {
    let Some(name) = name else { return Ok(0) };
    match materials.iter().position(|m| m.name == name) {
        Some(k) => Ok(k + 1),
        None if materials.is_empty() => Err(c.invalid(
            field,
            format!("\"{name}\""),
            "the name of a [[wall_material]] (the scene defines none)",
        )),
        None => Err(c.invalid(
            field,
            format!("\"{name}\""),
            format!(
                "one of the wall materials: {}",
                names(materials.iter().map(|m| &m.name))
            ),
        )),
    }
}

/// `[[wall_contact.pair]]`: each (species, material) once, coefficients in range.
pub(super) fn wall_pairs(
    c: &Checker,
    raw: &[RawWallPair],
    species: &[Species],
    materials: &[WallMaterial],
    hertz: bool,
) -> Result<Vec<WallPair>, SceneError> {
    let mut pairs: Vec<WallPair> = Vec::new();
    for (k, p) in raw.iter().enumerate() {
        let field = |f: &str| format!("wall_contact.pair[{k}].{f}");
        if !hertz {
            return Err(c.invalid(format!("wall_contact.pair[{k}]"), "set", HERTZ_ONLY));
        }
        let s = species_index(c, &field("species"), &p.species, species)?;
        let material = material_index(c, &field("material"), p.material.as_deref(), materials)?;
        if let Some(j) = pairs
            .iter()
            .position(|q| q.species == s && q.material == material)
        {
            return Err(c.invalid(
                field("species"),
                format!("\"{}\"", p.species),
                format!("a species and wall material given once: wall_contact.pair[{j}] gives them already"),
            ));
        }
        if p.restitution.is_none() && p.friction.is_none() && p.rolling_friction.is_none() {
            return Err(c.invalid(
                format!("wall_contact.pair[{k}]"),
                "no coefficient",
                "at least one of restitution, friction, rolling_friction",
            ));
        }
        let restitution = match p.restitution {
            Some(e) if !(e > 0.0 && e <= 1.0) => {
                return Err(c.invalid(field("restitution"), e, "0 < e <= 1"))
            }
            e => e,
        };
        pairs.push(WallPair {
            species: s,
            material,
            restitution,
            friction: p
                .friction
                .map(|mu| c.non_negative(&field("friction"), mu))
                .transpose()?,
            rolling_friction: p
                .rolling_friction
                .map(|r| c.non_negative(&field("rolling_friction"), r))
                .transpose()?,
        });
    }
    Ok(pairs)
}

#[cfg(test)]
mod tests {
    use super::super::super::*;
    use std::path::Path;

    /// Two species `a` and `b` (with `species_b` added to its table), a floor wall; the
    /// model's [contact] (`wca`, `yang`: Hertz with Yang's damping, else Hertz), `tables` at
    /// the end.
    fn scene(model: &str, species_b: &str, tables: &str) -> Result<Scene, SceneError> {
        let contact = match model {
            "wca" => "model = \"wca\"\nepsilon = 1.0\nsigma = 8.908987e-4\ngamma_n = 0.0\ngamma_t = 0.0",
            "yang" => "model = \"hertz\"\nyoungs_modulus = 5e6\npoisson_ratio = 0.3\nfriction = 0.5\ndamping = \"yang\"\ngamma_n_yang = 1e-5",
            _ => "model = \"hertz\"\nyoungs_modulus = 5e6\npoisson_ratio = 0.3\nrestitution = 0.5\nfriction = 0.5",
        };
        let text = format!(
            r#"name = "materials"
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.01, 0.01, 0.01]
[[species]]
name = "a"
diameter = 1e-3
density = 2500.0
[[species]]
name = "b"
diameter = 1e-3
density = 1000.0
{species_b}
[contact]
{contact}
[wall_contact]
restitution = 0.5
friction = 0.5
[[wall]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[time]
dt = 1e-7
[[stage]]
name = "s"
duration = 1e-6
{tables}
"#
        );
        Scene::parse(&text, Path::new("materials.toml"))
    }

    #[test]
    fn bad_material_tables_name_the_field_and_what_is_allowed() {
        let steel =
            "[[wall_material]]\nname = \"steel\"\nyoungs_modulus = 2e11\npoisson_ratio = 0.3\n";
        let cases: Vec<(&str, &str, String, &str, &str)> = vec![
            // (model, species b's extra lines, tables, field, allowed)
            ("hertz", "", "[[contact.pair]]\nspecies = [\"a\"]\nfriction = 0.1".into(), "contact.pair[0].species", "two species names"),
            ("hertz", "", "[[contact.pair]]\nspecies = [\"a\", \"b\"]".into(), "contact.pair[0]", "at least one of"),
            ("hertz", "", "[[contact.pair]]\nspecies = [\"a\", \"b\"]\nfriction = -0.1".into(), "contact.pair[0].friction", ">= 0"),
            ("hertz", "", "[[contact.pair]]\nspecies = [\"a\", \"b\"]\nrolling_friction = 0.1".into(), "contact.pair[0].rolling_friction", "only with rolling"),
            ("hertz", "", "[[contact.pair]]\nspecies = [\"a\", \"b\"]\nhamaker_constant = 1e-20".into(), "contact.pair[0].hamaker_constant", "cohesion = \"vdw\""),
            ("yang", "", "[[contact.pair]]\nspecies = [\"a\", \"b\"]\nrestitution = 0.5".into(), "contact.pair[0].restitution", "not with damping"),
            ("hertz", "youngs_modulus = -1.0", String::new(), "species[1].youngs_modulus", "> 0"),
            ("hertz", "poisson_ratio = 0.5", String::new(), "species[1].poisson_ratio", "< 0.5"),
            ("wca", "youngs_modulus = 1e7", String::new(), "species[1].youngs_modulus", "only with contact.model = \"hertz\""),
            ("hertz", "", "[[contact.pair]]\nspecies = [\"a\", \"b\"]\nrestitution = 1.5".into(), "contact.pair[0].restitution", "0 < e <= 1"),
            ("hertz", "", format!("{steel}[[wall_contact.pair]]\nspecies = \"a\"\nmaterial = \"iron\"\nfriction = 0.1"), "wall_contact.pair[0].material", "`steel`"),
            ("hertz", "", format!("{steel}[[wall_contact.pair]]\nspecies = \"a\"\nmaterial = \"steel\"\nfriction = 0.1\n[[wall_contact.pair]]\nspecies = \"a\"\nmaterial = \"steel\"\nrestitution = 0.1"), "wall_contact.pair[1].species", "given once"),
            ("hertz", "", format!("{steel}[[wall_contact.pair]]\nspecies = \"c\"\nfriction = 0.1"), "wall_contact.pair[0].species", "`a`, `b`"),
            ("hertz", "", "[[wall_material]]\nname = \"steel\"\nyoungs_modulus = 0.0\npoisson_ratio = 0.3".into(), "wall_material[0].youngs_modulus", "> 0"),
            ("hertz", "", format!("{steel}{steel}"), "wall_material[1].name", "no other wall material"),
            ("wca", "", "[[contact.pair]]\nspecies = [\"a\", \"b\"]\nfriction = 0.1".into(), "contact.pair", "only with model = \"hertz\""),
            ("wca", "", steel.into(), "wall_material[0]", "only with contact.model = \"hertz\""),
        ];
        for (model, extra, tables, field, allowed) in cases {
            let message = scene(model, extra, &tables).unwrap_err().to_string();
            assert!(
                message.starts_with("materials.toml: field `")
                    && message.contains(&format!("`{field}`"))
                    && message.contains(allowed),
                "{field}: {message}"
            );
        }
    }

    #[test]
    fn walls_and_bodies_name_wall_materials_and_pairs_are_read() {
        let steel =
            "[[wall_material]]\nname = \"steel\"\nyoungs_modulus = 2e11\npoisson_ratio = 0.3\n";
        let s = scene(
            "hertz",
            "",
            &format!("{steel}[[wall_contact.pair]]\nspecies = \"b\"\nmaterial = \"steel\"\nrestitution = 0.2\n[[wall_contact.pair]]\nspecies = \"b\"\nfriction = 0.1\n[[contact.pair]]\nspecies = [\"b\", \"a\"]\nfriction = 0.25"),
        )
        .unwrap()
        .wall_contact;
        assert_eq!(s.materials.len(), 1);
        assert_eq!(
            (
                s.pairs[0].species,
                s.pairs[0].material,
                s.pairs[0].restitution
            ),
            (1, 1, Some(0.2))
        );
        assert_eq!((s.pairs[1].material, s.pairs[1].friction), (0, Some(0.1)));
        let text = |wall: &str| {
            format!("{steel}[[wall]]\nname = \"side\"\npoint = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n{wall}")
        };
        let s = scene("hertz", "", &text("material = \"steel\"")).unwrap();
        assert_eq!((s.walls[0].material, s.walls[1].material), (0, 1));
        let m = scene("wca", "", "[[wall]]\nname = \"side\"\npoint = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\nmaterial = \"steel\"")
            .unwrap_err()
            .to_string();
        assert!(m.contains("wall[1].material") && m.contains("hertz"), "{m}");
        let m = scene("hertz", "", "[[wall]]\nname = \"side\"\npoint = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\nmaterial = \"steel\"")
            .unwrap_err()
            .to_string();
        assert!(
            m.contains("wall[1].material") && m.contains("defines none"),
            "{m}"
        );
    }
}
