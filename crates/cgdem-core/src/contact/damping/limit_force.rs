//! `limit_force = true` (LIGGGHTS `limitForce on`): the dashpot may slow the separation only
//! as far as the elastic force goes, so the normal force `F_e + F_d` never turns attractive.
//!
//! At the end of a damped contact the surfaces separate while the overlap vanishes: the
//! elastic force tends to zero and the dashpot, `-gamma v_n` with `v_n > 0`, pulls. Without
//! the clamp the net normal impulse holds that pull, and the rebound of a sliding contact (whose
//! friction impulse is `mu` times the pushing part only) falls below the rigid-body value.
//!
//! The clamp takes the pull out of the normal impulse, so with LIGGGHTS's coefficient
//! `2 sqrt(5/6) |beta(e)|` the contact restitutes more than `e` (0.55 for `e = 0.5`).
//! [`clamped_damping_factor`] gives the coefficient with which the clamped Hertz contact
//! restitutes exactly `e`: found once, when the scene is read, from the dimensionless impact
//! `x'' = -max(x^(3/2) + c x^(1/4) x', 0)`, `c = sqrt(3/2) factor` (the LIGGGHTS Hertz dashpot
//! makes restitution independent of speed, size and stiffness, so one number per `e`).

use super::super::{Contact, DampingModel, NormalResponse};
use crate::math::Real;

/// A dashpot `D` whose force is bounded below by `-F_e`: `F_e + F_d >= 0` when `F_e >= 0`.
#[derive(Clone, Debug)]
pub struct LimitForce<D>(pub D);

impl<D: DampingModel> DampingModel for LimitForce<D> {
    #[inline(always)]
    fn force(&self, contact: &Contact, elastic: &NormalResponse) -> Real {
        self.0.force(contact, elastic).max(-elastic.force)
    }

    fn linear_coefficient(&self, species_pair: usize, stiffness: Real, m_eff: Real) -> Real {
        self.0.linear_coefficient(species_pair, stiffness, m_eff)
    }
}

/// The restitution of a clamped Hertz impact with damping factor `factor` (`gamma = factor
/// sqrt(S_n m_eff)`): `x'' = -max(x^(3/2) + c x^(1/4) x', 0)` from `x = 0`, `x' = 1`, until
/// `x` is back to 0, with `c = sqrt(3/2) factor`; RK4 at 1/4000 of the undamped contact time.
pub fn clamped_restitution(factor: Real) -> Real {
    let c = (1.5_f64).sqrt() * factor;
    let accel = |x: Real, v: Real| -> Real {
        let x = x.max(0.0);
        -(x.powf(1.5) + c * x.powf(0.25) * v).max(0.0)
    };
    // Undamped contact time of the unit impact: 2.9432 x_max, x_max = (5/4)^(2/5).
    let h = 2.943_2 * 1.25_f64.powf(0.4) / 4000.0;
    let (mut x, mut v) = (0.0, 1.0);
    for _ in 0..4_000_000 {
        let k1 = (v, accel(x, v));
        let k2 = (
            v + 0.5 * h * k1.1,
            accel(x + 0.5 * h * k1.0, v + 0.5 * h * k1.1),
        );
        let k3 = (
            v + 0.5 * h * k2.1,
            accel(x + 0.5 * h * k2.0, v + 0.5 * h * k2.1),
        );
        let k4 = (v + h * k3.1, accel(x + h * k3.0, v + h * k3.1));
        let (x_new, v_new) = (
            x + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
            v + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
        );
        if x_new <= 0.0 && v_new < 0.0 {
            return -v_new;
        }
        (x, v) = (x_new, v_new);
    }
    0.0 // never left the contact: restitution zero
}

/// The damping factor with which a clamped Hertz contact restitutes `restitution` (0 < e <= 1):
/// `clamped_restitution` inverted by bisection (it falls as the factor grows), to 1e-10.
pub fn clamped_damping_factor(restitution: Real) -> Real {
    if restitution >= 1.0 {
        return 0.0;
    }
    // Start from LIGGGHTS's factor (the clamp only raises the restitution: more damping needed).
    let mut lo = super::liggghts_damping_factor(restitution);
    let mut hi = 2.0 * lo.max(0.1);
    while clamped_restitution(hi) > restitution && hi < 1e6 {
        (lo, hi) = (hi, 2.0 * hi);
    }
    while hi - lo > 1e-10 * hi {
        let mid = 0.5 * (lo + hi);
        if clamped_restitution(mid) > restitution {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::damping::HertzDamping;
    use crate::contact::normal::Hertz;
    use crate::contact::normal_force;
    use crate::contact::tests::contact_at;

    #[test]
    fn the_normal_force_is_never_attractive_and_unchanged_while_it_pushes() {
        let hertz = Hertz {
            y_eff: vec![1e7],
            characteristic_velocity: 1.0,
        };
        let plain = HertzDamping::from_restitution(&[0.3]);
        let limited = LimitForce(plain.clone());
        for (delta, v_n) in [
            (1e-5, 0.5),
            (1e-7, 2.0),
            (1e-9, 5.0),
            (1e-5, -1.0),
            (1e-6, 0.0),
        ] {
            let mut c = contact_at(delta, 5e-4);
            c.normal_speed = v_n;
            let free = normal_force(&hertz, &plain, &c);
            let clamped = normal_force(&hertz, &limited, &c);
            assert!(clamped >= 0.0, "delta {delta}, v_n {v_n}: {clamped}");
            if free >= 0.0 {
                assert_eq!(clamped, free);
            } else {
                // Separating fast at a small overlap: the free dashpot pulls, the clamp gives 0.
                assert!(v_n > 0.0 && clamped == 0.0);
            }
        }
        // The case the clamp is for does occur: fast separation at a tiny overlap pulls.
        let mut c = contact_at(1e-9, 5e-4);
        c.normal_speed = 5.0;
        assert!(normal_force(&hertz, &plain, &c) < 0.0);
    }

    #[test]
    fn the_unclamped_unit_impact_restitutes_liggghts_e_and_the_calibrated_factor_gives_e() {
        // Without the clamp the dimensionless impact is LIGGGHTS's: its factor gives e. Here,
        // with the clamp, LIGGGHTS's factor restitutes more, and the calibrated one exactly e.
        for e in [0.2, 0.5, 0.9] {
            let liggghts = clamped_restitution(crate::contact::damping::liggghts_damping_factor(e));
            assert!(
                liggghts > e,
                "e = {e}: clamped with LIGGGHTS's factor {liggghts}"
            );
            let f = clamped_damping_factor(e);
            assert!((clamped_restitution(f) - e).abs() < 1e-6, "e = {e}");
        }
        assert_eq!(clamped_damping_factor(1.0), 0.0);
        assert!((clamped_restitution(0.0) - 1.0).abs() < 1e-6);
    }
}
