//! `[domain]`, `[[species]]`, `[time]` and `[neighbor]`.

use super::super::raw::*;
use super::super::*;
use super::{materials, Checker};

/// `[domain]`: the box and what happens to a particle that leaves it (`stop_on_lost`).
pub(super) fn domain(c: &Checker, raw: &RawDomain) -> Result<(Domain, bool), SceneError> {
    let lo = c.vector("domain.lo", raw.lo)?;
    let hi = c.vector("domain.hi", raw.hi)?;
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
        periodic: raw.periodic,
    };
    let stop_on_lost = match raw.lost.as_deref() {
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
    Ok((domain, stop_on_lost))
}

/// `[[species]]`: at least one, each smaller than the box, names unique; a material of its
/// own only in a Hertz scene (`hertz`).
pub(super) fn species(
    c: &Checker,
    raw: &[RawSpecies],
    domain: &Domain,
    hertz: bool,
) -> Result<Vec<Species>, SceneError> {
    let shortest_side = (0..3)
        .map(|a| domain.hi[a] - domain.lo[a])
        .fold(f64::INFINITY, f64::min);
    if raw.is_empty() {
        return Err(c.invalid("species", "none", "at least one [[species]] table"));
    }
    let mut species = Vec::new();
    for (k, s) in raw.iter().enumerate() {
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
        let (youngs_modulus, poisson_ratio) = materials::species_material(c, k, s, hertz)?;
        species.push(Species {
            name: s.name.clone(),
            diameter,
            density,
            frozen: s.frozen,
            youngs_modulus,
            poisson_ratio,
        });
    }
    Ok(species)
}

/// `[time]`: the time step (a fraction of the contact period or seconds) and the integrator.
pub(super) fn time(
    c: &Checker,
    raw: &RawTime,
) -> Result<(TimeStepRequest, Integrator), SceneError> {
    let time_step = match (raw.dt_fraction, raw.dt) {
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
    let integrator = match raw.integrator.as_deref() {
        None | Some("verlet") => Integrator::VelocityVerlet,
        Some("pcvv") => Integrator::Pcvv,
        Some(other) => return Err(c.invalid("time.integrator", format!("\"{other}\""), "\"verlet\" (velocity Verlet, default) or \"pcvv\" (predictor-corrector velocity Verlet, paper B Eq. 11-15)")),
    };
    Ok((time_step, integrator))
}

/// `[neighbor]`: skin and resort interval; a periodic side must hold (2 + skin) diameters.
pub(super) fn neighbor(
    c: &Checker,
    neighbor: Option<&RawNeighbor>,
    domain: &Domain,
    species: &[Species],
) -> Result<(Real, u32), SceneError> {
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
    let (lo, hi) = (domain.lo, domain.hi);
    for axis in 0..3 {
        let needed = (2.0 + skin_fraction) * max_diameter;
        if domain.periodic[axis] && hi[axis] - lo[axis] < needed {
            return Err(c.invalid(format!("domain.periodic[{axis}]"), true, format!("a periodic side of at least (2 + skin) diameters = {needed:.4e} m; this side is {:.4e} m", hi[axis] - lo[axis])));
        }
    }
    Ok((skin_fraction, resort_every))
}
