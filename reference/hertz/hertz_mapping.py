#!/usr/bin/env python3
"""LIGGGHTS 'model hertz' -> LAMMPS 29 Sep 2021 'hertz/material ... damping tsuji' mapping.

usage: hertz_mapping.py E NU  -> prints the tsuji input q and x_gamma_t for several e
       hertz_mapping.py E NU e -> for one e
LIGGGHTS: k_n = 4/3 Y* sqrt(R* d), gamma_n = -2 sqrt(5/6) beta sqrt(S_n m*), S_n = 2 Y* sqrt(R* d)
          => gamma_n = sqrt(5) |beta| sqrt(m* k_n),  beta = ln e / sqrt(ln^2 e + pi^2)
LAMMPS tsuji: damping = P(q) sqrt(m_eff k_n), P = Tsuji polynomial of the pair_coeff number q.
So q = P^-1(sqrt(5)|beta|); possible only while sqrt(5)|beta| <= P(0) = 1.2728 (e >~ 0.114).
Tangential: LIGGGHTS gamma_t/gamma_n = sqrt(S_t/S_n) = sqrt(4 G*/Y*) = sqrt(2(1-nu)/(2-nu)).
"""
import math
import sys


def tsuji_poly(q):
    return (1.2728 - 4.2783 * q + 11.087 * q**2 - 22.348 * q**3 + 27.467 * q**4
            - 18.022 * q**5 + 4.8218 * q**6)


def liggghts_alpha(e):
    le = math.log(e)
    return math.sqrt(5.0) * abs(le) / math.sqrt(le * le + math.pi**2)


def tsuji_input_for(e):
    """q in [0,1] with P(q) = sqrt(5)|beta(e)|; P is decreasing on [0,1]."""
    a = liggghts_alpha(e)
    if a > tsuji_poly(0.0):
        return None
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if tsuji_poly(mid) > a:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def main():
    E, nu = float(sys.argv[1]), float(sys.argv[2])
    es = [float(sys.argv[3])] if len(sys.argv) > 3 else [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95]
    xgt = math.sqrt(2.0 * (1.0 - nu) / (2.0 - nu))
    print(f"E={E:g} nu={nu:g}: Y*={E / (2 * (1 - nu**2)):.6e} G*={E / (4 * (2 - nu) * (1 + nu)):.6e} "
          f"x_gamma_t={xgt:.12f}")
    for e in es:
        q = tsuji_input_for(e)
        qs = "NOT REACHABLE (alpha > P(0)=1.2728)" if q is None else f"{q:.12f}"
        print(f"e={e:<5g} alpha_LIGGGHTS={liggghts_alpha(e):.12f} P(e)={tsuji_poly(e):.6f} q={qs}")
        if q is not None:
            print(f"   pair_coeff 1 1 hertz/material {E:g} {q:.12f} {nu:g} damping tsuji "
                  f"tangential mindlin NULL {xgt:.12f} MU")


if __name__ == "__main__":
    main()
