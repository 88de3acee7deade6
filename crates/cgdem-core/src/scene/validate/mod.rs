//! Raw scene -> typed settings, with one precise error per bad value: one function per
//! scene table, called in the order the errors have always been reported in.

mod bodies;
mod contact;
mod domain;
mod insertion;
mod materials;
mod packing;
mod particles;
mod stages;

pub use particles::given_particles_from_data;

use std::path::Path;

use super::raw::*;
use super::*;

struct Checker<'a> {
    file: &'a Path,
    /// `[silo]`, checked: the built-in silo the `silo:` meshes are made from.
    silo: Option<crate::geometry::silo::SiloSpec>,
}

impl Checker<'_> {
    fn invalid(
        &self,
        field: impl Into<String>,
        value: impl std::fmt::Display,
        allowed: impl Into<String>,
    ) -> SceneError {
        SceneError::Invalid {
            file: self.file.to_path_buf(),
            field: field.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }

    fn positive(&self, field: &str, value: f64) -> Result<f64, SceneError> {
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(self.invalid(field, value, "a finite number > 0"))
        }
    }

    fn non_negative(&self, field: &str, value: f64) -> Result<f64, SceneError> {
        if value.is_finite() && value >= 0.0 {
            Ok(value)
        } else {
            Err(self.invalid(field, value, "a finite number >= 0"))
        }
    }

    fn vector(&self, field: &str, v: [f64; 3]) -> Result<Vec3, SceneError> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(Vec3::from_array(v))
        } else {
            Err(self.invalid(field, format!("{v:?}"), "three finite numbers"))
        }
    }

    fn required<T>(&self, field: &str, value: Option<T>, what: &str) -> Result<T, SceneError> {
        value.ok_or_else(|| self.invalid(field, "missing", what))
    }

    /// `name` must be one of `known` (stages, walls, bodies: `what` says which).
    fn one_of<'a>(
        &self,
        field: impl Into<String>,
        name: &str,
        what: &str,
        known: impl Iterator<Item = &'a String> + Clone,
    ) -> Result<(), SceneError> {
        if known.clone().any(|k| k == name) {
            Ok(())
        } else {
            Err(self.invalid(field, name, format!("one of the {what}: {}", names(known))))
        }
    }
}

pub fn scene(raw: RawScene, file: &Path) -> Result<Scene, SceneError> {
    let silo = raw.silo.as_ref().map(|s| silo(file, s)).transpose()?;
    let c = Checker { file, silo };
    if raw.name.trim().is_empty() {
        return Err(c.invalid("name", "\"\"", "a non-empty case name"));
    }
    let (domain, stop_on_lost) = domain::domain(&c, &raw.domain)?;
    let hertz = raw.contact.model == "hertz";
    let species = domain::species(&c, &raw.species, &domain, hertz)?;
    let contact = contact::contact(&c, &raw.contact, &species)?;
    let wall_contact = contact::wall_contact(&c, &raw, &species, hertz)?;
    let walls = contact::walls(&c, &raw.walls, &wall_contact.materials, hertz)?;
    let gravity = c.vector("gravity", raw.gravity.unwrap_or([0.0, 0.0, -9.81]))?;
    let (time_step, integrator) = domain::time(&c, &raw.time)?;
    let (skin_fraction, resort_every) =
        domain::neighbor(&c, raw.neighbor.as_ref(), &domain, &species)?;
    let insertions = insertion::insertions(&c, &raw, &domain, &species)?;
    let particles = particles::given_particles(&c, &raw, &domain, &species)?;
    let stages = stages::stages(&c, &raw.stages, &walls)?;
    let output = stages::output(&c, raw.output.as_ref(), &stages)?;
    let repose = raw
        .repose
        .as_ref()
        .map(|r| stages::repose(&c, r, &stages))
        .transpose()?;
    let bodies = bodies::bodies(&c, &raw, &species, &wall_contact.materials, hertz)?;
    let deletions = bodies::deletions(&c, &raw.deletions)?;
    let conveying = raw
        .conveying
        .as_ref()
        .map(|cv| bodies::conveying(&c, cv, &raw.stages, &bodies))
        .transpose()?;
    let packing = raw
        .packing
        .as_ref()
        .map(|pk| packing::packing(&c, pk, &stages, &domain, &species))
        .transpose()?;
    let discharge = raw
        .discharge
        .as_ref()
        .map(|d| stages::discharge(&c, d, &stages, &deletions))
        .transpose()?;

    Ok(Scene {
        discharge,
        packing,
        bodies,
        deletions,
        conveying,
        stop_on_lost,
        name: raw.name,
        description: raw.description,
        source: file.to_path_buf(),
        domain,
        species,
        contact,
        wall_contact,
        walls,
        gravity,
        time_step,
        integrator,
        skin_fraction,
        resort_every,
        insertions,
        particles,
        stages,
        output,
        repose,
        lambda: 1,
        cg_rule: Default::default(),
    })
}

/// `[silo]` over the benchmark silo's defaults, checked.
fn silo(file: &Path, raw: &RawSilo) -> Result<crate::geometry::silo::SiloSpec, SceneError> {
    let d = crate::geometry::silo::SiloSpec::default();
    let spec = crate::geometry::silo::SiloSpec {
        silo_diameter: raw.silo_diameter.unwrap_or(d.silo_diameter),
        orifice_diameter: raw.orifice_diameter.unwrap_or(d.orifice_diameter),
        hopper_half_angle: raw.hopper_half_angle.unwrap_or(d.hopper_half_angle),
        cylinder_height: raw.cylinder_height.unwrap_or(d.cylinder_height),
        orifice_z: raw.orifice_z.unwrap_or(d.orifice_z),
        wall_thickness: raw.wall_thickness.unwrap_or(d.wall_thickness),
        segments: raw.segments.unwrap_or(d.segments),
        max_edge: raw.max_edge.unwrap_or(d.max_edge),
        fill_height: raw.fill_height,
    };
    match spec.problem() {
        None => Ok(spec),
        Some((field, value, allowed)) => Err(SceneError::Invalid {
            file: file.to_path_buf(),
            field: format!("silo.{field}"),
            value,
            allowed: allowed.into(),
        }),
    }
}

/// `screw-feeder:<part>`, `silo:wall` or `silo:fill` (from `[silo]`), or an STL path relative
/// to the scene file; `field` names the value in errors.
fn mesh_source(c: &Checker, field: &str, text: &str) -> Result<MeshSource, SceneError> {
    if let Some(part) = text.strip_prefix("screw-feeder:") {
        return Ok(MeshSource::ScrewFeeder(part.to_string()));
    }
    let Some(part) = text.strip_prefix("silo:") else {
        return Ok(MeshSource::Stl(
            c.file.parent().unwrap_or(Path::new(".")).join(text),
        ));
    };
    let part = match part {
        "wall" => SiloPart::Wall,
        "fill" => SiloPart::Fill,
        _ => return Err(c.invalid(field, text, "`silo:wall` or `silo:fill`")),
    };
    let Some(spec) = &c.silo else {
        return Err(c.invalid(
            field,
            text,
            "a `silo:` mesh with a [silo] table giving the silo's dimensions",
        ));
    };
    if part == SiloPart::Fill && spec.fill_height.is_none() {
        return Err(c.invalid(
            "silo.fill_height",
            "missing",
            "the fill region's top above the hopper's top, m (needed by `silo:fill`)",
        ));
    }
    Ok(MeshSource::Silo(part, spec.clone()))
}

fn names<'a>(list: impl Iterator<Item = &'a String>) -> String {
    list.map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::super::*;
    use std::path::Path;

    /// Paper B's combination in a minimal scene; `contact` replaces the [contact] table body.
    fn scene_with(contact: &str, time: &str) -> Result<Scene, SceneError> {
        let text = format!(
            r#"
name = "t"
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.01, 0.01, 0.01]
[[species]]
name = "fine"
diameter = 5e-5
density = 2500.0
[contact]
{contact}
[time]
{time}
[[stage]]
name = "s"
duration = 0.1
"#
        );
        Scene::parse(&text, Path::new("case.toml"))
    }

    const PAPER_B: &str = r#"model = "hertz"
youngs_modulus = 1e7
poisson_ratio = 0.29
friction = 0.3
rolling_friction = 0.002
damping = "yang"
gamma_n_yang = 1e-5
tangential = "yang"
rolling = "constant_torque"
cohesion = "vdw"
hamaker_constant = 6.5e-20
h_min = 4e-10"#;

    #[test]
    fn a_paper_b_hertz_scene_is_read_with_liggghts_keywords_and_pcvv() {
        let scene = scene_with(PAPER_B, "dt = 1e-8\nintegrator = \"pcvv\"").unwrap();
        assert_eq!(scene.integrator, Integrator::Pcvv);
        let ContactSettings::Hertz(h) = scene.contact else {
            panic!("not hertz")
        };
        assert_eq!(h.damping, HertzDampingKind::Yang { gamma_n: 1e-5 });
        assert_eq!(h.tangential, TangentialKind::Yang);
        assert_eq!(h.rolling, RollingKind::ConstantTorque);
        assert_eq!(
            h.cohesion,
            CohesionKind::VanDerWaals {
                hamaker_constant: 6.5e-20,
                h_min: 4e-10,
                cutoff: None
            }
        );
    }

    #[test]
    fn bad_hertz_values_name_the_file_field_value_and_what_is_allowed() {
        let cases = [
            (
                PAPER_B.replace("poisson_ratio = 0.29", "poisson_ratio = 0.7"),
                "contact.poisson_ratio",
                "-1 <= poisson_ratio < 0.5",
            ),
            (
                PAPER_B.replace("damping = \"yang\"", "damping = \"tsuji\""),
                "contact.damping",
                "\"yang\"",
            ),
            (
                PAPER_B.replace("rolling = \"constant_torque\"", "rolling = \"cdt\""),
                "contact.rolling",
                "epsd2",
            ),
            (
                PAPER_B.replace("h_min = 4e-10", ""),
                "contact.h_min",
                "van der Waals",
            ),
            (
                PAPER_B.replace("gamma_n_yang = 1e-5", "gamma_n = 1e-5"),
                "contact.gamma_n",
                "gamma_n_yang",
            ),
            (
                PAPER_B.replace("damping = \"yang\"", "damping = \"hertz\""),
                "contact.gamma_n_yang",
                "only with damping",
            ),
        ];
        for (contact, field, allowed) in cases {
            let message = scene_with(&contact, "dt = 1e-8").unwrap_err().to_string();
            assert!(
                message.starts_with("case.toml: field `")
                    && message.contains(field)
                    && message.contains(allowed),
                "{message}"
            );
        }
        let message = scene_with(PAPER_B, "dt = 1e-8\nintegrator = \"rk4\"")
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("time.integrator")
                && message.contains("\"rk4\"")
                && message.contains("pcvv"),
            "{message}"
        );
        let message = scene_with("model = \"wca\"\nepsilon = 1.0\nsigma = 4.4545e-5\ngamma_n = 0.0\ngamma_t = 0.0\nfriction = 0.3", "dt = 1e-8").unwrap_err().to_string();
        assert!(
            message.contains("contact.friction") && message.contains("hertz"),
            "{message}"
        );
    }
}
