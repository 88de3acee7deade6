//! An `[[accuracy]]` entry of a suite file: the case, its reference setting, one series per
//! knob, the seeds and the targets, validated when the suite is read.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::code::Code;
use crate::suite_entry::{parse_codes, parse_variant, rule_names, SuiteError};
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::{Override, Scene};

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
    pub(crate) fn file_name(&self) -> String {
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
    pub(crate) fn name(&self, sweep_rule: CoarseGrainRule) -> String {
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
    /// Relative discharge-rate error (a silo's, against the reference run).
    pub discharge_rate: f64,
    /// A drum's dynamic angle of repose, deg.
    pub dynamic_angle_deg: f64,
    /// Relative error of the period of a drum's zone-count swing.
    pub mixing_period: f64,
    /// Absolute difference of a drum's Lacey index.
    pub mixing_index: f64,
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
    /// How each run is measured as a discharge (`discharge`, as a suite case's): the silo's
    /// rate, as mass, against the reference's.
    pub discharge: Option<crate::quantity::discharge::DischargeSettings>,
    /// How each run is measured as a rotating drum (`drum`, as a suite case's): its dynamic
    /// angle, the period of its zone counts' swing and its Lacey index, against the
    /// reference's.
    pub drum: Option<crate::quantity::drum::DrumSettings>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSweep {
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
    discharge_rate_target: Option<f64>,
    discharge: Option<crate::quantity::discharge::RawDischarge>,
    dynamic_angle_target_deg: Option<f64>,
    mixing_period_target: Option<f64>,
    mixing_index_target: Option<f64>,
    drum: Option<crate::quantity::drum::RawDrum>,
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

/// The error targets of `[[accuracy]]` entry `k` of suite file `path`, defaults filled in.
fn parse_targets(raw: &RawSweep, k: usize, path: &Path) -> Result<Targets, SuiteError> {
    let invalid = |field: &str, value: String, allowed: &str| SuiteError::Invalid {
        file: path.to_path_buf(),
        field: format!("accuracy[{k}].{field}"),
        value,
        allowed: allowed.into(),
    };
    let target = |field: &str, v: Option<f64>, default: f64| {
        let v = v.unwrap_or(default);
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(invalid(field, v.to_string(), "a positive number"))
        }
    };
    Ok(Targets {
        angle_deg: target("angle_target_deg", raw.angle_target_deg, 1.0)?,
        profile: target("profile_target", raw.profile_target, 0.05)?,
        mass_flow: target("mass_flow_target", raw.mass_flow_target, 0.05)?,
        t_half: target("t_half_target", raw.t_half_target, 0.1)?,
        front: target("front_target", raw.front_target, 0.1)?,
        porosity: target("porosity_target", raw.porosity_target, 0.02)?,
        pore_size: target("pore_size_target", raw.pore_size_target, 0.1)?,
        discharge_rate: target("discharge_rate_target", raw.discharge_rate_target, 0.05)?,
        dynamic_angle_deg: target(
            "dynamic_angle_target_deg",
            raw.dynamic_angle_target_deg,
            2.0,
        )?,
        mixing_period: target("mixing_period_target", raw.mixing_period_target, 0.1)?,
        mixing_index: target("mixing_index_target", raw.mixing_index_target, 0.05)?,
    })
}

impl AccuracySweep {
    /// Validates `[[accuracy]]` entry `k` of suite file `path`.
    pub(crate) fn from_raw(mut raw: RawSweep, k: usize, path: &Path) -> Result<Self, SuiteError> {
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
            None => CoarseGrainRule::RelativeOverlap,
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
        for (j, s) in std::mem::take(&mut raw.series).into_iter().enumerate() {
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
        let seeds = raw.seeds.take().unwrap_or_else(|| vec![1]);
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
        let targets = parse_targets(&raw, k, path)?;
        let discharge = raw
            .discharge
            .map(|d| {
                crate::quantity::discharge::parse_discharge(d, &format!("accuracy[{k}]"), path)
            })
            .transpose()?;
        let drum = (raw.drum.take())
            .map(|d| crate::quantity::drum::parse_drum(d, &format!("accuracy[{k}]"), path))
            .transpose()?;
        Ok(AccuracySweep {
            file: crate::suite_entry::beside_suite(path, &raw.file),
            overrides,
            variant: raw.variant,
            seeds,
            rule: sweep_rule,
            reference,
            series,
            targets,
            discharge,
            drum,
        })
    }

    /// Every code that runs a series (cgdem first), each of which also runs the reference.
    pub(crate) fn codes(&self) -> Vec<Code> {
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
    pub(crate) fn scene(
        &self,
        knobs: &BTreeMap<Knob, f64>,
        origin: &Path,
    ) -> Result<(Scene, u32), String> {
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
