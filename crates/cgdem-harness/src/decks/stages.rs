//! What a deck runs, in LAMMPS's commands that LIGGGHTS takes too: the kinetic energy the
//! settle loops test, the trajectory dump, and the scene's stages (wall removal, settle
//! loops, duration runs with their repose dumps, a code's own lines at a stage start or
//! every so many steps), marked in the log for the post-processing.

use std::fmt::Write as _;

use super::lines::g;
use super::TRAJECTORY_FILE;
use cgdem_core::math::Real;
use cgdem_core::scene::{Scene, StageEnd};

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
/// `begin(stage)` adds what starts with a stage (a body's motion, a top-up),
/// `periodic(stage)` gives lines to run every so many steps of a duration stage, and
/// `run(n)` is the line that runs `n` steps after the first setup ([`run_without_setup`],
/// or LIGGGHTS's deletion chunks).
pub(crate) struct StageHooks<'a> {
    pub unfix: &'a dyn Fn(&str) -> String,
    pub begin: &'a dyn Fn(&str) -> String,
    pub periodic: &'a dyn Fn(&str) -> Option<Periodic>,
    pub run: &'a dyn Fn(u64) -> String,
}

impl StageHooks<'_> {
    /// Hooks that only remove walls (`unfix`), for decks without bodies or top-ups.
    pub fn walls_only(unfix: &dyn Fn(&str) -> String) -> StageHooks<'_> {
        StageHooks {
            unfix,
            begin: &|_| String::new(),
            periodic: &|_| None,
            run: &run_without_setup,
        }
    }
}

/// `run n pre no post no`: `n` steps without a new setup (see [`stage_lines`]).
pub(crate) fn run_without_setup(n: u64) -> String {
    format!("run             {n} pre no post no\n")
}

/// Where a duration stage stops: repose sample `j` at time `t`, or periodic stop `n`.
#[derive(Clone, Copy)]
enum Stop {
    Sample(usize, Real),
    Periodic(usize),
}

/// The scene's stages as deck lines (LAMMPS and LIGGGHTS take the same commands), appended to
/// `d` after the trajectory dump is defined; returns the repose samples (stage, time after
/// its start, file). One `run 0` sets the system up; every later run is `hooks.run`, which in
/// the LAMMPS decks is `pre no` ([`run_without_setup`]), so it is set up exactly once: LAMMPS's `fix wall/gran ... damping tsuji` applies its polynomial to its
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
                        *d += &(hooks.run)(at - done);
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
                    *d += &(hooks.run)(total - done);
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
                let (min_chunks, max_chunks) = settle_chunks(min_duration, max_duration, chunk_s);
                let (var, label) = (format!("chunk{k}"), format!("stage{k}"));
                let _ = writeln!(d, "variable        {var} loop {max_chunks}");
                let _ = writeln!(d, "label           loop_{label}");
                *d += &(hooks.run)(dump_every);
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

/// A settled stage's bounds in whole output intervals of `chunk_s` (the decks test the
/// kinetic energy once per interval): at least `ceil(min)`, at most `max` rounded to the
/// nearest interval, but never fewer than the minimum (with `min = max = 1.5` intervals,
/// 0.015 / 0.01 is 1.4999..., which rounded to 1, and the stage ended before its minimum).
fn settle_chunks(min_duration: Real, max_duration: Real, chunk_s: Real) -> (u64, u64) {
    let min_chunks = (min_duration / chunk_s - 1e-9).ceil().max(0.0) as u64;
    let max_chunks = ((max_duration / chunk_s).round() as u64)
        .max(min_chunks)
        .max(1);
    (min_chunks, max_chunks)
}

#[cfg(test)]
mod tests {
    use super::settle_chunks;

    #[test]
    fn a_settled_stage_never_ends_before_its_minimum_in_whole_intervals() {
        // The case found: min = max = 0.015 s with outputs every 0.01 s.
        assert_eq!(settle_chunks(0.015, 0.015, 0.01), (2, 2));
        assert_eq!(settle_chunks(0.045, 0.1, 0.01), (5, 10));
        assert_eq!(settle_chunks(0.0, 0.004, 0.01), (0, 1));
        for (min, max, chunk) in [(0.3, 0.3, 0.02), (0.11, 0.12, 0.05), (0.7, 0.71, 0.1)] {
            let (lo, hi) = settle_chunks(min, max, chunk);
            assert!(
                lo <= hi && lo as f64 * chunk >= min - 1e-9,
                "{min} {max} {chunk}"
            );
        }
    }
}
