//! `summary.json`: everything a run reports, whichever code made it.

use serde::Serialize;

use crate::analysis::conveying::ConveyingSummary;
use crate::analysis::PackingSummary;
use crate::guard::{GuardKind, GuardPeaks, GuardTrip};
use crate::math::Real;
use crate::particles::Particles;

use super::ReposeSample;

/// Why a stage ended; in `summary.json` as its sentence (`StageRecord::ended_by`).
#[derive(Clone, Debug, PartialEq)]
pub enum StageEnding {
    /// It ran its whole duration (a settling stage: its `max_duration`, unsettled).
    Duration(Real),
    /// Its kinetic energy per mass fell below the threshold.
    Settled {
        kinetic_energy_per_mass: Real,
        threshold: Real,
    },
    /// A guard stopped the run.
    Guard(GuardKind),
    /// The stop flag (SIGINT/SIGTERM) was raised: the run stopped at the end of a step.
    Interrupted,
}

impl std::fmt::Display for StageEnding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StageEnding::Duration(d) => write!(f, "duration {d} s"),
            StageEnding::Settled {
                kinetic_energy_per_mass,
                threshold,
            } => write!(
                f,
                "kinetic energy per mass {kinetic_energy_per_mass:.3e} J/kg < {threshold:.3e} J/kg"
            ),
            StageEnding::Guard(kind) => write!(f, "stopped by the {} guard", kind.name()),
            StageEnding::Interrupted => write!(f, "interrupted (SIGINT/SIGTERM)"),
        }
    }
}

impl StageEnding {
    /// Whether `summary` (a summary.json) is that of a run SIGINT/SIGTERM ended: its last
    /// stage ended so, and its outputs stop there. Such a run is not finished; `validate
    /// --reuse` runs it again (or resumes it from its restart file).
    pub fn interrupted_summary(summary: &serde_json::Value) -> bool {
        summary["stages"]
            .as_array()
            .and_then(|stages| stages.last())
            .and_then(|stage| stage["ended_by"].as_str())
            == Some(StageEnding::Interrupted.to_string().as_str())
    }
}

#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct StageRecord {
    pub name: String,
    pub start_s: Real,
    pub end_s: Real,
    pub steps: u64,
    pub ended_by: String,
}

/// Everything `summary.json` holds.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct RunSummary {
    pub case: String,
    pub code: String,
    pub lambda: u32,
    pub cg_rule: crate::coarse_graining::CoarseGrainRule,
    pub n_particles: usize,
    pub n_particles_inserted: usize,
    /// Particles added by top-ups (`[[insert]] refill`).
    pub n_particles_refilled: u64,
    /// Particles that make up bodies built of particles (frozen, counted in `n_particles`).
    pub n_body_particles: usize,
    pub lost_particles: u64,
    pub steps: u64,
    pub dt_s: Real,
    pub contact_period_s: Real,
    pub stable_dt_s: Real,
    pub simulated_s: Real,
    pub wall_s: Real,
    pub particle_steps: u64,
    pub particle_steps_per_s: Real,
    pub threads: usize,
    pub repose_angle_deg: Option<Real>,
    pub repose_fit_r2: Option<Real>,
    pub repose_rule: Option<String>,
    /// Why the headline repose angle could not be measured, when the scene asks for one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repose_not_measured: Option<String>,
    pub runout_m: Option<Real>,
    pub repose_samples: Vec<ReposeSample>,
    pub stages: Vec<StageRecord>,
    /// Particles deleted in `[[delete]]` regions, and their mass.
    pub deleted_particles: u64,
    pub deleted_mass_kg: Real,
    pub conveying: Option<ConveyingSummary>,
    /// Porosity and pore sizes of the bed (`[packing]`), measured when its stage ends.
    pub packing: Option<PackingSummary>,
    pub warnings: Vec<String>,
    /// The guard that stopped the run early, if one did.
    pub stopped_by: Option<GuardTrip>,
    /// How close the run came to the guards' thresholds (none for reference codes).
    pub guard_peaks: Option<GuardPeaks>,
    pub scene_file: String,
    /// `Scene::digest` of the (coarse-grained) scene this run simulated.
    pub scene_digest: String,
    pub cgdem_version: String,
    /// The particles at the end (with `RunOptions::keep_final_state`).
    #[serde(skip)]
    pub final_state: Option<Particles>,
    /// The solver's arrays at the end (none for reference codes).
    pub memory: Option<crate::memory_use::MemoryUse>,
    /// The subdomains of a `--grid` run (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decomposition: Option<crate::decomposition::DecompositionSummary>,
}
