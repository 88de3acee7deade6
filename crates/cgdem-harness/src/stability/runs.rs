//! A stability case run by each code: cgdem with its guards (decomposed when `validate
//! --grid` asks), LAMMPS and LIGGGHTS on the validation deck with `lost error`; each run's
//! evidence read from what it left.

use std::panic::AssertUnwindSafe;
use std::path::Path;

use super::measurement::{classify, energy_evidence, frame_overlap, LogFindings};
use super::{Evidence, StabilityCase, StabilityRecord, Verdict};
use crate::code::Code;
use crate::decks::runner::{log_tail_of, RunStatus, RunnerOptions};
use crate::ranks::run_scene;
use crate::runs::CgdemDecomposition;
use cgdem_core::math::Real;
use cgdem_core::run::{RunOptions, RunSummary};
use cgdem_core::scene::{ContactSettings, Scene};
use cgdem_core::timestep::Timescales;

pub(crate) fn record(
    scene: &Scene,
    code: Code,
    case: &StabilityCase,
    dir: &Path,
) -> StabilityRecord {
    StabilityRecord {
        case: scene.name.clone(),
        code,
        verdict: Verdict::NotApplicable,
        message: String::new(),
        log_tail: None,
        dir: dir.to_path_buf(),
        force_dt: case.force_dt,
        evidence: None,
    }
}

/// cgdem with its guards (`--force-dt` where the case forces the step), decomposed when
/// `validate --grid` asks.
pub(crate) fn run_cgdem(
    scene: &Scene,
    case: &StabilityCase,
    dir: &Path,
    keep_going: bool,
    decomposition: &CgdemDecomposition,
) -> StabilityRecord {
    let mut rec = record(scene, Code::Cgdem, case, dir);
    let options = RunOptions {
        out_dir: dir.to_path_buf(),
        force_dt: case.force_dt,
        keep_going,
        grid: decomposition.grid,
        balance: decomposition.balance,
        ..Default::default()
    };
    let ranks = decomposition.ranks.as_ref();
    let outcome = std::panic::catch_unwind(AssertUnwindSafe(|| run_scene(scene, &options, ranks)));
    let stop = match outcome {
        Ok(Ok(_)) => None,
        Ok(Err(e)) => Some(e),
        Err(_) => {
            rec.verdict = Verdict::Failed;
            rec.message = "cgdem panicked".into();
            return rec;
        }
    };
    let summary: Option<serde_json::Value> = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let mut ev = Evidence {
        overlap_measured: "every step (guard peak)".into(),
        ..Evidence::default()
    };
    if let Some(s) = &summary {
        ev.particles = s["n_particles_inserted"].as_u64().unwrap_or(0) as usize;
        ev.particles_lost = s["lost_particles"].as_u64().unwrap_or(0);
        ev.steps = s["steps"].as_u64().unwrap_or(0);
        ev.dt_s = s["dt_s"].as_f64().unwrap_or(Real::NAN);
        ev.stable_dt_s = s["stable_dt_s"].as_f64().unwrap_or(Real::NAN);
        ev.largest_overlap = s["guard_peaks"]["overlap_fraction"].as_f64();
    }
    energy_evidence(scene, dir, &mut ev);
    let (verdict, message) = classify(case, &ev, stop, None);
    rec.verdict = verdict;
    rec.message = message;
    rec.evidence = Some(ev);
    rec
}

/// Why a reference code cannot run this scene, if it cannot (before writing a deck).
pub(crate) fn not_applicable(code: Code, scene: &Scene) -> Option<String> {
    if !scene.bodies.is_empty() {
        return Some(
            "the reference decks express planar walls only: no SDF or moving bodies".into(),
        );
    }
    if let ContactSettings::Hertz(h) = &scene.contact {
        if h.cohesion != cgdem_core::scene::CohesionKind::None {
            return Some("the decks have no van der Waals (Hamaker) cohesion: LAMMPS's granular pair style offers JKR/DMT, LIGGGHTS 3.8 SJKR only".into());
        }
    }
    if code == Code::Liggghts && matches!(scene.contact, ContactSettings::Wca(_)) {
        return Some("LIGGGHTS cannot express the WCA model of Hirose (model = \"wca\")".into());
    }
    None
}

const LOST_IGNORE: &str = "thermo_modify   lost ignore norm no\n";
const LOST_ERROR: &str = "thermo_modify   lost error norm no\n";

/// LAMMPS or LIGGGHTS on the validation deck with `lost error`, at cgdem's time step.
pub(crate) fn run_reference(
    code: Code,
    scene: &Scene,
    case: &StabilityCase,
    dir: &Path,
    timeout_s: u64,
) -> StabilityRecord {
    use crate::decks::{self, postprocess, write_summary};
    let mut rec = record(scene, code, case, dir);
    if let Some(reason) = not_applicable(code, scene) {
        rec.message = reason;
        return rec;
    }
    let prepared = cgdem_core::run::time_step(scene, case.force_dt)
        .map_err(|e| e.to_string())
        .and_then(|(dt, scales, _)| {
            let particles =
                cgdem_core::run::initial_particles(scene, false, &[]).map_err(|e| e.to_string())?;
            let deck = decks::write_deck(code, scene, &particles, dt).map_err(|e| e.to_string())?;
            Ok((scales, deck))
        });
    let (scales, mut deck) = match prepared {
        Ok(p) => p,
        Err(reason) => {
            rec.message = reason;
            return rec;
        }
    };
    deck.input = deck.input.replace(LOST_IGNORE, LOST_ERROR);
    if let Err(e) = deck.write_to(dir) {
        rec.verdict = Verdict::Failed;
        rec.message = format!("cannot write the deck into {}: {e}", dir.display());
        return rec;
    }
    let runner = RunnerOptions {
        np: None,
        stop: None,
        timeout: std::time::Duration::from_secs(timeout_s),
    };
    let Some(dialect) = decks::dialect(code) else {
        rec.message = "cgdem is not a reference code".into();
        return rec;
    };
    let status = decks::run_deck(dialect, dir, &runner);
    let wall_s = match &status {
        RunStatus::Skipped {
            reason,
            install_hint,
        } => {
            rec.verdict = Verdict::Skipped;
            rec.message = format!("{reason}; install with `{install_hint}`");
            return rec;
        }
        RunStatus::Completed { wall_s } => *wall_s,
        RunStatus::Failed { .. } => Real::NAN,
        RunStatus::TimedOut { after_s, .. } => *after_s,
    };
    // Whatever the run left is post-processed, also after an error (the dumps so far).
    let postprocessed = postprocess(scene, dir, &deck.plan, &scales, wall_s, 1);
    if let Ok(summary) = &postprocessed {
        let _ = write_summary(summary, dir);
    }
    // Lossy: LIGGGHTS's "Lost atoms" error writes stray bytes after its message.
    let read = |name: &str| {
        std::fs::read(dir.join(name))
            .map(|b| String::from_utf8_lossy(&b).into_owned())
            .unwrap_or_default()
    };
    let text = read(deck.plan.log_file) + &read("stdout.txt");
    let log = LogFindings::of(&text);
    let ev = reference_evidence(
        scene,
        dir,
        &deck.plan,
        &scales,
        &log,
        postprocessed.as_ref().ok(),
    );
    let tail = log_tail_of(dir, deck.plan.log_file, 12);
    let (stop, crash) = stop_or_crash(code, &status, &log);
    if postprocessed.is_err() && stop.is_none() && crash.is_none() {
        rec.verdict = Verdict::Failed;
        rec.message = format!(
            "its outputs could not be read: {}",
            postprocessed
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default()
        );
        rec.log_tail = Some(tail);
        rec.evidence = Some(ev);
        return rec;
    }
    let (verdict, message) = classify(case, &ev, stop, crash);
    rec.verdict = verdict;
    rec.message = message;
    if verdict != Verdict::Stable {
        rec.log_tail = Some(tail);
    }
    rec.evidence = Some(ev);
    rec
}

/// What a reference run left: its step count, energies, lost atoms and largest overlap.
fn reference_evidence(
    scene: &Scene,
    dir: &Path,
    plan: &crate::decks::DeckPlan,
    scales: &Timescales,
    log: &LogFindings,
    summary: Option<&RunSummary>,
) -> Evidence {
    let particles = cgdem_core::run::initial_particles(scene, false, &[])
        .map(|p| p.len())
        .unwrap_or(0);
    let mut ev = Evidence {
        particles,
        dt_s: plan.dt,
        stable_dt_s: scales.stable_limit,
        overlap_measured: "at the dump frames".into(),
        non_finite: log.non_finite,
        ..Evidence::default()
    };
    if let Some(s) = summary {
        ev.steps = s.steps;
    }
    energy_evidence(scene, dir, &mut ev);
    ev.particles_lost = ev.particles_lost.max(log.lost_atoms);
    let trajectory = dir.join(crate::decks::TRAJECTORY_FILE);
    match frame_overlap(scene, &trajectory) {
        Ok(o) => ev.largest_overlap = o,
        Err(non_finite) => ev.non_finite |= non_finite,
    }
    ev
}

/// The reference code's own stop (its `ERROR` line) or a crash without one.
fn stop_or_crash(
    code: Code,
    status: &RunStatus,
    log: &LogFindings,
) -> (Option<String>, Option<String>) {
    match status {
        RunStatus::Failed { exit_code, .. } => match &log.error {
            Some(e) => (Some(e.clone()), None),
            None => (
                None,
                Some(format!(
                    "{} exited with code {exit_code:?} without an ERROR line",
                    code.name()
                )),
            ),
        },
        RunStatus::TimedOut { after_s, cpu_s, .. } => (
            None,
            Some(format!(
                "{} timed out after {cpu_s:.0} s of CPU per rank ({after_s:.0} s of wall clock)",
                code.name()
            )),
        ),
        _ => (log.error.clone(), None),
    }
}
