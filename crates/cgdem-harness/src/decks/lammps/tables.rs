//! The LAMMPS lines of a Hertz scene with material tables (`scene::ContactTables`): one
//! `pair_coeff I J` per species pair, and, `fix wall/gran` having one model, one wall fix
//! per planar wall and mobile species (reference/MAPPING.md).

use std::fmt::Write as _;

use super::coefficients::{rolling_args, tangential_damping_ratio, tsuji_q_of};
use super::{plane_args, WallModulus};
use crate::decks::lines::g;
use crate::decks::DeckError;
use cgdem_core::math::Real;
use cgdem_core::scene::{ContactTables, HertzSettings, Scene};

/// `pair_style granular` with one `pair_coeff I J` per species pair of the scene's tables.
/// `hertz/material E q nu` takes `E` and `nu` as one material for both sides
/// (`Y* = E/(2 (1 - nu^2))`), so each pair is given the one material with its own `Y*` and
/// `G*` ([`one_material`]); `q`, `mu` and `mu_r` are the pair's own, `k_roll` is that of
/// its `R*` and `m*` (reference/MAPPING.md). Every pair is written: LAMMPS's mixing of an
/// unset pair is not LIGGGHTS's.
pub fn table_pair_lines(
    scene: &Scene,
    h: &HertzSettings,
    t: &ContactTables,
) -> Result<String, DeckError> {
    let mut d = String::from("pair_style      granular\n");
    d += "# per species pair: E, nu of one material with the pair's Y*, G*; q = P^-1(sqrt(5)|beta(e)|); x = sqrt(4 G*/Y*)\n";
    let n = t.n_species();
    for a in 0..n {
        for b in a..n {
            let (y, g_eff) = (t.y_eff(a, b), t.g_eff(a, b));
            let (sa, sb) = (&scene.species[a], &scene.species[b]);
            let r_eff = sa.radius() * sb.radius() / (sa.radius() + sb.radius());
            let m_eff = sa.mass() * sb.mass() / (sa.mass() + sb.mass());
            let (e, nu) = one_material(y, g_eff);
            let p = t.pair(a, b);
            let _ = writeln!(
                d,
                "pair_coeff      {} {} hertz/material {} {} {} damping tsuji tangential mindlin NULL {} {}{}",
                a + 1,
                b + 1,
                g(e),
                g(tsuji_q_of(scene, p.restitution)?),
                g(nu),
                g(tangential_damping_ratio(y, g_eff)),
                g(p.friction),
                rolling_args(h, p, y, g_eff, r_eff, m_eff)
            );
        }
    }
    Ok(d)
}

/// The one material `(E, nu)` with `Y* = y_eff` and `G* = g_eff` against itself:
/// `G*/Y* = r = (1 - nu)/(2 (2 - nu))` for one material, so `nu = (1 - 4r)/(1 - 2r)` and
/// `E = 2 (1 - nu^2) Y*`.
pub fn one_material(y_eff: Real, g_eff: Real) -> (Real, Real) {
    let r = g_eff / y_eff;
    let nu = (1.0 - 4.0 * r) / (1.0 - 2.0 * r);
    (2.0 * (1.0 - nu * nu) * y_eff, nu)
}

/// The particles one wall fix acts on: `fix wall/gran` has one model, so with material
/// tables and several mobile species each species gets its own fix of each wall
/// (`w_NAME_T` on group `grains_T`, T its atom type); one mobile species takes `w_NAME`.
pub(super) struct WallGroup {
    /// The species whose wall coefficients the fix takes (None: the uniform deck's).
    pub species: Option<usize>,
    /// Appended to the fix's name `w_NAME`.
    pub suffix: String,
    pub group: String,
}

impl WallGroup {
    /// The one fix of a wall in a scene with one material.
    pub fn all() -> WallGroup {
        WallGroup {
            species: None,
            suffix: String::new(),
            group: "all".into(),
        }
    }
}

/// The wall fixes of a scene with material tables and the groups they act on.
pub(super) fn wall_fixes(
    scene: &Scene,
    h: &HertzSettings,
    t: &ContactTables,
    modulus: WallModulus,
) -> Result<(String, Vec<WallGroup>), DeckError> {
    let groups = wall_groups(scene);
    Ok((table_wall_fix_lines(scene, h, t, &groups, modulus)?, groups))
}

fn wall_groups(scene: &Scene) -> Vec<WallGroup> {
    let mobile: Vec<usize> = (0..scene.species.len())
        .filter(|&a| !scene.species[a].frozen)
        .collect();
    match mobile[..] {
        [a] => vec![WallGroup {
            species: Some(a),
            suffix: String::new(),
            group: "all".into(),
        }],
        _ => mobile
            .iter()
            .map(|&a| WallGroup {
                species: Some(a),
                suffix: format!("_{}", a + 1),
                group: format!("grains_{}", a + 1),
            })
            .collect(),
    }
}

/// The `granular` arguments of species `a` against wall material `k` (see
/// [`table_wall_fix_lines`]).
pub(super) fn table_wall_model(
    scene: &Scene,
    h: &HertzSettings,
    t: &ContactTables,
    a: usize,
    k: usize,
    modulus: WallModulus,
) -> Result<String, DeckError> {
    let (s, nu) = (&scene.species[a], t.species[a].poisson_ratio);
    let (y, g_eff) = (t.wall_y_eff(a, k), t.wall_g_eff(a, k));
    let p = t.wall_pair(a, k);
    Ok(format!(
        "hertz/material {} {} {} damping tsuji tangential mindlin {} {} {}{}",
        g(modulus.modulus(y, nu)),
        g(tsuji_q_of(scene, p.restitution)?),
        g(nu),
        g(8.0 * g_eff),
        g(tangential_damping_ratio(y, g_eff)),
        g(p.friction),
        rolling_args(h, p, y, g_eff, s.radius(), s.mass())
    ))
}

/// The wall fixes of a scene with material tables: for each planar wall and each of
/// `groups`, the model of that species against the wall's material. The wall fix of this
/// LAMMPS takes `k_n = (4/3) E/(2 (1 - nu)) sqrt(R delta)`, so `E = 2 (1 - nu) Y*` with the
/// species' `nu`, and the Mindlin stiffness `8 G*` explicitly (as `wall_model`); the wall is
/// a particle of infinite radius and mass, so `R* = r`, `m* = m`.
fn table_wall_fix_lines(
    scene: &Scene,
    h: &HertzSettings,
    t: &ContactTables,
    groups: &[WallGroup],
    modulus: WallModulus,
) -> Result<String, DeckError> {
    let mut lines = String::new();
    for w in groups.iter().filter(|w| w.group != "all") {
        let a = w.species.expect("a table wall group names its species");
        let _ = writeln!(lines, "group           {} type {}", w.group, a + 1);
    }
    for wall in &scene.walls {
        let plane = plane_args(scene, wall)?;
        for w in groups {
            let a = w.species.expect("a table wall group names its species");
            let _ = writeln!(
                lines,
                "fix             w_{}{} {} wall/gran granular {} {plane}",
                wall.name,
                w.suffix,
                w.group,
                table_wall_model(scene, h, t, a, wall.material, modulus)?
            );
        }
    }
    Ok(lines)
}
