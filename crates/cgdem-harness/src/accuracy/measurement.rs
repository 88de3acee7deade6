//! What a sweep measured: each point's errors against its code's reference run with the
//! same seed, settings averaged over their seeds, the floor of the reference runs, the
//! Pareto front and the cheapest setting within a target.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::{Targets, SPREAD_STANDARD_ERRORS};
use crate::code::Code;
use crate::quantity::flow::{front_history_gap, FlowSeries};
use crate::quantity::repose::{profile_distance, read_profile};
use crate::runs::Outcome;
use cgdem_core::coarse_graining::CoarseGrainRule;

/// One run of the sweep, as recorded in `summary.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AccuracyPoint {
    pub case: String,
    pub code: Code,
    /// "reference" or the knob.
    pub series: String,
    /// The varied knob's value (the reference's for "reference").
    pub value: f64,
    /// The setting in words, e.g. "time.dt_fraction = 0.1".
    pub setting: String,
    pub lambda: u32,
    #[serde(default)]
    pub cg_rule: CoarseGrainRule,
    pub seed: u64,
    pub status: Outcome,
    pub reason: Option<String>,
    pub dir: PathBuf,
    pub reused: bool,
    pub n_particles: Option<u64>,
    pub steps: Option<u64>,
    pub particle_steps: Option<f64>,
    pub wall_s: Option<f64>,
    pub repose_angle_deg: Option<f64>,
    /// |angle - the angle of the same code's reference run with the same seed|, degrees.
    pub angle_error_deg: Option<f64>,
    /// RMS gap between the heap profile and the reference's, over the reference heap's
    /// height ([`profile_distance`]).
    pub profile_distance: Option<f64>,
    pub mass_flow_kg_s: Option<f64>,
    /// |Q / Q_reference - 1|.
    pub mass_flow_error: Option<f64>,
    /// Eq. (7) with the run's own measured fill ratio.
    pub eq7_mass_flow_kg_s: Option<f64>,
    /// |Q / Q_Eq7 - 1|.
    pub eq7_error: Option<f64>,
    /// The collapse's characteristic time (front at half its largest advance,
    /// [`FlowSeries::t_half`]) in the measured stage.
    #[serde(default)]
    pub t_half_s: Option<f64>,
    /// |t_half / t_half of the reference run with the same seed - 1|.
    #[serde(default)]
    pub t_half_error: Option<f64>,
    /// Porosity of a packing (`summary.json` `packing.porosity`).
    #[serde(default)]
    pub porosity: Option<f64>,
    /// |porosity - the reference run's|.
    #[serde(default)]
    pub porosity_error: Option<f64>,
    /// Mean pore diameter of a packing (`packing.mean_pore_diameter_m`) over the diameter of
    /// the run's particles (parcels): pores of a similar packing scale with its particles.
    #[serde(default)]
    pub pore_diameter_d: Option<f64>,
    /// |pore_diameter_d / the reference run's - 1|.
    #[serde(default)]
    pub pore_size_error: Option<f64>,
    /// The stage whose flow (front, wall height) the run measured (the repose stage).
    #[serde(default)]
    pub flow_stage: Option<String>,
    /// Largest gap, over the flow, between the fractions of their run-outs the run's front
    /// and the reference run's (same seed) have covered ([`front_history_gap`]).
    #[serde(default)]
    pub front_error: Option<f64>,
    /// A silo's discharge rate, kg/s (mass: a parcel counts lambda^3 grains), over the
    /// sweep's window, with its block standard error (`crate::quantity::discharge::discharge_rate`).
    #[serde(default)]
    pub discharge_rate_kg_s: Option<f64>,
    #[serde(default)]
    pub discharge_rate_std_error_kg_s: Option<f64>,
    /// |Q / Q of the reference run with the same seed - 1|.
    #[serde(default)]
    pub discharge_rate_error: Option<f64>,
    /// The fill's bulk density when the gate opened, kg/m3 (Beverloo's rho_b).
    #[serde(default)]
    pub bulk_density_kg_m3: Option<f64>,
    /// The run's particle (parcel) diameter, m.
    #[serde(default)]
    pub particle_diameter_m: Option<f64>,
    /// When the discharge stopped (s after the gate opened): no grain left over the last
    /// two blocks of the window, an arch over the orifice (a clog).
    #[serde(default)]
    pub flow_stopped_at_s: Option<f64>,
    /// A drum's dynamic angle of repose, deg: its mean over the steady frames
    /// (`crate::quantity::drum`).
    #[serde(default)]
    pub dynamic_angle_deg: Option<f64>,
    /// |dynamic angle - the reference run's with the same seed|, deg.
    #[serde(default)]
    pub dynamic_angle_error_deg: Option<f64>,
    /// The period of a drum's zone-count swing over the steady frames, s.
    #[serde(default)]
    pub mixing_period_s: Option<f64>,
    /// |period / the reference run's with the same seed - 1|.
    #[serde(default)]
    pub mixing_period_error: Option<f64>,
    /// A drum's Lacey index, mean over the steady frames (0 segregated, 1 random).
    #[serde(default)]
    pub mixing_index: Option<f64>,
    /// |Lacey index - the reference run's with the same seed|.
    #[serde(default)]
    pub mixing_index_error: Option<f64>,
    /// The large grains' share of the solid volume in a drum's zones 1 and 2 (steady means):
    /// the segregation the zones see, the same measure at every lambda.
    #[serde(default)]
    pub large_share_zones: Option<[f64; 2]>,
}

impl AccuracyPoint {
    /// The run with none of its errors against a reference (`measure` sets them).
    pub(crate) fn without_errors(&self) -> AccuracyPoint {
        AccuracyPoint {
            angle_error_deg: None,
            profile_distance: None,
            mass_flow_error: None,
            eq7_error: None,
            t_half_error: None,
            porosity_error: None,
            pore_size_error: None,
            front_error: None,
            discharge_rate_error: None,
            dynamic_angle_error_deg: None,
            mixing_period_error: None,
            mixing_index_error: None,
            ..self.clone()
        }
    }
}

/// The cheapest point within a target error, per case, code and error measure.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CheapestSetting {
    pub case: String,
    pub code: Code,
    pub measure: String,
    pub target: f64,
    /// None: no point other than the reference met the target.
    pub setting: Option<String>,
    /// Means over the setting's seeds.
    pub wall_s: Option<f64>,
    pub particle_steps: Option<f64>,
    pub error: Option<f64>,
    /// Standard error of `error` over the seeds (None with one seed).
    pub error_se: Option<f64>,
    /// Seeds the setting was measured with.
    pub seeds: usize,
    pub reference_wall_s: Option<f64>,
    /// The largest difference between two reference runs with different insertion seeds.
    pub floor: Option<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AccuracySummary {
    pub points: Vec<AccuracyPoint>,
    pub cheapest: Vec<CheapestSetting>,
}

/// The error measures, each with the unit its target and axis use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measure {
    Angle,
    Profile,
    MassFlow,
    Eq7,
    THalf,
    Front,
    Porosity,
    PoreSize,
    DischargeRate,
    DynamicAngle,
    MixingPeriod,
    MixingIndex,
}

impl Measure {
    pub const ALL: [Measure; 12] = [
        Measure::Angle,
        Measure::Profile,
        Measure::MassFlow,
        Measure::Eq7,
        Measure::THalf,
        Measure::Front,
        Measure::Porosity,
        Measure::PoreSize,
        Measure::DischargeRate,
        Measure::DynamicAngle,
        Measure::MixingPeriod,
        Measure::MixingIndex,
    ];

    /// The run's error under this measure.
    pub fn of(self, p: &AccuracyPoint) -> Option<f64> {
        match self {
            Measure::Angle => p.angle_error_deg,
            Measure::Profile => p.profile_distance,
            Measure::MassFlow => p.mass_flow_error,
            Measure::Eq7 => p.eq7_error,
            Measure::THalf => p.t_half_error,
            Measure::Front => p.front_error,
            Measure::Porosity => p.porosity_error,
            Measure::PoreSize => p.pore_size_error,
            Measure::DischargeRate => p.discharge_rate_error,
            Measure::DynamicAngle => p.dynamic_angle_error_deg,
            Measure::MixingPeriod => p.mixing_period_error,
            Measure::MixingIndex => p.mixing_index_error,
        }
    }

    /// The quantity's short name (`cgdem advise --quantity`).
    pub fn quantity(self) -> &'static str {
        match self {
            Measure::Angle => "repose_angle",
            Measure::Profile => "profile",
            Measure::MassFlow => "mass_flow",
            Measure::Eq7 => "mass_flow_eq7",
            Measure::THalf => "t_half",
            Measure::Front => "front_history",
            Measure::Porosity => "porosity",
            Measure::PoreSize => "pore_size",
            Measure::DischargeRate => "discharge_rate",
            Measure::DynamicAngle => "dynamic_angle",
            Measure::MixingPeriod => "mixing_period",
            Measure::MixingIndex => "mixing_index",
        }
    }

    pub fn from_quantity(name: &str) -> Option<Measure> {
        Self::ALL.into_iter().find(|m| m.quantity() == name)
    }

    pub fn name(self) -> &'static str {
        match self {
            Measure::Angle => "repose angle vs reference",
            Measure::Profile => "heap profile vs reference",
            Measure::MassFlow => "mass flow vs reference",
            Measure::Eq7 => "mass flow vs Eq. (7)",
            Measure::THalf => "t_half vs reference",
            Measure::Front => "front history vs reference",
            Measure::Porosity => "porosity vs reference",
            Measure::PoreSize => "pore size (in diameters) vs reference",
            Measure::DischargeRate => "discharge rate vs reference",
            Measure::DynamicAngle => "dynamic angle vs reference",
            Measure::MixingPeriod => "mixing period vs reference",
            Measure::MixingIndex => "mixing index vs reference",
        }
    }

    pub(crate) fn stem(self) -> &'static str {
        match self {
            Measure::Angle => "angle_error",
            Measure::Profile => "profile_distance",
            Measure::MassFlow => "mass_flow_error",
            Measure::Eq7 => "eq7_error",
            Measure::THalf => "t_half_error",
            Measure::Front => "front_error",
            Measure::Porosity => "porosity_error",
            Measure::PoreSize => "pore_size_error",
            Measure::DischargeRate => "discharge_rate_error",
            Measure::DynamicAngle => "dynamic_angle_error",
            Measure::MixingPeriod => "mixing_period_error",
            Measure::MixingIndex => "mixing_index_error",
        }
    }

    pub(crate) fn axis(self) -> &'static str {
        match self {
            Measure::Angle => "|repose angle - reference| [deg]",
            Measure::Profile => "RMS profile gap / reference heap height [-]",
            Measure::MassFlow => "|Q / Q_reference - 1| [-]",
            Measure::Eq7 => "|Q / Q_Eq.(7) - 1| [-]",
            Measure::THalf => "|t_half / t_half,reference - 1| [-]",
            Measure::Front => "largest gap in run-out covered [-]",
            Measure::Porosity => "|porosity - reference| [-]",
            Measure::PoreSize => "|pore diameter / d over the reference's - 1| [-]",
            Measure::DischargeRate => "|W / W_reference - 1| (discharge rate) [-]",
            Measure::DynamicAngle => "|dynamic angle - reference| [deg]",
            Measure::MixingPeriod => "|T / T_reference - 1| (zone-count swing) [-]",
            Measure::MixingIndex => "|Lacey index - reference| [-]",
        }
    }

    pub(crate) fn target(self, t: &Targets) -> f64 {
        match self {
            Measure::Angle => t.angle_deg,
            Measure::Profile => t.profile,
            Measure::MassFlow | Measure::Eq7 => t.mass_flow,
            Measure::THalf => t.t_half,
            Measure::Front => t.front,
            Measure::Porosity => t.porosity,
            Measure::PoreSize => t.pore_size,
            Measure::DischargeRate => t.discharge_rate,
            Measure::DynamicAngle => t.dynamic_angle_deg,
            Measure::MixingPeriod => t.mixing_period,
            Measure::MixingIndex => t.mixing_index,
        }
    }

    /// A value in the measure's unit, for tables and answers.
    pub fn format(self, v: f64) -> String {
        match self {
            Measure::Angle | Measure::DynamicAngle => format!("{v:.2} deg"),
            Measure::Porosity | Measure::MixingIndex => format!("{v:.4}"),
            _ => format!("{:.1}%", 100.0 * v),
        }
    }

    /// Measured against the reference run: the reference itself is zero by construction.
    pub(crate) fn against_reference(self) -> bool {
        self != Measure::Eq7
    }
}

/// Indices of the points on the Pareto front of (cost, error), cheapest first: those that no
/// other point beats in both (no cheaper-or-equal point has a smaller-or-equal error, one
/// strictly). Points with a non-finite cost or error are not candidates.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&k| points[k].0.is_finite() && points[k].1.is_finite())
        .collect();
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for k in order {
        if points[k].1 < best {
            best = points[k].1;
            front.push(k);
        }
    }
    front
}

/// The index of the cheapest point (least cost) whose error is within `target` (ties: the
/// smaller error).
pub fn cheapest_within(points: &[(f64, f64)], target: f64) -> Option<usize> {
    (0..points.len())
        .filter(|&k| points[k].0.is_finite() && points[k].1 <= target)
        .min_by(|&a, &b| {
            points[a]
                .0
                .total_cmp(&points[b].0)
                .then(points[a].1.total_cmp(&points[b].1))
        })
}

/// Fills each point's errors against its code's reference run with the same seed.
pub(crate) fn measure(points: &mut [AccuracyPoint]) {
    let references: Vec<AccuracyPoint> = points
        .iter()
        .filter(|p| p.series == "reference" && p.status == Outcome::Ok)
        .cloned()
        .collect();
    for p in points.iter_mut().filter(|p| p.status == Outcome::Ok) {
        if let (Some(q), Some(eq7)) = (p.mass_flow_kg_s, p.eq7_mass_flow_kg_s) {
            p.eq7_error = Some((q / eq7 - 1.0).abs()).filter(|e| e.is_finite());
        }
        let Some(r) = references
            .iter()
            .find(|r| r.code == p.code && r.seed == p.seed)
        else {
            continue;
        };
        p.angle_error_deg = difference(Measure::Angle, p, r);
        p.profile_distance = difference(Measure::Profile, p, r);
        p.mass_flow_error = difference(Measure::MassFlow, p, r);
        p.t_half_error = difference(Measure::THalf, p, r);
        p.front_error = difference(Measure::Front, p, r);
        p.porosity_error = difference(Measure::Porosity, p, r);
        p.pore_size_error = difference(Measure::PoreSize, p, r);
        p.discharge_rate_error = difference(Measure::DischargeRate, p, r);
        p.dynamic_angle_error_deg = difference(Measure::DynamicAngle, p, r);
        p.mixing_period_error = difference(Measure::MixingPeriod, p, r);
        p.mixing_index_error = difference(Measure::MixingIndex, p, r);
    }
}

/// How far run `p` is from run `r` under measure `m` (None where either measured nothing).
fn difference(m: Measure, p: &AccuracyPoint, r: &AccuracyPoint) -> Option<f64> {
    let finite = |v: f64| Some(v).filter(|v| v.is_finite());
    match m {
        Measure::Angle => finite((p.repose_angle_deg? - r.repose_angle_deg?).abs()),
        Measure::Profile => {
            p.repose_angle_deg?;
            r.repose_angle_deg?;
            // A profile that cannot be read gives the point no profile error.
            let profile = |q: &AccuracyPoint| read_profile(&q.dir).unwrap_or_default();
            profile_distance(&profile(r), &profile(p))
        }
        Measure::MassFlow => finite((p.mass_flow_kg_s? / r.mass_flow_kg_s? - 1.0).abs()),
        Measure::Eq7 => finite((p.eq7_error? - r.eq7_error?).abs()),
        Measure::THalf => finite((p.t_half_s? / r.t_half_s? - 1.0).abs()),
        Measure::Front => {
            let flow = |q: &AccuracyPoint| FlowSeries::read(&q.dir, q.flow_stage.as_deref()?);
            finite(front_history_gap(&flow(r)?, &flow(p)?)?)
        }
        Measure::Porosity => finite((p.porosity? - r.porosity?).abs()),
        Measure::PoreSize => finite((p.pore_diameter_d? / r.pore_diameter_d? - 1.0).abs()),
        Measure::DischargeRate => {
            finite((p.discharge_rate_kg_s? / r.discharge_rate_kg_s? - 1.0).abs())
        }
        Measure::DynamicAngle => finite((p.dynamic_angle_deg? - r.dynamic_angle_deg?).abs()),
        Measure::MixingPeriod => finite((p.mixing_period_s? / r.mixing_period_s? - 1.0).abs()),
        Measure::MixingIndex => finite((p.mixing_index? - r.mixing_index?).abs()),
    }
}

/// The floor of a code under measure `m`: the largest difference between two of its
/// reference runs (same setting, different insertion seeds); None with fewer than two.
pub(crate) fn floor(code: Code, m: Measure, points: &[AccuracyPoint]) -> Option<f64> {
    let references: Vec<&AccuracyPoint> = points
        .iter()
        .filter(|p| p.code == code && p.series == "reference" && p.status == Outcome::Ok)
        .collect();
    let mut worst: Option<f64> = None;
    for (k, a) in references.iter().enumerate() {
        for b in &references[k + 1..] {
            if let Some(d) = difference(m, b, a) {
                worst = Some(worst.map_or(d, |w| w.max(d)));
            }
        }
    }
    worst
}

/// One setting of one code (the reference or a series point) over the seeds it ran with.
pub(crate) struct Setting<'a> {
    pub series: &'a str,
    pub setting: &'a str,
    pub value: f64,
    pub runs: Vec<&'a AccuracyPoint>,
}

impl Setting<'_> {
    /// Mean over the runs that measured `m`, with its cost `cost` (the same runs' mean), the
    /// standard error of the mean (None with one run) and the number of runs.
    pub fn mean(&self, m: Measure, cost: Cost) -> Option<SettingMean> {
        let pairs: Vec<(f64, f64)> = self
            .runs
            .iter()
            .filter_map(|p| Some((cost.of(p)?, m.of(p)?)))
            .collect();
        let n = pairs.len();
        if n == 0 {
            return None;
        }
        let cost = pairs.iter().map(|p| p.0).sum::<f64>() / n as f64;
        let error = pairs.iter().map(|p| p.1).sum::<f64>() / n as f64;
        let se = (n > 1).then(|| {
            let var = pairs.iter().map(|p| (p.1 - error).powi(2)).sum::<f64>() / (n - 1) as f64;
            (var / n as f64).sqrt()
        });
        Some(SettingMean { cost, error, se, n })
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SettingMean {
    pub cost: f64,
    pub error: f64,
    pub se: Option<f64>,
    pub n: usize,
}

/// The settings of `code`, in the order of the points, each with its successful runs.
pub(crate) fn settings(code: Code, points: &[AccuracyPoint]) -> Vec<Setting<'_>> {
    let mut out: Vec<Setting> = Vec::new();
    for p in points
        .iter()
        .filter(|p| p.code == code && p.status == Outcome::Ok)
    {
        match out
            .iter_mut()
            .find(|s| s.series == p.series && s.setting == p.setting)
        {
            Some(s) => s.runs.push(p),
            None => out.push(Setting {
                series: &p.series,
                setting: &p.setting,
                value: p.value,
                runs: vec![p],
            }),
        }
    }
    out
}

pub(crate) fn measure_named(name: &str) -> Measure {
    Measure::ALL
        .into_iter()
        .find(|m| m.name() == name)
        .unwrap_or(Measure::Angle)
}

/// The settings to choose from: the series, and the reference where its error is not zero
/// by construction.
pub(crate) fn candidates(code: Code, m: Measure, points: &[AccuracyPoint]) -> Vec<Setting<'_>> {
    settings(code, points)
        .into_iter()
        .filter(|s| s.series != "reference" || !m.against_reference())
        .collect()
}

pub(crate) fn cheapest_setting(
    case: &str,
    code: Code,
    m: Measure,
    targets: &Targets,
    points: &[AccuracyPoint],
) -> CheapestSetting {
    // Chosen by particle-steps, not wall time: within one code the two are proportional at a
    // given per-step cost, and on a shared machine the wall time of equal work varied
    // two-fold between runs (reports/accuracy/one-seed-2026-11-22/NOTE.md). A setting's
    // error is its mean over the seeds. A setting qualifies only when every seed ran to its
    // end (a seed stopped by a guard means the setting does not hold) and its mean error plus
    // spread meets the target (issue 24: chance must not choose it).
    let found: Vec<(Setting, SettingMean)> = candidates(code, m, points)
        .into_iter()
        .filter(|s| every_seed_ran(code, s, points))
        .filter_map(|s| {
            let mean = s.mean(m, Cost::ParticleSteps)?;
            Some((s, mean))
        })
        .collect();
    let cost: Vec<(f64, f64)> = found
        .iter()
        .map(|(_, a)| (a.cost, error_reach(a)))
        .collect();
    let best = cheapest_within(&cost, m.target(targets)).map(|k| &found[k]);
    let reference = settings(code, points)
        .into_iter()
        .find(|s| s.series == "reference");
    let mean_of = |s: &Setting, f: fn(&AccuracyPoint) -> Option<f64>| {
        let v: Vec<f64> = s.runs.iter().filter_map(|p| f(p)).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    CheapestSetting {
        case: case.to_string(),
        code,
        measure: m.name().into(),
        target: m.target(targets),
        setting: best.map(|(s, _)| s.setting.to_string()),
        wall_s: best.and_then(|(s, _)| mean_of(s, |p| p.wall_s)),
        particle_steps: best.map(|(_, a)| a.cost),
        error: best.map(|(_, a)| a.error),
        error_se: best.and_then(|(_, a)| a.se),
        seeds: best.map_or(0, |(_, a)| a.n),
        reference_wall_s: reference.as_ref().and_then(|s| mean_of(s, |p| p.wall_s)),
        floor: floor(code, m, points),
    }
}

/// Mean error plus its spread over the seeds (`SPREAD_STANDARD_ERRORS` standard errors of
/// the mean; none with one seed).
fn error_reach(mean: &SettingMean) -> f64 {
    mean.error + mean.se.map_or(0.0, |se| SPREAD_STANDARD_ERRORS * se)
}

/// Whether every run of `setting` (each seed) finished.
fn every_seed_ran(code: Code, setting: &Setting, points: &[AccuracyPoint]) -> bool {
    points
        .iter()
        .filter(|p| p.code == code && p.series == setting.series && p.setting == setting.setting)
        .all(|p| p.status == Outcome::Ok)
}

/// The cost a figure's x axis shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Cost {
    WallTime,
    ParticleSteps,
}

impl Cost {
    pub fn of(self, p: &AccuracyPoint) -> Option<f64> {
        match self {
            Cost::WallTime => p.wall_s,
            Cost::ParticleSteps => p.particle_steps,
        }
    }

    pub(crate) fn name(self) -> &'static str {
        match self {
            Cost::WallTime => "wall time",
            Cost::ParticleSteps => "particle-steps",
        }
    }
}
