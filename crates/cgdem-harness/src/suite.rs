//! Suite files (`validation/suites/*.toml`): which cases, codes, lambda levels, rules and
//! seeds a validation run covers, and the tolerances it is judged by.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::accuracy::{AccuracySweep, RawSweep};
use super::verdict::KnownDifference;
use crate::quantity::flow::FlowTolerances;
use crate::quantity::CaseOrigin;
use cgdem_core::coarse_graining::CoarseGrainRule;
use cgdem_core::scene::{Override, Scene, SceneError};

pub use crate::code::Code;
pub use crate::suite_entry::SuiteError;
pub(crate) use crate::suite_entry::{
    beside_suite, load_variant, parse_codes, parse_variant, rule_names,
};

#[derive(Clone, Debug, PartialEq)]
pub struct SuiteCase {
    /// The scene file; the suite names it relative to the suite file ([`beside_suite`]).
    pub file: PathBuf,
    pub codes: Vec<Code>,
    pub lambdas: Vec<u32>,
    pub cg_rules: Vec<CoarseGrainRule>,
    pub seeds: Vec<u64>,
    /// Largest acceptable repose-angle difference between codes or levels, degrees, when
    /// it is not already within the combined seed spread.
    pub angle_tolerance_deg: f64,
    /// Largest acceptable |ratio - 1| of the characteristic flow times (`t_half`, the time
    /// for the front to cover half its largest advance) between codes or levels.
    pub time_ratio_tolerance: f64,
    /// Largest acceptable gap between two front-position histories, as a fraction of the
    /// box length.
    pub front_tolerance: f64,
    /// Largest acceptable gap between two wall-height histories, as a fraction of the
    /// column's initial height.
    pub wall_height_tolerance: f64,
    /// Largest acceptable gap between two kinetic-energy histories, as a fraction of the
    /// peak.
    pub kinetic_energy_tolerance: f64,
    /// Comparisons expected to differ, each with its reason, evidence and band.
    pub known_differences: Vec<KnownDifference>,
    /// Scene overrides (`KEY=VALUE`) that make this case a variant of its file.
    pub overrides: Vec<Override>,
    /// The variant's name, appended to the scene's name (`aor_collapse-smooth-walls`) in run
    /// directories and the report; required with `set`.
    pub variant: Option<String>,
    /// Screw speeds (rev/min) for a scene with `[conveying]`: one run per speed, the stage
    /// scaled to the same number of turns (`sweep::at_speed`); empty: the scene's own speed.
    pub rpms: Vec<f64>,
    /// cgdem's guards only warn in this case's runs (as `--keep-going`): for a case whose
    /// geometry is known to wedge grains deeper than the overlap guard allows (the screw
    /// feeder's tip clearance is narrower than a grain); the warnings stay in each run's
    /// summary, and the reference codes, which have no such guard, run it alike.
    pub keep_going: bool,
    /// Measured as a silo discharge (`[case.discharge]`, `crate::quantity::discharge`).
    pub discharge: Option<crate::quantity::discharge::DischargeSettings>,
    /// Measured as a rotating drum (`[case.drum]`, `crate::quantity::drum`).
    pub drum: Option<crate::quantity::drum::DrumSettings>,
}

impl SuiteCase {
    /// The case's scene: its file with the overrides applied, named after the variant.
    pub fn load_scene(&self) -> Result<Scene, SceneError> {
        load_variant(&self.file, &self.overrides, self.variant.as_deref())
    }

    /// What the quantities' sections say of this case.
    pub fn origin(&self) -> CaseOrigin<'_> {
        CaseOrigin {
            file: &self.file,
            seeds: &self.seeds,
            rpms: &self.rpms,
            keep_going: self.keep_going,
        }
    }

    /// The tolerances of the dynamics criteria.
    pub fn flow_tolerances(&self) -> FlowTolerances {
        FlowTolerances {
            time_ratio: self.time_ratio_tolerance,
            front: self.front_tolerance,
            wall_height: self.wall_height_tolerance,
            kinetic_energy: self.kinetic_energy_tolerance,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Suite {
    pub name: String,
    pub description: String,
    pub source: PathBuf,
    pub cases: Vec<SuiteCase>,
    /// Error-against-run-time sweeps (`[[accuracy]]`).
    pub accuracy: Vec<AccuracySweep>,
    /// `[[stability]]` cases (`harness::stability`).
    pub stability: Vec<super::stability::StabilityCase>,
    /// `[[chung_ooi]]` laws (`harness::chung_ooi`).
    pub chung_ooi: Vec<super::chung_ooi::ChungOoiLaw>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSuite {
    name: String,
    #[serde(default)]
    description: String,
    #[serde(rename = "case", default)]
    cases: Vec<RawCase>,
    #[serde(default)]
    accuracy: Vec<RawSweep>,
    #[serde(default)]
    stability: Vec<super::stability::RawStabilityCase>,
    #[serde(default)]
    chung_ooi: Vec<super::chung_ooi::RawChungOoiLaw>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCase {
    file: PathBuf,
    codes: Vec<String>,
    lambdas: Vec<u32>,
    #[serde(default)]
    cg_rules: Vec<String>,
    seeds: Vec<u64>,
    angle_tolerance_deg: Option<f64>,
    time_ratio_tolerance: Option<f64>,
    front_tolerance: Option<f64>,
    wall_height_tolerance: Option<f64>,
    kinetic_energy_tolerance: Option<f64>,
    #[serde(default)]
    known_difference: Vec<RawKnownDifference>,
    #[serde(default)]
    set: Vec<String>,
    variant: Option<String>,
    #[serde(default)]
    rpms: Vec<f64>,
    #[serde(default)]
    keep_going: bool,
    discharge: Option<crate::quantity::discharge::RawDischarge>,
    drum: Option<crate::quantity::drum::RawDrum>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawKnownDifference {
    comparison: String,
    criterion: String,
    reason: String,
    evidence: String,
    band: [f64; 2],
}

/// The criteria a comparison is judged by (`verdict::Criterion::name`).
pub const CRITERIA: [&str; 12] = [
    crate::quantity::repose::CRITERION,
    "t_half ratio",
    "front gap",
    "wall height gap",
    "kinetic energy gap",
    crate::quantity::discharge::CRITERION,
    crate::quantity::mass_flow::CRITERION,
    crate::quantity::drum::CRITERIA[0],
    crate::quantity::drum::CRITERIA[1],
    crate::quantity::drum::CRITERIA[2],
    crate::quantity::drum::CRITERIA[3],
    crate::quantity::drum::CRITERIA[4],
];

impl Suite {
    pub fn load(path: &Path) -> Result<Suite, SuiteError> {
        let text = std::fs::read_to_string(path).map_err(|source| SuiteError::Unreadable {
            file: path.to_path_buf(),
            source,
        })?;
        Suite::parse(&text, path)
    }

    /// Validates suite text; `path` is used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Suite, SuiteError> {
        let raw: RawSuite = toml::from_str(text).map_err(|e| SuiteError::Syntax {
            file: path.to_path_buf(),
            message: e.to_string().trim_end().replace('\n', "\n  "),
        })?;
        let cases = raw
            .cases
            .into_iter()
            .enumerate()
            .map(|(k, c)| parse_case(c, k, path))
            .collect::<Result<Vec<_>, _>>()?;
        let accuracy = raw
            .accuracy
            .into_iter()
            .enumerate()
            .map(|(k, a)| AccuracySweep::from_raw(a, k, path))
            .collect::<Result<Vec<_>, _>>()?;
        let stability = super::stability::parse_cases(raw.stability, path)?;
        let chung_ooi = super::chung_ooi::parse_laws(raw.chung_ooi, path)?;
        if cases.is_empty() && accuracy.is_empty() && stability.is_empty() && chung_ooi.is_empty() {
            return Err(invalid(
                path,
                "case".into(),
                "(none)".into(),
                "at least one [[case]], [[accuracy]], [[stability]] or [[chung_ooi]]",
            ));
        }
        Ok(Suite {
            name: raw.name,
            description: raw.description,
            source: path.to_path_buf(),
            cases,
            accuracy,
            stability,
            chung_ooi,
        })
    }
}

impl Suite {
    /// The suite `cgdem validate CASE.toml` runs for a scene file of one's own: one case
    /// with the default tolerances, run by `codes` at `lambdas` under the default rule
    /// (relative-overlap) with `seeds`, measured as its scene's observers say (`[repose]`,
    /// `[conveying]`, `[discharge]`, `[packing]`). `name` is the scene's.
    pub fn for_scene(
        file: &Path,
        name: &str,
        codes: &[Code],
        lambdas: &[u32],
        seeds: &[u64],
    ) -> Result<Suite, SuiteError> {
        // Named absolutely, the case's file resolves to itself beside any suite path; the
        // messages then name the scene file, which is what the user gave.
        let absolute = std::path::absolute(file).unwrap_or_else(|_| file.to_path_buf());
        let raw = RawCase {
            file: absolute,
            codes: codes.iter().map(|c| c.name().to_string()).collect(),
            lambdas: lambdas.to_vec(),
            cg_rules: Vec::new(),
            seeds: seeds.to_vec(),
            angle_tolerance_deg: None,
            time_ratio_tolerance: None,
            front_tolerance: None,
            wall_height_tolerance: None,
            kinetic_energy_tolerance: None,
            known_difference: Vec::new(),
            set: Vec::new(),
            variant: None,
            rpms: Vec::new(),
            keep_going: false,
            discharge: None,
            drum: None,
        };
        let case = parse_case(raw, 0, file)?;
        Ok(Suite {
            name: name.to_string(),
            description: format!(
                "The scene {} in {}, {} seeds per code and level.",
                file.display(),
                codes
                    .iter()
                    .map(|c| c.label())
                    .collect::<Vec<_>>()
                    .join(", "),
                seeds.len()
            ),
            source: file.to_path_buf(),
            cases: vec![case],
            accuracy: Vec::new(),
            stability: Vec::new(),
            chung_ooi: Vec::new(),
        })
    }

    /// Every code some entry of the suite runs, each once.
    pub fn codes(&self) -> Vec<Code> {
        let mut codes: Vec<Code> = self
            .cases
            .iter()
            .flat_map(|c| c.codes.clone())
            .chain(self.accuracy.iter().flat_map(|a| a.codes()))
            .chain(self.stability.iter().flat_map(|s| s.codes.clone()))
            .collect();
        codes.sort();
        codes.dedup();
        codes
    }
}

/// `[[case]]` number `k` of the suite at `path`, checked.
fn parse_case(c: RawCase, k: usize, path: &Path) -> Result<SuiteCase, SuiteError> {
    let invalid =
        |field: String, value: String, allowed: &str| invalid(path, field, value, allowed);
    let codes = parse_codes(&c.codes, &format!("case[{k}].codes"), path)?;
    if codes.is_empty() {
        return Err(invalid(
            format!("case[{k}].codes"),
            "[]".into(),
            "at least one code",
        ));
    }
    if c.lambdas.is_empty() || c.lambdas.iter().any(|l| !l.is_power_of_two()) {
        return Err(invalid(
            format!("case[{k}].lambdas"),
            format!("{:?}", c.lambdas),
            "one or more powers of two",
        ));
    }
    if c.seeds.is_empty() {
        return Err(invalid(
            format!("case[{k}].seeds"),
            "[]".into(),
            "at least one insertion seed",
        ));
    }
    let cg_rules = if c.cg_rules.is_empty() {
        vec![CoarseGrainRule::RelativeOverlap]
    } else {
        c.cg_rules
            .iter()
            .map(|name| {
                CoarseGrainRule::from_name(name).ok_or_else(|| {
                    invalid(
                        format!("case[{k}].cg_rules"),
                        format!("\"{name}\""),
                        &rule_names(),
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?
    };
    let angle_tolerance_deg = c.angle_tolerance_deg.unwrap_or(2.0);
    if angle_tolerance_deg.is_nan() || angle_tolerance_deg <= 0.0 {
        return Err(invalid(
            format!("case[{k}].angle_tolerance_deg"),
            angle_tolerance_deg.to_string(),
            "a number of degrees > 0",
        ));
    }
    let fraction = |field: &str, value: Option<f64>, default: f64| {
        let v = value.unwrap_or(default);
        if v.is_finite() && v > 0.0 && v < 1.0 {
            Ok(v)
        } else {
            Err(invalid(
                format!("case[{k}].{field}"),
                v.to_string(),
                "a fraction between 0 and 1 (exclusive)",
            ))
        }
    };
    let time_ratio_tolerance = fraction("time_ratio_tolerance", c.time_ratio_tolerance, 0.10)?;
    let front_tolerance = fraction("front_tolerance", c.front_tolerance, 0.05)?;
    let wall_height_tolerance = fraction("wall_height_tolerance", c.wall_height_tolerance, 0.05)?;
    let kinetic_energy_tolerance =
        fraction("kinetic_energy_tolerance", c.kinetic_energy_tolerance, 0.10)?;
    let known_differences = c
        .known_difference
        .into_iter()
        .enumerate()
        .map(|(j, kd)| parse_known_difference(kd, k, j, path))
        .collect::<Result<Vec<_>, _>>()?;
    let overrides = parse_variant(&c.set, c.variant.as_deref(), &format!("case[{k}]"), path)?;
    if let Some(bad) = c.rpms.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
        return Err(invalid(
            format!("case[{k}].rpms"),
            bad.to_string(),
            "screw speeds in rev/min, finite and > 0",
        ));
    }
    Ok(SuiteCase {
        file: beside_suite(path, &c.file),
        codes,
        lambdas: c.lambdas,
        cg_rules,
        seeds: c.seeds,
        angle_tolerance_deg,
        time_ratio_tolerance,
        front_tolerance,
        wall_height_tolerance,
        kinetic_energy_tolerance,
        known_differences,
        overrides,
        variant: c.variant,
        rpms: c.rpms,
        keep_going: c.keep_going,
        discharge: c
            .discharge
            .map(|d| crate::quantity::discharge::parse_discharge(d, &format!("case[{k}]"), path))
            .transpose()?,
        drum: c
            .drum
            .map(|d| crate::quantity::drum::parse_drum(d, &format!("case[{k}]"), path))
            .transpose()?,
    })
}

/// The `j`th known difference of `[[case]]` number `k`, checked.
fn parse_known_difference(
    kd: RawKnownDifference,
    k: usize,
    j: usize,
    path: &Path,
) -> Result<KnownDifference, SuiteError> {
    let invalid =
        |field: String, value: String, allowed: &str| invalid(path, field, value, allowed);
    let field = |f: &str| format!("case[{k}].known_difference[{j}].{f}");
    if !CRITERIA.contains(&kd.criterion.as_str()) {
        return Err(invalid(
            field("criterion"),
            format!("\"{}\"", kd.criterion),
            "one of \"repose angle\", \"t_half ratio\", \"front gap\", \"wall height gap\", \"kinetic energy gap\", \"discharge rate\" (a silo case), \"mass flow\" (a screw case)",
        ));
    }
    if !(kd.band[0].is_finite() && kd.band[1].is_finite() && kd.band[0] <= kd.band[1]) {
        return Err(invalid(
            field("band"),
            format!("{:?}", kd.band),
            "[low, high], finite, low <= high, in the criterion's units",
        ));
    }
    if kd.reason.trim().is_empty() {
        return Err(invalid(
            field("reason"),
            "\"\"".into(),
            "why the codes or levels differ, in words",
        ));
    }
    // The evidence is a file, named relative to the suite file as `file` is.
    let evidence = beside_suite(path, Path::new(&kd.evidence));
    if !evidence.is_file() {
        return Err(invalid(
            field("evidence"),
            format!("\"{}\" ({})", kd.evidence, evidence.display()),
            "an existing file, relative to the suite file, that documents the difference",
        ));
    }
    if kd.comparison.trim().is_empty() {
        return Err(invalid(
            field("comparison"),
            "\"\"".into(),
            "the start of a comparison's name, e.g. \"cgdem vs lammps\"",
        ));
    }
    Ok(KnownDifference {
        comparison: crate::verdict::renamed_rule(&kd.comparison),
        criterion: kd.criterion,
        reason: kd.reason,
        evidence: evidence.display().to_string(),
        band: kd.band,
    })
}

/// A suite field's bad value, with what is allowed.
fn invalid(path: &Path, field: String, value: String, allowed: &str) -> SuiteError {
    SuiteError::Invalid {
        file: path.to_path_buf(),
        field,
        value,
        allowed: allowed.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CASE: &str = "name = \"t\"\n[[case]]\nfile = \"validation/cases/aor_smoke.toml\"\ncodes = [\"cgdem\"]\nlambdas = [8]\nseeds = [1]\n";

    #[test]
    fn a_variant_overrides_its_scene_and_is_named_after_it() {
        crate::at_repo_root();
        let text =
            format!("{CASE}set = [\"wall_contact.friction=0.0\"]\nvariant = \"smooth-walls\"\n");
        let suite = Suite::parse(&text, Path::new("s.toml")).unwrap();
        let scene = suite.cases[0].load_scene().unwrap();
        let plain = Scene::load(Path::new("validation/cases/aor_smoke.toml")).unwrap();
        assert_eq!(scene.name, format!("{}-smooth-walls", plain.name));
        assert_ne!(scene.digest(), plain.digest());
        assert_ne!(scene.wall_contact, plain.wall_contact);
    }

    #[test]
    fn keep_going_is_per_case_and_off_unless_asked() {
        let suite = Suite::parse(CASE, Path::new("s.toml")).unwrap();
        assert!(!suite.cases[0].keep_going);
        let suite =
            Suite::parse(&format!("{CASE}keep_going = true\n"), Path::new("s.toml")).unwrap();
        assert!(suite.cases[0].keep_going);
    }

    #[test]
    fn set_needs_a_variant_name_and_valid_overrides() {
        let e = Suite::parse(
            &format!("{CASE}set = [\"wall_contact.friction=0.0\"]\n"),
            Path::new("s.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("case[0].variant") && e.contains("(missing)"),
            "{e}"
        );
        let e = Suite::parse(
            &format!("{CASE}set = [\"friction\"]\nvariant = \"v\"\n"),
            Path::new("s.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("case[0].set") && e.contains("KEY=VALUE"), "{e}");
        let e = Suite::parse(&format!("{CASE}variant = \"a b\"\n"), Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("case[0].variant"), "{e}");
    }

    #[test]
    fn a_known_difference_needs_a_criterion_a_band_and_its_evidence() {
        crate::at_repo_root();
        let entry = |criterion: &str, band: &str, evidence: &str| {
            format!(
                "{CASE}[[case.known_difference]]\ncomparison = \"cgdem vs lammps\"\ncriterion = \"{criterion}\"\nreason = \"wall friction cap\"\nevidence = \"{evidence}\"\nband = {band}\n"
            )
        };
        let ok = Suite::parse(
            &entry(
                "repose angle",
                "[5.0, 25.0]",
                "reference/lammps/SEED_MODEL.md",
            ),
            Path::new("s.toml"),
        )
        .unwrap();
        assert_eq!(ok.cases[0].known_differences[0].band, [5.0, 25.0]);
        for (text, field) in [
            (
                entry("angle", "[5.0, 25.0]", "reference/lammps/SEED_MODEL.md"),
                "criterion",
            ),
            (
                entry(
                    "repose angle",
                    "[25.0, 5.0]",
                    "reference/lammps/SEED_MODEL.md",
                ),
                "band",
            ),
            (
                entry("repose angle", "[5.0, 25.0]", "reference/nowhere.md"),
                "evidence",
            ),
        ] {
            let e = Suite::parse(&text, Path::new("s.toml"))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&format!("case[0].known_difference[0].{field}")),
                "{e}"
            );
        }
    }

    #[test]
    fn every_shipped_suite_loads_and_every_case_scene_with_its_overrides() {
        crate::at_repo_root();
        let mut suites = 0;
        for entry in std::fs::read_dir("validation/suites").unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                let suite = Suite::load(&path).unwrap_or_else(|e| panic!("{e}"));
                for case in &suite.cases {
                    case.load_scene()
                        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                }
                suites += 1;
            }
        }
        assert!(suites >= 10, "only {suites} suite files found");
    }
}
