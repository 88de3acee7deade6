//! `[[insert]]`: where, what and how much to insert, and the optional refill.

use super::super::raw::*;
use super::super::*;
use super::{mesh_source, names, Checker};

pub(super) fn insertions(
    c: &Checker,
    raw: &RawScene,
    domain: &Domain,
    species: &[Species],
) -> Result<Vec<Insertion>, SceneError> {
    let (lo, hi) = (domain.lo, domain.hi);
    let mut insertions = Vec::new();
    for (k, ins) in raw.insertions.iter().enumerate() {
        let species_index = species
            .iter()
            .position(|s| s.name == ins.species)
            .ok_or_else(|| {
                c.invalid(
                    format!("insert[{k}].species"),
                    &ins.species,
                    format!(
                        "one of the species: {}",
                        names(species.iter().map(|s| &s.name))
                    ),
                )
            })?;
        let ilo = c.vector(&format!("insert[{k}].lo"), ins.lo)?;
        let ihi = c.vector(&format!("insert[{k}].hi"), ins.hi)?;
        for axis in 0..3 {
            if ihi[axis] <= ilo[axis] || ilo[axis] < lo[axis] || ihi[axis] > hi[axis] {
                return Err(c.invalid(
                    format!("insert[{k}].lo/hi[{axis}]"),
                    format!("{} .. {}", ilo[axis], ihi[axis]),
                    format!(
                        "a non-empty range inside the domain, {} .. {}",
                        lo[axis], hi[axis]
                    ),
                ));
            }
        }
        let amount = amount(c, k, ins, species[species_index].diameter)?;
        let refill = match &ins.refill {
            None => None,
            Some(r) => Some(refill(c, k, r, &amount, &raw.stages)?),
        };
        insertions.push(Insertion {
            refill,
            species: species_index,
            lo: ilo,
            hi: ihi,
            mesh: ins
                .mesh
                .as_deref()
                .map(|m| mesh_source(c, &format!("insert[{k}].mesh"), m))
                .transpose()?,
            amount,
            seed: ins.seed,
            velocity: c.vector(
                &format!("insert[{k}].velocity"),
                ins.velocity.unwrap_or([0.0; 3]),
            )?,
            omega: match ins.omega {
                None => Vec3::ZERO,
                // The seed's WCA law has no spin (particles carry no angular state).
                Some(w) if raw.contact.model != "hertz" => {
                    return Err(c.invalid(
                        format!("insert[{k}].omega"),
                        format!("{w:?}"),
                        "no omega: the contact law does not rotate particles; an initial angular velocity needs contact.model = \"hertz\"",
                    ))
                }
                Some(w) => c.vector(&format!("insert[{k}].omega"), w)?,
            },
            overlap: match ins.overlap {
                None => 0.0,
                Some(f) if (0.0..=0.9).contains(&f) => f,
                Some(f) => {
                    return Err(c.invalid(
                        format!("insert[{k}].overlap"),
                        f,
                        "a fraction of the sum of the radii from 0 (default) to 0.9",
                    ))
                }
            },
        });
    }
    Ok(insertions)
}

/// Exactly one of `count`, `solid_volume` or `lattice` (with its spacing, origin, radius).
fn amount(
    c: &Checker,
    k: usize,
    ins: &RawInsertion,
    diameter: Real,
) -> Result<InsertAmount, SceneError> {
    let lattice_only = [
        ("spacing", ins.spacing.is_some()),
        ("origin", ins.origin.is_some()),
        ("radius", ins.radius.is_some()),
    ];
    match (&ins.lattice, ins.count, ins.solid_volume) {
        (Some(kind), None, None) => {
            let kind = match kind.as_str() {
                "cubic" => LatticeKind::Cubic,
                "hexagonal" => LatticeKind::Hexagonal,
                other => {
                    return Err(c.invalid(
                        format!("insert[{k}].lattice"),
                        other,
                        "\"cubic\" or \"hexagonal\"",
                    ))
                }
            };
            let spacing = ins.spacing.ok_or_else(|| {
                c.invalid(
                    format!("insert[{k}].spacing"),
                    "missing",
                    "the distance between nearest lattice sites, m (at least the diameter)",
                )
            })?;
            if !spacing.is_finite() || spacing < diameter * (1.0 - 1e-9) {
                return Err(c.invalid(
                    format!("insert[{k}].spacing"),
                    spacing,
                    format!("at least the species' diameter, {diameter} m, so that no two particles overlap"),
                ));
            }
            Ok(InsertAmount::Lattice(Lattice {
                kind,
                spacing,
                origin: ins
                    .origin
                    .map(|o| c.vector(&format!("insert[{k}].origin"), o))
                    .transpose()?,
                radius: ins
                    .radius
                    .map(|r| c.positive(&format!("insert[{k}].radius"), r))
                    .transpose()?,
            }))
        }
        (Some(_), _, _) => Err(c.invalid(
            format!("insert[{k}]"),
            "lattice with count or solid_volume",
            "a lattice insertion fills every site in the box: leave out count and solid_volume",
        )),
        (None, _, _) if lattice_only.iter().any(|(_, given)| *given) => {
            let (field, _) = lattice_only.iter().find(|(_, given)| *given).unwrap();
            Err(c.invalid(
                format!("insert[{k}].{field}"),
                "given without lattice",
                "only with lattice = \"cubic\" or \"hexagonal\"",
            ))
        }
        (None, Some(n), None) if n > 0 => Ok(InsertAmount::Count(n)),
        (None, None, Some(v)) => Ok(InsertAmount::SolidVolume(
            c.positive(&format!("insert[{k}].solid_volume"), v)?,
        )),
        _ => Err(c.invalid(
            format!("insert[{k}]"),
            "count and solid_volume",
            "exactly one of count (> 0), solid_volume (m^3) or lattice",
        )),
    }
}

/// `[insert.refill]`: a random insertion repeated every `interval` during a named stage.
fn refill(
    c: &Checker,
    k: usize,
    r: &RawRefill,
    amount: &InsertAmount,
    stages: &[RawStage],
) -> Result<Refill, SceneError> {
    c.one_of(
        format!("insert[{k}].refill.stage"),
        &r.stage,
        "stages",
        stages.iter().map(|s| &s.name),
    )?;
    if matches!(amount, InsertAmount::Lattice(_)) {
        return Err(c.invalid(
            format!("insert[{k}].refill"),
            "given with lattice",
            "refill only for a random insertion (count or solid_volume)",
        ));
    }
    Ok(Refill {
        interval: c.positive(&format!("insert[{k}].refill.interval"), r.interval)?,
        stage: r.stage.clone(),
    })
}
