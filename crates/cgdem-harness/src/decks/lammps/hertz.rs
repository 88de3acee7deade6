//! The LAMMPS input for a Hertz scene (`damping = "hertz"`, `tangential = "history"`,
//! `rolling = "none" | "epsd2"`), written from the scene alone, for small collision cases.
//!
//! The mapping onto `pair_style granular` is derived in `reference/MAPPING.md`:
//! `hertz/material E q nu damping tsuji` with `q = P^-1(sqrt(5) |beta(e)|)` ([`super::coefficients::tsuji_q`]),
//! `tangential mindlin NULL x mu` with `x = sqrt(4 G_eff / Y_eff)` ([`super::coefficients::tangential_damping_ratio`]),
//! and for epsd2 `rolling sds k_roll 0 mu_r` with a *constant* `k_roll` (LAMMPS has no
//! overlap-dependent rolling stiffness): `k_roll = 8 G_eff sqrt(R_eff delta_max)`, the
//! Hertz tangential stiffness at the largest overlap of an undamped impact at the scene's
//! `characteristic_velocity`. Walls are axis-aligned planes, `fix wall/gran granular` with
//! the same sub-models (`zplane lo NULL` for a floor), their E and Mindlin stiffness chosen
//! to give the particle-wall `Y_eff`, `G_eff` (see the wall lines below: the wall fix of this
//! LAMMPS does not use `1 - nu^2`).
//!
//! A scene with material tables (`scene::ContactTables`) gets one `pair_coeff I J` per species
//! pair ([`super::tables`]) and, `fix wall/gran` having one model, one wall fix per wall
//! and mobile species; scenes with one material keep the one `pair_coeff * *`.
//!
//! Stages, wall removal (`unfix w_NAME`) and repose samples are written by `decks::stages`,
//! as for the seed's deck and LIGGGHTS's, so the run goes through the same post-processing.

use std::fmt::Write as _;

use super::bodies::{body_lines, BodyLines};
use super::coefficients::{rolling_stiffness, tangential_damping_ratio, tsuji_q_of};
use super::tables::{table_pair_lines, table_wall_model, wall_fixes, WallGroup};
use super::{plane_args, removal_pads, WallModulus, DIALECT};
use crate::decks::hertz::{hertz_settings, material, wall_material, HERTZ_COLUMNS};
use crate::decks::lines::{
    block_region, data_file, frozen_lines, g, neighbor_lines, preamble, unfix_wall, written_by,
};
use crate::decks::stages::{
    run_without_setup, stage_lines, trajectory_lines, Periodic, StageHooks,
};
use crate::decks::{Deck, DeckError, DeckPlan};
use cgdem_core::contact::normal::Material;
use cgdem_core::math::Real;
use cgdem_core::particles::Particles;
use cgdem_core::scene::{ContactTables, HertzSettings, RollingKind, Scene};
use cgdem_core::simulation::DELETE_EVERY;

/// The deck for a Hertz `scene` starting from `particles`, stepping `dt`, one frame every
/// time-series interval (id type x y z vx vy vz omegax omegay omegaz radius), for the
/// LAMMPS release the decks were verified against (29 Sep 2021).
pub fn write_hertz_deck(scene: &Scene, particles: &Particles, dt: Real) -> Result<Deck, DeckError> {
    write_hertz_deck_for(scene, particles, dt, WallModulus::BeforeRework)
}

/// [`write_hertz_deck`] for a LAMMPS that reads the walls' modulus as `modulus` says.
pub fn write_hertz_deck_for(
    scene: &Scene,
    particles: &Particles,
    dt: Real,
    modulus: WallModulus,
) -> Result<Deck, DeckError> {
    let h = hertz_settings(scene, "LAMMPS", true)?;
    let unsupported = |reason: String| DeckError::unsupported(scene, reason);
    // A scene with material tables: one `pair_coeff I J` per species pair and one wall fix
    // per wall and mobile species (`super::tables`); without, the one material of `[contact]`.
    let tables = if scene.gives_material_tables() {
        if scene.bodies.iter().any(|b| b.particles.is_some()) {
            return Err(unsupported("LAMMPS decks with bodies built of particles take the one material and coefficients of [contact] and [wall_contact]: this scene has materials per species or pair (LIGGGHTS decks take them)".into()));
        }
        Some(ContactTables::of_hertz(scene, h))
    } else {
        None
    };
    let m = material(h);
    let dump_every = ((scene.output.timeseries_interval / dt).round() as u64).max(1);

    let data = species_data(scene, particles);

    let mut files = Vec::new();
    let mut d = written_by(&DIALECT, scene);
    d += "): Hertz, reference/MAPPING.md.\n";
    d += &preamble(&DIALECT, scene);
    d += &match &tables {
        Some(t) => table_pair_lines(scene, h, t)?,
        None => pair_lines(scene, h, m)?,
    };
    d += &neighbor_lines(&DIALECT, scene);
    let (integrated, freeze) = frozen_lines(scene);
    d += &freeze;
    d += &integration_lines(scene, integrated, dt);
    let wall_model = wall_model(scene, h, m, modulus)?;
    let (wall_lines, wall_groups) = match &tables {
        Some(t) => wall_fixes(scene, h, t, modulus)?,
        None => (wall_fix_lines(scene, &wall_model)?, vec![WallGroup::all()]),
    };
    d += &wall_lines;
    let walls = RegionWalls {
        tables: tables.as_ref().map(|t| (h, t, modulus)),
        groups: &wall_groups,
        integrated,
        wall_model: &wall_model,
    };
    let bodies = body_lines(scene, dt, &|region, k| walls.fixes(scene, region, k))?;
    d += &bodies.setup;
    let later_setups = later_setups(scene, &bodies)?;
    for (start, motion) in &bodies.motions {
        if start.is_none() {
            d += motion;
        }
    }
    d += &removal_pads(scene, wall_groups.len());
    d += &deletion_lines(scene, integrated);
    let top_ups = top_up_lines(scene, integrated, dt, &mut files);
    d += &top_ups.setup;
    let dumps = trajectory_lines(
        &mut d,
        dump_every,
        true,
        HERTZ_COLUMNS,
        "format float %.17g sort id",
    );
    let begin = |stage: &str| {
        let mut lines = String::new();
        for (start, motion) in &bodies.motions {
            if start.as_deref() == Some(stage) {
                lines += motion;
            }
        }
        lines += &top_ups.begin(stage);
        if !lines.is_empty() {
            lines += &bodies.refix_walls;
            lines += "run             0 post no\n";
        }
        let turns = bodies.turns.iter().filter(|(start, _)| start == stage);
        turns.map(|(_, l)| l.as_str()).collect::<String>() + &lines
    };
    let periodic = |stage: &str| top_ups.periodic(stage, &bodies.refix_walls);
    let repose_dumps = stage_lines(
        &mut d,
        scene,
        dt,
        dump_every,
        &dumps,
        &StageHooks {
            unfix: &|name: &str| {
                let fixes = wall_groups.iter().map(|w| format!("{name}{}", w.suffix));
                fixes.map(|f| unfix_wall(&f)).collect::<String>()
            },
            begin: &begin,
            periodic: &periodic,
            run: &run_without_setup,
        },
    );
    let mut notes = bodies.notes;
    if !bodies.refix_walls.is_empty() && later_setups {
        notes.push("LAMMPS: the body region's wall fix is defined anew at each setup (when the screw starts, at each top-up), so grains sliding on the casing lose their tangential history then".into());
    }
    notes.extend(model_notes(h));
    Ok(Deck {
        input: d,
        data,
        files,
        plan: DeckPlan {
            code: DIALECT.code.name(),
            log_file: DIALECT.log_file,
            notes,
            dt,
            dump_every,
            repose_dumps,
        },
    })
}

/// Whether the deck sets up again after its first run: later setups (`run 0` after a
/// particle body starts turning or a top-up) re-apply LAMMPS's Tsuji polynomial to its wall
/// fixes' coefficient; the body region's fix is defined anew before each, planar walls
/// cannot be (refused). A turning region needs none.
fn later_setups(scene: &Scene, bodies: &BodyLines) -> Result<bool, DeckError> {
    let later = bodies.motions.iter().any(|(start, _)| start.is_some())
        || scene.insertions.iter().any(|i| i.refill.is_some());
    if later && !scene.walls.is_empty() {
        return Err(DeckError::unsupported(scene, "planar walls with a top-up or a body that starts later: LAMMPS would re-apply its Tsuji polynomial to the walls' damping at each setup (reference/HERTZ_COLLAPSE.md)".into()));
    }
    Ok(later)
}

/// What a region body's wall fixes are made of: the deck's one wall model on the mobile
/// atoms (`integrated`), or with material tables one fix per wall group.
struct RegionWalls<'a> {
    tables: Option<(&'a HertzSettings, &'a ContactTables, WallModulus)>,
    groups: &'a [WallGroup],
    integrated: &'a str,
    wall_model: &'a str,
}

impl RegionWalls<'_> {
    /// The `fix wall/gran/region` lines of `region`, with material tables each species
    /// against the body's wall material `k`.
    fn fixes(&self, scene: &Scene, region: &str, k: usize) -> Result<String, DeckError> {
        let mut lines = String::new();
        for w in self.groups {
            let (group, model) = match (self.tables, w.species) {
                (Some((h, t, modulus)), Some(a)) => (
                    w.group.as_str(),
                    table_wall_model(scene, h, t, a, k, modulus)?,
                ),
                _ => ("all", self.wall_model.to_string()),
            };
            let group = if group == "all" {
                self.integrated
            } else {
                group
            };
            let _ = writeln!(
                lines,
                "fix             w_{region}{} {group} wall/gran/region granular {model} region {region}",
                w.suffix
            );
        }
        Ok(lines)
    }
}

/// The data file: one atom type per species, with its diameter and density.
fn species_data(scene: &Scene, particles: &Particles) -> String {
    let diameters: Vec<Real> = scene.species.iter().map(|s| s.diameter).collect();
    let densities: Vec<Real> = scene.species.iter().map(|s| s.density).collect();
    data_file(
        scene,
        particles,
        &diameters,
        &densities,
        scene.species.len(),
    )
}

/// `pair_style granular` with the particle-particle `pair_coeff` (Hertz, Tsuji damping,
/// Mindlin, and `rolling sds` for epsd2 at the scene's characteristic speed, first species).
fn pair_lines(scene: &Scene, h: &HertzSettings, m: Material) -> Result<String, DeckError> {
    let (y_eff, g_eff) = (Material::y_eff(m, m), Material::g_eff(m, m));
    let s0 = &scene.species[0];
    let rolling = match h.rolling {
        RollingKind::Epsd2 => format!(
            " rolling sds {} 0.0 {}",
            g(rolling_stiffness(
                y_eff,
                g_eff,
                s0.radius() * 0.5,
                s0.mass() * 0.5,
                h.characteristic_velocity
            )),
            g(h.rolling_friction)
        ),
        _ => String::new(),
    };
    let mut d = String::from("pair_style      granular\n");
    let _ = writeln!(
        d,
        "# q = P^-1(sqrt(5)|beta(e)|) for e = {}; x = sqrt(4 G*/Y*)",
        h.restitution
    );
    let _ = writeln!(
        d,
        "pair_coeff      * * hertz/material {} {} {} damping tsuji tangential mindlin NULL {} {}{}",
        g(m.youngs_modulus),
        g(tsuji_q_of(scene, h.restitution)?),
        g(m.poisson_ratio),
        g(tangential_damping_ratio(y_eff, g_eff)),
        g(h.friction),
        rolling
    );
    Ok(d)
}

/// Time integration of the `integrated` group, gravity and the time step.
fn integration_lines(scene: &Scene, integrated: &str, dt: Real) -> String {
    let mut d = String::new();
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
    d
}

/// The particle-wall model of `fix wall/gran granular` (planar walls and body regions),
/// empty for a scene with neither.
fn wall_model(
    scene: &Scene,
    h: &HertzSettings,
    m: Material,
    modulus: WallModulus,
) -> Result<String, DeckError> {
    let s0 = &scene.species[0];
    // Particle-wall pair values, passed so that LAMMPS computes them exactly: E such that
    // its wall stiffness is (4/3) Y_eff sqrt(R delta) ([`WallModulus`]); the Mindlin
    // stiffness explicitly (8 G_eff) rather than NULL.
    let wm = wall_material(scene, h);
    let (y_w, g_w) = (Material::y_eff(m, wm), Material::g_eff(m, wm));
    let w = &scene.wall_contact;
    // The wall acts as a particle of infinite radius and mass: R_eff = r, m_eff = m.
    let wall_rolling = if h.rolling == RollingKind::Epsd2 {
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
    if scene.walls.is_empty() && scene.bodies.is_empty() {
        return Ok(String::new());
    }
    Ok(format!(
        "hertz/material {} {} {} damping tsuji tangential mindlin {} {} {}{wall_rolling}",
        g(modulus.modulus(y_w, m.poisson_ratio)),
        g(tsuji_q_of(scene, w.restitution)?),
        g(m.poisson_ratio),
        g(8.0 * g_w),
        g(tangential_damping_ratio(y_w, g_w)),
        g(w.friction),
    ))
}

/// One `fix wall/gran` per planar wall, with the particle-wall `model`.
fn wall_fix_lines(scene: &Scene, wall_model: &str) -> Result<String, DeckError> {
    let mut lines = String::new();
    for wall in &scene.walls {
        let _ = writeln!(
            lines,
            "fix             w_{} all wall/gran granular {wall_model} {}",
            wall.name,
            plane_args(scene, wall)?
        );
    }
    Ok(lines)
}

/// `[[delete]]` boxes: grains whose centres enter one are removed, checked every
/// [`DELETE_EVERY`] steps as in cgdem.
fn deletion_lines(scene: &Scene, integrated: &str) -> String {
    let mut d = String::new();
    for (k, (lo, hi)) in scene.deletions.iter().enumerate() {
        d += &block_region(&format!("delete_{k}"), *lo, *hi);
        let _ = writeln!(
            d,
            "fix             delete_{k} {integrated} evaporate {DELETE_EVERY} 1000000 delete_{k} {}",
            DEPOSIT_SEEDS[k % DEPOSIT_SEEDS.len()]
        );
    }
    d
}

/// Where this LAMMPS deck's model differs from cgdem's and LIGGGHTS's.
fn model_notes(h: &HertzSettings) -> Vec<String> {
    let mut notes = Vec::new();
    if h.rolling == RollingKind::Epsd2 {
        notes.push(format!("LAMMPS rolling sds has a constant stiffness (that of the Hertz tangential spring at the largest overlap of a {} m/s impact), LIGGGHTS/cgdem epsd2 the current k_t R*^2 (reference/MAPPING.md)", h.characteristic_velocity));
    }
    notes.push("LAMMPS tangential mindlin is not LIGGGHTS tangential history: full radii in the contact-point velocity, spring + dashpot capped at the Coulomb limit (reference/MAPPING.md)".into());
    notes
}

/// Seeds of LAMMPS's random deletions and top-ups (primes; any positive integer will do).
const DEPOSIT_SEEDS: [u64; 4] = [1000003, 2000003, 3000017, 4000037];

/// The top-ups of a LAMMPS deck (`[[insert]] refill`): as cgdem, every `interval` of the
/// refill stage the insertion box is filled back to the count it held when the stage began.
/// LAMMPS's `create_atoms random` has no overlap check here, so each top-up is a `fix deposit`
/// of the missing count (one atom per step, none closer to another than the two radii),
/// whose one-atom molecule template carries the species' diameter and mass.
struct TopUps {
    setup: String,
    entries: Vec<TopUp>,
}

struct TopUp {
    insertion: usize,
    stage: String,
    every: u64,
    near: Real,
    group: String,
}

fn top_up_lines(
    scene: &Scene,
    integrated: &str,
    dt: Real,
    files: &mut Vec<(String, Vec<u8>)>,
) -> TopUps {
    let mut out = TopUps {
        setup: String::new(),
        entries: Vec::new(),
    };
    let max_radius = 0.5 * scene.max_diameter();
    for (k, ins) in scene.insertions.iter().enumerate() {
        let Some(refill) = &ins.refill else { continue };
        let species = &scene.species[ins.species];
        out.setup += &block_region(&format!("top_{k}"), ins.lo, ins.hi);
        let file = format!("top_{k}.mol");
        let _ = writeln!(out.setup, "molecule        top_{k} {file}");
        let template = format!(
            "# one {} grain (written by cgdem)\n\n1 atoms\n\nCoords\n\n1 0.0 0.0 0.0\n\nTypes\n\n1 {}\n\nDiameters\n\n1 {}\n\nMasses\n\n1 {}\n",
            species.name,
            ins.species + 1,
            g(species.diameter),
            g(species.mass())
        );
        files.push((file, template.into_bytes()));
        out.entries.push(TopUp {
            insertion: k,
            stage: refill.stage.clone(),
            every: ((refill.interval / dt).round() as u64).max(1),
            near: species.radius() + max_radius,
            group: integrated.to_string(),
        });
    }
    out
}

impl TopUps {
    /// At the start of `stage`: the count each of its top-ups keeps.
    fn begin(&self, stage: &str) -> String {
        let mut d = String::new();
        for t in self.entries.iter().filter(|t| t.stage == stage) {
            let k = t.insertion;
            let _ = writeln!(
                d,
                "variable        top_target_{k} equal $(count(all,top_{k}))"
            );
        }
        d
    }

    /// Every top-up interval of `stage`: deposit what each box lacks, define the walls anew
    /// (`refix_walls`) and set up. Top-ups of one stage share the first one's interval.
    fn periodic(&self, stage: &str, refix_walls: &str) -> Option<Periodic> {
        let entries: Vec<(usize, Real, String)> = self
            .entries
            .iter()
            .filter(|t| t.stage == stage)
            .map(|t| (t.insertion, t.near, t.group.clone()))
            .collect();
        let every = self.entries.iter().find(|t| t.stage == stage)?.every;
        let refix_walls = refix_walls.to_string();
        Some(Periodic {
            every,
            lines: Box::new(move |n| {
                let mut d = String::new();
                for (k, near, group) in &entries {
                    let add = format!("top_add_{k}_{n}");
                    let _ = writeln!(
                        d,
                        "variable        {add} equal $((v_top_target_{k}-count(all,top_{k}))*(v_top_target_{k}>count(all,top_{k})))"
                    );
                    let seed = DEPOSIT_SEEDS[k % DEPOSIT_SEEDS.len()] + 7919 * n as u64;
                    let _ = writeln!(
                        d,
                        "if              \"${{{add}}} > 0\" then \"fix {add} {group} deposit ${{{add}}} 0 1 {seed} region top_{k} near {} attempt 200 mol top_{k} id max\"",
                        g(*near)
                    );
                }
                d += &refix_walls;
                d += "run             0 post no\n";
                d
            }),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decks::hertz::{at, collapse_scene_and_particle};
    use crate::decks::lammps::coefficients::tsuji_q;
    use crate::decks::lammps::tables::one_material;

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
    fn screw_deck_turns_the_particle_screw_from_the_conveying_stage_inside_the_casing_region() {
        crate::at_repo_root();
        let scene = Scene::load(std::path::Path::new(
            "validation/cases/screw_feeder_hertz_particles.toml",
        ))
        .unwrap();
        let particles = cgdem_core::run::initial_particles_clear_of_bodies(&scene).unwrap();
        let screw_atoms = (0..particles.len())
            .filter(|&k| particles.species[k] == 1)
            .count();
        assert!(screw_atoms > 1000, "{screw_atoms}");
        let deck = write_hertz_deck(&scene, &particles, 6e-5).unwrap();
        let d = &deck.input;
        // The screw's atoms: frozen (effective mass the grain's), grouped, their pairs excluded.
        at(d, "fix             freeze frozen freeze");
        at(d, "neigh_modify    exclude type 2 2");
        at(d, "group           body_screw type 2");
        assert_eq!(
            deck.data
                .lines()
                .filter(|l| l.split_whitespace().nth(1) == Some("2")
                    && l.split_whitespace().count() == 7)
                .count(),
            screw_atoms
        );
        // Casing and hopper: one union region, felt by the mobile grains.
        let walls = at(
            d,
            "fix             w_casing_hopper mobile wall/gran/region granular hertz/material",
        );
        at(d, "region          casing_hopper union 5");
        // rpm -100 about +x: counter-clockwise about -x, 0.6 s per turn, from `convey` on,
        // with the wall fix defined anew before the setup that starts it.
        let settle_end = at(d, "CGDEM_STAGE settle end");
        let turn = at(d, "fix             move_screw body_screw move rotate 0.00000000000000000e0 0.00000000000000000e0 0.00000000000000000e0 -1.00000000000000000e0 -0.00000000000000000e0 -0.00000000000000000e0 5.99999999999999978e-1");
        let target = at(d, "variable        top_target_0 equal $(count(all,top_0))");
        let refix = at(d, "unfix           w_casing_hopper");
        let convey = at(d, "CGDEM_STAGE convey start");
        assert!(
            walls < settle_end
                && settle_end < turn
                && turn < target
                && target < refix
                && refix < convey
        );
        assert!(d[refix..convey].contains("run             0 post no"));
        // Top-ups every 0.1 s (1667 steps): deposit what the box lacks, refix, set up.
        let first = at(d, "variable        top_add_0_0 equal");
        assert!(first > convey);
        at(d, "fix top_add_0_0 mobile deposit ${top_add_0_0} 0 1 1000003 region top_0 near 2.16000000000000011e-2 attempt 200 mol top_0 id max");
        let runs: Vec<&str> = d[convey..first]
            .lines()
            .filter(|l| l.starts_with("run"))
            .collect();
        assert_eq!(runs, ["run             1667 pre no post no"]);
        // 1.8 s = 30000 steps: 17 top-ups, the last chunk 30000 - 17 * 1667 = 1661 steps.
        assert!(d.contains("top_add_0_16 ") && !d.contains("top_add_0_17 "));
        at(d, "run             1661 pre no post no");
        let template = deck
            .files
            .iter()
            .find(|(name, _)| name == "top_0.mol")
            .unwrap();
        let template = String::from_utf8_lossy(&template.1);
        assert!(
            template.contains("Diameters\n\n1 2.16000000000000011e-2"),
            "{template}"
        );
        // The outlet's deletion box.
        at(d, "region          delete_0 block 4.50000000000000011e-1");
        at(d, "fix             delete_0 mobile evaporate");
    }

    #[test]
    fn planar_walls_are_refused_with_a_top_up() {
        let (mut scene, particles) = collapse_scene_and_particle();
        scene.insertions[0].refill = Some(cgdem_core::scene::Refill {
            interval: 0.1,
            stage: "collapse".into(),
        });
        let e = write_hertz_deck(&scene, &particles, 5e-5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("planar walls with a top-up"), "{e}");
    }

    /// tests/data/tiny_two_material_collapse.toml: bead (type 1) and grit (2); every species
    /// pair its own `pair_coeff` whose one material gives the pair's `Y*` and `G*`; each wall
    /// one fix per species (grains_1, grains_2) with that species' coefficients against the
    /// wall's material (steel floor, default material elsewhere), removed together.
    #[test]
    fn material_tables_give_a_pair_coeff_per_species_pair_and_a_wall_fix_per_species() {
        crate::at_repo_root();
        let scene = Scene::load(std::path::Path::new(
            "tests/data/tiny_two_material_collapse.toml",
        ))
        .unwrap();
        let particles = cgdem_core::run::initial_particles_clear_of_bodies(&scene).unwrap();
        let deck = write_hertz_deck(&scene, &particles, 1e-5).unwrap();
        let d = &deck.input;
        let t = ContactTables::of(&scene).unwrap();
        assert!(!d.contains("pair_coeff      * *"));
        for (a, b, e, mu) in [(0, 0, 0.5, 0.5), (0, 1, 0.4, 0.6), (1, 1, 0.3, 0.7)] {
            let (y, g_eff) = (t.y_eff(a, b), t.g_eff(a, b));
            let (young, nu) = one_material(y, g_eff);
            // The one material reproduces the pair's mixed Y* and G*.
            let m = Material {
                youngs_modulus: young,
                poisson_ratio: nu,
            };
            assert!((Material::y_eff(m, m) / y - 1.0).abs() < 1e-12);
            assert!((Material::g_eff(m, m) / g_eff - 1.0).abs() < 1e-12);
            at(
                d,
                &format!(
                    "pair_coeff      {} {} hertz/material {} {} {} damping tsuji tangential mindlin NULL {} {} rolling sds ",
                    a + 1,
                    b + 1,
                    g(young),
                    g(tsuji_q(e).unwrap()),
                    g(nu),
                    g(tangential_damping_ratio(y, g_eff)),
                    g(mu)
                ),
            );
        }
        // Unlike materials: the pair's own nu is neither species' (0.3, 0.25).
        let (_, nu_12) = one_material(t.y_eff(0, 1), t.g_eff(0, 1));
        assert!(
            (nu_12 - 0.3).abs() > 1e-3 && (nu_12 - 0.25).abs() > 1e-3,
            "{nu_12}"
        );
        at(d, "group           grains_1 type 1\n");
        at(d, "group           grains_2 type 2\n");
        // The grit on the steel floor: e = 0.6, mu = 0.3, E = 2 (1 - nu) Y* with grit's nu.
        let (y, g_eff) = (t.wall_y_eff(1, 1), t.wall_g_eff(1, 1));
        at(
            d,
            &format!(
                "fix             w_floor_2 grains_2 wall/gran granular hertz/material {} {} {} damping tsuji tangential mindlin {} {} {} rolling sds ",
                g(2.0 * (1.0 - 0.25) * y),
                g(tsuji_q(0.6).unwrap()),
                g(0.25),
                g(8.0 * g_eff),
                g(tangential_damping_ratio(y, g_eff)),
                g(0.3)
            ),
        );
        at(d, "fix             w_floor_1 grains_1 wall/gran granular");
        for wall in ["back", "gate", "end"] {
            for k in [1, 2] {
                at(
                    d,
                    &format!("fix             w_{wall}_{k} grains_{k} wall/gran granular"),
                );
            }
        }
        // The gate goes with both its fixes, and two pads follow the wall fixes.
        at(d, "unfix           w_gate_1\nunfix           w_gate_2\n");
        at(d, "fix             pad_1 all addforce 0.0 0.0 0.0");
        assert!(!d.contains("pad_2"));
    }

    /// The planar walls' fixes, with one material and with material tables (their names,
    /// groups and `Xplane lo hi`), as written before the two writers shared the bounds: a
    /// wall facing +x or +z bounds from below (`lo NULL`), one facing -x from above.
    #[test]
    fn planar_wall_fixes_keep_their_planes_with_one_material_and_with_tables() {
        crate::at_repo_root();
        let planes = |d: &str| -> Vec<String> {
            d.lines()
                .filter(|l| l.starts_with("fix ") && l.contains(" wall/gran granular "))
                .map(|l| {
                    let w: Vec<&str> = l.split_whitespace().collect();
                    [&w[1..3], &w[w.len() - 3..]].concat().join(" ")
                })
                .collect()
        };
        let (scene, particles) = collapse_scene_and_particle();
        let uniform = write_hertz_deck(&scene, &particles, 5e-5).unwrap();
        let scene = Scene::load(std::path::Path::new(
            "tests/data/tiny_two_material_collapse.toml",
        ))
        .unwrap();
        let particles = cgdem_core::run::initial_particles_clear_of_bodies(&scene).unwrap();
        let tables = write_hertz_deck(&scene, &particles, 1e-5).unwrap();
        assert_eq!(
            planes(&uniform.input),
            [
                "w_floor all zplane 0.00000000000000000e0 NULL",
                "w_back all xplane 0.00000000000000000e0 NULL",
                "w_gate all xplane NULL 1.00000000000000006e-1",
                "w_end all xplane NULL 5.00000000000000000e-1",
            ]
        );
        assert_eq!(
            planes(&tables.input),
            [
                "w_floor_1 grains_1 zplane 0.00000000000000000e0 NULL",
                "w_floor_2 grains_2 zplane 0.00000000000000000e0 NULL",
                "w_back_1 grains_1 xplane 0.00000000000000000e0 NULL",
                "w_back_2 grains_2 xplane 0.00000000000000000e0 NULL",
                "w_gate_1 grains_1 xplane NULL 4.00000000000000008e-2",
                "w_gate_2 grains_2 xplane NULL 4.00000000000000008e-2",
                "w_end_1 grains_1 xplane NULL 1.49999999999999994e-1",
                "w_end_2 grains_2 xplane NULL 1.49999999999999994e-1",
            ]
        );
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
