//! The LAMMPS input for a Hertz scene (`damping = "hertz"`, `tangential = "history"`,
//! `rolling = "none" | "epsd2"`), written from the scene alone, for small collision cases.
//!
//! The mapping onto `pair_style granular` is derived in `reference/MAPPING.md`:
//! `hertz/material E q nu damping tsuji` with `q = P^-1(sqrt(5) |beta(e)|)` ([`tsuji_q`]),
//! `tangential mindlin NULL x mu` with `x = sqrt(4 G_eff / Y_eff)` ([`tangential_damping_ratio`]),
//! and for epsd2 `rolling sds k_roll 0 mu_r` with a *constant* `k_roll` (LAMMPS has no
//! overlap-dependent rolling stiffness): `k_roll = 8 G_eff sqrt(R_eff delta_max)`, the
//! Hertz tangential stiffness at the largest overlap of an undamped impact at the scene's
//! `characteristic_velocity`. Walls are axis-aligned planes, `fix wall/gran granular` with
//! the same sub-models (`zplane lo NULL` for a floor), their E and Mindlin stiffness chosen
//! to give the particle-wall `Y_eff`, `G_eff` (see the wall lines below: the wall fix of this
//! LAMMPS does not use `1 - nu^2`).
//!
//! Stages, wall removal (`unfix w_NAME`) and repose samples are written by `deck::stage_lines`,
//! as for the seed's deck, so the run goes through the same post-processing.

use std::fmt::Write as _;

use super::deck::{
    boundary_line, data_file, frozen_lines, g, kinetic_energy_lines, stage_lines, Deck, DeckError,
    DeckPlan, StageDumps, DATA_FILE, TRAJECTORY_FILE,
};
use crate::contact::damping::restitution_beta;
use crate::contact::normal::{Hertz, Material};
use crate::math::Real;
use crate::particles::Particles;
use crate::scene::{
    CohesionKind, ContactSettings, HertzDampingKind, HertzSettings, RollingKind, Scene,
    TangentialKind, WallSettings,
};

/// Dump columns of the Hertz decks (LAMMPS and LIGGGHTS): with spins.
pub(crate) const HERTZ_COLUMNS: &str = "id type x y z vx vy vz omegax omegay omegaz radius";

/// LAMMPS's Tsuji polynomial `P(q)`: `damping tsuji q` gives `gamma_n = P(q) sqrt(m_eff k_n)`.
pub fn tsuji_polynomial(q: Real) -> Real {
    let c = [1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218];
    c.iter().rev().fold(0.0, |acc, &a| acc * q + a)
}

/// The `damping tsuji` number that reproduces LIGGGHTS's `model hertz` dashpot for
/// restitution `e`: `P(q) = sqrt(5) |beta(e)|` (P decreases on [0, 1]); None below e ~ 0.114,
/// where `sqrt(5) |beta| > P(0)`, and near e = 1, where it is below `P(1)`.
pub fn tsuji_q(restitution: Real) -> Option<Real> {
    let target = 5.0_f64.sqrt() * restitution_beta(restitution).abs();
    if target > tsuji_polynomial(0.0) || target < tsuji_polynomial(1.0) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if tsuji_polynomial(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// `gamma_t / gamma_n` of LIGGGHTS `model hertz` = `sqrt(S_t / S_n) = sqrt(4 G_eff / Y_eff)`,
/// the `x` of LAMMPS `tangential mindlin NULL x mu`.
pub fn tangential_damping_ratio(y_eff: Real, g_eff: Real) -> Real {
    (4.0 * g_eff / y_eff).sqrt()
}

/// The Hertz settings a reference deck can express, or why not.
/// `meshes`: the code takes the scene's bodies as meshes and its `[[delete]]` boxes (LIGGGHTS).
pub(crate) fn hertz_settings<'a>(
    scene: &'a Scene,
    code: &str,
    meshes: bool,
) -> Result<&'a HertzSettings, DeckError> {
    let unsupported = |reason: String| DeckError::Unsupported {
        file: scene.source.display().to_string(),
        reason,
    };
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
    if !meshes && (!scene.bodies.is_empty() || !scene.deletions.is_empty()) {
        return Err(unsupported(format!(
            "{code} Hertz decks take planar walls only (no [[body]], no [[delete]]): LAMMPS has no mesh walls, and the deck with a particle-built screw is not written yet"
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

/// `k_roll` for LAMMPS `rolling sds`: the Hertz tangential stiffness `8 G_eff sqrt(R delta)` at
/// the largest overlap of an undamped impact at `v`.
pub fn rolling_stiffness(y_eff: Real, g_eff: Real, r_eff: Real, m_eff: Real, v: Real) -> Real {
    let delta = Hertz::max_overlap(y_eff, r_eff, m_eff, v);
    8.0 * g_eff * (r_eff * delta).sqrt()
}

/// The deck for a Hertz `scene` starting from `particles`, stepping `dt`, one frame every
/// time-series interval (id type x y z vx vy vz omegax omegay omegaz radius).
pub fn write_hertz_deck(scene: &Scene, particles: &Particles, dt: Real) -> Result<Deck, DeckError> {
    let h = hertz_settings(scene, "LAMMPS", false)?;
    let unsupported = |reason: String| DeckError::Unsupported {
        file: scene.source.display().to_string(),
        reason,
    };
    let q_of = |e: Real| {
        tsuji_q(e).ok_or_else(|| {
            unsupported(if e < 0.5 {
                format!("restitution {e}: damping tsuji cannot reach LIGGGHTS's dashpot below e ~ 0.114")
            } else {
                format!("restitution {e}: damping tsuji cannot damp as little as LIGGGHTS's dashpot does (its least damping, q = 1, is more)")
            })
        })
    };
    let m = material(h);
    let (y_eff, g_eff) = (Material::y_eff(m, m), Material::g_eff(m, m));
    let x_t = tangential_damping_ratio(y_eff, g_eff);
    let dump_every = ((scene.output.timeseries_interval / dt).round() as u64).max(1);
    // Rolling stiffness at the scene's characteristic speed, for the first species pair.
    let s0 = &scene.species[0];
    let rolling = |y: Real, gg: Real, r: Real, mass: Real| match h.rolling {
        RollingKind::Epsd2 => format!(
            " rolling sds {} 0.0 {}",
            g(rolling_stiffness(y, gg, r, mass, h.characteristic_velocity)),
            g(h.rolling_friction)
        ),
        _ => String::new(),
    };

    let diameters: Vec<Real> = scene.species.iter().map(|s| s.diameter).collect();
    let densities: Vec<Real> = scene.species.iter().map(|s| s.density).collect();
    let data = data_file(
        scene,
        particles,
        &diameters,
        &densities,
        scene.species.len(),
    );

    let mut d = String::new();
    let _ = writeln!(
        d,
        "# LAMMPS input written by cgdem {} from {} (scene `{}`): Hertz, reference/MAPPING.md.",
        env!("CARGO_PKG_VERSION"),
        scene.source.display(),
        scene.name
    );
    d += "units           si\natom_style      sphere\natom_modify     map array\n";
    d += &boundary_line(scene);
    d += "newton          off\ncomm_modify     vel yes\n";
    let _ = writeln!(d, "read_data       {DATA_FILE}");
    d += "pair_style      granular\n";
    let _ = writeln!(
        d,
        "# q = P^-1(sqrt(5)|beta(e)|) for e = {}; x = sqrt(4 G*/Y*)",
        h.restitution
    );
    let _ = writeln!(
        d,
        "pair_coeff      * * hertz/material {} {} {} damping tsuji tangential mindlin NULL {} {}{}",
        g(m.youngs_modulus),
        g(q_of(h.restitution)?),
        g(m.poisson_ratio),
        g(x_t),
        g(h.friction),
        rolling(y_eff, g_eff, s0.radius() * 0.5, s0.mass() * 0.5)
    );
    let _ = writeln!(
        d,
        "neighbor        {} bin",
        g(scene.skin_fraction * scene.max_diameter())
    );
    d += "neigh_modify    every 1 delay 0 check yes\n";
    let (integrated, freeze) = frozen_lines(scene);
    d += &freeze;
    let _ = writeln!(d, "fix             integ {integrated} nve/sphere");
    if scene.gravity.length() > 0.0 {
        let dir = scene.gravity / scene.gravity.length();
        let _ = writeln!(
            d,
            "fix             grav all gravity {} vector {} {} {}",
            g(scene.gravity.length()),
            g(dir.x),
            g(dir.y),
            g(dir.z)
        );
    }
    let _ = writeln!(d, "timestep        {}", g(dt));
    if !scene.walls.is_empty() {
        // Particle-wall pair values, passed so that this LAMMPS computes them exactly: its
        // fix wall/gran hertz/material takes k_n = (4/3) E/(2(1 - nu)) sqrt(R delta) (measured:
        // contact 10% short with E itself, (1 + nu)^(-2/5)), so E is given as 2 (1 - nu) Y_eff;
        // the Mindlin stiffness is given explicitly (8 G_eff) rather than NULL.
        let wm = wall_material(scene, h);
        let (y_w, g_w) = (Material::y_eff(m, wm), Material::g_eff(m, wm));
        let e_lammps = 2.0 * (1.0 - m.poisson_ratio) * y_w;
        let w = &scene.wall_contact;
        // The wall acts as a particle of infinite radius and mass: R_eff = r, m_eff = m.
        let roll = if h.rolling == RollingKind::Epsd2 {
            format!(
                " rolling sds {} 0.0 {}",
                g(rolling_stiffness(
                    y_w,
                    g_w,
                    s0.radius(),
                    s0.mass(),
                    h.characteristic_velocity
                )),
                g(w.rolling_friction)
            )
        } else {
            String::new()
        };
        for wall in &scene.walls {
            let (axis, up) = wall_axis(scene, wall)?;
            let at = g([wall.point.x, wall.point.y, wall.point.z][axis]);
            let (lo, hi) = if up {
                (at, "NULL".to_string())
            } else {
                ("NULL".to_string(), at)
            };
            let _ = writeln!(
                d,
                "fix             w_{} all wall/gran granular hertz/material {} {} {} damping tsuji tangential mindlin {} {} {}{} {}plane {lo} {hi}",
                wall.name,
                g(e_lammps),
                g(q_of(w.restitution)?),
                g(m.poisson_ratio),
                g(8.0 * g_w),
                g(tangential_damping_ratio(y_w, g_w)),
                g(w.friction),
                roll,
                ["x", "y", "z"][axis]
            );
        }
        d += &super::deck::removal_pads(scene, 1);
    }
    d += &kinetic_energy_lines(dump_every, true);
    let _ = writeln!(
        d,
        "dump            traj all custom {dump_every} {TRAJECTORY_FILE} {HERTZ_COLUMNS}"
    );
    d += "dump_modify     traj format float %.17g sort id\n";
    let dumps = StageDumps {
        columns: HERTZ_COLUMNS,
        modify: "format float %.17g sort id",
    };
    let repose_dumps = stage_lines(
        &mut d,
        scene,
        dt,
        dump_every,
        &dumps,
        |name| format!("unfix           w_{name}\n"),
        |_| String::new(),
    );
    let mut notes = Vec::new();
    if h.rolling == RollingKind::Epsd2 {
        notes.push(format!("LAMMPS rolling sds has a constant stiffness (that of the Hertz tangential spring at the largest overlap of a {} m/s impact), LIGGGHTS/cgdem epsd2 the current k_t R*^2 (reference/MAPPING.md)", h.characteristic_velocity));
    }
    notes.push("LAMMPS tangential mindlin is not LIGGGHTS tangential history: full radii in the contact-point velocity, spring + dashpot capped at the Coulomb limit (reference/MAPPING.md)".into());
    Ok(Deck {
        input: d,
        data,
        files: Vec::new(),
        plan: DeckPlan {
            code: "lammps",
            log_file: super::runner::LOG_FILE,
            notes,
            dt,
            dump_every,
            repose_dumps,
        },
    })
}

/// The deck of `validation/cases/aor_hertz.toml` with one particle, for the deck tests of
/// both codes.
#[cfg(test)]
pub(crate) fn collapse_scene_and_particle() -> (Scene, Particles) {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/cases/aor_hertz.toml");
    let scene = Scene::load(&path).unwrap();
    let mut particles = Particles::new(true);
    let s = &scene.species[0];
    particles.push(
        0,
        crate::math::Vec3::new(0.05, 0.025, 0.1),
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

    #[test]
    fn collapse_deck_settles_then_unfixes_the_gate_then_samples_the_collapse() {
        let (scene, particles) = collapse_scene_and_particle();
        let deck = write_hertz_deck(&scene, &particles, 5e-5).unwrap();
        let d = &deck.input;
        assert_eq!(deck.plan.code, "lammps");
        assert_eq!(deck.plan.dump_every, 200);
        for wall in ["floor", "back", "gate", "end"] {
            at(
                d,
                &format!("fix             w_{wall} all wall/gran granular hertz/material"),
            );
        }
        at(d, "xplane NULL 1.00000000000000006e-1");
        // One zero-force pad after the last wall fix, for the one wall unfixed.
        assert!(
            at(d, "fix             w_end")
                < at(d, "fix             pad_0 all addforce 0.0 0.0 0.0")
        );
        assert!(!d.contains("pad_1"));
        // Kinetic energy with the spins, as cgdem counts it.
        at(d, "variable        kepm equal (c_ke+c_rke)/mass(all)");
        // Settle: chunks of 0.01 s, at least 0.4 s (40), at most 2 s (200).
        let settle = at(d, "variable        chunk0 loop 200");
        at(d, &format!("${{chunk0}} >= 40 && ${{kepm}} < {}", g(1e-5)));
        let settle_end = at(d, "label           end_stage0");
        // The gate goes between the stages, and only the gate.
        let unfix = at(d, "unfix           w_gate");
        assert!(!d.contains("unfix           w_floor"));
        let collapse = at(d, "CGDEM_STAGE collapse start");
        assert!(settle < settle_end && settle_end < unfix && unfix < collapse);
        // Collapse: at least 1 s, at most 3 s, samples at chunks 25, 50, 100 with spins.
        at(d, "variable        chunk1 loop 300");
        at(d, &format!("${{chunk1}} >= 100 && ${{kepm}} < {}", g(1e-5)));
        let sample = at(d, "if              \"${chunk1} == 25\" then \"write_dump all custom repose_0.dump id type x y z vx vy vz omegax omegay omegaz radius modify format float %.17g sort id\"");
        assert!(collapse < sample);
        let times: Vec<Real> = deck.plan.repose_dumps.iter().map(|r| r.1).collect();
        assert_eq!(times, [0.25, 0.5, 1.0]);
        assert!(deck.plan.notes.iter().any(|n| n.contains("rolling sds")));
    }

    #[test]
    fn tsuji_q_matches_the_mapping_table() {
        // reference/MAPPING.md, from hertz_mapping.py.
        for (e, q) in [
            (0.3, 0.158329946363),
            (0.5, 0.366651361569),
            (0.9, 0.862122151068),
        ] {
            assert!((tsuji_q(e).unwrap() - q).abs() < 1e-11, "e = {e}");
        }
        assert!(tsuji_q(0.1).is_none());
    }

    #[test]
    fn tangential_ratio_is_0_907_for_nu_0_3() {
        let m = Material {
            youngs_modulus: 5e6,
            poisson_ratio: 0.3,
        };
        let x = tangential_damping_ratio(Material::y_eff(m, m), Material::g_eff(m, m));
        assert!((x - 0.907485212973).abs() < 1e-11);
    }
}
