//! The LAMMPS input for a scene with `ContactSettings::Wca`, written from the scene alone.
//!
//! The scene must already be coarse-grained (the deck never sees lambda). Every number comes
//! from the scene, the particles and the time step passed in; the lines follow the verified
//! forms in `reference/lammps/SEED_MODEL.md`:
//!
//! - pair: `hybrid/overlay lj/cut rc granular`, `lj/cut` shifted (exactly the WCA), granular
//!   `hooke 0.0 gamma_n damping velocity tangential linear_nohistory (gamma_t/gamma_n) 1e8`;
//!   every atom's diameter is `rc = 2^(1/6) sigma` so the dashpots act exactly while the WCA
//!   does (cgdem's rule), and the mass is set per type from the species (`rho pi d^3 / 6`).
//! - walls: each named plane is a `region plane` with a removable pair of fixes
//!   `wall/region lj126 eps sigma/2 rc/2` (the mirror WCA `Phi(h) = phi(2h)`) and
//!   `wall/gran/region granular hooke 0.0 gamma_w damping velocity tangential
//!   linear_nohistory m/(2 dt gamma_w) mu_w`; a stage's `remove_walls` becomes `unfix`.
//!   Known difference: LAMMPS caps wall friction with the dashpot force only, cgdem with
//!   WCA + dashpot (SEED_MODEL.md claim 11).
//! - integration: `fix nve` (no rotation), which splits velocity Verlet exactly as cgdem does.
//! - stages: a settle stage runs in chunks of one time-series interval and stops at the
//!   first chunk end after `min_duration` with kinetic energy per mass below the threshold;
//!   a duration stage runs its steps, stopping at each repose time for a `write_dump`.
//! - output: `dump custom id type x y z vx vy vz radius` every time-series interval, full
//!   precision; the log marks stage boundaries with `CGDEM_STAGE` lines.

use std::fmt::Write as _;

use super::{removal_pads, DIALECT};
use crate::decks::lines::{data_file, g, neighbor_lines, preamble, written_by};
use crate::decks::stages::{stage_lines, trajectory_lines, StageHooks};
use crate::decks::{Deck, DeckError, DeckPlan};
use cgdem_core::math::{Real, TWO_POW_ONE_SIXTH};
use cgdem_core::particles::Particles;
use cgdem_core::scene::{ContactSettings, Scene, WcaSettings};
use cgdem_core::walls::restitution_damping_ratio;

/// Dump columns of the WCA deck (no rotation).
const WCA_COLUMNS: &str = "id type x y z vx vy vz radius";

/// The deck for `scene` starting from `particles` (positions and velocities), stepping `dt`:
/// the seed's WCA model here, a Hertz scene by `hertz::write_hertz_deck`.
pub fn write_wca_deck(scene: &Scene, particles: &Particles, dt: Real) -> Result<Deck, DeckError> {
    let (wca, masses) = wca_settings(scene, dt)?;
    let rc = TWO_POW_ONE_SIXTH * wca.sigma;
    let wall_mass = masses[0];
    let dump_every = ((scene.output.timeseries_interval / dt).round() as u64).max(1);

    // Data file: cgdem's own particles, so both codes start from the same packing.
    let diameters = vec![rc; scene.species.len()];
    let volume = std::f64::consts::PI / 6.0 * rc.powi(3);
    let densities: Vec<Real> = masses.iter().map(|m| m / volume).collect();
    let data = data_file(
        scene,
        particles,
        &diameters,
        &densities,
        scene.species.len(),
    );

    let mut d = written_by(&DIALECT, scene);
    let _ = writeln!(d, ", lambda = {}).", scene.lambda);
    let _ = writeln!(d, "# Model lines: reference/lammps/SEED_MODEL.md. Do not edit: rewrite with `cgdem reference lammps`.");
    d += &preamble(&DIALECT, scene);
    // Diameter rc for the granular contact range; mass from the species' own diameter.
    for (t, m) in masses.iter().enumerate() {
        let _ = writeln!(
            d,
            "set             type {} mass {}   # {}: rho pi d^3/6, d = {} m",
            t + 1,
            g(*m),
            scene.species[t].name,
            scene.species[t].diameter
        );
    }
    let _ = writeln!(
        d,
        "pair_style      hybrid/overlay lj/cut {} granular",
        g(rc)
    );
    let _ = writeln!(
        d,
        "pair_coeff      * * lj/cut {} {} {}",
        g(wca.epsilon),
        g(wca.sigma),
        g(rc)
    );
    let _ = writeln!(d, "pair_coeff      * * granular hooke 0.0 {} damping velocity tangential linear_nohistory {} 1.0e8", g(wca.gamma_n), g(wca.gamma_t / wca.gamma_n));
    d += "pair_modify     pair lj/cut shift yes\n";
    d += &neighbor_lines(&DIALECT, scene);
    d += "fix             integ all nve\n";
    let gravity = scene.gravity;
    if gravity.length() > 0.0 {
        let dir = gravity / gravity.length();
        let _ = writeln!(
            d,
            "fix             grav all gravity {} vector {} {} {}",
            g(gravity.length()),
            g(dir.x),
            g(dir.y),
            g(dir.z)
        );
    }
    let _ = writeln!(d, "timestep        {}", g(dt));

    if !scene.walls.is_empty() {
        wall_lines(&mut d, scene, &wca, wall_mass, dt);
    }

    let stages = trajectory_lines(
        &mut d,
        dump_every,
        false,
        WCA_COLUMNS,
        "format float %.16g sort id",
    );
    let repose_dumps = stage_lines(
        &mut d,
        scene,
        dt,
        dump_every,
        &stages,
        &StageHooks::walls_only(&|name| {
            format!("unfix           wlj_{name}\nunfix           wgran_{name}\n")
        }),
    );
    Ok(Deck {
        input: d,
        data,
        files: Vec::new(),
        plan: DeckPlan {
            code: DIALECT.code.name(),
            log_file: DIALECT.log_file,
            notes: vec!["LAMMPS caps wall friction with the wall dashpot force only, cgdem with WCA + dashpot (reference/lammps/SEED_MODEL.md claim 11)".into()],
            dt,
            dump_every,
            repose_dumps,
        },
    })
}

/// The scene's WCA settings and its species' masses, or why LAMMPS cannot run the scene
/// as cgdem does.
fn wca_settings(scene: &Scene, dt: Real) -> Result<(WcaSettings, Vec<Real>), DeckError> {
    let unsupported = |reason: String| DeckError::unsupported(scene, reason);
    let ContactSettings::Wca(wca) = scene.contact else {
        return Err(unsupported(
            "not the WCA model of Hirose: Hertz scenes get `hertz::write_hertz_deck`".into(),
        ));
    };
    if wca.gamma_n <= 0.0 {
        return Err(unsupported(
            "gamma_n = 0: LAMMPS sets gamma_t as a multiple of gamma_n".into(),
        ));
    }
    if !dt.is_finite() || dt <= 0.0 {
        return Err(unsupported(format!("time step {dt} s")));
    }
    // A deck without the scene's bodies or outlets would run another case under its name.
    if !scene.bodies.is_empty() || !scene.deletions.is_empty() {
        return Err(unsupported(
            "LAMMPS seed-model decks take planar walls only (no [[body]], no [[delete]])".into(),
        ));
    }
    if scene.insertions.iter().any(|i| i.refill.is_some()) {
        return Err(unsupported(
            "LAMMPS seed-model decks take no top-ups ([[insert]] refill): the region would not be refilled".into(),
        ));
    }
    let masses: Vec<Real> = scene.species.iter().map(|s| s.mass()).collect();
    let wall_mass = masses[0];
    if !scene.walls.is_empty()
        && masses
            .iter()
            .any(|&m| (m - wall_mass).abs() > 1e-12 * wall_mass)
    {
        return Err(unsupported(
            "walls with species of different masses: fix wall/gran takes one gamma_w for all atoms"
                .into(),
        ));
    }
    Ok((wca, masses))
}

/// The walls: each a plane region with a mirror WCA and a dashpot with friction (removable
/// by name), and the removal pads.
fn wall_lines(d: &mut String, scene: &Scene, wca: &WcaSettings, wall_mass: Real, dt: Real) {
    let rc = TWO_POW_ONE_SIXTH * wca.sigma;
    let stiffness = 4.0 * 72.0 * wca.epsilon / (rc * rc);
    let gamma_w = 2.0
        * restitution_damping_ratio(scene.wall_contact.restitution)
        * (stiffness * wall_mass).sqrt();
    let x_t = wall_mass / (2.0 * dt * gamma_w);
    let _ = writeln!(
        d,
        "# walls: mirror WCA + dashpot gamma_w = {} kg/s (restitution {}), friction {}",
        g(gamma_w),
        scene.wall_contact.restitution,
        scene.wall_contact.friction
    );
    for w in &scene.walls {
        let (p, n) = (w.point, w.normal);
        let _ = writeln!(
            d,
            "region          w_{} plane {} {} {} {} {} {} side in units box",
            w.name,
            g(p.x),
            g(p.y),
            g(p.z),
            g(n.x),
            g(n.y),
            g(n.z)
        );
        let _ = writeln!(
            d,
            "fix             wlj_{0} all wall/region w_{0} lj126 {1} {2} {3}",
            w.name,
            g(wca.epsilon),
            g(0.5 * wca.sigma),
            g(0.5 * rc)
        );
        let _ = writeln!(d, "fix             wgran_{0} all wall/gran/region granular hooke 0.0 {1} damping velocity tangential linear_nohistory {2} {3} region w_{0}", w.name, g(gamma_w), g(x_t), g(scene.wall_contact.friction));
    }
    *d += &removal_pads(scene, 2);
}

#[cfg(test)]
mod tests {
    use super::*;
    use cgdem_core::coarse_graining::coarse_grain;

    #[test]
    fn a_seed_model_scene_with_bodies_is_refused_not_run_without_them() {
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("validation/cases/screw_feeder_nightly.toml");
        let scene = Scene::load(&path).unwrap();
        assert!(matches!(scene.contact, ContactSettings::Wca(_)));
        let err = write_wca_deck(&scene, &Particles::new(false), 1e-6).unwrap_err();
        let message = err.to_string();
        assert!(message.contains("[[body]]"), "{message}");
        assert!(message.contains("screw_feeder_nightly.toml"), "{message}");
    }

    #[test]
    fn collapse_deck_has_removable_walls_settle_loop_and_repose_dumps() {
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("validation/cases/aor_collapse.toml");
        let scene = coarse_grain(&Scene::load(&path).unwrap(), 8).unwrap();
        let mut particles = Particles::new(false);
        let s = &scene.species[0];
        particles.push(
            0,
            cgdem_core::math::Vec3::new(0.05, 0.025, 0.1),
            s.radius(),
            s.mass(),
        );
        let dt = 1e-6;
        let deck = write_wca_deck(&scene, &particles, dt).unwrap();
        assert_eq!(deck.plan.dump_every, 10_000);
        let d = &deck.input;
        assert!(d.contains("boundary        f p f"));
        for wall in ["floor", "back", "gate", "end"] {
            assert!(
                d.contains(&format!(
                    "fix             wlj_{wall} all wall/region w_{wall} lj126"
                )),
                "{wall}"
            );
        }
        // The gate goes after the settle loop, before the collapse runs.
        let settle_end = d.find("label           end_stage0").unwrap();
        let unfix = d.find("unfix           wgran_gate").unwrap();
        assert!(settle_end < unfix && unfix < d.find("repose_0.dump").unwrap());
        assert!(!d.contains("unfix           wgran_floor"));
        // Two zero-force pads after the last wall fix, for the two gate fixes unfixed.
        let last_wall = d.find("fix             wgran_end").unwrap();
        assert!(
            last_wall
                < d.find("fix             pad_0 all addforce 0.0 0.0 0.0")
                    .unwrap()
        );
        assert!(d.contains("fix             pad_1 all addforce") && !d.contains("pad_2"));
        // 0.4 s minimum = 40 chunks of 0.01 s, at most 3 s = 300 chunks.
        assert!(d.contains("variable        chunk0 loop 300"));
        assert!(d.contains(&format!("${{chunk0}} >= 40 && ${{kepm}} < {}", g(1e-6))));
        assert_eq!(deck.plan.repose_dumps.len(), 4);
        // The data file carries the particle with diameter rc and the species mass.
        let rc = TWO_POW_ONE_SIXTH * (1.203e-3 * 8.0);
        let density = s.mass() / (std::f64::consts::PI / 6.0 * rc.powi(3));
        assert!(deck.data.contains(&format!("1 1 {} {}", g(rc), g(density))));
    }
}
