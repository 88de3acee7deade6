//! What a stability run is judged on: the evidence it left (energy balance, overlaps, lost
//! particles, non-finite values, the log's `ERROR`) and the verdict from it.

use std::path::Path;

use serde::Serialize;

use super::StabilityCase;
use crate::csv_table::CsvTable;
use cgdem_core::guard::overlap_fraction;
use cgdem_core::math::{Real, Vec3, TWO_POW_ONE_SIXTH};
use cgdem_core::particles::Particles;
use cgdem_core::scene::{ContactSettings, Scene};

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

pub(crate) fn number_after(text: &str, word: &str) -> Option<u64> {
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
pub(crate) fn energy_evidence(scene: &Scene, dir: &Path, ev: &mut Evidence) {
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

pub(crate) fn min_image(mut d: Vec3, periodic: [bool; 3], length: Vec3) -> Vec3 {
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
pub(crate) fn frame_overlap(scene: &Scene, trajectory: &Path) -> Result<Option<Real>, bool> {
    let frames = crate::decks::read_dump(trajectory).map_err(|_| false)?;
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
        let p = crate::decks::postprocess::frame_particles(frame, scene, trajectory)
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
