//! The time step, derived from the stiffest contact.
//!
//! Each contact (particle-particle per species pair, particle-wall per species) is
//! linearized to a spring `k` and dashpot `gamma` on the effective mass `m`. Its period is
//! `T = 2 pi sqrt(m / k)`; the scene's time step is a stated fraction of the shortest `T`.
//! Velocity Verlet on a damped oscillator is stable for
//! `dt < (2 / omega) (sqrt(1 + zeta^2) - zeta)`, `omega = sqrt(k/m)`, `zeta = gamma / (2 sqrt(k m))`
//! (the undamped limit `T / pi` shrinks as damping grows); the smallest such bound over all
//! contacts is the stable limit that an explicit `dt` may not exceed without `--force-dt`.

use crate::math::Real;
use std::f64::consts::PI;

/// A contact linearized for the time step.
#[derive(Clone, Debug)]
pub struct LinearContact {
    pub label: String,
    pub stiffness: Real,
    pub damping: Real,
    pub mass: Real,
}

impl LinearContact {
    pub fn period(&self) -> Real {
        2.0 * PI * (self.mass / self.stiffness).sqrt()
    }

    pub fn damping_ratio(&self) -> Real {
        self.damping / (2.0 * (self.stiffness * self.mass).sqrt())
    }

    /// Largest stable velocity-Verlet step for this contact alone.
    pub fn stable_limit(&self) -> Real {
        let omega = (self.stiffness / self.mass).sqrt();
        let zeta = self.damping_ratio();
        2.0 / omega * ((1.0 + zeta * zeta).sqrt() - zeta)
    }
}

/// The shortest period and the stable limit over a scene's contacts.
#[derive(Clone, Debug)]
pub struct Timescales {
    pub shortest_period: Real,
    pub stable_limit: Real,
    /// Which contact sets the limit, for messages.
    pub limiting: String,
}

impl Timescales {
    pub fn of(contacts: &[LinearContact]) -> Timescales {
        let mut scales = Timescales {
            shortest_period: Real::INFINITY,
            stable_limit: Real::INFINITY,
            limiting: String::from("no contact"),
        };
        for c in contacts {
            scales.shortest_period = scales.shortest_period.min(c.period());
            if c.stable_limit() < scales.stable_limit {
                scales.stable_limit = c.stable_limit();
                scales.limiting = c.label.clone();
            }
        }
        scales
    }
}

/// How the scene asks for its time step.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum TimeStepRequest {
    /// This fraction of the shortest contact period.
    FractionOfPeriod(Real),
    /// An explicit step in seconds.
    Explicit(Real),
}

#[derive(Debug, thiserror::Error, PartialEq)]
#[error("time step {dt:.4e} s exceeds the stable limit {limit:.4e} s set by the {limiting} contact (period {period:.4e} s); use dt <= {limit:.4e} or pass --force-dt to run anyway")]
pub struct UnstableTimeStep {
    pub dt: Real,
    pub limit: Real,
    pub period: Real,
    pub limiting: String,
}

/// The step to use. A step above the stable limit is refused unless `force` is set, in which
/// case a warning is returned with it.
pub fn choose(
    request: TimeStepRequest,
    scales: &Timescales,
    force: bool,
) -> Result<(Real, Option<String>), UnstableTimeStep> {
    let dt = match request {
        TimeStepRequest::FractionOfPeriod(f) => f * scales.shortest_period,
        TimeStepRequest::Explicit(dt) => dt,
    };
    if dt <= scales.stable_limit {
        return Ok((dt, None));
    }
    let error = UnstableTimeStep {
        dt,
        limit: scales.stable_limit,
        period: scales.shortest_period,
        limiting: scales.limiting.clone(),
    };
    if force {
        Ok((dt, Some(format!("forced past the guard: {error}"))))
    } else {
        Err(error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undamped_limit_is_period_over_pi() {
        let c = LinearContact {
            label: "test".into(),
            stiffness: 4.0,
            damping: 0.0,
            mass: 1.0,
        };
        assert!((c.stable_limit() - c.period() / PI).abs() < 1e-12);
    }

    #[test]
    fn explicit_step_above_limit_is_refused_with_the_limit_and_forced_with_a_warning() {
        let scales = Timescales::of(&[LinearContact {
            label: "coke-coke".into(),
            stiffness: 4.0,
            damping: 0.0,
            mass: 1.0,
        }]);
        let err = choose(TimeStepRequest::Explicit(2.0), &scales, false).unwrap_err();
        assert!(err.to_string().contains("stable limit 1.0000e0 s"));
        assert!(err.to_string().contains("coke-coke"));
        let (dt, warning) = choose(TimeStepRequest::Explicit(2.0), &scales, true).unwrap();
        assert_eq!(dt, 2.0);
        assert!(warning.unwrap().contains("forced"));
        let (dt, warning) =
            choose(TimeStepRequest::FractionOfPeriod(0.05), &scales, false).unwrap();
        assert!((dt - 0.05 * PI).abs() < 1e-12 && warning.is_none());
    }
}
