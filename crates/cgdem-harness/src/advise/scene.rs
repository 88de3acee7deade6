//! The coarse-graining matrix of a scene that no suite names (`cgdem advise CASE.toml --run`):
//! its levels, rules and seeds from the scene alone, and what the scene can measure.
//!
//! Levels run from the scene's own (lambda = 1, the fine reference) up to the coarsest power
//! of two that still keeps [`MIN_PARTICLES`] particles and, where the scene has an opening
//! (a silo's or hopper's orifice), [`MIN_ACROSS_OPENING`] particle diameters across it. The
//! rules are those defined for the scene's law; rules that give this scene the same
//! parameters as an earlier one are run once, under the earlier one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::AdviseError;
use crate::accuracy::{AccuracySweep, Knob, KnobSeries, Measure, Targets};
use crate::code::Code;
pub use crate::quantity::discharge::{discharge_settings, opening, Opening};
use cgdem_core::coarse_graining::{coarse_grain_by, CoarseGrainRule};
use cgdem_core::scene::{ContactSettings, Scene};

/// Fewest particles a default level keeps: below a few hundred, a heap, a bed or a flow is
/// a handful of parcels whose measurement is mostly their packing.
pub const MIN_PARTICLES: f64 = 200.0;

/// Fewest parcel diameters across the narrowest opening a default level keeps. Below about
/// five diameters a circular orifice arches and the flow clogs (the silo of the validation
/// suite stopped at lambda 4, 2.5 and 3.75 parcels across its 40 and 60 mm orifices), so a
/// coarser level measures a clog, not the fine system's flow.
pub const MIN_ACROSS_OPENING: f64 = 5.0;

/// Insertion seeds of a default matrix: three, so that each setting has a spread.
pub const DEFAULT_SEEDS: [u64; 3] = [1, 2, 3];

/// The variant the matrix's runs carry: the case is `<scene name>-advise`.
pub const VARIANT: &str = "advise";

/// Coarsest level a default matrix tries.
const MAX_LAMBDA: u32 = 64;

/// What the user chose of the matrix (`--lambdas`, `--rules`, `--seeds`); None: the default.
#[derive(Clone, Debug, Default)]
pub struct MatrixChoice {
    pub lambdas: Option<Vec<u32>>,
    pub rules: Option<Vec<CoarseGrainRule>>,
    pub seeds: Option<Vec<u64>>,
}

/// One level of the matrix: its particle count and parcel diameter.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelPlan {
    pub lambda: u32,
    pub particles: f64,
    pub diameter_m: f64,
    /// Parcel diameters across the opening.
    pub across_opening: Option<f64>,
}

/// The matrix a scene alone gives, as an accuracy sweep with what led to it.
#[derive(Clone, Debug)]
pub struct SceneMatrix {
    pub scene: Scene,
    pub sweep: AccuracySweep,
    pub levels: Vec<LevelPlan>,
    pub rules: Vec<CoarseGrainRule>,
    /// Rules left out because they give this scene the parameters of the rule named.
    pub same_as: Vec<(CoarseGrainRule, CoarseGrainRule)>,
    pub seeds: Vec<u64>,
    pub opening: Option<Opening>,
    /// Why the default levels stop where they do (None: chosen by `--lambdas`).
    pub coarsest_because: Option<String>,
    /// Levels chosen by `--lambdas` below the minimums, said.
    pub warnings: Vec<String>,
}

fn law(scene: &Scene) -> &'static str {
    match scene.contact {
        ContactSettings::Wca(_) => "wca",
        ContactSettings::Hertz(_) => "hertz",
    }
}

/// The quantities a scene measures: a heap (`[repose]`), a screw's flow (`[conveying]`), a
/// bed (`[packing]`), a discharge (grains of one species counted out through `[[delete]]`).
pub fn measurable(scene: &Scene) -> Vec<Measure> {
    let mut out = Vec::new();
    if scene.repose.is_some() {
        out.extend([
            Measure::Angle,
            Measure::Profile,
            Measure::THalf,
            Measure::Front,
        ]);
    }
    if scene.conveying.is_some() {
        out.extend([Measure::MassFlow, Measure::Eq7]);
    }
    if scene.packing.is_some() {
        out.extend([Measure::Porosity, Measure::PoreSize]);
    }
    if discharge_settings(scene, None).is_some() {
        out.push(Measure::DischargeRate);
    }
    out
}

/// The level `lambda` of `scene`: its particles (the insertions' amounts at that level, as
/// the run makes them) and parcel diameter; Err: the level cannot be built (too coarse for
/// the box).
fn level(scene: &Scene, lambda: u32, opening: Option<&Opening>) -> Result<LevelPlan, String> {
    let coarse = coarse_grain_by(scene, lambda, CoarseGrainRule::RelativeOverlap)
        .or_else(|_| coarse_grain_by(scene, lambda, CoarseGrainRule::ScaledParticle))
        .map_err(|e| e.to_string())?;
    let diameter_m = coarse.max_diameter();
    Ok(LevelPlan {
        lambda,
        particles: cgdem_core::run::memory::estimate(&coarse, None).particles,
        diameter_m,
        across_opening: opening.map(|o| o.diameter_m / diameter_m),
    })
}

/// Why `l` falls short of the default minimums, if it does.
fn short_of_minimums(l: &LevelPlan) -> Option<String> {
    if l.particles < MIN_PARTICLES {
        return Some(format!(
            "lambda = {} keeps {:.0} particles, fewer than {MIN_PARTICLES:.0}",
            l.lambda, l.particles
        ));
    }
    match l.across_opening {
        Some(a) if a < MIN_ACROSS_OPENING => Some(format!(
            "lambda = {} puts {a:.1} parcel diameters across the opening, fewer than {MIN_ACROSS_OPENING}",
            l.lambda
        )),
        _ => None,
    }
}

/// The default levels: 1, 2, 4, ... while each keeps the minimums; and why they stop.
fn default_levels(
    scene: &Scene,
    opening: Option<&Opening>,
) -> Result<(Vec<LevelPlan>, String), AdviseError> {
    let mut levels = vec![level(scene, 1, opening).map_err(|reason| no_matrix(scene, reason))?];
    let mut lambda = 2;
    let because = loop {
        if lambda > MAX_LAMBDA {
            break format!("{MAX_LAMBDA} is the coarsest level tried");
        }
        let l = match level(scene, lambda, opening) {
            Ok(l) => l,
            Err(reason) => break reason,
        };
        if let Some(reason) = short_of_minimums(&l) {
            break reason;
        }
        levels.push(l);
        lambda *= 2;
    };
    if levels.len() < 2 {
        return Err(no_matrix(
            scene,
            format!("no coarse level keeps the minimums ({because}); choose levels with --lambdas"),
        ));
    }
    Ok((levels, because))
}

fn no_matrix(scene: &Scene, reason: String) -> AdviseError {
    AdviseError::NoMatrix {
        file: scene.source.clone(),
        reason,
    }
}

/// The rules of the scene's law, each run unless an earlier one gives the scene the same
/// parameters at lambda = 2 (then named in `same_as`).
fn default_rules(
    scene: &Scene,
) -> (
    Vec<CoarseGrainRule>,
    Vec<(CoarseGrainRule, CoarseGrainRule)>,
) {
    let mut rules: Vec<(CoarseGrainRule, Option<Scene>)> = Vec::new();
    let mut same_as = Vec::new();
    for rule in CoarseGrainRule::ALL
        .into_iter()
        .filter(|r| r.defined_for(law(scene)))
    {
        let coarse = coarse_grain_by(scene, 2, rule).ok().map(|mut s| {
            s.cg_rule = CoarseGrainRule::RelativeOverlap;
            s
        });
        match rules.iter().find(|(_, c)| coarse.is_some() && *c == coarse) {
            Some((first, _)) => same_as.push((rule, *first)),
            None => rules.push((rule, coarse)),
        }
    }
    (rules.into_iter().map(|(r, _)| r).collect(), same_as)
}

/// The matrix of `scene` (read from `path`) for quantity `m` with the user's `choice`; Err
/// when the scene cannot measure `m`, a choice is not allowed, or no matrix can be made.
pub fn scene_matrix(
    path: &Path,
    scene: Scene,
    m: Measure,
    target: f64,
    choice: &MatrixChoice,
) -> Result<SceneMatrix, AdviseError> {
    let can = measurable(&scene);
    if !can.contains(&m) {
        return Err(AdviseError::NotMeasurable {
            file: path.to_path_buf(),
            quantity: m.quantity().into(),
            measurable: if can.is_empty() {
                "none: it has no [repose], [conveying], [packing] or [[delete]] of one species"
                    .into()
            } else {
                can.iter()
                    .map(|q| q.quantity())
                    .collect::<Vec<_>>()
                    .join(", ")
            },
        });
    }
    let (rules, same_as) = match &choice.rules {
        None => default_rules(&scene),
        Some(rules) => {
            for rule in rules {
                if !rule.defined_for(law(&scene)) {
                    return Err(choice_error(
                        path,
                        "--rules",
                        rule.name(),
                        format!(
                            "not defined for the scene's law ({}): {}",
                            law(&scene),
                            CoarseGrainRule::names_for(law(&scene))
                        ),
                    ));
                }
            }
            (rules.clone(), Vec::new())
        }
    };
    let opening = opening(&scene);
    let mut warnings = Vec::new();
    let (levels, coarsest_because) = match &choice.lambdas {
        None => {
            let (levels, because) = default_levels(&scene, opening.as_ref())?;
            (levels, Some(because))
        }
        Some(lambdas) => {
            let mut sorted = lambdas.clone();
            sorted.sort_unstable();
            sorted.dedup();
            if sorted.len() < 2 {
                return Err(choice_error(
                    path,
                    "--lambdas",
                    format!("{lambdas:?}"),
                    "two or more levels: the finest is the reference, each coarser one a point"
                        .into(),
                ));
            }
            let mut levels = Vec::new();
            for lambda in sorted {
                let l = level(&scene, lambda, opening.as_ref())
                    .map_err(|reason| choice_error(path, "--lambdas", lambda, reason))?;
                warnings.extend(short_of_minimums(&l));
                levels.push(l);
            }
            (levels, None)
        }
    };
    let seeds = choice
        .seeds
        .clone()
        .unwrap_or_else(|| DEFAULT_SEEDS.to_vec());
    let sweep = sweep(
        path,
        &scene,
        &levels,
        &rules,
        &seeds,
        (m, target),
        opening.as_ref(),
    );
    Ok(SceneMatrix {
        scene,
        sweep,
        levels,
        rules,
        same_as,
        seeds,
        opening,
        coarsest_because,
        warnings,
    })
}

fn choice_error(
    path: &Path,
    option: &str,
    value: impl std::fmt::Display,
    reason: String,
) -> AdviseError {
    AdviseError::Choice {
        file: path.to_path_buf(),
        option: option.into(),
        value: value.to_string(),
        reason,
    }
}

/// The accuracy sweep of the matrix: the finest level under the first rule is the
/// reference, every coarser level a point under each rule, cgdem only.
fn sweep(
    path: &Path,
    scene: &Scene,
    levels: &[LevelPlan],
    rules: &[CoarseGrainRule],
    seeds: &[u64],
    (m, target): (Measure, f64),
    opening: Option<&Opening>,
) -> AccuracySweep {
    let reference = levels[0].lambda;
    let coarse: Vec<f64> = levels[1..].iter().map(|l| l.lambda as f64).collect();
    let mut targets = DEFAULT_TARGETS;
    set_target(&mut targets, m, target);
    AccuracySweep {
        file: PathBuf::from(path),
        overrides: Vec::new(),
        variant: VARIANT.into(),
        seeds: seeds.to_vec(),
        rule: rules[0],
        reference: BTreeMap::from([(Knob::Lambda, reference as f64)]),
        series: rules
            .iter()
            .map(|&rule| KnobSeries {
                knob: Knob::Lambda,
                values: coarse.clone(),
                codes: vec![Code::Cgdem],
                rule,
            })
            .collect(),
        targets,
        discharge: discharge_settings(scene, opening),
        // A drum is measured as its suite says (`[case.drum]`): a scene alone cannot.
        drum: None,
    }
}

/// A suite's targets when it names none (`accuracy::suite`).
const DEFAULT_TARGETS: Targets = Targets {
    angle_deg: 1.0,
    profile: 0.05,
    mass_flow: 0.05,
    t_half: 0.1,
    front: 0.1,
    porosity: 0.02,
    pore_size: 0.1,
    discharge_rate: 0.05,
    dynamic_angle_deg: 2.0,
    mixing_period: 0.1,
    mixing_index: 0.05,
};

fn set_target(t: &mut Targets, m: Measure, target: f64) {
    let slot = match m {
        Measure::Angle => &mut t.angle_deg,
        Measure::Profile => &mut t.profile,
        Measure::MassFlow | Measure::Eq7 => &mut t.mass_flow,
        Measure::THalf => &mut t.t_half,
        Measure::Front => &mut t.front,
        Measure::Porosity => &mut t.porosity,
        Measure::PoreSize => &mut t.pore_size,
        Measure::DischargeRate => &mut t.discharge_rate,
        Measure::DynamicAngle => &mut t.dynamic_angle_deg,
        Measure::MixingPeriod => &mut t.mixing_period,
        Measure::MixingIndex => &mut t.mixing_index,
    };
    *slot = target;
}
