//! Faults planted in cgdem's runs only (`cgdem validate --fault KEY=VALUE`), so that the
//! comparisons with the reference codes' unchanged runs show whether the verdicts can fail
//! (scripts/planted-faults.sh). A fault is a scene override (`contact.friction=0.1`),
//! applied after the case's own, or `rpm_factor=F`: the screw of a conveying case turns F
//! times as fast as the case says. The speed needs a key of its own because a suite's
//! `rpms` set the screw's speed after the overrides, so an override of the body's `rpm`
//! would not survive them.

use std::path::Path;

use cgdem_core::scene::{Override, Scene, SceneError};

/// The key of the screw-speed fault.
pub const RPM_FACTOR: &str = "rpm_factor";

/// The faults of `--fault`, parsed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Faults {
    /// Scene overrides, in the order given.
    pub overrides: Vec<Override>,
    /// `rpm_factor=F`: the conveying body's speed times F (after the suite's `rpms`).
    pub rpm_factor: Option<f64>,
}

impl Faults {
    /// Parses each `KEY=VALUE`; a bad one is an error naming it, before any run is made.
    pub fn parse(faults: &[String]) -> Result<Faults, SceneError> {
        let origin = Path::new("--fault");
        let mut out = Faults::default();
        for text in faults {
            match text.split_once('=') {
                Some((key, value)) if key.trim() == RPM_FACTOR => {
                    let factor = value.trim().parse::<f64>().ok();
                    let factor = factor.filter(|f| f.is_finite() && *f > 0.0);
                    out.rpm_factor = Some(factor.ok_or_else(|| {
                        SceneError::Invalid {
                            file: origin.to_path_buf(),
                            field: RPM_FACTOR.into(),
                            value: value.trim().into(),
                            allowed: "a factor > 0 on the screw's speed, e.g. 0.8: the screw of \
                                  a conveying case turning 0.8 times as fast as the case says"
                                .into(),
                        }
                    })?);
                }
                _ => out.overrides.push(Override::parse(text, origin)?),
            }
        }
        Ok(out)
    }

    /// No fault at all.
    pub fn is_empty(&self) -> bool {
        self.overrides.is_empty() && self.rpm_factor.is_none()
    }

    /// `scene` with the speed fault applied: the body its `[conveying]` names turning
    /// `rpm_factor` times as fast, the stages left as they are (so the run covers fewer or
    /// more turns in the same time). None when there is no speed fault or no conveying body.
    pub fn at_faulty_speed(&self, scene: &Scene) -> Option<Scene> {
        let factor = self.rpm_factor?;
        let body = &scene.conveying.as_ref()?.body;
        let mut faulty = scene.clone();
        for b in faulty.bodies.iter_mut().filter(|b| &b.name == body) {
            b.rpm *= factor;
        }
        Some(faulty)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(faults: &[&str]) -> Result<Faults, SceneError> {
        Faults::parse(&faults.iter().map(|f| f.to_string()).collect::<Vec<_>>())
    }

    #[test]
    fn the_speed_fault_is_accepted_and_turns_the_screw_slower_after_the_suite_speed() {
        crate::at_repo_root();
        let faults = parse(&["rpm_factor=0.8", "contact.friction=0.3"]).unwrap();
        assert_eq!(faults.rpm_factor, Some(0.8));
        assert_eq!(faults.overrides.len(), 1);
        let scene = Scene::load(Path::new("validation/cases/screw_feeder_hertz.toml")).unwrap();
        // The suite's speed first (140 rpm, the stages scaled to 3 turns), then the fault.
        let at_140 = crate::sweep::at_speed(&scene, "screw", 140.0);
        let faulty = faults.at_faulty_speed(&at_140).unwrap();
        let rpm = |s: &Scene| s.bodies.iter().find(|b| b.name == "screw").unwrap().rpm;
        assert_eq!(rpm(&at_140), -140.0);
        assert!((rpm(&faulty) + 112.0).abs() < 1e-12, "{}", rpm(&faulty));
        // Only the screw turns slower; nothing else of the scene changes.
        let mut back = faulty.clone();
        for b in back.bodies.iter_mut().filter(|b| b.name == "screw") {
            b.rpm = -140.0;
        }
        assert!(back == at_140);
        assert!(faulty != at_140);
        // A scene without a screw is not touched by it; no speed fault changes nothing.
        let heap = Scene::load(Path::new("validation/cases/aor_hertz_smoke.toml")).unwrap();
        assert!(faults.at_faulty_speed(&heap).is_none());
        assert!(parse(&["contact.friction=0.3"])
            .unwrap()
            .at_faulty_speed(&at_140)
            .is_none());
    }

    #[test]
    fn a_bad_speed_factor_is_refused_with_its_key() {
        for bad in [
            "rpm_factor=0",
            "rpm_factor=-1",
            "rpm_factor=fast",
            "rpm_factor=inf",
        ] {
            let e = parse(&[bad]).unwrap_err().to_string();
            assert!(
                e.contains("rpm_factor") && e.contains("factor > 0"),
                "{bad}: {e}"
            );
        }
        assert!(parse(&["no_equals_sign"]).is_err());
        assert!(parse(&[]).unwrap().is_empty());
    }
}
