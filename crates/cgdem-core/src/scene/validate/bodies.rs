//! `[[body]]`, `[[delete]]` and `[conveying]`.

use super::super::raw::*;
use super::super::*;
use super::{mesh_source, names, Checker};

/// `[[body]]`: a moving rigid body, met on its triangles, on an SDF grid (`cell_size`) or
/// built of particles.
pub(super) fn bodies(
    c: &Checker,
    raw: &RawScene,
    species: &[Species],
    materials: &[WallMaterial],
    hertz: bool,
) -> Result<Vec<BodySettings>, SceneError> {
    let mut bodies = Vec::new();
    for (k, b) in raw.bodies.iter().enumerate() {
        if b.name.trim().is_empty() || raw.bodies[..k].iter().any(|o| o.name == b.name) {
            return Err(c.invalid(
                format!("body[{k}].name"),
                &b.name,
                "a non-empty name used by no other body",
            ));
        }
        if let Some(stage) = &b.start_stage {
            c.one_of(
                format!("body[{k}].start_stage"),
                stage,
                "stages",
                raw.stages.iter().map(|s| &s.name),
            )?;
        }
        if !b.rpm.is_finite() {
            return Err(c.invalid(
                format!("body[{k}].rpm"),
                b.rpm,
                "a finite number (rev/min, sign = sense about axis)",
            ));
        }
        let axis = c.vector(
            &format!("body[{k}].axis"),
            b.axis.unwrap_or([0.0, 0.0, 1.0]),
        )?;
        if axis.length() < 1e-12 {
            return Err(c.invalid(
                format!("body[{k}].axis"),
                format!("{axis:?}"),
                "a non-zero vector",
            ));
        }
        let particles = match &b.particles {
            None => None,
            Some(bp) => Some(body_particles(c, k, b, bp, species)?),
        };
        // Without `contact`, a body given a grid spacing (or built of particles) keeps its grid
        // and one given none is met on its triangles: exact, in memory with its surface, and
        // the cheaper where grains are small against the triangles (the silo), while a grid
        // pays where they are large (the screw: reports/exact_walls/NOTE.md).
        let contact = match b.contact.as_deref() {
            Some("grid") => BodyContact::Grid,
            Some("mesh") => BodyContact::Mesh,
            None if b.cell_size.is_some() || b.padding.is_some() || particles.is_some() => {
                BodyContact::Grid
            }
            None => BodyContact::Mesh,
            Some(other) => {
                return Err(c.invalid(
                    format!("body[{k}].contact"),
                    other,
                    "\"grid\" (a signed-distance grid of cell_size; the default with cell_size) or \"mesh\" (the triangles themselves, as LIGGGHTS's mesh walls; the default without)",
                ))
            }
        };
        if contact == BodyContact::Mesh {
            let field = if particles.is_some() {
                Some("particles")
            } else if b.cell_size.is_some() {
                Some("cell_size")
            } else if b.padding.is_some() {
                Some("padding")
            } else {
                None
            };
            if let Some(field) = field {
                return Err(c.invalid(
                    format!("body[{k}].{field}"),
                    "given with contact = \"mesh\"",
                    "nothing: a body with contact = \"mesh\" is met on its triangles, it has no grid and is not built of particles",
                ));
            }
        }
        let cell_size = match (&particles, b.cell_size) {
            (Some(_), _) => 0.0,
            (None, _) if contact == BodyContact::Mesh => 0.0,
            (None, Some(cell)) => c.positive(&format!("body[{k}].cell_size"), cell)?,
            (None, None) => {
                return Err(c.invalid(
                    format!("body[{k}].cell_size"),
                    "missing",
                    "the SDF grid spacing, m, with contact = \"grid\" (without both, the body is met on its triangles)",
                ))
            }
        };
        let material_field = format!("body[{k}].material");
        if b.material.is_some() && !hertz {
            return Err(c.invalid(material_field, "set", "only with contact.model = \"hertz\""));
        }
        if b.material.is_some() && particles.is_some() {
            return Err(c.invalid(
                material_field,
                "set",
                "no material for a body built of particles: they carry their species' (species youngs_modulus, poisson_ratio)",
            ));
        }
        let material =
            super::materials::material_index(c, &material_field, b.material.as_deref(), materials)?;
        bodies.push(BodySettings {
            material,
            contact,
            name: b.name.clone(),
            mesh: mesh_source(c, &format!("body[{k}].mesh"), &b.mesh)?,
            cell_size,
            particles,
            padding: b
                .padding
                .map(|p| c.positive(&format!("body[{k}].padding"), p))
                .transpose()?,
            rpm: b.rpm,
            axis: axis.normalize(),
            point: c.vector(&format!("body[{k}].point"), b.point.unwrap_or([0.0; 3]))?,
            velocity: c.vector(
                &format!("body[{k}].velocity"),
                b.velocity.unwrap_or([0.0; 3]),
            )?,
            start_stage: b.start_stage.clone(),
        });
    }
    Ok(bodies)
}

/// `[[body]] particles = {...}`: a frozen species on an fcc lattice, no SDF grid.
fn body_particles(
    c: &Checker,
    k: usize,
    b: &RawBody,
    bp: &RawBodyParticles,
    species: &[Species],
) -> Result<BodyParticles, SceneError> {
    let index = species.iter().position(|s| s.name == bp.species);
    let Some(index) = index.filter(|&i| species[i].frozen) else {
        let frozen = names(species.iter().filter(|s| s.frozen).map(|s| &s.name));
        return Err(c.invalid(
            format!("body[{k}].particles.species"),
            &bp.species,
            format!(
                "a species with frozen = true (the body's particles are moved by the body, not integrated); frozen species: {}",
                if frozen.is_empty() { "none".to_string() } else { frozen }
            ),
        ));
    };
    if let Some(lattice) = bp.lattice.as_deref().filter(|l| *l != "fcc") {
        return Err(c.invalid(
            format!("body[{k}].particles.lattice"),
            lattice,
            "\"fcc\" (the default)",
        ));
    }
    if b.cell_size.is_some() || b.padding.is_some() {
        return Err(c.invalid(
            format!("body[{k}].cell_size"),
            "given with particles",
            "no cell_size or padding for a body built of particles (it has no SDF grid)",
        ));
    }
    Ok(BodyParticles { species: index })
}

/// `[[delete]]`: boxes emptied of particles, lo < hi on every axis.
pub(super) fn deletions(c: &Checker, raw: &[RawDelete]) -> Result<Vec<(Vec3, Vec3)>, SceneError> {
    let mut deletions = Vec::new();
    for (k, d) in raw.iter().enumerate() {
        let dlo = c.vector(&format!("delete[{k}].lo"), d.lo)?;
        let dhi = c.vector(&format!("delete[{k}].hi"), d.hi)?;
        if dlo.cmpge(dhi).any() {
            return Err(c.invalid(
                format!("delete[{k}].hi"),
                format!("{dhi:?}"),
                format!("greater than lo = {dlo:?} on every axis"),
            ));
        }
        deletions.push((dlo, dhi));
    }
    Ok(deletions)
}

/// `[conveying]`: the screw feeder's mass flow, fill level and bulk density measurement.
pub(super) fn conveying(
    c: &Checker,
    cv: &RawConveying,
    stages: &[RawStage],
    bodies: &[BodySettings],
) -> Result<ConveyingSettings, SceneError> {
    c.one_of(
        "conveying.stage",
        &cv.stage,
        "stages",
        stages.iter().map(|s| &s.name),
    )?;
    c.one_of(
        "conveying.body",
        &cv.body,
        "bodies",
        bodies.iter().map(|b| &b.name),
    )?;
    let outer_diameter = c.positive("conveying.outer_diameter", cv.outer_diameter)?;
    let shaft_diameter = c.positive("conveying.shaft_diameter", cv.shaft_diameter)?;
    if shaft_diameter >= outer_diameter {
        return Err(c.invalid(
            "conveying.shaft_diameter",
            shaft_diameter,
            format!("less than outer_diameter = {outer_diameter}"),
        ));
    }
    if cv.fill_x[1] <= cv.fill_x[0] {
        return Err(c.invalid(
            "conveying.fill_x",
            format!("{:?}", cv.fill_x),
            "an increasing range [x0, x1]",
        ));
    }
    if let Some(x) = cv.flow_x.filter(|x| !x.is_finite()) {
        return Err(c.invalid("conveying.flow_x", x, "a finite axial position in m"));
    }
    // A standard error needs at least two blocks.
    let blocks = cv.blocks.unwrap_or(5);
    if blocks < 2 {
        return Err(c.invalid(
            "conveying.blocks",
            blocks,
            "at least 2 (the mass flow's standard error is taken over the blocks)",
        ));
    }
    let bulk_lo = c.vector("conveying.bulk_lo", cv.bulk_lo)?;
    let bulk_hi = c.vector("conveying.bulk_hi", cv.bulk_hi)?;
    if bulk_lo.cmpge(bulk_hi).any() {
        return Err(c.invalid(
            "conveying.bulk_hi",
            format!("{bulk_hi:?}"),
            format!("greater than bulk_lo = {bulk_lo:?} on every axis"),
        ));
    }
    Ok(ConveyingSettings {
        stage: cv.stage.clone(),
        body: cv.body.clone(),
        discard: c.non_negative("conveying.discard", cv.discard)?,
        blocks,
        outer_diameter,
        shaft_diameter,
        pitch: c.positive("conveying.pitch", cv.pitch)?,
        bore_radius: c.positive("conveying.bore_radius", cv.bore_radius)?,
        fill_x: cv.fill_x,
        flow_x: cv.flow_x,
        bulk_lo,
        bulk_hi,
    })
}
