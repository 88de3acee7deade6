//! Raw scene -> typed settings, with one precise error per bad value.

use std::path::Path;

use super::raw::*;
use super::*;
use crate::integrate::Integrator;
use crate::math::TWO_POW_ONE_SIXTH;

struct Checker<'a> {
    file: &'a Path,
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
}

pub fn scene(raw: RawScene, file: &Path) -> Result<Scene, SceneError> {
    let c = Checker { file };
    if raw.name.trim().is_empty() {
        return Err(c.invalid("name", "\"\"", "a non-empty case name"));
    }

    let lo = c.vector("domain.lo", raw.domain.lo)?;
    let hi = c.vector("domain.hi", raw.domain.hi)?;
    for axis in 0..3 {
        if hi[axis] <= lo[axis] {
            return Err(c.invalid(
                format!("domain.hi[{axis}]"),
                hi[axis],
                format!("greater than domain.lo[{axis}] = {}", lo[axis]),
            ));
        }
    }
    let domain = Domain {
        lo,
        hi,
        periodic: raw.domain.periodic,
    };
    let stop_on_lost = match raw.domain.lost.as_deref() {
        None | Some("error") => true,
        Some("warn") => false,
        Some(other) => {
            return Err(c.invalid(
                "domain.lost",
                format!("\"{other}\""),
                "\"error\" (a particle leaving through a bounded face stops the run) or \"warn\" (it is removed with a warning)",
            ))
        }
    };
    let shortest_side = (0..3).map(|a| hi[a] - lo[a]).fold(f64::INFINITY, f64::min);

    if raw.species.is_empty() {
        return Err(c.invalid("species", "none", "at least one [[species]] table"));
    }
    let mut species = Vec::new();
    for (k, s) in raw.species.iter().enumerate() {
        let diameter = c.positive(&format!("species[{k}].diameter"), s.diameter)?;
        if diameter >= shortest_side {
            return Err(c.invalid(
                format!("species[{k}].diameter"),
                diameter,
                format!("smaller than the shortest box side, {shortest_side} m"),
            ));
        }
        let density = c.positive(&format!("species[{k}].density"), s.density)?;
        if species.iter().any(|t: &Species| t.name == s.name) {
            return Err(c.invalid(
                format!("species[{k}].name"),
                &s.name,
                "a name not used by another species",
            ));
        }
        species.push(Species {
            name: s.name.clone(),
            diameter,
            density,
            frozen: s.frozen,
        });
    }

    let contact = match raw.contact.model.as_str() {
        "hertz" => ContactSettings::Hertz(hertz_contact(&c, &raw.contact)?),
        "wca" => {
            let rc = &raw.contact;
            for (field, set) in [
                ("youngs_modulus", rc.youngs_modulus.is_some()),
                ("poisson_ratio", rc.poisson_ratio.is_some()),
                ("restitution", rc.restitution.is_some()),
                ("friction", rc.friction.is_some()),
                ("rolling_friction", rc.rolling_friction.is_some()),
                ("damping", rc.damping.is_some()),
                ("gamma_n_yang", rc.gamma_n_yang.is_some()),
                ("tangential", rc.tangential.is_some()),
                ("rolling", rc.rolling.is_some()),
                ("cohesion", rc.cohesion.is_some()),
                ("hamaker_constant", rc.hamaker_constant.is_some()),
                ("h_min", rc.h_min.is_some()),
                ("cohesion_cutoff", rc.cohesion_cutoff.is_some()),
                (
                    "characteristic_velocity",
                    rc.characteristic_velocity.is_some(),
                ),
            ] {
                if set {
                    return Err(c.invalid(format!("contact.{field}"), "set", "only with model = \"hertz\"; the wca model takes epsilon, sigma, gamma_n, gamma_t"));
                }
            }
            let epsilon = c.positive(
                "contact.epsilon",
                c.required("contact.epsilon", raw.contact.epsilon, "the WCA energy, J")?,
            )?;
            let sigma = c.positive(
                "contact.sigma",
                c.required("contact.sigma", raw.contact.sigma, "the WCA length, m")?,
            )?;
            let gamma_n = c.non_negative(
                "contact.gamma_n",
                c.required(
                    "contact.gamma_n",
                    raw.contact.gamma_n,
                    "the normal dashpot, kg/s",
                )?,
            )?;
            let gamma_t = c.non_negative(
                "contact.gamma_t",
                c.required(
                    "contact.gamma_t",
                    raw.contact.gamma_t,
                    "the tangential dashpot, kg/s",
                )?,
            )?;
            // The WCA cut-off 2^(1/6) sigma is the particle diameter (paper A); a mismatch
            // would make particles touch before or after they repel. Frozen species (e.g. a
            // body's particles) get sigma mixed by the mean diameter of each pair instead.
            for s in species.iter().filter(|s| !s.frozen) {
                let rc = TWO_POW_ONE_SIXTH * sigma;
                if (rc / s.diameter - 1.0).abs() > 0.01 {
                    return Err(c.invalid("contact.sigma", sigma, format!("2^(1/6) sigma within 1% of the diameter of species `{}` ({} m), i.e. sigma near {:.6e}", s.name, s.diameter, s.diameter / TWO_POW_ONE_SIXTH)));
                }
            }
            ContactSettings::Wca {
                epsilon,
                sigma,
                gamma_n,
                gamma_t,
            }
        }
        other => {
            return Err(c.invalid(
                "contact.model",
                format!("\"{other}\""),
                "\"wca\" (the seed's model) or \"hertz\"",
            ))
        }
    };

    let wall_contact = match &raw.wall_contact {
        Some(w) => {
            if !(w.restitution > 0.0 && w.restitution <= 1.0) {
                return Err(c.invalid("wall_contact.restitution", w.restitution, "0 < e <= 1"));
            }
            let youngs_modulus = match w.youngs_modulus {
                Some(y) => Some(c.positive("wall_contact.youngs_modulus", y)?),
                None => None,
            };
            let poisson_ratio = match w.poisson_ratio {
                Some(nu) => Some(poisson(&c, "wall_contact.poisson_ratio", nu)?),
                None => None,
            };
            WallContactSettings {
                restitution: w.restitution,
                friction: c.non_negative("wall_contact.friction", w.friction)?,
                youngs_modulus,
                poisson_ratio,
                rolling_friction: c.non_negative(
                    "wall_contact.rolling_friction",
                    w.rolling_friction.unwrap_or(0.0),
                )?,
            }
        }
        None if raw.walls.is_empty() => WallContactSettings {
            restitution: 1.0,
            friction: 0.0,
            youngs_modulus: None,
            poisson_ratio: None,
            rolling_friction: 0.0,
        },
        None => {
            return Err(c.invalid(
                "wall_contact",
                "missing",
                "a [wall_contact] table with restitution and friction when the scene has walls",
            ))
        }
    };

    let mut walls = Vec::new();
    for (k, w) in raw.walls.iter().enumerate() {
        let point = c.vector(&format!("wall[{k}].point"), w.point)?;
        let normal = c.vector(&format!("wall[{k}].normal"), w.normal)?;
        if normal.length() == 0.0 {
            return Err(c.invalid(
                format!("wall[{k}].normal"),
                format!("{:?}", w.normal),
                "a non-zero vector",
            ));
        }
        if walls.iter().any(|x: &WallSettings| x.name == w.name) {
            return Err(c.invalid(
                format!("wall[{k}].name"),
                &w.name,
                "a name not used by another wall",
            ));
        }
        walls.push(WallSettings {
            name: w.name.clone(),
            point,
            normal: normal.normalize(),
        });
    }

    let gravity = c.vector("gravity", raw.gravity.unwrap_or([0.0, 0.0, -9.81]))?;

    let time_step = match (raw.time.dt_fraction, raw.time.dt) {
        (Some(f), None) if f > 0.0 && f <= 0.5 => TimeStepRequest::FractionOfPeriod(f),
        (Some(f), None) => {
            return Err(c.invalid(
                "time.dt_fraction",
                f,
                "0 < dt_fraction <= 0.5 of the shortest contact period",
            ))
        }
        (None, Some(dt)) => TimeStepRequest::Explicit(c.positive("time.dt", dt)?),
        _ => {
            return Err(c.invalid(
                "time",
                "both or neither of dt_fraction and dt",
                "exactly one of dt_fraction (of the contact period) or dt (seconds)",
            ))
        }
    };

    let integrator = match raw.time.integrator.as_deref() {
        None | Some("verlet") => Integrator::VelocityVerlet,
        Some("pcvv") => Integrator::Pcvv,
        Some(other) => return Err(c.invalid("time.integrator", format!("\"{other}\""), "\"verlet\" (velocity Verlet, default) or \"pcvv\" (predictor-corrector velocity Verlet, paper B Eq. 11-15)")),
    };

    let neighbor = raw.neighbor.as_ref();
    let skin_fraction = neighbor.and_then(|n| n.skin_fraction).unwrap_or(0.3);
    if !(skin_fraction > 0.0 && skin_fraction <= 2.0) {
        return Err(c.invalid(
            "neighbor.skin_fraction",
            skin_fraction,
            "0 < skin_fraction <= 2 (of the largest diameter)",
        ));
    }
    let resort_every = neighbor.and_then(|n| n.resort_every).unwrap_or(20);
    let max_diameter = species.iter().map(|s| s.diameter).fold(0.0, f64::max);
    for axis in 0..3 {
        let needed = (2.0 + skin_fraction) * max_diameter;
        if domain.periodic[axis] && hi[axis] - lo[axis] < needed {
            return Err(c.invalid(format!("domain.periodic[{axis}]"), true, format!("a periodic side of at least (2 + skin) diameters = {needed:.4e} m; this side is {:.4e} m", hi[axis] - lo[axis])));
        }
    }

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
        let lattice_only = [
            ("spacing", ins.spacing.is_some()),
            ("origin", ins.origin.is_some()),
            ("radius", ins.radius.is_some()),
        ];
        let amount = match (&ins.lattice, ins.count, ins.solid_volume) {
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
                let diameter = species[species_index].diameter;
                if !spacing.is_finite() || spacing < diameter * (1.0 - 1e-9) {
                    return Err(c.invalid(
                        format!("insert[{k}].spacing"),
                        spacing,
                        format!("at least the species' diameter, {diameter} m, so that no two particles overlap"),
                    ));
                }
                InsertAmount::Lattice(Lattice {
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
                })
            }
            (Some(_), _, _) => return Err(c.invalid(
                format!("insert[{k}]"),
                "lattice with count or solid_volume",
                "a lattice insertion fills every site in the box: leave out count and solid_volume",
            )),
            (None, _, _) if lattice_only.iter().any(|(_, given)| *given) => {
                let (field, _) = lattice_only.iter().find(|(_, given)| *given).unwrap();
                return Err(c.invalid(
                    format!("insert[{k}].{field}"),
                    "given without lattice",
                    "only with lattice = \"cubic\" or \"hexagonal\"",
                ));
            }
            (None, Some(n), None) if n > 0 => InsertAmount::Count(n),
            (None, None, Some(v)) => {
                InsertAmount::SolidVolume(c.positive(&format!("insert[{k}].solid_volume"), v)?)
            }
            _ => {
                return Err(c.invalid(
                    format!("insert[{k}]"),
                    "count and solid_volume",
                    "exactly one of count (> 0), solid_volume (m^3) or lattice",
                ))
            }
        };
        let refill = match &ins.refill {
            None => None,
            Some(r) => {
                if !raw.stages.iter().any(|s| s.name == r.stage) {
                    return Err(c.invalid(
                        format!("insert[{k}].refill.stage"),
                        &r.stage,
                        format!(
                            "one of the stages: {}",
                            names(raw.stages.iter().map(|s| &s.name))
                        ),
                    ));
                }
                if matches!(amount, InsertAmount::Lattice(_)) {
                    return Err(c.invalid(
                        format!("insert[{k}].refill"),
                        "given with lattice",
                        "refill only for a random insertion (count or solid_volume)",
                    ));
                }
                Some(Refill {
                    interval: c.positive(&format!("insert[{k}].refill.interval"), r.interval)?,
                    stage: r.stage.clone(),
                })
            }
        };
        insertions.push(Insertion {
            refill,
            species: species_index,
            lo: ilo,
            hi: ihi,
            mesh: ins.mesh.as_deref().map(|m| mesh_source(m, file)),
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

    if raw.stages.is_empty() {
        return Err(c.invalid("stage", "none", "at least one [[stage]]"));
    }
    let mut stages = Vec::new();
    for (k, s) in raw.stages.iter().enumerate() {
        for name in &s.remove_walls {
            if !walls.iter().any(|w| &w.name == name) {
                return Err(c.invalid(
                    format!("stage[{k}].remove_walls"),
                    name,
                    format!("one of the walls: {}", names(walls.iter().map(|w| &w.name))),
                ));
            }
        }
        let end = match (s.duration, s.until_kinetic_energy_per_mass_below, s.max_duration) {
            (Some(d), None, None) if s.min_duration.is_none() => StageEnd::Duration(c.positive(&format!("stage[{k}].duration"), d)?),
            (None, Some(threshold), Some(max)) => {
                let min = c.non_negative(&format!("stage[{k}].min_duration"), s.min_duration.unwrap_or(0.0))?;
                let max = c.positive(&format!("stage[{k}].max_duration"), max)?;
                if min > max {
                    return Err(c.invalid(format!("stage[{k}].min_duration"), min, format!("at most max_duration = {max} s")));
                }
                StageEnd::Settled {
                    kinetic_energy_per_mass: c.positive(&format!("stage[{k}].until_kinetic_energy_per_mass_below"), threshold)?,
                    min_duration: min,
                    max_duration: max,
                }
            }
            _ => return Err(c.invalid(format!("stage[{k}]"), &s.name, "either duration alone, or until_kinetic_energy_per_mass_below (J/kg) with max_duration (and optionally min_duration)")),
        };
        stages.push(Stage {
            name: s.name.clone(),
            remove_walls: s.remove_walls.clone(),
            end,
        });
    }

    let output = raw.output.as_ref();
    let vtk_interval = c.non_negative(
        "output.vtk_interval",
        output.and_then(|o| o.vtk_interval).unwrap_or(0.0),
    )?;
    let timeseries_interval = c.positive(
        "output.timeseries_interval",
        output.and_then(|o| o.timeseries_interval).unwrap_or(0.01),
    )?;

    let repose = match &raw.repose {
        None => None,
        Some(r) => {
            let stage = stages.iter().find(|s| s.name == r.stage).ok_or_else(|| {
                c.invalid(
                    "repose.stage",
                    &r.stage,
                    format!(
                        "one of the stages: {}",
                        names(stages.iter().map(|s| &s.name))
                    ),
                )
            })?;
            if r.at_times.windows(2).any(|w| w[1] <= w[0])
                || r.at_times.first().is_some_and(|&t| t <= 0.0)
            {
                return Err(c.invalid(
                    "repose.at_times",
                    format!("{:?}", r.at_times),
                    "increasing times > 0 s after the stage starts",
                ));
            }
            if r.at_times.is_empty() && !r.at_stage_end {
                return Err(c.invalid(
                    "repose",
                    "no measurement time",
                    "at_times, or at_stage_end = true, or both",
                ));
            }
            if let StageEnd::Duration(d) = stage.end {
                let last = *r.at_times.last().unwrap_or(&0.0);
                if last > d {
                    return Err(c.invalid(
                        "repose.at_times",
                        last,
                        format!("times within the stage `{}`, which lasts {d} s", stage.name),
                    ));
                }
            }
            let fraction = |field: &str, v: Option<f64>, default: f64| -> Result<f64, SceneError> {
                let v = v.unwrap_or(default);
                if (0.0..0.5).contains(&v) {
                    Ok(v)
                } else {
                    Err(c.invalid(field, v, "0 <= fraction < 0.5 of the run-out"))
                }
            };
            Some(ReposeSettings {
                stage: r.stage.clone(),
                wall_x: r.wall_x,
                at_times: r.at_times.clone(),
                at_stage_end: r.at_stage_end,
                bin_width_diameters: c.positive(
                    "repose.bin_width_diameters",
                    r.bin_width_diameters.unwrap_or(1.0),
                )?,
                exclude_wall_fraction: fraction(
                    "repose.exclude_wall_fraction",
                    r.exclude_wall_fraction,
                    0.15,
                )?,
                exclude_toe_fraction: fraction(
                    "repose.exclude_toe_fraction",
                    r.exclude_toe_fraction,
                    0.15,
                )?,
            })
        }
    };

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
            if !raw.stages.iter().any(|s| &s.name == stage) {
                return Err(c.invalid(
                    format!("body[{k}].start_stage"),
                    stage,
                    format!(
                        "one of the stages: {}",
                        names(raw.stages.iter().map(|s| &s.name))
                    ),
                ));
            }
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
            Some(bp) => {
                let index = species.iter().position(|s| s.name == bp.species);
                let Some(index) = index.filter(|&i| species[i].frozen) else {
                    return Err(c.invalid(
                        format!("body[{k}].particles.species"),
                        &bp.species,
                        {
                            let frozen = names(species.iter().filter(|s| s.frozen).map(|s| &s.name));
                            format!(
                                "a species with frozen = true (the body's particles are moved by the body, not integrated); frozen species: {}",
                                if frozen.is_empty() { "none".to_string() } else { frozen }
                            )
                        },
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
                Some(BodyParticles { species: index })
            }
        };
        let cell_size = match (&particles, b.cell_size) {
            (Some(_), _) => 0.0,
            (None, Some(cell)) => c.positive(&format!("body[{k}].cell_size"), cell)?,
            (None, None) => {
                return Err(c.invalid(
                    format!("body[{k}].cell_size"),
                    "missing",
                    "the SDF grid spacing, m (or particles = { species = ..., lattice = \"fcc\" } for a body built of particles)",
                ))
            }
        };
        bodies.push(BodySettings {
            name: b.name.clone(),
            mesh: mesh_source(&b.mesh, file),
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
    let mut deletions = Vec::new();
    for (k, d) in raw.deletions.iter().enumerate() {
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
    let conveying = match &raw.conveying {
        None => None,
        Some(cv) => {
            if !raw.stages.iter().any(|s| s.name == cv.stage) {
                return Err(c.invalid(
                    "conveying.stage",
                    &cv.stage,
                    format!(
                        "one of the stages: {}",
                        names(raw.stages.iter().map(|s| &s.name))
                    ),
                ));
            }
            if !bodies.iter().any(|b| b.name == cv.body) {
                return Err(c.invalid(
                    "conveying.body",
                    &cv.body,
                    format!(
                        "one of the bodies: {}",
                        names(bodies.iter().map(|b| &b.name))
                    ),
                ));
            }
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
            let bulk_lo = c.vector("conveying.bulk_lo", cv.bulk_lo)?;
            let bulk_hi = c.vector("conveying.bulk_hi", cv.bulk_hi)?;
            if bulk_lo.cmpge(bulk_hi).any() {
                return Err(c.invalid(
                    "conveying.bulk_hi",
                    format!("{bulk_hi:?}"),
                    format!("greater than bulk_lo = {bulk_lo:?} on every axis"),
                ));
            }
            Some(ConveyingSettings {
                stage: cv.stage.clone(),
                body: cv.body.clone(),
                discard: c.non_negative("conveying.discard", cv.discard)?,
                blocks: cv.blocks.unwrap_or(5).max(2),
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
    };

    let packing = match &raw.packing {
        None => None,
        Some(pk) => Some(packing(&c, pk, &stages, &domain, &species)?),
    };

    Ok(Scene {
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
        stages,
        output: OutputSettings {
            vtk_interval,
            vtk_contact_network: output.and_then(|o| o.vtk_contact_network).unwrap_or(false),
            timeseries_interval,
        },
        repose,
        lambda: 1,
        cg_rule: Default::default(),
    })
}

/// `[packing]`: a poured bed in a box periodic in x and y with a floor below.
fn packing(
    c: &Checker,
    pk: &RawPacking,
    stages: &[Stage],
    domain: &Domain,
    species: &[Species],
) -> Result<PackingSettings, SceneError> {
    if !stages.iter().any(|s| s.name == pk.stage) {
        return Err(c.invalid(
            "packing.stage",
            &pk.stage,
            format!(
                "one of the stages: {}",
                names(stages.iter().map(|s| &s.name))
            ),
        ));
    }
    if !(domain.periodic[0] && domain.periodic[1]) || domain.periodic[2] {
        return Err(c.invalid(
            "domain.periodic",
            format!("{:?}", domain.periodic),
            "[true, true, false] with [packing] (a bed periodic in x and y on a floor)",
        ));
    }
    if species.len() != 1 {
        return Err(c.invalid(
            "species",
            format!("{} species", species.len()),
            "exactly one species with [packing] (monodisperse beds)",
        ));
    }
    let default = crate::analysis::BedRegionRule::default();
    let margin = |field: &str, v: Option<f64>, default: f64| -> Result<f64, SceneError> {
        let v = v.unwrap_or(default);
        if v.is_finite() && (0.0..=50.0).contains(&v) {
            Ok(v)
        } else {
            Err(c.invalid(field, v, "0 <= margin <= 50 diameters"))
        }
    };
    let top_quantile = pk.top_quantile.unwrap_or(default.top_quantile);
    if !(top_quantile > 0.0 && top_quantile <= 1.0) {
        return Err(c.invalid(
            "packing.top_quantile",
            top_quantile,
            "0 < top_quantile <= 1",
        ));
    }
    let voxels_per_diameter = pk.voxels_per_diameter.unwrap_or(16);
    if !(2..=64).contains(&voxels_per_diameter) {
        return Err(c.invalid(
            "packing.voxels_per_diameter",
            voxels_per_diameter,
            "2 ..= 64 voxels per particle diameter",
        ));
    }
    let d = species[0].diameter;
    for axis in 0..2 {
        let cells = (domain.hi[axis] - domain.lo[axis]) / d * voxels_per_diameter as f64;
        if (cells - cells.round()).abs() > 1e-6 * cells {
            return Err(c.invalid(
                format!("domain.hi[{axis}]"),
                domain.hi[axis],
                format!("a lateral period that is a whole number of pore-size voxels (d / {voxels_per_diameter}); it is {cells:.4} voxels"),
            ));
        }
    }
    let bin_width_diameters = pk.bin_width_diameters.unwrap_or(0.1);
    if !(bin_width_diameters.is_finite()
        && bin_width_diameters * voxels_per_diameter as f64 >= 1.0 - 1e-9
        && bin_width_diameters <= 1.0)
    {
        return Err(c.invalid(
            "packing.bin_width_diameters",
            bin_width_diameters,
            format!(
                "1 / voxels_per_diameter = {:.4} ..= 1 (at least one voxel)",
                1.0 / voxels_per_diameter as f64
            ),
        ));
    }
    Ok(PackingSettings {
        stage: pk.stage.clone(),
        rule: crate::analysis::BedRegionRule {
            floor_margin: margin(
                "packing.floor_margin",
                pk.floor_margin,
                default.floor_margin,
            )?,
            top_quantile,
            top_margin: margin("packing.top_margin", pk.top_margin, default.top_margin)?,
        },
        voxels_per_diameter,
        bin_width_diameters,
    })
}

fn poisson(c: &Checker, field: &str, nu: f64) -> Result<f64, SceneError> {
    if nu.is_finite() && (-1.0..0.5).contains(&nu) {
        Ok(nu)
    } else {
        Err(c.invalid(field, nu, "-1 <= poisson_ratio < 0.5"))
    }
}

/// `[contact] model = "hertz"`: keywords as in LIGGGHTS/LAMMPS.
fn hertz_contact(c: &Checker, rc: &RawContact) -> Result<HertzSettings, SceneError> {
    for (field, set) in [
        ("epsilon", rc.epsilon.is_some()),
        ("sigma", rc.sigma.is_some()),
        ("gamma_n", rc.gamma_n.is_some()),
        ("gamma_t", rc.gamma_t.is_some()),
    ] {
        if set {
            return Err(c.invalid(
                format!("contact.{field}"),
                "set",
                "only with model = \"wca\"; for Yang damping use gamma_n_yang",
            ));
        }
    }
    let youngs_modulus = c.positive(
        "contact.youngs_modulus",
        c.required(
            "contact.youngs_modulus",
            rc.youngs_modulus,
            "Young's modulus of the particles, Pa",
        )?,
    )?;
    let poisson_ratio = poisson(
        c,
        "contact.poisson_ratio",
        c.required(
            "contact.poisson_ratio",
            rc.poisson_ratio,
            "Poisson's ratio of the particles",
        )?,
    )?;
    let friction = c.non_negative(
        "contact.friction",
        c.required(
            "contact.friction",
            rc.friction,
            "the Coulomb friction coefficient",
        )?,
    )?;
    let rolling_friction = c.non_negative(
        "contact.rolling_friction",
        rc.rolling_friction.unwrap_or(0.0),
    )?;
    let damping = match rc.damping.as_deref().unwrap_or("hertz") {
        "hertz" => {
            if rc.gamma_n_yang.is_some() {
                return Err(c.invalid(
                    "contact.gamma_n_yang",
                    "set",
                    "only with damping = \"yang\"",
                ));
            }
            HertzDampingKind::Restitution
        }
        "yang" => HertzDampingKind::Yang {
            gamma_n: c.non_negative(
                "contact.gamma_n_yang",
                c.required(
                    "contact.gamma_n_yang",
                    rc.gamma_n_yang,
                    "the Yang damping time gamma_n, s",
                )?,
            )?,
        },
        other => {
            return Err(c.invalid(
                "contact.damping",
                format!("\"{other}\""),
                "\"hertz\" (LIGGGHTS restitution-based, default) or \"yang\" (paper B Eq. 4)",
            ))
        }
    };
    let restitution = match (damping, rc.restitution) {
        (HertzDampingKind::Restitution, None) => {
            return Err(c.invalid(
                "contact.restitution",
                "missing",
                "the coefficient of restitution, 0 < e <= 1",
            ))
        }
        (_, Some(e)) if !(e > 0.0 && e <= 1.0) => {
            return Err(c.invalid("contact.restitution", e, "0 < e <= 1"))
        }
        (HertzDampingKind::Yang { .. }, Some(_)) => {
            return Err(c.invalid(
                "contact.restitution",
                "set",
                "not with damping = \"yang\" (its damping is gamma_n_yang)",
            ))
        }
        (_, e) => e.unwrap_or(1.0),
    };
    let tangential =
        match rc.tangential.as_deref().unwrap_or("history") {
            "history" => TangentialKind::History,
            "yang" => TangentialKind::Yang,
            other => return Err(c.invalid(
                "contact.tangential",
                format!("\"{other}\""),
                "\"history\" (LIGGGHTS tangential history, default) or \"yang\" (paper B Eq. 5)",
            )),
        };
    let rolling = match rc.rolling.as_deref().unwrap_or("none") {
        "none" => RollingKind::None,
        "constant_torque" => RollingKind::ConstantTorque,
        "epsd2" => RollingKind::Epsd2,
        other => return Err(c.invalid(
            "contact.rolling",
            format!("\"{other}\""),
            "\"none\", \"constant_torque\" (paper B Eq. 10) or \"epsd2\" (LIGGGHTS rolling spring)",
        )),
    };
    if rolling != RollingKind::None && rolling_friction == 0.0 {
        return Err(c.invalid(
            "contact.rolling_friction",
            rolling_friction,
            "> 0 when rolling is not \"none\"",
        ));
    }
    let cohesion = match rc.cohesion.as_deref().unwrap_or("none") {
        "none" => {
            for (field, set) in [
                ("hamaker_constant", rc.hamaker_constant.is_some()),
                ("h_min", rc.h_min.is_some()),
                ("cohesion_cutoff", rc.cohesion_cutoff.is_some()),
            ] {
                if set {
                    return Err(c.invalid(
                        format!("contact.{field}"),
                        "set",
                        "only with cohesion = \"vdw\"",
                    ));
                }
            }
            CohesionKind::None
        }
        "vdw" => {
            let h_min = c.positive(
                "contact.h_min",
                c.required(
                    "contact.h_min",
                    rc.h_min,
                    "the van der Waals cut-off gap, m (e.g. 4e-10)",
                )?,
            )?;
            let cutoff = match rc.cohesion_cutoff {
                Some(x) if x.is_finite() && x > h_min => Some(x),
                Some(x) => {
                    return Err(c.invalid(
                        "contact.cohesion_cutoff",
                        x,
                        format!("a gap > h_min = {h_min} m"),
                    ))
                }
                None => None,
            };
            CohesionKind::VanDerWaals {
                hamaker_constant: c.positive(
                    "contact.hamaker_constant",
                    c.required(
                        "contact.hamaker_constant",
                        rc.hamaker_constant,
                        "the Hamaker constant, J",
                    )?,
                )?,
                h_min,
                cutoff,
            }
        }
        other => {
            return Err(c.invalid(
                "contact.cohesion",
                format!("\"{other}\""),
                "\"none\" or \"vdw\" (van der Waals, paper B Eq. 7-8)",
            ))
        }
    };
    Ok(HertzSettings {
        youngs_modulus,
        poisson_ratio,
        restitution,
        friction,
        rolling_friction,
        damping,
        tangential,
        rolling,
        cohesion,
        characteristic_velocity: c.positive(
            "contact.characteristic_velocity",
            rc.characteristic_velocity.unwrap_or(1.0),
        )?,
    })
}

/// `screw-feeder:<part>` or an STL path relative to the scene file.
fn mesh_source(text: &str, file: &Path) -> MeshSource {
    match text.strip_prefix("screw-feeder:") {
        Some(part) => MeshSource::ScrewFeeder(part.to_string()),
        None => MeshSource::Stl(file.parent().unwrap_or(Path::new(".")).join(text)),
    }
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
