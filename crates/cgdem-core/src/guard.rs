//! Guards that stop an unstable run instead of letting it write garbage.
//!
//! Three cheap checks, folded into loops that run anyway or done every few steps:
//!
//! - **Non-finite state**: the last velocity (and spin) update of each step reports whether
//!   every value it wrote is finite. A NaN or infinite force, velocity or position shows up
//!   there in the step it appears.
//! - **Overlap**: the pair loop reduces the largest `overlap / min(r_i, r_j)`, and the
//!   particle gather the largest wall and body overlap `(r - h) / r` (`h` the centre-to-
//!   surface distance; a centre up to one radius behind a wall counts, as it has tunnelled).
//!   Above [`GuardSettings::max_overlap_fraction`] the contact is no longer resolved.
//! - **Energy growth without work**: every [`GuardSettings::energy_every`] steps the
//!   kinetic plus gravitational energy `E = KE + sum m g_abs h` (height `h` above the box's
//!   lowest corner along gravity) is compared with its value at the last reference point (the
//!   run's start, each stage start; particles removed take their energy with them). Contacts that only
//!   repel and dissipate can store energy but not create it, so `E` may not exceed the
//!   reference by more than [`GuardSettings::energy_growth`] of `max(E_ref, M e_floor)`.
//!   The check is off while a moving body does work and for cohesive laws (binding energy
//!   turns into kinetic energy legitimately). The reference includes the elastic energy
//!   stored in overlapping pairs, which particles placed overlapping may turn into motion.
//! - **Lost particles** (unless the scene says `[domain] lost = "warn"`): the list rebuild
//!   finds particles that left the box through a bounded face; as in LAMMPS (`thermo_modify
//!   lost error`), that stops the run, since the box no longer holds what is simulated, but
//!   the particles stay in the outputs. With `lost = "warn"` (or `--keep-going`) they are
//!   removed with a warning.

use crate::math::{Real, Vec3};

/// Thresholds of the guards. The defaults are what `cgdem run` uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardSettings {
    /// Largest overlap, as a fraction of the smaller radius, before the run is stopped.
    /// Default 0.25: four times the deepest overlap of the shipped Hertz case (hertz_settle,
    /// 6%), hundreds of times that of the seed's WCA cases (aor_smoke, 0.06%); Hertz theory
    /// itself assumes overlaps of a few percent.
    pub max_overlap_fraction: Real,
    /// Allowed rise of kinetic plus gravitational energy over its reference, as a fraction
    /// of `max(E_ref, total mass * energy_floor_per_mass)`.
    pub energy_growth: Real,
    /// Energy scale per unit mass below which `energy_growth` is taken of this instead,
    /// J/kg (per mass, so it is the same at every coarse-graining level).
    pub energy_floor_per_mass: Real,
    /// Steps between energy checks (16: an instability grows by orders of magnitude per
    /// contact period, which is 20 steps at the default dt_fraction 0.05).
    pub energy_every: u64,
    /// The scene's stable time-step limit, s (for messages; NaN when unknown).
    pub stable_dt: Real,
    /// Whether a particle leaving the box through a bounded face stops the run.
    pub stop_on_lost: bool,
}

impl Default for GuardSettings {
    fn default() -> Self {
        GuardSettings {
            max_overlap_fraction: 0.25,
            energy_growth: 0.05,
            energy_floor_per_mass: 1e-3,
            energy_every: 16,
            stable_dt: Real::NAN,
            stop_on_lost: true,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GuardKind {
    NonFinite,
    Overlap,
    EnergyGrowth,
    LostParticles,
}

impl GuardKind {
    pub fn name(self) -> &'static str {
        match self {
            GuardKind::NonFinite => "non-finite state",
            GuardKind::Overlap => "overlap",
            GuardKind::EnergyGrowth => "energy growth",
            GuardKind::LostParticles => "lost particles",
        }
    }
}

/// A guard that fired: when, what was measured, which particles, why, and a step that would
/// be stable.
#[derive(Clone, Debug, PartialEq, thiserror::Error, serde::Serialize, serde::Deserialize)]
#[error("guard `{}` fired at step {step} (t = {time:.6e} s): {detail}; particles (id) {}; likely cause: {cause}{}", kind.name(), format_ids(particles), format_stable(*kind, *stable_dt, *dt))]
pub struct GuardTrip {
    pub kind: GuardKind,
    pub step: u64,
    pub time: Real,
    /// Stable ids of the particles involved (at most a few).
    pub particles: Vec<u32>,
    pub detail: String,
    pub cause: String,
    /// The run's step and the step that would be stable here, s.
    pub dt: Real,
    pub stable_dt: Real,
}

fn format_ids(ids: &[u32]) -> String {
    if ids.is_empty() {
        return "none identified".into();
    }
    ids.iter()
        .map(|id| id.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The stable step, for the guards a smaller step can cure; a lost particle is a geometry
/// or insertion matter, so its message does not send the user to the time step.
fn format_stable(kind: GuardKind, stable_dt: Real, dt: Real) -> String {
    if kind == GuardKind::LostParticles {
        String::new()
    } else if stable_dt.is_finite() {
        format!("; a stable time step: dt <= {stable_dt:.3e} s (this run: {dt:.3e} s)")
    } else {
        format!("; a stable time step: unknown (this run: {dt:.3e} s)")
    }
}

/// The cause when the step itself was forced past the limit, if it was.
pub(crate) fn forced_step_cause(dt: Real, stable_dt: Real) -> Option<String> {
    (dt > stable_dt).then(|| {
        format!(
            "the time step is {:.2} times the stable limit (forced with --force-dt)",
            dt / stable_dt
        )
    })
}

/// Why the deepest contact passed the overlap limit when the step was not forced: its overlap
/// `fraction`, its normal approach `speed` (positive while closing), the step, the contact's
/// own stable step (NaN when unknown) and the smallest radius.
pub(crate) fn overlap_cause(
    fraction: Real,
    speed: Real,
    dt: Real,
    local_limit: Real,
    smallest_radius: Real,
) -> String {
    if fraction > 1.0 {
        format!(
            "the particle passed through the surface: at {speed:.3} m/s it moved {:.0}% of its radius per step",
            100.0 * speed.abs() * dt / smallest_radius
        )
    } else if speed <= 0.0 {
        // Not closing: the contact was pressed in by something else, not by the particle's
        // own approach (a parcel caught between a turning screw and its casing leaves at
        // whatever speed the jam gave it).
        format!(
            "the particle is moving away from the surface at {:.3e} m/s, so its own approach did not drive it in: likely squeezed between surfaces that close on it (a moving body against a wall or another body; particles too large for a gap: a smaller lambda or diameter), or thrown back within one step by a contact stiffer than the step resolves",
            -speed
        )
    } else if dt > local_limit {
        format!("an impact at {speed:.3} m/s (normal approach speed) made the contact stiffer than the step resolves (Hertz scenes: contact.characteristic_velocity below the impact speed)")
    } else {
        format!("an impact at {speed:.3} m/s (normal approach speed) is more than the contact law absorbs within this overlap; the step is inside the stable limit, so the material is too soft for the impact (raise youngs_modulus or epsilon) or the impact too fast")
    }
}

/// Undamped stable step `2 / omega` of a contact of local stiffness `k` on mass `m`.
pub(crate) fn undamped_limit(stiffness: Real, mass: Real) -> Real {
    if stiffness > 0.0 && mass > 0.0 {
        2.0 / (stiffness / mass).sqrt()
    } else {
        Real::NAN
    }
}

/// Guard state the world carries between steps.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct GuardState {
    /// From the scene and options, not from a restart file.
    #[serde(skip)]
    pub settings: GuardSettings,
    /// Largest pair and wall/body overlap fractions of the last force evaluation.
    pub pair_overlap: Real,
    pub wall_overlap: Real,
    /// Whether the last velocity update wrote only finite values.
    pub finite: bool,
    /// Overlap at the first force evaluation (particles placed overlapping).
    pub initial_overlap: Option<Real>,
    /// Energy reference, and the energy of particles removed since the last check (it
    /// leaves the reference with them).
    pub energy_reference: Option<Real>,
    pub removed_energy: Real,
    /// Ids of particles that the list rebuild found at a non-finite position.
    pub removed_non_finite: Vec<u32>,
    /// Particles the list rebuild found outside the box's bounded faces since the last
    /// check (kept in place: the run stops): id, position and velocity.
    pub left_box: Vec<(u32, Vec3, Vec3)>,
    pub trip: Option<GuardTrip>,
    pub peaks: GuardPeaks,
}

/// How close a run came to each guard's threshold: the largest overlap fraction seen and
/// the largest energy rise as a fraction of the scale it is judged against (the guard fires
/// above `energy_growth`).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GuardPeaks {
    pub overlap_fraction: Real,
    pub energy_rise: Real,
}

/// Overlap of a particle of radius `r` whose centre is `distance` in front of a surface, as a
/// fraction of `r`; a centre up to one radius behind the surface has tunnelled (fraction
/// between 1 and 2); further behind, or not touching, 0.
#[inline(always)]
pub fn overlap_fraction(distance: Real, radius: Real) -> Real {
    if distance < radius && distance > -radius {
        1.0 - distance / radius
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A contact pressed in while its particle moves away was squeezed (a parcel caught by a
    /// turning screw), not hit: the cause says so instead of quoting a negative impact speed.
    #[test]
    fn a_separating_contact_is_reported_as_squeezed_not_as_an_impact() {
        let squeezed = overlap_cause(0.895, -1.7e13, 2.2e-4, Real::NAN, 0.02);
        assert!(squeezed.contains("squeezed between surfaces"), "{squeezed}");
        assert!(squeezed.contains("1.700e13"), "{squeezed}");
        assert!(!squeezed.contains("impact at"), "{squeezed}");
        let hit = overlap_cause(0.4, 3.0, 1e-6, 1e-5, 0.001);
        assert!(hit.contains("an impact at 3.000 m/s"), "{hit}");
        assert!(hit.contains("too soft"), "{hit}");
        let stiff = overlap_cause(0.4, 3.0, 1e-5, 1e-6, 0.001);
        assert!(stiff.contains("stiffer than the step resolves"), "{stiff}");
        let through = overlap_cause(1.2, 50.0, 1e-5, 1e-6, 0.001);
        assert!(through.contains("passed through"), "{through}");
    }
}
