//! Error against run time (`[[accuracy]]` in a suite): what each knob that buys speed costs in
//! accuracy.
//!
//! A sweep names a case, a reference setting (the finest affordable) and one series per knob:
//! the coarse-graining level `lambda`, or a scene key (`time.dt_fraction`,
//! `neighbor.skin_fraction`, `body[0].cell_size`). Each point changes one knob from the
//! reference and is judged against the same code's reference run: repose-angle difference and
//! heap-profile distance for a collapse, mass-flow difference (and the distance from Eq. 7) for
//! a screw feeder. Every setting (the reference and each point) is run with each of the
//! sweep's insertion seeds, and a point's error is taken against the reference run with the
//! same seed (the same packing), so the packing largely cancels; a setting's error is the mean
//! over seeds with its standard error (the error bars). The largest difference between two
//! reference runs with different seeds is the floor below which a difference is the packing,
//! not the knob. The report plots error against wall time on log axes with each code's Pareto
//! front, and tables the cheapest setting within each target.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::dynamics::{flow_difference, FlowSeries, FLOW_GRID_S};
use crate::code::Code;
use crate::csv_table::CsvTable;
use crate::report::{write_figure, Cell, Figure, Report, Section, Series, SeriesStyle, Table};
use crate::runs::{
    output_error, run_concurrently, run_one, Outcome, ValidateError, ValidateOptions,
};
use crate::suite_entry::{parse_codes, parse_variant, rule_names, SuiteError};
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::io::{write_atomic, CsvBuffer};
use cgdem_core::scene::{Override, Scene};

/// Spread = this many standard errors of the mean over seeds (the matrix's columns and
/// `cgdem advise`).
pub const SPREAD_STANDARD_ERRORS: f64 = 2.0;

/// What a point varies: the coarse-graining level or a scene key.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Knob {
    Lambda,
    Scene(String),
}

impl Knob {
    fn parse(name: &str) -> Knob {
        match name {
            "lambda" => Knob::Lambda,
            key => Knob::Scene(key.to_string()),
        }
    }

    pub fn name(&self) -> &str {
        match self {
            Knob::Lambda => "lambda",
            Knob::Scene(key) => key,
        }
    }

    /// `time.dt_fraction` -> `time_dt_fraction`, for directory names.
    fn file_name(&self) -> String {
        self.name()
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect::<String>()
            .trim_matches('_')
            .to_string()
    }
}

/// One knob's values, each run with every code listed.
#[derive(Clone, Debug, PartialEq)]
pub struct KnobSeries {
    pub knob: Knob,
    pub values: Vec<f64>,
    pub codes: Vec<Code>,
    /// The coarse-graining rule of this series' runs (the sweep's unless it names one).
    pub rule: CoarseGrainRule,
}

impl KnobSeries {
    /// The series' name in tables, figures and `summary.json`: the knob, with the rule when
    /// it is not the sweep's.
    fn name(&self, sweep_rule: CoarseGrainRule) -> String {
        if self.rule == sweep_rule {
            self.knob.name().to_string()
        } else {
            format!("{} ({})", self.knob.name(), self.rule.name())
        }
    }
}

/// Target errors for the cheapest-setting table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Targets {
    pub angle_deg: f64,
    /// Heap-profile distance, as a fraction of the reference heap's height.
    pub profile: f64,
    /// Relative mass-flow error (against the reference run and against Eq. 7).
    pub mass_flow: f64,
    /// Relative error of the collapse's characteristic time t_half.
    pub t_half: f64,
    /// Front history: largest gap over the flow in the fraction of its run-out each front
    /// has covered.
    pub front: f64,
    /// Absolute porosity difference.
    pub porosity: f64,
    /// Relative difference of the mean pore diameter in particle diameters.
    pub pore_size: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct AccuracySweep {
    pub file: PathBuf,
    /// Overrides every point shares (e.g. a shorter run), with `variant` naming them.
    pub overrides: Vec<Override>,
    pub variant: String,
    /// Insertion seeds: every setting runs with each (issue 24: at least 3 where affordable).
    pub seeds: Vec<u64>,
    /// The coarse-graining rule of the reference and of series that name none.
    pub rule: CoarseGrainRule,
    /// Every knob's value at the reference; `lambda` always among them.
    pub reference: BTreeMap<Knob, f64>,
    pub series: Vec<KnobSeries>,
    pub targets: Targets,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSweep {
    file: PathBuf,
    variant: String,
    #[serde(default)]
    set: Vec<String>,
    seeds: Option<Vec<u64>>,
    cg_rule: Option<String>,
    reference: BTreeMap<String, toml::Value>,
    series: Vec<RawSeries>,
    angle_target_deg: Option<f64>,
    profile_target: Option<f64>,
    mass_flow_target: Option<f64>,
    t_half_target: Option<f64>,
    front_target: Option<f64>,
    porosity_target: Option<f64>,
    pore_size_target: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSeries {
    knob: String,
    values: Vec<toml::Value>,
    codes: Option<Vec<String>>,
    cg_rule: Option<String>,
}

fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(f) => Some(*f),
        _ => None,
    }
}

impl AccuracySweep {
    /// Validates `[[accuracy]]` entry `k` of suite file `path`.
    pub(super) fn from_raw(raw: RawSweep, k: usize, path: &Path) -> Result<Self, SuiteError> {
        let invalid = |field: &str, value: String, allowed: &str| SuiteError::Invalid {
            file: path.to_path_buf(),
            field: format!("accuracy[{k}].{field}"),
            value,
            allowed: allowed.into(),
        };
        // An accuracy sweep always names its variant: its runs sit beside the case's own.
        let overrides = parse_variant(
            &raw.set,
            Some(&raw.variant),
            &format!("accuracy[{k}]"),
            path,
        )?;
        let parse_rule = |name: &str, field: &str| {
            CoarseGrainRule::from_name(name)
                .ok_or_else(|| invalid(field, format!("\"{name}\""), &rule_names()))
        };
        let sweep_rule = match &raw.cg_rule {
            None => CoarseGrainRule::Seed,
            Some(name) => parse_rule(name, "cg_rule")?,
        };
        let lambda_ok = |v: f64| v >= 1.0 && v.fract() == 0.0 && (v as u32).is_power_of_two();
        let mut reference = BTreeMap::new();
        for (key, value) in &raw.reference {
            let v = number(value)
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| {
                    invalid(
                        &format!("reference.{key}"),
                        value.to_string(),
                        "a positive number",
                    )
                })?;
            reference.insert(Knob::parse(key), v);
        }
        let lambda = *reference.entry(Knob::Lambda).or_insert(1.0);
        if !lambda_ok(lambda) {
            return Err(invalid(
                "reference.lambda",
                lambda.to_string(),
                "a power of two",
            ));
        }
        let mut series = Vec::new();
        for (j, s) in raw.series.into_iter().enumerate() {
            let knob = Knob::parse(&s.knob);
            if !reference.contains_key(&knob) {
                return Err(invalid(
                    &format!("series[{j}].knob"),
                    format!("\"{}\"", s.knob),
                    "a knob whose reference value is given in [accuracy.reference]",
                ));
            }
            let values = s
                .values
                .iter()
                .map(|v| number(v).filter(|v| v.is_finite() && *v > 0.0))
                .collect::<Option<Vec<f64>>>()
                .filter(|v| !v.is_empty())
                .filter(|v| knob != Knob::Lambda || v.iter().all(|&l| lambda_ok(l)))
                .ok_or_else(|| {
                    invalid(
                        &format!("series[{j}].values"),
                        format!("{:?}", s.values),
                        "one or more positive numbers (powers of two for lambda)",
                    )
                })?;
            let codes = match s.codes {
                None => vec![Code::Cgdem],
                Some(names) => {
                    parse_codes(&names, &format!("accuracy[{k}].series[{j}].codes"), path)?
                }
            };
            let rule = match s.cg_rule {
                None => sweep_rule,
                Some(name) => parse_rule(&name, &format!("series[{j}].cg_rule"))?,
            };
            series.push(KnobSeries {
                knob,
                values,
                codes,
                rule,
            });
        }
        let target = |field: &str, v: Option<f64>, default: f64| {
            let v = v.unwrap_or(default);
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(invalid(field, v.to_string(), "a positive number"))
            }
        };
        let seeds = raw.seeds.unwrap_or_else(|| vec![1]);
        let mut distinct = seeds.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if seeds.is_empty() || distinct.len() != seeds.len() {
            return Err(invalid(
                "seeds",
                format!("{seeds:?}"),
                "one or more distinct insertion seeds, e.g. [1, 2, 3]",
            ));
        }
        Ok(AccuracySweep {
            file: raw.file,
            overrides,
            variant: raw.variant,
            seeds,
            rule: sweep_rule,
            reference,
            series,
            targets: Targets {
                angle_deg: target("angle_target_deg", raw.angle_target_deg, 1.0)?,
                profile: target("profile_target", raw.profile_target, 0.05)?,
                mass_flow: target("mass_flow_target", raw.mass_flow_target, 0.05)?,
                t_half: target("t_half_target", raw.t_half_target, 0.1)?,
                front: target("front_target", raw.front_target, 0.1)?,
                porosity: target("porosity_target", raw.porosity_target, 0.02)?,
                pore_size: target("pore_size_target", raw.pore_size_target, 0.1)?,
            },
        })
    }

    /// Every code that runs a series (cgdem first), each of which also runs the reference.
    fn codes(&self) -> Vec<Code> {
        let mut codes: Vec<Code> = self.series.iter().flat_map(|s| s.codes.clone()).collect();
        codes.sort();
        codes.dedup();
        codes
    }

    /// The name of the case the sweep reports (its reference scene's, variant included).
    pub fn case_name(&self, origin: &Path) -> Result<String, String> {
        Ok(self.scene(&self.reference, origin)?.0.name)
    }

    /// The scene of the setting `knobs` (the reference with some knobs changed): the file
    /// with the shared overrides, then one override per scene knob; and its level.
    fn scene(&self, knobs: &BTreeMap<Knob, f64>, origin: &Path) -> Result<(Scene, u32), String> {
        let mut overrides = self.overrides.clone();
        for (knob, value) in knobs {
            if let Knob::Scene(key) = knob {
                overrides.push(
                    Override::parse(&format!("{key} = {value:?}"), origin)
                        .map_err(|e| e.to_string())?,
                );
            }
        }
        let mut scene =
            Scene::load_with_overrides(&self.file, &overrides).map_err(|e| e.to_string())?;
        scene.name = format!("{}-{}", scene.name, self.variant);
        Ok((scene, knobs[&Knob::Lambda] as u32))
    }
}

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
}

impl AccuracyPoint {
    /// The run with none of its errors against a reference (`measure` sets them).
    fn without_errors(&self) -> AccuracyPoint {
        AccuracyPoint {
            angle_error_deg: None,
            profile_distance: None,
            mass_flow_error: None,
            eq7_error: None,
            t_half_error: None,
            porosity_error: None,
            pore_size_error: None,
            front_error: None,
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
}

impl Measure {
    pub const ALL: [Measure; 8] = [
        Measure::Angle,
        Measure::Profile,
        Measure::MassFlow,
        Measure::Eq7,
        Measure::THalf,
        Measure::Front,
        Measure::Porosity,
        Measure::PoreSize,
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
        }
    }

    fn stem(self) -> &'static str {
        match self {
            Measure::Angle => "angle_error",
            Measure::Profile => "profile_distance",
            Measure::MassFlow => "mass_flow_error",
            Measure::Eq7 => "eq7_error",
            Measure::THalf => "t_half_error",
            Measure::Front => "front_error",
            Measure::Porosity => "porosity_error",
            Measure::PoreSize => "pore_size_error",
        }
    }

    fn axis(self) -> &'static str {
        match self {
            Measure::Angle => "|repose angle - reference| [deg]",
            Measure::Profile => "RMS profile gap / reference heap height [-]",
            Measure::MassFlow => "|Q / Q_reference - 1| [-]",
            Measure::Eq7 => "|Q / Q_Eq.(7) - 1| [-]",
            Measure::THalf => "|t_half / t_half,reference - 1| [-]",
            Measure::Front => "largest gap in run-out covered [-]",
            Measure::Porosity => "|porosity - reference| [-]",
            Measure::PoreSize => "|pore diameter / d over the reference's - 1| [-]",
        }
    }

    fn target(self, t: &Targets) -> f64 {
        match self {
            Measure::Angle => t.angle_deg,
            Measure::Profile => t.profile,
            Measure::MassFlow | Measure::Eq7 => t.mass_flow,
            Measure::THalf => t.t_half,
            Measure::Front => t.front,
            Measure::Porosity => t.porosity,
            Measure::PoreSize => t.pore_size,
        }
    }

    /// A value in the measure's unit, for tables and answers.
    pub fn format(self, v: f64) -> String {
        match self {
            Measure::Angle => format!("{v:.2} deg"),
            Measure::Porosity => format!("{v:.4}"),
            _ => format!("{:.1}%", 100.0 * v),
        }
    }

    /// Measured against the reference run: the reference itself is zero by construction.
    fn against_reference(self) -> bool {
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

/// RMS gap between two heap profiles `(x, h)` (x ascending), over the reference's largest
/// height: both are interpolated linearly on the union of their abscissae from the first to
/// the last, and a profile is zero beyond its last point (no deposit) and constant before its
/// first (the bins start half a width from the wall).
pub fn profile_distance(reference: &[(f64, f64)], other: &[(f64, f64)]) -> Option<f64> {
    let height = reference.iter().map(|p| p.1).fold(0.0, f64::max);
    if reference.is_empty() || other.is_empty() || height <= 0.0 {
        return None;
    }
    let at = |profile: &[(f64, f64)], x: f64| -> f64 {
        let k = profile.partition_point(|p| p.0 < x);
        if k == 0 {
            profile[0].1
        } else if k == profile.len() {
            0.0
        } else {
            let (a, b) = (profile[k - 1], profile[k]);
            a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
        }
    };
    let mut xs: Vec<f64> = reference.iter().chain(other).map(|p| p.0).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let sum: f64 = xs
        .iter()
        .map(|&x| (at(reference, x) - at(other, x)).powi(2))
        .sum();
    Some((sum / xs.len() as f64).sqrt() / height)
}

/// Runs every `[[accuracy]]` sweep of the suite, writes the "Error against run time" section
/// of the report and its figures; None when the suite has no sweep.
pub(super) fn run_sweeps(
    sweeps: &[AccuracySweep],
    suite_file: &Path,
    options: &ValidateOptions,
    report: &mut Report,
) -> Result<Option<AccuracySummary>, ValidateError> {
    if sweeps.is_empty() {
        return Ok(None);
    }
    let section = report.section("Error against run time");
    section.paragraph(
        "For each case: a reference setting (the finest affordable) and one series per knob \
         that buys speed (coarse-graining level lambda, time-step fraction of the contact \
         period, neighbour skin, SDF cell size), each point changing one knob from the \
         reference. Every setting runs with each of the sweep's insertion seeds, and a run's \
         error is against the same code's reference run with the same seed (the same \
         packing); a setting's error is the mean over its seeds, the error bars one standard \
         error of that mean. The largest difference between two reference runs with \
         different seeds (\"floor\") shows how far a different random packing alone moves the \
         result. Wall time is the whole run (insertion and output included) on the \
         machine and thread count in the provenance; the machine is shared, so wall times \
         carry some percent of noise. Figures: error against wall time on log axes, one series \
         per knob and code, the Pareto front of each code dashed, the target dotted.",
    );
    let mut summary = AccuracySummary {
        points: Vec::new(),
        cheapest: Vec::new(),
    };
    for sweep in sweeps {
        let mut points = run_sweep(sweep, suite_file, options)?;
        measure(&mut points);
        let case = points.first().map(|p| p.case.clone()).unwrap_or_default();
        let dir = options.out.join("figures").join("accuracy").join(&case);
        let cheapest = write_sweep_section(section, sweep, &case, &points, &dir, None)?;
        let own = own_rule_sweeps(sweep, &case, &points);
        summary.points.extend(points);
        summary.cheapest.extend(cheapest);
        for (own_sweep, mut own_points) in own {
            measure(&mut own_points);
            let own_case = own_points[0].case.clone();
            let dir = options.out.join("figures").join("accuracy").join(&own_case);
            let note = format!(
                "The {} rule's own matrix: its levels against its own lambda = {}, from the runs of case {case} (none made again).",
                own_sweep.rule.name(),
                own_sweep.reference[&Knob::Lambda]
            );
            let cheapest = write_sweep_section(
                section,
                &own_sweep,
                &own_case,
                &own_points,
                &dir,
                Some(&note),
            )?;
            summary.points.extend(own_points);
            summary.cheapest.extend(cheapest);
        }
    }
    Ok(Some(summary))
}

/// Each other rule's own matrix, from runs already made: a lambda series under another rule
/// than the reference's that includes the reference's level is also a sweep of its own, with
/// that level as its reference, reported as case `<case>-<rule>-rule`. "How far does lambda
/// 16 move from lambda 8 under this rule" then needs no second set of runs (the scene name
/// is part of a run's digest, so a second sweep of the same runs would make them again).
fn own_rule_sweeps(
    sweep: &AccuracySweep,
    case: &str,
    points: &[AccuracyPoint],
) -> Vec<(AccuracySweep, Vec<AccuracyPoint>)> {
    let Some(&level) = sweep.reference.get(&Knob::Lambda) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for s in sweep
        .series
        .iter()
        .filter(|s| s.knob == Knob::Lambda && s.rule != sweep.rule && s.values.contains(&level))
    {
        let series = s.name(sweep.rule);
        let own_case = format!("{case}-{}-rule", s.rule.name());
        let own_points: Vec<AccuracyPoint> = points
            .iter()
            .filter(|p| p.series == series)
            .map(|p| {
                let (series, setting) = if p.value == level {
                    ("reference".to_string(), "reference".to_string())
                } else {
                    let knob = Knob::Lambda.name();
                    (knob.to_string(), format!("{knob} = {}", p.value))
                };
                AccuracyPoint {
                    case: own_case.clone(),
                    series,
                    setting,
                    ..p.without_errors()
                }
            })
            .collect();
        if own_points.iter().any(|p| p.series == "reference") {
            let own_sweep = AccuracySweep {
                rule: s.rule,
                series: vec![KnobSeries {
                    values: s.values.iter().copied().filter(|&v| v != level).collect(),
                    ..s.clone()
                }],
                ..sweep.clone()
            };
            out.push((own_sweep, own_points));
        }
    }
    out
}

/// Runs, seed by seed, the reference of every code, then each series point; codes alternate
/// within each point so machine drift hits all alike. With `--jobs`, that many of these runs
/// are made at a time, in the same order.
fn run_sweep(
    sweep: &AccuracySweep,
    origin: &Path,
    options: &ValidateOptions,
) -> Result<Vec<AccuracyPoint>, ValidateError> {
    let case_error = |message: String| ValidateError::Case {
        file: sweep.file.clone(),
        message,
    };
    let (reference_scene, _) = sweep.scene(&sweep.reference, origin).map_err(case_error)?;
    let case = reference_scene.name.clone();
    // (series, varied knob, value, codes, rule, seed)
    let mut jobs: Vec<(String, Knob, f64, Vec<Code>, CoarseGrainRule, u64)> = Vec::new();
    let all = sweep.codes();
    for &seed in &sweep.seeds {
        jobs.push((
            "reference".into(),
            Knob::Lambda,
            0.0,
            all.clone(),
            sweep.rule,
            seed,
        ));
        for s in &sweep.series {
            for &v in &s.values {
                // The reference's own value is the reference, unless the rule differs.
                if v != sweep.reference[&s.knob] || s.rule != sweep.rule {
                    jobs.push((
                        s.name(sweep.rule),
                        s.knob.clone(),
                        v,
                        s.codes.clone(),
                        s.rule,
                        seed,
                    ));
                }
            }
        }
    }
    // Every run prepared first (scene, directory, labels), then made `--jobs` at a time:
    // the seeds and levels of a sweep are independent runs.
    struct PointRun {
        scene: std::sync::Arc<Scene>,
        lambda: u32,
        code: Code,
        rule: CoarseGrainRule,
        seed: u64,
        series: String,
        setting: String,
        value: f64,
        dir: PathBuf,
    }
    let mut runs = Vec::new();
    for (series, knob, value, codes, rule, seed) in jobs {
        let mut knobs = sweep.reference.clone();
        let (setting, name) = match series.as_str() {
            "reference" => ("reference".to_string(), format!("reference-seed{seed}")),
            _ => {
                knobs.insert(knob.clone(), value);
                let (setting, rule_dir) = if rule == sweep.rule {
                    (format!("{} = {value}", knob.name()), String::new())
                } else {
                    (
                        format!("{} = {value}, {} rule", knob.name(), rule.name()),
                        format!("-{}", rule.name()),
                    )
                };
                (
                    setting,
                    format!("{}-{value}{rule_dir}-seed{seed}", knob.file_name()),
                )
            }
        };
        let (scene, lambda) = sweep.scene(&knobs, origin).map_err(case_error)?;
        let scene = std::sync::Arc::new(scene);
        for code in codes {
            runs.push(PointRun {
                scene: scene.clone(),
                lambda,
                code,
                rule,
                seed,
                series: series.clone(),
                setting: setting.clone(),
                // The reference is plotted at its own value of the knob.
                value: knobs[&knob],
                dir: options
                    .runs_dir()
                    .join(&case)
                    .join("accuracy")
                    .join(format!("{}-{name}", code.name())),
            });
        }
    }
    let points = run_concurrently(&runs, options.jobs, |run| {
        let point = run_point(
            &run.scene, run.code, run.lambda, run.rule, run.seed, &run.dir, options,
        );
        let p = AccuracyPoint {
            case: case.clone(),
            code: run.code,
            series: run.series.clone(),
            value: run.value,
            setting: run.setting.clone(),
            ..point
        };
        if !options.quiet {
            eprintln!(
                "{case} accuracy {} {} (seed {}): {}{}",
                run.code.name(),
                p.setting,
                run.seed,
                p.status,
                p.reason
                    .as_deref()
                    .map_or(String::new(), |r| format!(" ({r})"))
            );
        }
        p
    });
    Ok(points)
}

/// Runs one point (or reuses it) and reads what it measured.
fn run_point(
    scene: &Scene,
    code: Code,
    lambda: u32,
    rule: CoarseGrainRule,
    seed: u64,
    dir: &Path,
    options: &ValidateOptions,
) -> AccuracyPoint {
    let mut record = run_one(scene, code, lambda, rule, seed, dir, options);
    // A run that stopped early (a guard, a time limit) measured nothing comparable.
    if record.partial {
        record.status = Outcome::Failed;
    }
    let summary: serde_json::Value = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default();
    // A run that lost particles (LIGGGHTS and LAMMPS drop atoms that leave the box) may end
    // without a heap or a flow to measure.
    if record.status == Outcome::Ok
        && record.repose_angle_deg.is_none()
        && summary["conveying"]["mass_flow_kg_s"].as_f64().is_none()
        && summary["packing"]["porosity"].as_f64().is_none()
    {
        record.status = Outcome::Failed;
        record.reason = Some(format!(
            "measured nothing: {} particles at the end",
            record.n_particles.map_or("?".into(), |n| n.to_string())
        ));
    }
    let ok = record.status == Outcome::Ok;
    let conveying = |key: &str| {
        summary["conveying"][key]
            .as_f64()
            .filter(|v| ok && v.is_finite())
    };
    let particle_steps = summary["particle_steps"]
        .as_f64()
        .or_else(|| Some(record.n_particles? as f64 * record.steps? as f64));
    AccuracyPoint {
        case: record.case,
        code,
        series: String::new(),
        value: f64::NAN,
        setting: String::new(),
        lambda,
        cg_rule: rule,
        seed,
        status: record.status,
        reason: record.reason,
        dir: dir.to_path_buf(),
        reused: record.reused,
        n_particles: record.n_particles,
        steps: record.steps,
        particle_steps: particle_steps.filter(|_| ok),
        wall_s: record.wall_s.filter(|_| ok),
        repose_angle_deg: record.repose_angle_deg.filter(|_| ok),
        angle_error_deg: None,
        profile_distance: None,
        mass_flow_kg_s: conveying("mass_flow_kg_s"),
        mass_flow_error: None,
        eq7_mass_flow_kg_s: conveying("eq7_mass_flow_kg_s"),
        eq7_error: None,
        t_half_s: scene
            .repose
            .as_ref()
            .filter(|_| ok)
            .and_then(|r| FlowSeries::read(dir, &r.stage)?.t_half()),
        t_half_error: None,
        flow_stage: scene
            .repose
            .as_ref()
            .filter(|_| ok)
            .map(|r| r.stage.clone()),
        front_error: None,
        porosity: summary["packing"]["porosity"]
            .as_f64()
            .filter(|v| ok && v.is_finite()),
        porosity_error: None,
        pore_diameter_d: summary["packing"]["mean_pore_diameter_m"]
            .as_f64()
            .map(|pore| pore / (scene.max_diameter() * lambda as f64))
            .filter(|v| ok && v.is_finite() && *v > 0.0),
        pore_size_error: None,
    }
}

/// The run's heap profile (`profile.csv`); empty when the run wrote none or it cannot be read
/// (the point then has no profile error).
fn read_profile(dir: &Path) -> Vec<(f64, f64)> {
    CsvTable::read(&dir.join("profile.csv"))
        .and_then(|t| t.numbers(&["x_m", "height_m"]))
        .map(|rows| rows.iter().map(|r| (r[0], r[1])).collect())
        .unwrap_or_default()
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
    }
}

/// The front history's gap: each run's front as the fraction of its own largest advance it
/// has covered, and the largest difference of the two fractions over the flow (on a common
/// time grid; the run that ended first holds its last value). 0.1 means "a tenth of the
/// run-out apart at worst". How far the fronts get is the heap's (angle, profile); this is
/// how they get there. Each run's own advance also takes out the front's definition in
/// particle diameters (where the deposit is two diameters deep), which puts a coarser
/// level's front further back by about two diameters over the toe's slope. None when a
/// front never advanced.
pub fn front_history_gap(reference: &FlowSeries, other: &FlowSeries) -> Option<f64> {
    let covered = |flow: &FlowSeries| -> Option<FlowSeries> {
        let start = *flow.front_m.first()?;
        let advance = flow.front_m.iter().map(|x| x - start).fold(0.0, f64::max);
        (advance > 0.0).then(|| FlowSeries {
            front_m: flow.front_m.iter().map(|x| (x - start) / advance).collect(),
            ..flow.clone()
        })
    };
    Some(flow_difference(&covered(reference)?, &covered(other)?, 1.0, FLOW_GRID_S)?.front_max)
}

/// How far run `p` is from run `r` under measure `m` (None where either measured nothing).
fn difference(m: Measure, p: &AccuracyPoint, r: &AccuracyPoint) -> Option<f64> {
    let finite = |v: f64| Some(v).filter(|v| v.is_finite());
    match m {
        Measure::Angle => finite((p.repose_angle_deg? - r.repose_angle_deg?).abs()),
        Measure::Profile => {
            p.repose_angle_deg?;
            r.repose_angle_deg?;
            profile_distance(&read_profile(&r.dir), &read_profile(&p.dir))
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
    }
}

/// The floor of a code under measure `m`: the largest difference between two of its
/// reference runs (same setting, different insertion seeds); None with fewer than two.
fn floor(code: Code, m: Measure, points: &[AccuracyPoint]) -> Option<f64> {
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

fn fmt_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |x| format!("{x:.digits$}"))
}

/// The sweep's subsection: runs table, one figure per error measure, the cheapest settings.
fn write_sweep_section(
    section: &mut Section,
    sweep: &AccuracySweep,
    case: &str,
    points: &[AccuracyPoint],
    dir: &Path,
    note: Option<&str>,
) -> Result<Vec<CheapestSetting>, ValidateError> {
    let sub = section.subsection(format!("Case {case}"));
    if let Some(note) = note {
        sub.paragraph(note);
    }
    let reference = sweep
        .reference
        .iter()
        .map(|(k, v)| format!("{} = {v}", k.name()))
        .collect::<Vec<_>>()
        .join(", ");
    let shared = sweep
        .overrides
        .iter()
        .map(|o| o.key.clone())
        .collect::<Vec<_>>()
        .join(", ");
    sub.paragraph(format!(
        "Scene file {} with the overrides of variant `{}` ({}); insertion seeds {}. \
         Reference setting: {reference}, {} rule.",
        sweep.file.display(),
        sweep.variant,
        if shared.is_empty() { "none" } else { &shared },
        sweep
            .seeds
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        sweep.rule.name(),
    ));
    let measures: Vec<Measure> = Measure::ALL
        .into_iter()
        .filter(|m| points.iter().any(|p| m.of(p).is_some()))
        .collect();

    let mut table = Table::new(
        [
            "code",
            "series",
            "setting",
            "seed",
            "status",
            "particles",
            "particle-steps",
            "wall s",
            "result",
        ]
        .into_iter()
        .map(String::from)
        .chain(measures.iter().map(|m| m.name().to_string())),
    )
    .caption("Every point: its cost and its errors");
    let mut csv = CsvBuffer::new([
        "case",
        "code",
        "series",
        "knob_value",
        "setting",
        "lambda",
        "cg_rule",
        "seed",
        "status",
        "n_particles",
        "steps",
        "particle_steps",
        "wall_s",
        "repose_angle_deg",
        "angle_error_deg",
        "profile_distance",
        "mass_flow_kg_s",
        "mass_flow_error",
        "eq7_mass_flow_kg_s",
        "eq7_error",
        "t_half_s",
        "t_half_error",
        "porosity",
        "porosity_error",
        "pore_diameter_d",
        "pore_size_error",
        "front_error",
    ]);
    let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    for p in points {
        let status = match p.status {
            Outcome::Ok if p.reused => Cell::pass("ok (reused)"),
            Outcome::Ok => Cell::pass("ok"),
            Outcome::Skipped => {
                Cell::skipped(format!("skipped: {}", p.reason.clone().unwrap_or_default()))
            }
            Outcome::Failed => {
                Cell::fail(format!("failed: {}", p.reason.clone().unwrap_or_default()))
            }
        };
        let result = match (p.repose_angle_deg, p.mass_flow_kg_s, p.porosity) {
            (Some(a), _, _) => format!("{a:.2} deg"),
            (_, Some(q), _) => format!("{q:.3} kg/s"),
            (_, _, Some(e)) => format!("porosity {e:.4}"),
            _ => "-".into(),
        };
        table.row(
            [
                Cell::text(p.code.name()),
                Cell::text(&p.series),
                Cell::text(&p.setting),
                Cell::num(p.seed.to_string()),
                status,
                Cell::num(p.n_particles.map_or("-".into(), |n| n.to_string())),
                Cell::num(p.particle_steps.map_or("-".into(), |n| format!("{n:.3e}"))),
                Cell::num(fmt_opt(p.wall_s, 1)),
                Cell::num(result),
            ]
            .into_iter()
            .chain(
                measures
                    .iter()
                    .map(|m| Cell::num(m.of(p).map_or("-".into(), |v| m.format(v)))),
            ),
        );
        csv.row([
            p.case.clone(),
            p.code.name().to_string(),
            p.series.clone(),
            p.value.to_string(),
            // Kept free of commas (a spreadsheet's eye reads the file too).
            p.setting.replace(',', ";"),
            p.lambda.to_string(),
            p.cg_rule.name().to_string(),
            p.seed.to_string(),
            p.status.to_string(),
            p.n_particles.map_or(String::new(), |n| n.to_string()),
            p.steps.map_or(String::new(), |n| n.to_string()),
            o(p.particle_steps),
            o(p.wall_s),
            o(p.repose_angle_deg),
            o(p.angle_error_deg),
            o(p.profile_distance),
            o(p.mass_flow_kg_s),
            o(p.mass_flow_error),
            o(p.eq7_mass_flow_kg_s),
            o(p.eq7_error),
            o(p.t_half_s),
            o(p.t_half_error),
            o(p.porosity),
            o(p.porosity_error),
            o(p.pore_diameter_d),
            o(p.pore_size_error),
            o(p.front_error),
        ]);
    }
    std::fs::create_dir_all(dir).map_err(|e| output_error(dir, e))?;
    let csv_path = dir.join("points.csv");
    csv.bytes()
        .and_then(|bytes| write_atomic(&csv_path, bytes))
        .map_err(|e| output_error(&csv_path, e))?;

    let mut cheapest = Vec::new();
    let codes = sweep.codes();
    for &m in &measures {
        for cost in [Cost::WallTime, Cost::ParticleSteps] {
            let fig = error_figure(case, m, cost, &sweep.targets, &codes, points);
            let stem = match cost {
                Cost::WallTime => m.stem().to_string(),
                Cost::ParticleSteps => format!("{}_vs_particle_steps", m.stem()),
            };
            let files = write_figure(dir, &stem, &fig).map_err(|e| output_error(dir, e))?;
            sub.figure(
                &files,
                fig.title.clone(),
                format!(
                    "{} against {}, log axes; one series per knob and code (points in the \
                     knob's order), the Pareto front of each code dashed, the target ({}) as a \
                     line.{} All points: points.csv beside it.",
                    m.name(),
                    cost.name(),
                    m.format(m.target(&sweep.targets)),
                    match cost {
                        Cost::WallTime => "",
                        Cost::ParticleSteps =>
                            " Particle-steps do not depend on the load of a shared machine, nor \
                             on the code's speed.",
                    }
                ),
            )
            .map_err(|e| output_error(dir, e))?;
        }
        for &code in &codes {
            cheapest.push(cheapest_setting(case, code, m, &sweep.targets, points));
        }
    }
    let mut choice = Table::new([
        "code",
        "error measure",
        "target",
        "cheapest setting within it",
        "wall s",
        "particle-steps",
        "its error (mean +- SE, seeds)",
        "reference wall s",
        "speed-up",
        "floor (other seeds)",
    ])
    .caption(format!("Cheapest setting within each target, per code: the fewest particle-steps (wall time beside it; on a shared machine the wall time of equal work varies too much to choose by) among the settings whose every seed ran to its end and whose mean error plus spread ({SPREAD_STANDARD_ERRORS} standard errors of the mean) meets the target. The reference is the yardstick: when no other point qualifies, none is named. A setting's error, cost and wall time are means over its seeds, the error with one standard error of the mean. Floor: the largest difference between two reference runs with different insertion seeds; a target below it is met by chance."));
    for c in &cheapest {
        let m = measure_named(&c.measure);
        let speedup = match (c.reference_wall_s, c.wall_s) {
            (Some(r), Some(w)) if w > 0.0 => format!("{:.1}x", r / w),
            _ => "-".into(),
        };
        choice.row([
            Cell::text(c.code.name()),
            Cell::text(&c.measure),
            Cell::num(m.format(c.target)),
            match &c.setting {
                Some(s) => Cell::pass(s.clone()),
                None => Cell::skipped("none: only the reference"),
            },
            Cell::num(fmt_opt(c.wall_s, 1)),
            Cell::num(c.particle_steps.map_or("-".into(), |n| format!("{n:.3e}"))),
            Cell::num(c.error.map_or("-".into(), |v| {
                format!(
                    "{}{} ({})",
                    m.format(v),
                    c.error_se
                        .map_or(String::new(), |se| format!(" +- {}", m.format(se))),
                    c.seeds
                )
            })),
            Cell::num(fmt_opt(c.reference_wall_s, 1)),
            Cell::num(speedup),
            Cell::num(c.floor.map_or("-".into(), |v| m.format(v))),
        ]);
    }
    sub.table(choice);
    if sweep.series.iter().any(|s| s.knob == Knob::Lambda) {
        write_matrix(sub, case, &measures, &sweep.targets, points, dir)?;
    }
    sub.table(table);
    Ok(cheapest)
}

/// The coarse-graining matrix of a sweep over lambda (cgdem's runs): for each error measure,
/// each lambda and rule with its mean error over seeds, its spread (as `cgdem advise` counts
/// it) and what it saves against the fine reference; a table and `matrix.csv`.
fn write_matrix(
    sub: &mut Section,
    case: &str,
    measures: &[Measure],
    targets: &Targets,
    points: &[AccuracyPoint],
    dir: &Path,
) -> Result<(), ValidateError> {
    let code = Code::Cgdem;
    let all = settings(code, points);
    let Some(reference) = all.iter().find(|s| s.series == "reference") else {
        return Ok(());
    };
    let mean_of = |s: &Setting, f: fn(&AccuracyPoint) -> Option<f64>| {
        let v: Vec<f64> = s.runs.iter().filter_map(|p| f(p)).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    let reference_steps = mean_of(reference, |p| p.particle_steps);
    let reference_wall = mean_of(reference, |p| p.wall_s);
    let mut table = Table::new([
        "quantity",
        "rule",
        "lambda",
        "particles",
        "error (mean +- spread, seeds)",
        "within target",
        "particle-steps saved",
        "wall time saved",
    ])
    .caption(format!(
        "Coarse-graining matrix: each level and rule against the fine reference ({}, rule {}), error = mean over seeds, spread = {SPREAD_STANDARD_ERRORS} standard errors of the mean (what `cgdem advise` adds to the mean); within target when mean + spread is. Savings: the reference's mean particle-steps (wall time) over the setting's. CSV: matrix.csv beside the figures.",
        reference.setting,
        reference.runs[0].cg_rule.name()
    ));
    let mut csv = CsvBuffer::new([
        "case",
        "quantity",
        "cg_rule",
        "lambda",
        "setting",
        "seeds",
        "n_particles",
        "error_mean",
        "error_se",
        "error_reach",
        "target",
        "within_target",
        "particle_steps",
        "wall_s",
        "saving_particle_steps",
        "saving_wall",
    ]);
    let o = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    for &m in measures {
        for s in all.iter().filter(|s| {
            s.series.starts_with("lambda") || (s.series == "reference" && !m.against_reference())
        }) {
            let Some(mean) = s.mean(m, Cost::ParticleSteps) else {
                continue;
            };
            let spread = mean.se.map(|se| SPREAD_STANDARD_ERRORS * se);
            let reach = mean.error + spread.unwrap_or(0.0);
            let target = m.target(targets);
            let wall = mean_of(s, |p| p.wall_s);
            let particles = mean_of(s, |p| p.n_particles.map(|n| n as f64));
            let saving_steps = reference_steps.map(|r| r / mean.cost);
            let saving_wall = reference_wall.zip(wall).map(|(r, w)| r / w);
            let first = s.runs[0];
            table.row([
                Cell::text(m.quantity()),
                Cell::text(first.cg_rule.name()),
                Cell::num(first.lambda.to_string()),
                Cell::num(particles.map_or("-".into(), |n| format!("{n:.0}"))),
                Cell::num(format!(
                    "{}{} ({})",
                    m.format(mean.error),
                    spread.map_or(" (spread unknown)".into(), |v| format!(
                        " +- {}",
                        m.format(v)
                    )),
                    mean.n
                )),
                if reach <= target {
                    Cell::pass(format!("yes ({})", m.format(target)))
                } else {
                    Cell::fail(format!("no ({})", m.format(target)))
                },
                Cell::num(saving_steps.map_or("-".into(), |v| format!("{v:.1}x"))),
                Cell::num(saving_wall.map_or("-".into(), |v| format!("{v:.1}x"))),
            ]);
            csv.row([
                case.to_string(),
                m.quantity().to_string(),
                first.cg_rule.name().to_string(),
                first.lambda.to_string(),
                s.setting.replace(',', ";"),
                mean.n.to_string(),
                o(particles),
                o(Some(mean.error)),
                o(mean.se),
                o(Some(reach)),
                o(Some(target)),
                (reach <= target).to_string(),
                o(Some(mean.cost)),
                o(wall),
                o(saving_steps),
                o(saving_wall),
            ]);
        }
    }
    let path = dir.join("matrix.csv");
    csv.bytes()
        .and_then(|bytes| write_atomic(&path, bytes))
        .map_err(|e| output_error(&path, e))?;
    sub.table(table);
    Ok(())
}

fn measure_named(name: &str) -> Measure {
    Measure::ALL
        .into_iter()
        .find(|m| m.name() == name)
        .unwrap_or(Measure::Angle)
}

/// The settings to choose from: the series, and the reference where its error is not zero
/// by construction.
fn candidates(code: Code, m: Measure, points: &[AccuracyPoint]) -> Vec<Setting<'_>> {
    settings(code, points)
        .into_iter()
        .filter(|s| s.series != "reference" || !m.against_reference())
        .collect()
}

fn cheapest_setting(
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

    fn name(self) -> &'static str {
        match self {
            Cost::WallTime => "wall time",
            Cost::ParticleSteps => "particle-steps",
        }
    }
}

fn error_figure(
    case: &str,
    m: Measure,
    cost_axis: Cost,
    targets: &Targets,
    codes: &[Code],
    points: &[AccuracyPoint],
) -> Figure {
    let mut fig = Figure::new(
        format!("{case}: {} against {}", m.name(), cost_axis.name()),
        match cost_axis {
            Cost::WallTime => "wall time [s]",
            Cost::ParticleSteps => "particle-steps [-]",
        },
        m.axis(),
    )
    .log_x()
    .log_y();
    let mut walls: Vec<f64> = Vec::new();
    for &code in codes {
        let all = settings(code, points);
        let mut knobs: Vec<&str> = all.iter().map(|s| s.series).collect();
        knobs.sort();
        knobs.dedup();
        for knob in knobs {
            let mut series: Vec<(f64, SettingMean)> = all
                .iter()
                .filter(|s| s.series == knob)
                .filter_map(|s| Some((s.value, s.mean(m, cost_axis)?)))
                .collect();
            series.sort_by(|a, b| a.0.total_cmp(&b.0));
            walls.extend(series.iter().map(|p| p.1.cost));
            if series.is_empty() || (knob == "reference" && m.against_reference()) {
                continue;
            }
            let xy = series.iter().map(|p| (p.1.cost, p.1.error)).collect();
            let se = series.iter().map(|p| p.1.se.unwrap_or(0.0)).collect();
            let style = match knob {
                "reference" => SeriesStyle::Markers,
                _ => SeriesStyle::LineMarkers,
            };
            fig.series.push(
                Series::new(format!("{}: {knob}", code.name()), xy)
                    .style(style)
                    .y_err(se),
            );
        }
        let cost: Vec<(f64, f64)> = candidates(code, m, points)
            .iter()
            .filter_map(|s| s.mean(m, cost_axis))
            .map(|a| (a.cost, a.error))
            .collect();
        let front: Vec<(f64, f64)> = pareto_front(&cost)
            .into_iter()
            .map(|k| cost[k])
            .filter(|p| p.1 > 0.0)
            .collect();
        if !front.is_empty() {
            // One point (it beats every other) is a front too; a lone dash would not show.
            let style = if front.len() > 1 {
                SeriesStyle::Dashed
            } else {
                SeriesStyle::Markers
            };
            fig.series
                .push(Series::new(format!("{}: Pareto front", code.name()), front).style(style));
        }
    }
    let (lo, hi) = walls
        .iter()
        .filter(|w| **w > 0.0)
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &w| {
            (lo.min(w), hi.max(w))
        });
    if lo < hi {
        let t = m.target(targets);
        fig.series.push(
            Series::new(format!("target {}", m.format(t)), vec![(lo, t), (hi, t)])
                .style(SeriesStyle::Dashed),
        );
    }
    fig
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::suite::Suite;

    #[test]
    fn the_pareto_front_keeps_only_points_no_cheaper_point_beats() {
        // (wall s, error): 1 is dominated by 0 (dearer and worse); 3 ties 2 in cost but is
        // worse; 4 is the most accurate; 5 has no error (a failed run).
        let points = [
            (1.0, 0.5),
            (2.0, 0.6),
            (4.0, 0.2),
            (4.0, 0.3),
            (10.0, 0.01),
            (0.5, f64::NAN),
        ];
        assert_eq!(pareto_front(&points), vec![0, 2, 4]);
        assert!(pareto_front(&[]).is_empty());
        // Equal points: only one is on the front.
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]).len(), 1);
    }

    #[test]
    fn the_cheapest_setting_is_the_least_cost_within_the_target() {
        let points = [(10.0, 0.01), (1.0, 2.0), (3.0, 0.9), (2.0, 1.0), (2.0, 0.5)];
        // Within 1: indices 0, 2, 3, 4; cheapest 2.0 s, of which the smaller error.
        assert_eq!(cheapest_within(&points, 1.0), Some(4));
        assert_eq!(cheapest_within(&points, 0.1), Some(0));
        assert_eq!(cheapest_within(&points, 0.001), None);
        assert_eq!(cheapest_within(&[(f64::NAN, 0.0)], 1.0), None);
    }

    /// A successful cgdem run at lambda 1 (seed rule) with its angle and cost; shared by
    /// the advise tests.
    pub(crate) fn run(
        series: &str,
        value: f64,
        seed: u64,
        angle: f64,
        particle_steps: f64,
    ) -> AccuracyPoint {
        AccuracyPoint {
            case: "c".into(),
            code: Code::Cgdem,
            series: series.into(),
            value,
            setting: format!("{series} = {value}"),
            lambda: 1,
            cg_rule: CoarseGrainRule::Seed,
            seed,
            status: Outcome::Ok,
            reason: None,
            dir: PathBuf::from("/nonexistent"),
            reused: false,
            n_particles: Some(100),
            steps: Some(10),
            particle_steps: Some(particle_steps),
            wall_s: Some(particle_steps / 1e6),
            repose_angle_deg: Some(angle),
            angle_error_deg: None,
            profile_distance: None,
            mass_flow_kg_s: None,
            mass_flow_error: None,
            eq7_mass_flow_kg_s: None,
            eq7_error: None,
            t_half_s: None,
            t_half_error: None,
            porosity: None,
            porosity_error: None,
            pore_diameter_d: None,
            pore_size_error: None,
            flow_stage: None,
            front_error: None,
        }
    }

    #[test]
    fn errors_pair_runs_by_seed_and_settings_average_over_seeds() {
        let mut points = vec![
            run("reference", 0.02, 1, 30.0, 1e7),
            run("reference", 0.02, 2, 31.0, 1e7),
            run("reference", 0.02, 3, 29.5, 1e7),
            run("dt", 0.1, 1, 30.5, 2e6),
            run("dt", 0.1, 2, 31.2, 2e6),
            run("dt", 0.1, 3, 29.0, 2e6),
            run("dt", 0.3, 1, 31.0, 1e6),
            run("dt", 0.3, 2, 30.0, 1e6),
            run("dt", 0.3, 3, 30.5, 1e6),
        ];
        // Seed 1's dynamics and packing: t_half 20% longer, porosity 0.01 higher.
        points[0].t_half_s = Some(1.0);
        points[3].t_half_s = Some(1.2);
        points[0].porosity = Some(0.40);
        points[3].porosity = Some(0.41);
        // Pores of 0.8 diameters in the reference, 0.6 in the point: 25% smaller.
        points[0].pore_diameter_d = Some(0.8);
        points[3].pore_diameter_d = Some(0.6);
        measure(&mut points);
        assert!((points[3].t_half_error.unwrap() - 0.2).abs() < 1e-12);
        assert!((points[3].porosity_error.unwrap() - 0.01).abs() < 1e-12);
        assert!((points[3].pore_size_error.unwrap() - 0.25).abs() < 1e-12);
        assert_eq!(points[4].pore_size_error, None);
        assert_eq!(points[4].t_half_error, None);
        // Against the reference with the same seed: 0.5, 0.2, 0.5 (against seed 1's
        // reference alone they would be 0.5, 1.2, 1.0).
        let errors: Vec<f64> = points[3..6]
            .iter()
            .map(|p| p.angle_error_deg.unwrap())
            .collect();
        for (e, want) in errors.iter().zip([0.5, 0.2, 0.5]) {
            assert!((e - want).abs() < 1e-12, "{errors:?}");
        }
        let all = settings(Code::Cgdem, &points);
        assert_eq!(all.len(), 3);
        let dt = all[1].mean(Measure::Angle, Cost::ParticleSteps).unwrap();
        assert_eq!(dt.n, 3);
        assert!((dt.error - 0.4).abs() < 1e-12, "{dt:?}");
        // Sample standard deviation sqrt(0.03), over sqrt(3).
        assert!((dt.se.unwrap() - 0.1).abs() < 1e-12, "{dt:?}");
        // The reference runs' largest difference between seeds: 31.0 against 29.5.
        assert_eq!(floor(Code::Cgdem, Measure::Angle, &points), Some(1.5));
        // dt 0.3 errs by 1.0, 1.0, 1.0: within 1.0 it is the cheapest. dt 0.1's mean, 0.4,
        // is within 0.5 but its mean plus spread (2 x 0.1) is not: nothing within 0.5, dt
        // 0.1 within 0.65.
        let targets = Targets {
            angle_deg: 0.5,
            profile: 0.05,
            mass_flow: 0.05,
            t_half: 0.1,
            front: 0.1,
            porosity: 0.02,
            pore_size: 0.1,
        };
        let c = cheapest_setting("c", Code::Cgdem, Measure::Angle, &targets, &points);
        assert_eq!(c.setting, None);
        let within = |angle_deg| Targets {
            angle_deg,
            ..targets
        };
        let c = cheapest_setting("c", Code::Cgdem, Measure::Angle, &within(0.65), &points);
        assert_eq!(c.setting.as_deref(), Some("dt = 0.1"));
        assert_eq!((c.seeds, c.particle_steps), (3, Some(2e6)));
        let c = cheapest_setting("c", Code::Cgdem, Measure::Angle, &within(1.0), &points);
        assert_eq!(c.setting.as_deref(), Some("dt = 0.3"));
        assert_eq!(c.error_se, Some(0.0));
        // A seed of dt 0.3 stopped by a guard: the setting does not hold, dt 0.1 is chosen.
        points[7].status = Outcome::Failed;
        let c = cheapest_setting("c", Code::Cgdem, Measure::Angle, &within(1.0), &points);
        assert_eq!(c.setting.as_deref(), Some("dt = 0.1"));
        points[7].status = Outcome::Ok;
        // A failed run drops out of its setting's mean.
        points[4].status = Outcome::Failed;
        let all = settings(Code::Cgdem, &points);
        assert_eq!(
            all[1].mean(Measure::Angle, Cost::ParticleSteps).unwrap().n,
            2
        );
    }

    #[test]
    fn profile_distance_is_zero_for_equal_heaps_and_scales_with_the_gap() {
        let heap: Vec<(f64, f64)> = (0..20)
            .map(|k| (0.005 + 0.01 * k as f64, (0.1 - 0.005 * k as f64).max(0.0)))
            .collect();
        assert_eq!(profile_distance(&heap, &heap), Some(0.0));
        // Uniformly 1 cm higher where the heap is: 0.01 / 0.1 over every point.
        let higher: Vec<(f64, f64)> = heap.iter().map(|&(x, h)| (x, h + 0.01)).collect();
        let d = profile_distance(&heap, &higher).unwrap();
        assert!((d - 0.1).abs() < 1e-12, "{d}");
        // Coarser bins of the same straight heap: only the interpolation differs.
        let coarse: Vec<(f64, f64)> = heap.iter().step_by(2).copied().collect();
        assert!(profile_distance(&heap, &coarse).unwrap() < 0.05);
        assert_eq!(profile_distance(&[], &heap), None);
    }

    /// A front 0.1 s behind the reference's has covered a tenth of its run-out less at worst;
    /// equal fronts, or the same shape shorter and offset, are 0 apart; a front that stops
    /// halfway at the same pace has covered all of its run-out when the reference has
    /// covered half: 0.5 apart.
    #[test]
    fn front_history_gap_compares_the_fraction_of_run_out_covered() {
        let flow = |front: &dyn Fn(f64) -> f64| {
            let time_s: Vec<f64> = (0..=200).map(|k| 0.01 * k as f64).collect();
            FlowSeries {
                front_m: time_s.iter().map(|&t| front(t)).collect(),
                wall_height_m: vec![0.3; time_s.len()],
                kinetic_energy_per_mass: vec![1.0; time_s.len()],
                time_s,
            }
        };
        // 0.2 m to 0.6 m at 0.4 m/s over the first second, then at rest.
        let reference = flow(&|t: f64| 0.2 + 0.4 * t.min(1.0));
        assert_eq!(front_history_gap(&reference, &reference), Some(0.0));
        let late = flow(&|t: f64| 0.2 + 0.4 * (t - 0.1).clamp(0.0, 1.0));
        let gap = front_history_gap(&reference, &late).unwrap();
        assert!((gap - 0.1).abs() < 1e-9, "{gap}");
        // Half the run-out at the same pace: done at 0.5 s, when the reference has covered
        // half of its own.
        let halfway = flow(&|t: f64| 0.2 + 0.4 * t.min(0.5));
        let gap = front_history_gap(&reference, &halfway).unwrap();
        assert!((gap - 0.5).abs() < 1e-9, "{gap}");
        // The same shape, shorter and offset (a coarser front's definition): no gap.
        let shorter = flow(&|t: f64| 0.15 + 0.3 * t.min(1.0));
        let gap = front_history_gap(&reference, &shorter).unwrap();
        assert!(gap < 1e-9, "{gap}");
        // A front that never moved has no run-out to measure against.
        let still = flow(&|_| 0.2);
        assert_eq!(front_history_gap(&still, &reference), None);
        assert_eq!(front_history_gap(&reference, &still), None);
    }

    #[test]
    fn shipped_suites_parse_and_every_accuracy_point_is_a_valid_scene() {
        crate::at_repo_root();
        for entry in std::fs::read_dir("validation/suites").unwrap() {
            let path = entry.unwrap().path();
            let suite = Suite::load(&path).unwrap_or_else(|e| panic!("{e}"));
            for sweep in &suite.accuracy {
                for s in &sweep.series {
                    for &v in &s.values {
                        let mut knobs = sweep.reference.clone();
                        knobs.insert(s.knob.clone(), v);
                        let (scene, lambda) = sweep.scene(&knobs, &path).unwrap_or_else(|e| {
                            panic!("{}: {} = {v}: {e}", path.display(), s.knob.name())
                        });
                        // The level fits the box under the series' rule (e.g. lambda 8 in
                        // the fidelity suite's deep Hertz box).
                        cgdem_core::coarse_graining::coarse_grain_by(&scene, lambda, s.rule)
                            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                    }
                }
            }
        }
    }

    /// A series under another rule that includes the reference's level is that rule's own
    /// matrix too: its runs at the reference's level become the reference, the others keep
    /// their errors to be measured against it; a series without that level adds nothing.
    #[test]
    fn a_rule_series_at_the_reference_level_is_also_its_own_matrix() {
        crate::at_repo_root();
        let suite = Suite::parse(
            "name = \"a\"\n[[accuracy]]\nfile = \"validation/cases/aor_collapse.toml\"\n\
             variant = \"f\"\nseeds = [1, 2]\n[accuracy.reference]\nlambda = 8\n\
             [[accuracy.series]]\nknob = \"lambda\"\nvalues = [16]\n\
             [[accuracy.series]]\nknob = \"lambda\"\nvalues = [8, 16]\ncg_rule = \"bulk-viscosity\"\n\
             [[accuracy.series]]\nknob = \"lambda\"\nvalues = [32]\ncg_rule = \"bulk-viscosity\"\n",
            Path::new("s.toml"),
        )
        .unwrap();
        let sweep = &suite.accuracy[0];
        let point = |series: &str, lambda: u32, rule: CoarseGrainRule, seed: u64, angle: f64| {
            let mut p = run(series, lambda as f64, seed, angle, 1e6 / lambda as f64);
            p.lambda = lambda;
            p.cg_rule = rule;
            p.angle_error_deg = Some(99.0);
            p
        };
        let (seed_rule, bv) = (CoarseGrainRule::Seed, CoarseGrainRule::BulkViscosity);
        let mut points = Vec::new();
        for seed in [1, 2] {
            points.push(point("reference", 8, seed_rule, seed, 40.0));
            points.push(point("lambda", 16, seed_rule, seed, 45.0));
            points.push(point(
                "lambda (bulk-viscosity)",
                8,
                bv,
                seed,
                20.0 + seed as f64,
            ));
            points.push(point(
                "lambda (bulk-viscosity)",
                16,
                bv,
                seed,
                23.0 + seed as f64,
            ));
        }
        let own = own_rule_sweeps(sweep, "c", &points);
        assert_eq!(own.len(), 1, "the lambda-32-only series has no reference");
        let (own_sweep, mut own_points) = own.into_iter().next().unwrap();
        assert_eq!(own_sweep.rule, bv);
        assert_eq!(own_sweep.series.len(), 1);
        assert_eq!(own_sweep.series[0].values, vec![16.0]);
        assert_eq!(own_points.len(), 4);
        assert!(own_points.iter().all(|p| p.case == "c-bulk-viscosity-rule"));
        assert!(own_points.iter().all(|p| p.angle_error_deg.is_none()));
        let settings: Vec<&str> = own_points.iter().map(|p| p.setting.as_str()).collect();
        assert_eq!(
            settings,
            ["reference", "lambda = 16", "reference", "lambda = 16"]
        );
        measure(&mut own_points);
        // 24 - 21 and 25 - 22: 3 deg in each seed, against the rule's own lambda 8.
        assert_eq!(own_points[1].angle_error_deg, Some(3.0));
        assert_eq!(own_points[3].angle_error_deg, Some(3.0));
    }

    #[test]
    fn a_sweep_needs_its_knobs_reference_values() {
        crate::at_repo_root();
        let suite = |series: &str| {
            format!(
                "name = \"a\"\n[[accuracy]]\nfile = \"validation/cases/aor_hertz_smoke.toml\"\n\
                 variant = \"acc\"\n[accuracy.reference]\nlambda = 1\n\"time.dt_fraction\" = 0.02\n\
                 [[accuracy.series]]\n{series}\n"
            )
        };
        let ok = Suite::parse(
            &suite("knob = \"time.dt_fraction\"\nvalues = [0.05, 0.1]\ncodes = [\"cgdem\", \"lammps\"]"),
            Path::new("s.toml"),
        )
        .unwrap();
        let sweep = &ok.accuracy[0];
        assert_eq!(sweep.codes(), vec![Code::Cgdem, Code::Lammps]);
        assert_eq!(sweep.targets.angle_deg, 1.0);
        let (scene, lambda) = sweep.scene(&sweep.reference, Path::new("s.toml")).unwrap();
        assert_eq!(lambda, 1);
        assert_eq!(scene.name, "aor_hertz_smoke-acc");
        let e = Suite::parse(
            &suite("knob = \"neighbor.skin_fraction\"\nvalues = [0.1]"),
            Path::new("s.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("accuracy[0].series[0].knob"), "{e}");
        let e = Suite::parse(
            &suite("knob = \"lambda\"\nvalues = [3]"),
            Path::new("s.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("accuracy[0].series[0].values"), "{e}");
        let with_seeds = |seeds: &str| {
            suite("knob = \"time.dt_fraction\"\nvalues = [0.1]").replace(
                "variant = \"acc\"\n",
                &format!("variant = \"acc\"\n{seeds}\n"),
            )
        };
        let ok = Suite::parse(&with_seeds("seeds = [3, 1, 2]"), Path::new("s.toml")).unwrap();
        assert_eq!(ok.accuracy[0].seeds, vec![3, 1, 2]);
        for bad in ["seeds = [1, 1]", "seeds = []"] {
            let e = Suite::parse(&with_seeds(bad), Path::new("s.toml"))
                .unwrap_err()
                .to_string();
            assert!(e.contains("accuracy[0].seeds"), "{bad}: {e}");
        }
        // A series under another coarse-graining rule is its own series, named by the rule.
        let ruled = suite("knob = \"lambda\"\nvalues = [2]\ncg_rule = \"bulk-viscosity\"");
        let ok = Suite::parse(&ruled, Path::new("s.toml")).unwrap();
        let s0 = &ok.accuracy[0].series[0];
        assert_eq!(s0.rule, CoarseGrainRule::BulkViscosity);
        assert_eq!(s0.name(ok.accuracy[0].rule), "lambda (bulk-viscosity)");
        let e = Suite::parse(&ruled.replace("bulk-viscosity", "pfm"), Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("accuracy[0].series[0].cg_rule") && e.contains("pfm"),
            "{e}"
        );
        // The former single seed is refused by name, not silently ignored.
        let e = Suite::parse(&with_seeds("seed = 1"), Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("seed"), "{e}");
    }
}
