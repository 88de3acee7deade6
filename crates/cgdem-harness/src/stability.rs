//! The stability suite: `[[stability]]` cases of a suite file, each run by cgdem and, where the
//! physics exists there, LAMMPS and LIGGGHTS, with one verdict per code:
//!
//! - **stable**: ran to the end; no particle lost; no non-finite value written; kinetic plus
//!   gravitational energy never above what the start held (kinetic + gravitational + the
//!   elastic energy of overlaps placed at the start) by more than the case's tolerance; the
//!   largest overlap below the case's limit.
//! - **detected**: the code stopped with a clear message (a cgdem guard or refusal, a
//!   reference code's `ERROR`) before any non-finite value or lost particle.
//! - **failed**: non-finite values, lost particles, an energy blow-up or drift, an overlap
//!   beyond the limit, or a crash without a message.
//!
//! Energy balance: with no work done (no moving body) and no attraction, `E0 + U0 = E(t) +
//! U(t) + D(t)` (`E` kinetic + gravitational, `U` elastic, `D` dissipated), so `E(t) <= E0 +
//! U0` and `E0 + U0 - E(t)` is what was dissipated or is stored at `t`. The reference decks
//! run with `thermo_modify lost error` (the codes' own default) instead of the validation
//! decks' `lost ignore`, so that a lost atom is the code's own error.

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::decks::runner::{log_tail_of, RunStatus, RunnerOptions};
use crate::code::Code;
use crate::csv_table::CsvTable;
use crate::ranks::run_scene;
use crate::report::{Cell, Report, Table};
use crate::runs::{CgdemDecomposition, ValidateOptions};
use crate::suite_entry::{load_variant, parse_codes, parse_variant, SuiteError};
use cgdem_core::coarse_graining::coarse_grain;
use cgdem_core::guard::overlap_fraction;
use cgdem_core::io::CsvBuffer;
use cgdem_core::math::{Real, Vec3, TWO_POW_ONE_SIXTH};
use cgdem_core::particles::Particles;
use cgdem_core::run::RunOptions;
use cgdem_core::scene::{ContactSettings, Override, Scene, SceneError};

/// One `[[stability]]` entry of a suite file, as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawStabilityCase {
    file: PathBuf,
    #[serde(default)]
    codes: Vec<String>,
    lambda: Option<u32>,
    #[serde(default)]
    force_dt: bool,
    energy_tolerance: Option<f64>,
    #[serde(default)]
    conserves_energy: bool,
    energy_not_judged: Option<String>,
    max_overlap: Option<f64>,
    #[serde(default)]
    set: Vec<String>,
    variant: Option<String>,
}

/// A stability case: a scene, the codes that try it, and what it is judged by.
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityCase {
    pub file: PathBuf,
    /// The codes that try it (default all three; a code whose deck cannot express the scene
    /// is recorded "not applicable" with the reason).
    pub codes: Vec<Code>,
    pub lambda: u32,
    /// Run above the stable time-step limit (`--force-dt`), in every code.
    pub force_dt: bool,
    /// Largest rise of kinetic + gravitational energy over what the start held, as a fraction
    /// of `max(E0 + U0, total mass * 1e-3 J/kg)`.
    pub energy_tolerance: f64,
    /// No dissipation at all (restitution 1, no friction): the end energy must also be
    /// within the tolerance of the start (drift), not only below it.
    pub conserves_energy: bool,
    /// Why the energy is not judged (work done by a body, binding energy of attraction).
    pub energy_not_judged: Option<String>,
    /// Largest overlap, as a fraction of the smaller radius (pairs) or the radius (walls).
    pub max_overlap: f64,
    pub overrides: Vec<Override>,
    /// The overrides as written (`KEY = VALUE`), for the report.
    pub set: Vec<String>,
    pub variant: Option<String>,
}

impl StabilityCase {
    pub fn load_scene(&self) -> Result<Scene, SceneError> {
        load_variant(&self.file, &self.overrides, self.variant.as_deref())
    }
}

pub(crate) fn parse_cases(
    raw: Vec<RawStabilityCase>,
    path: &Path,
) -> Result<Vec<StabilityCase>, SuiteError> {
    let invalid = |field: String, value: String, allowed: &str| SuiteError::Invalid {
        file: path.to_path_buf(),
        field,
        value,
        allowed: allowed.into(),
    };
    let mut out = Vec::new();
    for (k, c) in raw.into_iter().enumerate() {
        let codes = if c.codes.is_empty() {
            vec![Code::Cgdem, Code::Lammps, Code::Liggghts]
        } else {
            parse_codes(&c.codes, &format!("stability[{k}].codes"), path)?
        };
        let lambda = c.lambda.unwrap_or(1);
        if !lambda.is_power_of_two() {
            return Err(invalid(
                format!("stability[{k}].lambda"),
                lambda.to_string(),
                "a power of two",
            ));
        }
        let fraction = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(invalid(
                    format!("stability[{k}].{field}"),
                    v.to_string(),
                    "a fraction > 0",
                ))
            }
        };
        let energy_tolerance = fraction("energy_tolerance", c.energy_tolerance.unwrap_or(0.05))?;
        let max_overlap = fraction("max_overlap", c.max_overlap.unwrap_or(0.25))?;
        let overrides = parse_variant(
            &c.set,
            c.variant.as_deref(),
            &format!("stability[{k}]"),
            path,
        )?;
        out.push(StabilityCase {
            file: c.file,
            codes,
            lambda,
            force_dt: c.force_dt,
            energy_tolerance,
            conserves_energy: c.conserves_energy,
            energy_not_judged: c.energy_not_judged,
            max_overlap,
            overrides,
            set: c.set,
            variant: c.variant,
        });
    }
    Ok(out)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Stable,
    Detected,
    Failed,
    NotApplicable,
    Skipped,
}

impl Verdict {
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Stable => "stable",
            Verdict::Detected => "detected",
            Verdict::Failed => "failed",
            Verdict::NotApplicable => "not applicable",
            Verdict::Skipped => "skipped",
        }
    }
}

/// What a run left that the verdict is judged on.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Evidence {
    pub particles: usize,
    pub particles_lost: u64,
    pub steps: u64,
    pub dt_s: Real,
    pub stable_dt_s: Real,
    /// Kinetic + gravitational energy at the start, J.
    pub energy_start_j: Option<Real>,
    /// Elastic energy of the overlaps at the start (particles placed overlapping), J.
    pub elastic_start_j: Option<Real>,
    /// Largest and last kinetic + gravitational energy of the time series, J.
    pub energy_max_j: Option<Real>,
    pub energy_end_j: Option<Real>,
    /// `(E_max - E0 - U0) / scale`, `scale = max(E0 + U0, total mass * 1e-3 J/kg)`.
    pub energy_rise: Option<Real>,
    /// `(E_end - E0 - U0) / scale`.
    pub energy_drift: Option<Real>,
    /// `E0 + U0 - E_end`: dissipated, or stored elastically at the end, J.
    pub dissipated_j: Option<Real>,
    pub largest_overlap: Option<Real>,
    /// Where the overlap was measured: every step (cgdem's guard peak) or the dump frames.
    pub overlap_measured: String,
    pub non_finite: bool,
    pub samples: usize,
}

/// One code's run of one case.
#[derive(Clone, Debug, Serialize)]
pub struct StabilityRecord {
    pub case: String,
    pub code: Code,
    pub verdict: Verdict,
    /// Why: the guard's or the code's message, what failed, or why not applicable.
    pub message: String,
    /// The last lines of a reference code's log, when it stopped or failed.
    pub log_tail: Option<String>,
    pub dir: PathBuf,
    pub force_dt: bool,
    pub evidence: Option<Evidence>,
}

/// Runs every stability case of a suite in its codes under `RUNS/stability/` (the options'
/// runs directory), adds the "Stability" section to `report` and writes
/// `OUT/stability.csv` (none of it for a suite without stability cases).
pub fn run_stability(
    cases: &[StabilityCase],
    options: &ValidateOptions,
    report: &mut Report,
) -> Result<Vec<StabilityRecord>, String> {
    if cases.is_empty() {
        return Ok(Vec::new());
    }
    let (out, runs) = (&options.out, options.runs_dir());
    let (quiet, keep_going) = (options.quiet, options.keep_going);
    let (reference_timeout_s, decomposition) =
        (options.reference_timeout_s, &options.decomposition);
    let mut records = Vec::new();
    let mut described = Vec::new();
    for case in cases {
        let base = case
            .load_scene()
            .map_err(|e| format!("{}: {e}", case.file.display()))?;
        let mut label = base.name.clone();
        if case.lambda != 1 {
            label += &format!("-lambda{}", case.lambda);
        }
        let mut description = base.description.clone();
        if let Some(v) = &case.variant {
            description += &format!(" (variant `{v}`: {})", case.set.join(", "));
        }
        described.push((label.clone(), description, case.clone()));
        // A level cgdem refuses to build is its clear error; the reference codes get no scene.
        let scene = match coarse_grain(&base, case.lambda) {
            Ok(mut scene) => {
                scene.name = label.clone();
                scene
            }
            Err(e) => {
                for &code in &case.codes {
                    let mut rec = record(&base, code, case, Path::new(""));
                    rec.case = label.clone();
                    if code == Code::Cgdem {
                        rec.verdict = Verdict::Detected;
                        rec.message = format!("refused before the run: {e}");
                    } else {
                        rec.message = format!("no scene at lambda = {}: {e}", case.lambda);
                    }
                    if !quiet {
                        eprintln!(
                            "stability {label} {}: {}: {}",
                            code.name(),
                            rec.verdict.name(),
                            first_line(&rec.message)
                        );
                    }
                    records.push(rec);
                }
                continue;
            }
        };
        for &code in &case.codes {
            let dir = runs.join("stability").join(&scene.name).join(code.name());
            let _ = std::fs::remove_dir_all(&dir);
            let record = match code {
                Code::Cgdem => run_cgdem(&scene, case, &dir, keep_going, decomposition),
                Code::Lammps | Code::Liggghts => {
                    run_reference(code, &scene, case, &dir, reference_timeout_s)
                }
            };
            if !quiet {
                eprintln!(
                    "stability {} {}: {}: {}",
                    scene.name,
                    code.name(),
                    record.verdict.name(),
                    first_line(&record.message)
                );
            }
            records.push(record);
        }
    }
    write_csv(&records, &out.join("stability.csv"))?;
    write_section(report, &described, &records);
    Ok(records)
}

fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").chars().take(200).collect()
}

fn record(scene: &Scene, code: Code, case: &StabilityCase, dir: &Path) -> StabilityRecord {
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
fn not_applicable(code: Code, scene: &Scene) -> Option<String> {
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
        return Some("LIGGGHTS cannot express the seed's WCA model (model = \"wca\")".into());
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
    use super::decks::{self, postprocess, write_summary};
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
    let particles = cgdem_core::run::initial_particles(scene, false, &[])
        .map(|p| p.len())
        .unwrap_or(0);
    let mut ev = Evidence {
        particles,
        dt_s: deck.plan.dt,
        stable_dt_s: scales.stable_limit,
        overlap_measured: "at the dump frames".into(),
        non_finite: log.non_finite,
        ..Evidence::default()
    };
    if let Ok(s) = &postprocessed {
        ev.steps = s.steps;
    }
    energy_evidence(scene, dir, &mut ev);
    ev.particles_lost = ev.particles_lost.max(log.lost_atoms);
    let trajectory = dir.join(decks::TRAJECTORY_FILE);
    match frame_overlap(scene, &trajectory) {
        Ok(o) => ev.largest_overlap = o,
        Err(non_finite) => ev.non_finite |= non_finite,
    }
    let tail = log_tail_of(dir, deck.plan.log_file, 12);
    let (stop, crash) = match &status {
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
        RunStatus::TimedOut { after_s, .. } => (
            None,
            Some(format!("{} timed out after {after_s:.0} s", code.name())),
        ),
        _ => (log.error.clone(), None),
    };
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

/// What a LAMMPS or LIGGGHTS log says about the run's end.
#[derive(Debug, Default, PartialEq)]
pub struct LogFindings {
    /// The first `ERROR` line.
    pub error: Option<String>,
    /// `ERROR: Lost atoms: original N current M`: N - M.
    pub lost_atoms: u64,
    /// A `nan` or `inf` in a line of numbers (thermo output).
    pub non_finite: bool,
}

impl LogFindings {
    pub fn of(log: &str) -> LogFindings {
        let mut out = LogFindings::default();
        for line in log.lines() {
            let t = line.trim();
            if out.error.is_none() && t.starts_with("ERROR") {
                out.error = Some(t.to_string());
                // LIGGGHTS may print equal counts ("original 79 current 79"): one at least.
                if t.contains("Lost atoms") {
                    let counts = number_after(t, "original").zip(number_after(t, "current"));
                    out.lost_atoms = counts.map_or(1, |(a, b)| a.saturating_sub(b).max(1));
                }
            }
            let fields: Vec<&str> = t.split_whitespace().collect();
            let numeric = !fields.is_empty()
                && fields[0].parse::<u64>().is_ok()
                && fields.iter().all(|f| f.parse::<f64>().is_ok());
            if numeric
                && fields
                    .iter()
                    .any(|f| !f.parse::<f64>().is_ok_and(|v| v.is_finite()))
            {
                out.non_finite = true;
            }
        }
        out
    }
}

fn number_after(text: &str, word: &str) -> Option<u64> {
    let rest = &text[text.find(word)? + word.len()..];
    rest.split(|c: char| !c.is_ascii_digit())
        .find(|s| !s.is_empty())?
        .parse()
        .ok()
}

/// The verdict from the evidence, the clear stop message (guard, refusal, `ERROR`) if the
/// code stopped with one, and the crash message if it stopped without.
pub(crate) fn classify(
    case: &StabilityCase,
    ev: &Evidence,
    stop: Option<String>,
    crash: Option<String>,
) -> (Verdict, String) {
    let after = |what: String| match &stop {
        Some(m) => format!("{what}; then it stopped: {m}"),
        None => what,
    };
    if ev.non_finite {
        return (
            Verdict::Failed,
            after("non-finite values (NaN or inf) in its outputs".into()),
        );
    }
    if ev.particles_lost > 0 {
        return (
            Verdict::Failed,
            after(format!(
                "{} of {} particles lost",
                ev.particles_lost, ev.particles
            )),
        );
    }
    if let Some(message) = stop {
        return (Verdict::Detected, message);
    }
    if let Some(message) = crash {
        return (Verdict::Failed, message);
    }
    if case.energy_not_judged.is_none() {
        if let Some(rise) = ev.energy_rise.filter(|r| *r > case.energy_tolerance) {
            return (
                Verdict::Failed,
                format!(
                    "energy blow-up: kinetic + gravitational energy rose {:.3} of the start's above it (tolerance {})",
                    rise, case.energy_tolerance
                ),
            );
        }
        if case.conserves_energy {
            if let Some(drift) = ev.energy_drift.filter(|d| d.abs() > case.energy_tolerance) {
                return (
                    Verdict::Failed,
                    format!(
                        "energy drift {drift:.3e} of the start's energy without dissipation (tolerance {})",
                        case.energy_tolerance
                    ),
                );
            }
        }
    }
    if let Some(o) = ev.largest_overlap.filter(|o| *o > case.max_overlap) {
        return (
            Verdict::Failed,
            format!(
                "largest overlap {:.1}% of the radius, beyond the {:.0}% limit: contacts not resolved",
                100.0 * o,
                100.0 * case.max_overlap
            ),
        );
    }
    let energy = match (&case.energy_not_judged, ev.energy_rise, ev.energy_drift) {
        (Some(why), _, _) => format!("energy not judged ({why})"),
        (None, Some(rise), Some(drift)) => format!(
            "energy (kinetic + gravitational) peak {rise:+.2e}, end {drift:+.2e} relative to the start (tolerance {})",
            case.energy_tolerance
        ),
        _ => "no energy samples".into(),
    };
    (
        Verdict::Stable,
        format!(
            "ran to the end: {energy}; largest overlap {}; no particle lost",
            ev.largest_overlap
                .map_or("-".into(), |o| format!("{:.2}%", 100.0 * o))
        ),
    )
}

/// Fills the energy balance from `dir/timeseries.csv` (`mechanical_energy_j`, `n_particles`)
/// and the scene's starting state.
fn energy_evidence(scene: &Scene, dir: &Path, ev: &mut Evidence) {
    let Ok(table) = CsvTable::read(&dir.join("timeseries.csv")) else {
        return;
    };
    let (Ok(e_col), Ok(n_col)) = (
        table.column("mechanical_energy_j"),
        table.column("n_particles"),
    ) else {
        return;
    };
    let mut energies = Vec::new();
    let mut fewest = usize::MAX;
    for row in table.rows() {
        match row.parse::<Real>(e_col) {
            Ok(e) if e.is_finite() => energies.push(e),
            _ => ev.non_finite = true,
        }
        if let Ok(n) = row.parse::<usize>(n_col) {
            fewest = fewest.min(n);
        }
    }
    ev.samples = energies.len();
    if fewest != usize::MAX && ev.particles > fewest {
        ev.particles_lost = ev.particles_lost.max((ev.particles - fewest) as u64);
    }
    // The start: the particles as inserted (bodies would move them: not judged there).
    if !scene.bodies.is_empty() {
        return;
    }
    let Ok(start) = cgdem_core::run::initial_particles(scene, false, &[]) else {
        return;
    };
    let origin = cgdem_core::output_format::potential_origin(
        scene.gravity,
        scene.domain.lo,
        scene.domain.hi,
    );
    let e0: Real = (0..start.len())
        .map(|k| {
            let m = start.mass[k];
            0.5 * m * start.velocity[k].length_squared()
                - m * scene.gravity.dot(start.position[k] - origin)
        })
        .sum();
    let u0 = elastic_energy(scene, &start);
    let mass: Real = start.mass.iter().sum();
    let scale = (e0 + u0).max(mass * 1e-3);
    ev.energy_start_j = Some(e0);
    ev.elastic_start_j = Some(u0);
    if let (Some(max), Some(&end)) = (energies.iter().copied().reduce(Real::max), energies.last()) {
        ev.energy_max_j = Some(max);
        ev.energy_end_j = Some(end);
        ev.energy_rise = Some((max - e0 - u0) / scale);
        ev.energy_drift = Some((end - e0 - u0) / scale);
        ev.dissipated_j = Some(e0 + u0 - end);
    }
}

/// Elastic energy stored in the overlaps of `p` (placed overlapping): WCA `phi(r)` and the
/// mirror `phi(2h)` at walls; Hertz `8/15 E* sqrt(R*) delta^(5/2)`.
pub(crate) fn elastic_energy(scene: &Scene, p: &Particles) -> Real {
    let periodic = scene.domain.periodic;
    let length = scene.domain.hi - scene.domain.lo;
    type PairEnergy = Box<dyn Fn(Real, Real, Real) -> Real>;
    type WallEnergy = Box<dyn Fn(Real, Real) -> Real>;
    let (pair, wall): (PairEnergy, WallEnergy) = match &scene.contact {
        ContactSettings::Wca(w) => {
            let (eps, sigma) = (w.epsilon, w.sigma);
            let phi = move |r: Real| {
                if r >= TWO_POW_ONE_SIXTH * sigma || r <= 0.0 {
                    0.0
                } else {
                    let s6 = (sigma / r).powi(6);
                    4.0 * eps * (s6 * s6 - s6 + 0.25)
                }
            };
            (
                Box::new(move |d, _, _| phi(d)),
                Box::new(move |h, _| phi(2.0 * h)),
            )
        }
        ContactSettings::Hertz(h) => {
            let own = (1.0 - h.poisson_ratio * h.poisson_ratio) / h.youngs_modulus;
            let e_pair = 1.0 / (2.0 * own);
            let wall_e = scene
                .wall_contact
                .youngs_modulus
                .unwrap_or(h.youngs_modulus);
            let wall_nu = scene.wall_contact.poisson_ratio.unwrap_or(h.poisson_ratio);
            let e_wall = 1.0 / (own + (1.0 - wall_nu * wall_nu) / wall_e);
            let u = |e_star: Real, r_star: Real, delta: Real| {
                if delta > 0.0 {
                    8.0 / 15.0 * e_star * r_star.sqrt() * delta.powf(2.5)
                } else {
                    0.0
                }
            };
            (
                Box::new(move |d, ri, rj| u(e_pair, ri * rj / (ri + rj), ri + rj - d)),
                Box::new(move |h, r| u(e_wall, r, r - h)),
            )
        }
    };
    let mut total = 0.0;
    let n = p.len();
    for i in 0..n {
        for j in i + 1..n {
            let d = min_image(p.position[j] - p.position[i], periodic, length).length();
            if d < 1.5 * (p.radius[i] + p.radius[j]) {
                total += pair(d, p.radius[i], p.radius[j]);
            }
        }
        for w in &scene.walls {
            let h = (p.position[i] - w.point).dot(w.normal.normalize());
            if h < p.radius[i] {
                total += wall(h, p.radius[i]);
            }
        }
    }
    total
}

fn min_image(mut d: Vec3, periodic: [bool; 3], length: Vec3) -> Vec3 {
    if periodic[0] {
        d.x -= length.x * (d.x / length.x).round();
    }
    if periodic[1] {
        d.y -= length.y * (d.y / length.y).round();
    }
    if periodic[2] {
        d.z -= length.z * (d.z / length.z).round();
    }
    d
}

/// Largest overlap over the frames of a reference code's trajectory (pairs: of the smaller
/// radius; planar walls: of the radius, a centre behind the wall counting as in cgdem; walls a
/// stage removes are left out).
/// `Err(true)` when a frame holds non-finite values.
fn frame_overlap(scene: &Scene, trajectory: &Path) -> Result<Option<Real>, bool> {
    let frames = super::decks::read_dump(trajectory).map_err(|_| false)?;
    let periodic = scene.domain.periodic;
    let length = scene.domain.hi - scene.domain.lo;
    // Walls some stage removes are left out (their frames are not matched to stages here).
    let walls: Vec<_> = scene
        .walls
        .iter()
        .filter(|w| {
            !scene
                .stages
                .iter()
                .any(|s| s.remove_walls.contains(&w.name))
        })
        .collect();
    let mut largest: Option<Real> = None;
    for frame in &frames {
        let p = super::decks::postprocess::frame_particles(frame, scene, trajectory)
            .map_err(|_| false)?;
        if p.position.iter().any(|x| !x.is_finite()) {
            return Err(true);
        }
        let mut worst: Real = 0.0;
        for i in 0..p.position.len() {
            let ri = p.radius[i];
            for j in i + 1..p.position.len() {
                let rj = p.radius[j];
                let d = min_image(p.position[j] - p.position[i], periodic, length).length();
                if d < ri + rj {
                    worst = worst.max((ri + rj - d) / ri.min(rj));
                }
            }
            for w in &walls {
                let h = (p.position[i] - w.point).dot(w.normal.normalize());
                worst = worst.max(overlap_fraction(h, ri));
            }
        }
        largest = Some(largest.map_or(worst, |l| l.max(worst)));
    }
    Ok(largest)
}

fn fmt(v: Option<Real>, f: impl Fn(Real) -> String) -> String {
    v.map_or(String::new(), f)
}

fn write_csv(records: &[StabilityRecord], path: &Path) -> Result<(), String> {
    let mut csv = CsvBuffer::new([
        "case",
        "code",
        "verdict",
        "particles",
        "particles_lost",
        "steps",
        "dt_s",
        "dt_over_stable",
        "energy_start_j",
        "elastic_start_j",
        "energy_max_j",
        "energy_end_j",
        "energy_rise",
        "energy_drift",
        "dissipated_j",
        "largest_overlap",
        "overlap_measured",
        "message",
    ]);
    for r in records {
        let e = r.evidence.clone().unwrap_or_default();
        let sci = |v: Real| format!("{v:.6e}");
        let dt_ratio = (e.dt_s / e.stable_dt_s)
            .is_finite()
            .then(|| e.dt_s / e.stable_dt_s);
        csv.row([
            r.case.clone(),
            r.code.name().to_string(),
            r.verdict.name().to_string(),
            e.particles.to_string(),
            e.particles_lost.to_string(),
            e.steps.to_string(),
            if e.dt_s.is_finite() {
                sci(e.dt_s)
            } else {
                String::new()
            },
            fmt(dt_ratio, |v| format!("{v:.3}")),
            fmt(e.energy_start_j, sci),
            fmt(e.elastic_start_j, sci),
            fmt(e.energy_max_j, sci),
            fmt(e.energy_end_j, sci),
            fmt(e.energy_rise, sci),
            fmt(e.energy_drift, sci),
            fmt(e.dissipated_j, sci),
            fmt(e.largest_overlap, |v| format!("{v:.4}")),
            e.overlap_measured.to_string(),
            // One row per line.
            r.message.replace('\n', " "),
        ]);
    }
    csv.bytes()
        .and_then(|bytes| cgdem_core::io::write_atomic(path, bytes))
        .map_err(|e| format!("{}: {e}", path.display()))
}

fn verdict_cell(r: &StabilityRecord) -> Cell {
    match r.verdict {
        Verdict::Stable | Verdict::Detected => Cell::pass(r.verdict.name()),
        Verdict::Failed => Cell::fail(r.verdict.name()),
        Verdict::NotApplicable | Verdict::Skipped => Cell::skipped(r.verdict.name()),
    }
}

fn write_section(
    report: &mut Report,
    cases: &[(String, String, StabilityCase)],
    records: &[StabilityRecord],
) {
    let section = report.section("Stability");
    section.paragraph(
        "Each case run by cgdem (with its guards) and, where their decks can express the physics, \
         LAMMPS and LIGGGHTS (same particles, same time step, `thermo_modify lost error`). \
         stable: ran to the end, no particle lost, no non-finite value, kinetic + gravitational \
         energy never above the start's (kinetic + gravitational + elastic energy of overlaps \
         placed at the start) by more than the case's tolerance, largest overlap below its limit. \
         detected: stopped with a clear message (cgdem guard or refusal, a reference code's ERROR) \
         before any non-finite value or lost particle. failed: anything else. cgdem's overlap is its \
         guard's per-step peak; the reference codes' is measured on their dump frames. Every record, \
         with its numbers, is in summary.json (`stability`) and stability.csv.",
    );
    let codes = [Code::Cgdem, Code::Lammps, Code::Liggghts];
    let mut table = Table::new(["case", "what", "cgdem", "lammps", "liggghts"])
        .caption("Stability: verdict per code and case (details below)");
    for (name, description, _) in cases {
        let mut row = vec![Cell::text(name), Cell::text(description)];
        for code in codes {
            row.push(
                records
                    .iter()
                    .find(|r| &r.case == name && r.code == code)
                    .map_or(Cell::text("-"), verdict_cell),
            );
        }
        table.row(row);
    }
    section.table(table);
    let mut detail = Table::new([
        "case",
        "code",
        "verdict",
        "dt / stable",
        "energy rise",
        "energy at end",
        "largest overlap",
        "lost",
        "message (and log tail)",
    ])
    .caption("Stability: evidence per run (energies as fractions of the start's kinetic + gravitational + elastic energy)");
    for r in records {
        let e = r.evidence.clone().unwrap_or_default();
        let ratio = e.dt_s / e.stable_dt_s;
        let mut message = r.message.clone();
        if let Some(tail) = &r.log_tail {
            message += &format!(" | log tail: {}", tail.replace('\n', " / "));
        }
        detail.row([
            Cell::text(&r.case),
            Cell::text(r.code.name()),
            verdict_cell(r),
            Cell::num(if ratio.is_finite() {
                format!("{ratio:.2}")
            } else {
                "-".into()
            }),
            Cell::num(fmt(e.energy_rise, |v| format!("{v:.2e}"))),
            Cell::num(fmt(e.energy_drift, |v| format!("{v:+.2e}"))),
            Cell::num(fmt(e.largest_overlap, |v| format!("{:.2}%", 100.0 * v))),
            Cell::num(if r.evidence.is_some() {
                e.particles_lost.to_string()
            } else {
                String::new()
            }),
            Cell::text(message),
        ]);
    }
    section.table(detail);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lost_atoms_error_counts_the_atoms_and_a_nan_row_is_non_finite() {
        let log = "Step Time Atoms c_ke v_kepm\n0 0 40 1.5 0.2\n100 1e-3 40 -nan nan\nERROR: Lost atoms: original 40 current 37 (src/thermo.cpp:481)\n";
        let f = LogFindings::of(log);
        assert_eq!(f.lost_atoms, 3);
        assert!(f.non_finite);
        assert!(f.error.unwrap().starts_with("ERROR: Lost atoms"));
        let liggghts =
            LogFindings::of("ERROR: Lost atoms: original 79 current 79 (./src/thermo.cpp:445)\n");
        assert_eq!(liggghts.lost_atoms, 1);
        let clean = LogFindings::of("Step Time\n0 0 40 1.5 0.2\nLoop time of 1.0 on 1 procs\n");
        assert_eq!(clean, LogFindings::default());
    }

    #[test]
    fn a_suite_without_stability_cases_adds_no_section_and_no_csv() {
        let dir = std::env::temp_dir().join(format!("cgdem-stability-none-{}", std::process::id()));
        let mut report = Report::new("t");
        let options = ValidateOptions {
            out: dir.clone(),
            quiet: true,
            ..Default::default()
        };
        let records = run_stability(&[], &options, &mut report).unwrap();
        assert!(records.is_empty());
        assert!(!dir.join("stability.csv").exists());
        assert!(!report.render(&dir).contains("Stability"));
    }

    fn case() -> StabilityCase {
        StabilityCase {
            file: "x.toml".into(),
            codes: vec![Code::Cgdem],
            lambda: 1,
            force_dt: false,
            energy_tolerance: 0.05,
            conserves_energy: true,
            energy_not_judged: None,
            max_overlap: 0.25,
            overrides: Vec::new(),
            set: Vec::new(),
            variant: None,
        }
    }

    #[test]
    fn a_stop_is_detected_only_before_loss_and_a_run_to_the_end_is_judged_on_energy() {
        let ev = Evidence {
            energy_rise: Some(0.01),
            energy_drift: Some(-0.01),
            largest_overlap: Some(0.1),
            ..Evidence::default()
        };
        assert_eq!(classify(&case(), &ev, None, None).0, Verdict::Stable);
        let stop = Some("guard".to_string());
        assert_eq!(
            classify(&case(), &ev, stop.clone(), None).0,
            Verdict::Detected
        );
        let lost = Evidence {
            particles_lost: 2,
            ..ev.clone()
        };
        assert_eq!(classify(&case(), &lost, stop, None).0, Verdict::Failed);
        let drift = Evidence {
            energy_drift: Some(-0.2),
            ..ev.clone()
        };
        assert_eq!(classify(&case(), &drift, None, None).0, Verdict::Failed);
        let crash = Some("exit 139".to_string());
        assert_eq!(classify(&case(), &ev, None, crash).0, Verdict::Failed);
    }
}
