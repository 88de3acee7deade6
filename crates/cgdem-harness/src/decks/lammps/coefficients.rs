//! The coefficients of LAMMPS's `pair_style granular` that reproduce LIGGGHTS's `model
//! hertz` (reference/MAPPING.md): the Tsuji damping number, the tangential damping ratio and
//! the constant rolling stiffness, shared by the uniform deck (`hertz`) and the one with
//! material tables (`tables`).

use crate::decks::lines::g;
use crate::decks::DeckError;
use cgdem_core::contact::damping::restitution_beta;
use cgdem_core::contact::normal::Hertz;
use cgdem_core::math::Real;
use cgdem_core::scene::{HertzSettings, PairProperties, RollingKind, Scene};

/// LAMMPS's Tsuji polynomial `P(q)`: `damping tsuji q` gives `gamma_n = P(q) sqrt(m_eff k_n)`.
pub fn tsuji_polynomial(q: Real) -> Real {
    let c = [1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218];
    c.iter().rev().fold(0.0, |acc, &a| acc * q + a)
}

/// The `damping tsuji` number that reproduces LIGGGHTS's `model hertz` dashpot for
/// restitution `e`: `P(q) = sqrt(5) |beta(e)|` (P decreases on [0, 1]); None below e ~ 0.114,
/// where `sqrt(5) |beta| > P(0)`, and near e = 1, where it is below `P(1)`.
pub fn tsuji_q(restitution: Real) -> Option<Real> {
    let target = 5.0_f64.sqrt() * restitution_beta(restitution).abs();
    if target > tsuji_polynomial(0.0) || target < tsuji_polynomial(1.0) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if tsuji_polynomial(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// `gamma_t / gamma_n` of LIGGGHTS `model hertz` = `sqrt(S_t / S_n) = sqrt(4 G_eff / Y_eff)`,
/// the `x` of LAMMPS `tangential mindlin NULL x mu`.
pub fn tangential_damping_ratio(y_eff: Real, g_eff: Real) -> Real {
    (4.0 * g_eff / y_eff).sqrt()
}

/// `k_roll` for LAMMPS `rolling sds`: the Hertz tangential stiffness `8 G_eff sqrt(R delta)` at
/// the largest overlap of an undamped impact at `v`.
pub fn rolling_stiffness(y_eff: Real, g_eff: Real, r_eff: Real, m_eff: Real, v: Real) -> Real {
    let delta = Hertz::max_overlap(y_eff, r_eff, m_eff, v);
    8.0 * g_eff * (r_eff * delta).sqrt()
}

/// LAMMPS's Tsuji coefficient `q` for restitution `e`, or why this LAMMPS cannot damp so.
pub fn tsuji_q_of(scene: &Scene, e: Real) -> Result<Real, DeckError> {
    tsuji_q(e).ok_or_else(|| {
        DeckError::unsupported(scene, if e < 0.5 {
            format!("restitution {e}: damping tsuji cannot reach LIGGGHTS's dashpot below e ~ 0.114")
        } else {
            format!("restitution {e}: damping tsuji cannot damp as little as LIGGGHTS's dashpot does (its least damping, q = 1, is more)")
        })
    })
}

/// ` rolling sds k_roll 0 mu_r` of pair coefficients `p` for epsd2, else nothing.
pub fn rolling_args(
    h: &HertzSettings,
    p: &PairProperties,
    y_eff: Real,
    g_eff: Real,
    r_eff: Real,
    m_eff: Real,
) -> String {
    if h.rolling != RollingKind::Epsd2 {
        return String::new();
    }
    let k_roll = rolling_stiffness(y_eff, g_eff, r_eff, m_eff, h.characteristic_velocity);
    format!(" rolling sds {} 0.0 {}", g(k_roll), g(p.rolling_friction))
}
