//! The Coulomb-type caps of the laws (`|F_t| <= mu |F_n|`, `|M_r| <= mu_r R |F_n|`) decided on
//! squared lengths: the square root is taken only when a cap binds (its value then scales the
//! vector) or when the squares lie too close to tell, so a contact below its caps pays no
//! square root for them.

use crate::math::Real;

/// Caps in this range have a square that is a normal, finite number, rounded to within half
/// an ulp (relative 1.1e-16): `sqrt(f64::MIN_POSITIVE)` is 1.49e-154, `sqrt(f64::MAX)`
/// 1.34e154. Outside it (and for a negative or NaN cap) the test takes the square root.
const SQUARABLE: std::ops::RangeInclusive<Real> = 1.0e-153..=1.0e153;

/// Squares apart by more than this relative margin order as their roots do, whatever the
/// rounding: `cap * cap` and `sqrt(length_squared)` are each within half an ulp (1.1e-16) of
/// their exact values, far inside 1e-12.
const MARGIN: Real = 1.0e-12;

/// Whether `sqrt(length_squared) > cap`, with the same answer, bit for bit, as that
/// expression (`Vec3::length` is `dot(self).sqrt()`, so `length_squared` is the very value
/// it takes the root of): decided on `cap * cap` when the two are more than `MARGIN` apart,
/// by the expression itself otherwise. A NaN length never exceeds the cap, as before.
#[inline(always)]
pub fn exceeds(length_squared: Real, cap: Real) -> bool {
    if SQUARABLE.contains(&cap) {
        let cap_squared = cap * cap;
        if length_squared > cap_squared * (1.0 + MARGIN) {
            return true;
        }
        if length_squared < cap_squared * (1.0 - MARGIN) {
            return false;
        }
    }
    length_squared.sqrt() > cap
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The squared test against the root's at and around the cap, over many magnitudes, and
    /// at the edge cases (zero, negative and NaN caps, NaN and infinite lengths).
    #[test]
    fn decides_as_the_square_root_does() {
        let mut caps = vec![0.0, -1.0, Real::NAN, Real::INFINITY, 1e-160, 1e160];
        let mut x: Real = 1e-40;
        while x < 1e40 {
            caps.push(x);
            caps.push(x * 1.234_567_890_123);
            x *= 7.3;
        }
        for &cap in &caps {
            let mut lengths = vec![0.0, Real::NAN, Real::INFINITY, 1e-300, 1e300];
            for ulps in -3_i64..=3 {
                let at = if cap.is_finite() && cap > 0.0 {
                    Real::from_bits((cap.to_bits() as i64 + ulps) as u64)
                } else {
                    1.0
                };
                for scale in [
                    1.0,
                    1.0 + 1e-13,
                    1.0 - 1e-13,
                    1.0 + 1e-11,
                    1.0 - 1e-11,
                    2.0,
                    0.5,
                ] {
                    lengths.push(at * scale);
                }
            }
            for length in lengths {
                let squared = length * length;
                assert_eq!(
                    exceeds(squared, cap),
                    squared.sqrt() > cap,
                    "cap {cap:e}, length {length:e}"
                );
            }
        }
    }
}
