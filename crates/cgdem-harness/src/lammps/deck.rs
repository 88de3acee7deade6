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

use crate::code::Code;
use cgdem_core::math::{Real, Vec3, TWO_POW_ONE_SIXTH};
use cgdem_core::particles::Particles;
use cgdem_core::scene::{ContactSettings, Scene, StageEnd};
use cgdem_core::walls::restitution_damping_ratio;

/// File names inside a LAMMPS run directory.
pub const DECK_FILE: &str = "deck.in";
pub const DATA_FILE: &str = "particles.data";
pub const TRAJECTORY_FILE: &str = "traj.dump";
pub const LOG_FILE: &str = "log.lammps";

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DeckError {
    #[error("{file}: cannot write a reference-code deck for this scene: {reason}")]
    Unsupported { file: String, reason: String },
}

impl DeckError {
    /// The scene asks for something the deck cannot express, and why.
    pub fn unsupported(scene: &Scene, reason: String) -> Self {
        DeckError::Unsupported {
            file: scene.source.display().to_string(),
            reason,
        }
    }
}

/// What the deck will do, for post-processing.
#[derive(Clone, Debug, PartialEq)]
pub struct DeckPlan {
    /// The code the deck is for (`lammps` or `liggghts`), as the summary names it.
    pub code: &'static str,
    /// The code's log file in the run directory.
    pub log_file: &'static str,
    /// Known differences of this deck's model from cgdem's, carried into the summary's warnings.
    pub notes: Vec<String>,
    pub dt: Real,
    /// Steps between trajectory frames (one time-series interval).
    pub dump_every: u64,
    /// (stage, time after the stage starts, dump file) of each repose sample.
    pub repose_dumps: Vec<(String, Real, String)>,
}

/// The deck text, the data file text and the plan.
#[derive(Clone, Debug)]
pub struct Deck {
    pub input: String,
    pub data: String,
    pub plan: DeckPlan,
    /// Further files the deck reads (name in the run directory, content): LIGGGHTS's meshes.
    pub files: Vec<(String, Vec<u8>)>,
}

impl Deck {
    /// Writes `deck.in` and `particles.data` into `dir`.
    pub fn write_to(&self, dir: &std::path::Path) -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join(DECK_FILE), &self.input)?;
        for (name, content) in &self.files {
            std::fs::write(dir.join(name), content)?;
        }
        std::fs::write(dir.join(DATA_FILE), &self.data)
    }
}

/// The `boundary` line (LAMMPS and LIGGGHTS alike): `p` on periodic axes, `f` elsewhere.
pub(crate) fn boundary_line(scene: &Scene) -> String {
    let flag = |axis: usize| {
        if scene.domain.periodic[axis] {
            "p"
        } else {
            "f"
        }
    };
    format!("boundary        {} {} {}\n", flag(0), flag(1), flag(2))
}

/// The first words of a deck's header comment: `# LAMMPS input written by cgdem 0.1.0 from
/// case.toml (scene `name``; the caller closes it.
pub(crate) fn written_by(code: Code, scene: &Scene) -> String {
    format!(
        "# {} input written by cgdem {} from {} (scene `{}`",
        code.label(),
        env!("CARGO_PKG_VERSION"),
        scene.source.display(),
        scene.name
    )
}

/// The set-up every deck starts with, after its header: SI units, spheres with a diameter
/// (`sphere` in LAMMPS, `granular` in LIGGGHTS), the boundary, `newton off` with ghost
/// velocities communicated, and the data file.
pub(crate) fn preamble(code: Code, scene: &Scene) -> String {
    let (atom_style, communicate) = match code {
        Code::Liggghts => ("granular", "communicate     single vel yes"),
        _ => ("sphere", "comm_modify     vel yes"),
    };
    let mut d =
        format!("units           si\natom_style      {atom_style}\natom_modify     map array\n");
    d += &boundary_line(scene);
    let _ = writeln!(d, "newton          off\n{communicate}");
    let _ = writeln!(d, "read_data       {DATA_FILE}");
    d
}

/// The neighbour list: a skin of `skin_fraction` largest diameters, rebuilt when needed
/// (LIGGGHTS checks every step by default and takes only the delay).
pub(crate) fn neighbor_lines(code: Code, scene: &Scene) -> String {
    let mut d = format!(
        "neighbor        {} bin\n",
        g(scene.skin_fraction * scene.max_diameter())
    );
    d += match code {
        Code::Liggghts => "neigh_modify    delay 0\n",
        _ => "neigh_modify    every 1 delay 0 check yes\n",
    };
    d
}

/// Frozen species (LAMMPS and LIGGGHTS alike): the `nve/sphere` fix's group, and the lines
/// that freeze the rest (`fix freeze`, which also makes pair styles use the mobile partner's
/// mass as the effective mass) and exclude frozen-frozen pairs from the neighbour list, as
/// cgdem does. Without frozen species: `all` and nothing.
pub(crate) fn frozen_lines(scene: &Scene) -> (&'static str, String) {
    let frozen: Vec<usize> = (0..scene.species.len())
        .filter(|&k| scene.species[k].frozen)
        .map(|k| k + 1)
        .collect();
    if frozen.is_empty() {
        return ("all", String::new());
    }
    let types: Vec<String> = frozen.iter().map(|t| t.to_string()).collect();
    let mut lines = format!(
        "group           frozen type {}
",
        types.join(" ")
    );
    lines += "group           mobile subtract all frozen
";
    for (k, a) in frozen.iter().enumerate() {
        for b in &frozen[k..] {
            lines += &format!("neigh_modify    exclude type {a} {b}\n");
        }
    }
    lines += "fix             freeze frozen freeze\n";
    ("mobile", lines)
}

pub(crate) fn g(x: Real) -> String {
    format!("{x:.17e}")
}

/// Removes the wall fix `w_NAME` of a Hertz deck (LAMMPS and LIGGGHTS name them alike).
pub(crate) fn unfix_wall(name: &str) -> String {
    format!("unfix           w_{name}\n")
}

/// `region NAME block xlo xhi ylo yhi zlo zhi` for the box `lo..hi` (LAMMPS and LIGGGHTS).
pub(crate) fn block_region(name: &str, lo: Vec3, hi: Vec3) -> String {
    format!(
        "region          {name} block {} {} {} {} {} {}\n",
        g(lo.x),
        g(hi.x),
        g(lo.y),
        g(hi.y),
        g(lo.z),
        g(hi.z)
    )
}

/// A `read_data` file for `atom_style sphere` (LAMMPS) or `granular` (LIGGGHTS, same columns):
/// `n_types` atom types (at least one per species; LIGGGHTS walls take one more), per
/// species the diameter and density given, the particles' positions, velocities and
/// spins (zero without angular state). Ids are `id + 1`, types `species + 1`.
pub fn data_file(
    scene: &Scene,
    particles: &Particles,
    diameters: &[Real],
    densities: &[Real],
    n_types: usize,
) -> String {
    let title = format!(
        "LAMMPS data file written by cgdem {} for scene {} (lambda = {})",
        env!("CARGO_PKG_VERSION"),
        scene.name,
        scene.lambda
    );
    cgdem_core::lammps_data::data_text(
        &title,
        scene.domain.lo,
        scene.domain.hi,
        particles,
        diameters,
        densities,
        n_types,
    )
}

/// Dump columns of the WCA deck (no rotation).
const WCA_COLUMNS: &str = "id type x y z vx vy vz radius";

/// How a deck writes its repose samples: `write_dump all custom FILE {columns} modify {modify}`.
pub(crate) struct StageDumps<'a> {
    pub columns: &'a str,
    pub modify: &'a str,
}

/// The energy lines ([`kinetic_energy_lines`]), the trajectory dump every `dump_every` steps
/// with `columns` and `dump_modify traj <modify>`; the stage dumps take the same.
pub(crate) fn trajectory_lines<'a>(
    d: &mut String,
    dump_every: u64,
    rotation: bool,
    columns: &'a str,
    modify: &'a str,
) -> StageDumps<'a> {
    *d += &kinetic_energy_lines(dump_every, rotation);
    let _ = writeln!(
        d,
        "dump            traj all custom {dump_every} {TRAJECTORY_FILE} {columns}"
    );
    let _ = writeln!(d, "dump_modify     traj {modify}");
    StageDumps { columns, modify }
}

/// The kinetic energy per mass the settle loops test (`v_kepm`) and the thermo line: LAMMPS
/// and LIGGGHTS alike. With `rotation`, the rotational energy counts too, as in cgdem.
pub(crate) fn kinetic_energy_lines(dump_every: u64, rotation: bool) -> String {
    let mut d = String::from("compute         ke all ke\n");
    if rotation {
        d += "compute         rke all erotate/sphere\nvariable        kepm equal (c_ke+c_rke)/mass(all)\n";
    } else {
        d += "variable        kepm equal c_ke/mass(all)\n";
    }
    d += "thermo_style    custom step time atoms c_ke v_kepm\n";
    let _ = writeln!(d, "thermo          {dump_every}");
    d += "thermo_modify   lost ignore norm no\n";
    d
}

/// Lines a deck runs every `every` steps of a duration stage (LAMMPS's top-ups), `lines(n)`
/// at the `n`-th stop (from 0); lines that add fixes end with their own `run 0` setup.
pub(crate) struct Periodic {
    pub every: u64,
    pub lines: Box<dyn Fn(usize) -> String>,
}

/// What a code's deck adds to the shared stage lines: `unfix(wall)` removes a wall,
/// `begin(stage)` adds what starts with a stage (a body's motion, a top-up), and
/// `periodic(stage)` gives lines to run every so many steps of a duration stage.
pub(crate) struct StageHooks<'a> {
    pub unfix: &'a dyn Fn(&str) -> String,
    pub begin: &'a dyn Fn(&str) -> String,
    pub periodic: &'a dyn Fn(&str) -> Option<Periodic>,
}

impl StageHooks<'_> {
    /// Hooks that only remove walls (`unfix`), for decks without bodies or top-ups.
    pub fn walls_only(unfix: &dyn Fn(&str) -> String) -> StageHooks<'_> {
        StageHooks {
            unfix,
            begin: &|_| String::new(),
            periodic: &|_| None,
        }
    }
}

/// Where a duration stage stops: repose sample `j` at time `t`, or periodic stop `n`.
#[derive(Clone, Copy)]
enum Stop {
    Sample(usize, Real),
    Periodic(usize),
}

/// The scene's stages as deck lines (LAMMPS and LIGGGHTS take the same commands), appended to
/// `d` after the trajectory dump is defined; returns the repose samples (stage, time after
/// its start, file). One `run 0` sets the system up; every later run is `pre no`, so it is set
/// up exactly once: LAMMPS's `fix wall/gran ... damping tsuji` applies its polynomial to its
/// stored coefficient in every setup (measured: a second setup turned the wall restitution
/// 0.49998 into 0.60055, a third into 0.49247; `reference/HERTZ_COLLAPSE.md`), and the LAMMPS
/// decks pad their fix list for the `unfix` that follows ([`removal_pads`]). A stage first
/// removes its walls (`hooks.unfix`), adds what starts with it (`hooks.begin`), prints
/// `CGDEM_STAGE name start STEP`, then either runs its duration, stopping at each repose time
/// for a `write_dump` and, when `hooks.periodic` gives lines, every so many steps for them, or
/// runs in chunks of one output interval until the first chunk end
/// after `min_duration` with `v_kepm` below the threshold (at most `max_duration`), and prints
/// `CGDEM_STAGE name end STEP how`.
pub(crate) fn stage_lines(
    d: &mut String,
    scene: &Scene,
    dt: Real,
    dump_every: u64,
    dumps: &StageDumps,
    hooks: &StageHooks,
) -> Vec<(String, Real, String)> {
    let write_dump = |file: &str| {
        format!(
            "all custom {file} {} modify {}",
            dumps.columns, dumps.modify
        )
    };
    *d += "run             0 post no\n";
    let mut repose_dumps = Vec::new();
    for (k, stage) in scene.stages.iter().enumerate() {
        let _ = writeln!(d, "\n# stage `{}`", stage.name);
        for name in &stage.remove_walls {
            *d += &(hooks.unfix)(name);
        }
        *d += &(hooks.begin)(&stage.name);
        let _ = writeln!(
            d,
            "print           \"CGDEM_STAGE {} start $(step)\"",
            stage.name
        );
        let repose_times: Vec<Real> = match &scene.repose {
            Some(r) if r.stage == stage.name => r.at_times.clone(),
            _ => Vec::new(),
        };
        match stage.end {
            StageEnd::Duration(duration) => {
                let total = (duration / dt).round() as u64;
                // Stops inside the stage, by step: repose samples and periodic lines.
                let mut stops: Vec<(u64, Stop)> = Vec::new();
                for (j, &t) in repose_times.iter().enumerate() {
                    stops.push((((t / dt).round() as u64).min(total), Stop::Sample(j, t)));
                }
                let periodic = (hooks.periodic)(&stage.name);
                if let Some(p) = &periodic {
                    let every = p.every.max(1);
                    stops.extend(
                        (1..)
                            .map(|n| n * every)
                            .take_while(|&at| at < total)
                            .enumerate()
                            .map(|(n, at)| (at, Stop::Periodic(n))),
                    );
                }
                stops.sort_by_key(|&(at, _)| at);
                let mut done = 0;
                for (at, stop) in stops {
                    if at > done {
                        let _ = writeln!(d, "run             {} pre no post no", at - done);
                        done = at;
                    }
                    match stop {
                        Stop::Sample(j, t) => {
                            let file = format!("repose_{j}.dump");
                            let _ = writeln!(d, "write_dump      {}", write_dump(&file));
                            repose_dumps.push((stage.name.clone(), t, file));
                        }
                        Stop::Periodic(n) => {
                            *d += &(periodic
                                .as_ref()
                                .expect("a periodic stop has its lines")
                                .lines)(n)
                        }
                    }
                }
                if total > done {
                    let _ = writeln!(d, "run             {} pre no post no", total - done);
                }
                let _ = writeln!(
                    d,
                    "print           \"CGDEM_STAGE {} end $(step) duration\"",
                    stage.name
                );
            }
            StageEnd::Settled {
                kinetic_energy_per_mass,
                min_duration,
                max_duration,
            } => {
                let chunk_s = dump_every as Real * dt;
                let min_chunks = (min_duration / chunk_s - 1e-9).ceil().max(0.0) as u64;
                let max_chunks = ((max_duration / chunk_s).round() as u64).max(1);
                let (var, label) = (format!("chunk{k}"), format!("stage{k}"));
                let _ = writeln!(d, "variable        {var} loop {max_chunks}");
                let _ = writeln!(d, "label           loop_{label}");
                let _ = writeln!(d, "run             {dump_every} pre no post no");
                // Fixed-time repose samples inside a stage that ends by itself: the loop
                // counts chunks of one output interval, so sample j is chunk round(t_j / chunk).
                for (j, &t) in repose_times.iter().enumerate() {
                    let chunk = ((t / chunk_s).round() as u64).max(1);
                    let file = format!("repose_{j}.dump");
                    // Inside the if's double quotes: single quotes around a dump format.
                    let _ = writeln!(
                        d,
                        "if              \"${{{var}}} == {chunk}\" then \"write_dump {}\"",
                        write_dump(&file).replace('"', "'")
                    );
                    repose_dumps.push((stage.name.clone(), t, file));
                }
                let _ = writeln!(d, "if              \"${{{var}}} >= {min_chunks} && ${{kepm}} < {}\" then \"print 'CGDEM_STAGE {} end $(step) settled'\" \"jump SELF end_{label}\"", g(kinetic_energy_per_mass), stage.name);
                let _ = writeln!(d, "next            {var}");
                let _ = writeln!(d, "jump            SELF loop_{label}");
                let _ = writeln!(
                    d,
                    "print           \"CGDEM_STAGE {} end $(step) max_duration\"",
                    stage.name
                );
                let _ = writeln!(d, "label           end_{label}");
                let _ = writeln!(d, "variable        {var} delete");
            }
        }
    }
    repose_dumps
}

/// `fix pad_k all addforce 0 0 0` lines, one per wall fix some stage removes, to follow the
/// wall fixes of a LAMMPS deck. LAMMPS builds its per-stage fix lists in the setup only;
/// `unfix` shifts the fix array down and a `run pre no` then walks the old list, so the last
/// fixes are applied twice (measured: the floor's restitution 0.366 instead of 0.49998 after
/// removing a wall defined before it). With zero-force pads at the end of the list, the pads
/// are the ones applied twice.
pub(crate) fn removal_pads(scene: &Scene, fixes_per_wall: usize) -> String {
    let removed: usize = scene.stages.iter().map(|s| s.remove_walls.len()).sum();
    let mut d = String::new();
    for k in 0..removed * fixes_per_wall {
        let _ = writeln!(d, "fix             pad_{k} all addforce 0.0 0.0 0.0");
    }
    d
}

/// The deck for `scene` starting from `particles` (positions and velocities), stepping `dt`:
/// the seed's WCA model here, a Hertz scene by `hertz::write_hertz_deck`.
pub fn write_wca_deck(scene: &Scene, particles: &Particles, dt: Real) -> Result<Deck, DeckError> {
    let unsupported = |reason: String| DeckError::unsupported(scene, reason);
    let ContactSettings::Wca(wca) = scene.contact else {
        return Err(unsupported(
            "not the seed's WCA model: Hertz scenes get `hertz::write_hertz_deck`".into(),
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
    let rc = TWO_POW_ONE_SIXTH * wca.sigma;
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

    let mut d = written_by(Code::Lammps, scene);
    let _ = writeln!(d, ", lambda = {}).", scene.lambda);
    let _ = writeln!(d, "# Model lines: reference/lammps/SEED_MODEL.md. Do not edit: rewrite with `cgdem reference lammps`.");
    d += &preamble(Code::Lammps, scene);
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
    d += &neighbor_lines(Code::Lammps, scene);
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
        d += &removal_pads(scene, 2);
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
            code: "lammps",
            log_file: LOG_FILE,
            notes: vec!["LAMMPS caps wall friction with the wall dashpot force only, cgdem with WCA + dashpot (reference/lammps/SEED_MODEL.md claim 11)".into()],
            dt,
            dump_every,
            repose_dumps,
        },
    })
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
