#!/usr/bin/env python3
"""Independent check of the LAMMPS seed-model decks (seed_headon/oblique/wall.in).

Re-integrates the same ODE (WCA + viscous dashpots, paper A Eq. 1-2; mirror-particle wall)
with LAMMPS's velocity-Verlet (fix nve: half kick, drift, force at (x_new, v_half), half kick),
starting from the state in the dump's first frame, and compares every frame.
Prints collision observables (restitution, contact time, tangential retention).

usage: verify_seed.py DUMP [--lambda L] [--wall] [--dt DT] [--mu-wall MU] [--e-wall E]
"""
import argparse
import math
import sys

import numpy as np

D0, SIGMA0, EPS0, GAMMA0, RHO = 1.350e-3, 1.203e-3, 9.434e-2, 0.1257, 1370.0


def read_dump(path):
    frames, cols = [], None
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: TIMESTEP"):
            step = int(lines[i + 1])
            n = int(lines[i + 3])
            cols = lines[i + 8].split()[2:]
            data = np.array([[float(x) for x in lines[i + 9 + k].split()] for k in range(n)])
            frames.append((step, data))
            i += 9 + n
        else:
            i += 1
    return cols, frames


def wca_force(rvec, sigma, eps, rc):
    """force on i from j (rvec = x_i - x_j); zero beyond rc."""
    r = np.linalg.norm(rvec)
    if r >= rc:
        return np.zeros(3)
    sr6 = (sigma / r) ** 6
    return 24.0 * eps / r * (2.0 * sr6 * sr6 - sr6) * rvec / r


def pair_forces(x, v, p):
    f = np.zeros_like(x)
    rvec = x[0] - x[1]
    r = np.linalg.norm(rvec)
    fi = wca_force(rvec, p["sigma"], p["eps"], p["rc"])
    if r < p["dc"]:  # granular dashpot acts for r < r_i + r_j
        n = rvec / r
        vij = v[0] - v[1]
        vn = np.dot(vij, n) * n
        vt = vij - vn
        fn_d = -p["gamma"] * vn
        ft = -p["xgt"] * p["gamma"] * vt
        # LAMMPS linear_nohistory: |F_t| <= mu |F_n of the granular part| (dashpot only here)
        cap = p["mu"] * np.linalg.norm(fn_d)
        if np.linalg.norm(ft) > cap:
            ft = ft * cap / np.linalg.norm(ft)
        fi = fi + fn_d + ft
    f[0] += fi
    f[1] -= fi
    return f


def wall_forces(x, v, p):
    """Mirror-particle wall at z = 0 (normal +z): Phi(h) = phi(2h), -gamma_w v_n, Coulomb mu N."""
    f = np.zeros_like(x)
    for k in range(len(x)):
        h = x[k, 2]
        if h >= 0.5 * p["rc"]:
            continue
        # d/dh phi(2h) = 2 phi'(2h)
        fn = 2.0 * wca_force(np.array([0.0, 0.0, 2.0 * h]), p["sigma"], p["eps"], p["rc"])[2]
        if h < 0.5 * p["dc"]:
            fn_d = -p["gamma_w"] * v[k, 2]
        else:
            fn_d = 0.0
        f[k, 2] += fn + fn_d
        if h < 0.5 * p["dc"] and p["mu_w"] > 0.0:
            vt = np.array([v[k, 0], v[k, 1], 0.0])
            vtm = np.linalg.norm(vt)
            if vtm > 0.0:
                nforce = fn_d if p["lammps_cap"] else fn + fn_d
                ft = min(p["mu_w"] * abs(nforce), p["gamma_t_w"] * vtm)
                f[k] += -ft * vt / vtm
    return f


def integrate(x0, v0, m, nsteps, dt, forces):
    x, v = x0.copy(), v0.copy()
    f = forces(x, v)
    xs, vs = [x.copy()], [v.copy()]
    for _ in range(nsteps):
        v += 0.5 * dt * f / m[:, None]
        x += dt * v
        f = forces(x, v)
        v += 0.5 * dt * f / m[:, None]
        xs.append(x.copy())
        vs.append(v.copy())
    return np.array(xs), np.array(vs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dump")
    ap.add_argument("--lambda", dest="lam", type=float, default=1.0)
    ap.add_argument("--dt", type=float, default=1.0e-8)
    ap.add_argument("--wall", action="store_true")
    ap.add_argument("--xgt", type=float, default=1.0, help="x_gamma_t: gamma_t = xgt * gamma_n")
    ap.add_argument("--mu", type=float, default=float("inf"), help="pair friction cap (inf: none)")
    ap.add_argument("--dgran", choices=["rc", "d"], default="rc",
                    help="contact diameter of the dashpot: WCA range (default) or d")
    ap.add_argument("--e-wall", type=float, default=0.5)
    ap.add_argument("--mu-wall", type=float, default=0.413)
    ap.add_argument("--gamma-t-wall", type=float, default=1.0e3,
                    help="tangential dashpot of the wall (large: Coulomb branch)")
    ap.add_argument("--full-normal-cap", action="store_true",
                    help="cap friction with WCA+dashpot (cgdem) instead of dashpot only (LAMMPS)")
    a = ap.parse_args()

    lam = a.lam
    p = dict(d=lam * D0, sigma=lam * SIGMA0, eps=lam**3 * EPS0, gamma=lam**2 * GAMMA0)
    p["rc"] = 2.0 ** (1.0 / 6.0) * p["sigma"]
    p["xgt"], p["mu"] = a.xgt, a.mu
    p["dc"] = p["rc"] if a.dgran == "rc" else p["d"]
    m1 = RHO * math.pi / 6.0 * p["d"] ** 3
    cols, frames = read_dump(a.dump)
    ci = {c: k for k, c in enumerate(cols)}
    _, d0 = frames[0]
    x0 = d0[:, [ci["x"], ci["y"], ci["z"]]]
    v0 = d0[:, [ci["vx"], ci["vy"], ci["vz"]]]
    m = np.full(len(x0), m1)
    if "mass" in ci:
        print(f"dump mass rel. diff = {np.max(np.abs(d0[:, ci['mass']] / m1 - 1)):.1e}, "
              f"dump radius = {d0[0, ci['radius']]:.9e} (contact diameter {p['dc']:.9e})")
    steps = np.array([s for s, _ in frames])
    nsteps = steps[-1]
    print(f"lambda={lam} d={p['d']:.6e} sigma={p['sigma']:.6e} rc={p['rc']:.6e} "
          f"eps={p['eps']:.6e} gamma={p['gamma']:.6e} m={m1:.6e} dt={a.dt:g}")

    if a.wall:
        e = a.e_wall
        k_lin = 4.0 * 72.0 * p["eps"] / p["d"] ** 2
        zeta = -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)
        p["gamma_w"] = 2.0 * zeta * math.sqrt(k_lin * m1)
        p["mu_w"] = a.mu_wall
        p["gamma_t_w"] = a.gamma_t_wall
        p["lammps_cap"] = not a.full_normal_cap
        print(f"wall: K={k_lin:.6e} N/m zeta={zeta:.6f} gamma_w={p['gamma_w']:.9e} kg/s "
              f"mu={a.mu_wall} cap={'dashpot only (LAMMPS)' if p['lammps_cap'] else 'WCA+dashpot (cgdem)'}")
        forces = lambda x, v: wall_forces(x, v, p)
    else:
        forces = lambda x, v: pair_forces(x, v, p)

    xs, vs = integrate(x0, v0, m, nsteps, a.dt, forces)
    lx = np.array([fr[:, [ci["x"], ci["y"], ci["z"]]] for _, fr in frames])
    lv = np.array([fr[:, [ci["vx"], ci["vy"], ci["vz"]]] for _, fr in frames])
    dx = np.max(np.abs(xs[steps] - lx))
    dv = np.max(np.abs(vs[steps] - lv))
    vscale = np.max(np.abs(lv))
    print(f"max |x_lammps - x_python| = {dx:.3e} m  (relative to d: {dx / p['d']:.3e})")
    print(f"max |v_lammps - v_python| = {dv:.3e} m/s (relative: {dv / vscale:.3e})")
    if "omegax" in ci:
        om = max(np.max(np.abs(fr[:, [ci['omegax'], ci['omegay'], ci['omegaz']]])) for _, fr in frames)
        print(f"max |omega| in LAMMPS dump = {om:.3e} rad/s")

    if a.wall:
        z = lx[:, 0, 2]
        inc = z < 0.5 * p["rc"]
        tc = inc.sum() * a.dt
        vn_in, vn_out = lv[0, 0, 2], lv[-1, 0, 2]
        vt_in = np.linalg.norm(lv[0, 0, :2])
        vt_out = np.linalg.norm(lv[-1, 0, :2])
        print(f"wall: e = {-vn_out / vn_in:.9f}  contact time (h<rc/2) = {tc:.4e} s "
              f"vt_out/vt_in = {vt_out / vt_in:.9f}")
        zp = xs[:, 0, 2]
        print(f"python: e = {-vs[-1, 0, 2] / vs[0, 0, 2]:.9f}  vt_out/vt_in = "
              f"{np.linalg.norm(vs[-1, 0, :2]) / np.linalg.norm(vs[0, 0, :2]):.9f}")
    else:
        def obs(X, V):
            r0 = X[0, 0] - X[0, 1]
            r1 = X[-1, 0] - X[-1, 1]
            n0, n1 = r0 / np.linalg.norm(r0), r1 / np.linalg.norm(r1)
            w0, w1 = V[0, 0] - V[0, 1], V[-1, 0] - V[-1, 1]
            vn0, vn1 = np.dot(w0, n0), np.dot(w1, n1)
            vt0 = np.linalg.norm(w0 - vn0 * n0)
            vt1 = np.linalg.norm(w1 - vn1 * n1)
            r = np.linalg.norm(X[:, 0] - X[:, 1], axis=1)
            return -vn1 / vn0, (r < p["rc"]).sum() * a.dt, (r < p["dc"]).sum() * a.dt, \
                (vt1 / vt0 if vt0 > 0 else float("nan")), r.min()
        for name, X, V in (("lammps", lx, lv), ("python", xs, vs)):
            e, tc, tcd, rt, rmin = obs(X, V)
            print(f"{name}: e_n = {e:.9f}  contact time (r<rc) = {tc:.4e} s  (r<dc) = {tcd:.4e} s  "
                  f"|v_t| out/in = {rt:.9f}  r_min/d = {rmin / p['d']:.6f}")
    ok = dx / p["d"] < 1e-6 and dv / vscale < 1e-6
    print("MATCH (rel < 1e-6)" if ok else "MISMATCH")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
