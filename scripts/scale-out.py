#!/usr/bin/env python3
"""Scale-out estimate of the decomposed step (issue 23, reports/PERFORMANCE.md): step time
= compute / P + ghost exchange + reductions, projected for the seed's collapse at lambda = 1.

Inputs measured on this machine (given on the command line, defaults are the figures quoted
in PERFORMANCE.md): the compute per particle-step of the seed model on one core, the bytes
per ghost per step, and the time of one exchange step between two ranks here. Cluster
figures (latency and bandwidth of the interconnect) are assumptions, printed with the table.

Model, per step, for P subdomains of n = N / P particles each, cubes of side s with a ghost
layer w thick around them (all 26 neighbours):
    ghosts g = rho ((s + 2 w)^3 - s^3)
    compute = c (n + g_pairs / 2)    pairs with a ghost are computed on both sides (newton
                                     off): about half the ghost layer is within reach
    forward = m latency + g bytes / bandwidth     m messages per step
    reductions = 2 log2(P) latency   the rebuild decision and the guard's overlaps
The current transport routes with one MPI_Alltoallv: every rank meets every other, so
m = P - 1; the forward's point-to-point exchange meets each neighbouring subdomain's rank,
m = 26; LAMMPS's Comm stages it by dimension (x, then y carrying x's ghosts, then z), m = 6
(not built). All three are printed.

Usage: python3 scripts/scale-out.py [--c NS] [--bytes-per-ghost B] [--latency-us L]
                                    [--bandwidth-gbs G] [--csv OUT]
"""
import argparse
import csv
import math

# The seed's collapse at lambda = 1 (validation/cases/aor_collapse.toml, SEEDS.md paper A).
N = 420_000            # particles
STEPS = 2.8e7          # steps of 0.108 us (dt_fraction 0.05 of the contact period)
D = 1.35e-3            # diameter, m
SOLID = 0.6            # solid fraction of the heap
W = 1.3 * D            # ghost layer: diameter + reach (0 for WCA) + skin (0.3 d)


def project(p, c, bytes_per_ghost, latency, bandwidth, messages):
    rho = SOLID / (math.pi / 6 * D**3)
    n = N / p
    s = (n / rho) ** (1 / 3)
    g = rho * ((s + 2 * W) ** 3 - s**3) if p > 1 else 0.0
    compute = c * (n + 0.5 * g * (D / W))
    forward = (messages * latency + g * bytes_per_ghost / bandwidth) if p > 1 else 0.0
    reductions = 2 * math.log2(p) * latency if p > 1 else 0.0
    step = compute + forward + reductions
    return n, g, compute, forward + reductions, step


def main():
    a = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("--c", type=float, default=100.0, help="compute per particle-step, ns")
    a.add_argument("--bytes-per-ghost", type=float, default=72.0)
    a.add_argument("--latency-us", type=float, default=2.0, help="cluster message latency, us")
    a.add_argument("--bandwidth-gbs", type=float, default=10.0, help="cluster bandwidth, GB/s")
    a.add_argument("--csv", help="also write the table here")
    args = a.parse_args()
    c, lat, bw = args.c * 1e-9, args.latency_us * 1e-6, args.bandwidth_gbs * 1e9
    serial = c * N * STEPS
    print(f"inputs: c = {args.c} ns per particle-step, {args.bytes_per_ghost} bytes per ghost per step, "
          f"latency {args.latency_us} us, bandwidth {args.bandwidth_gbs} GB/s; N = {N}, {STEPS:.2g} steps")
    print(f"one core: {serial / 86400:.1f} days")
    rows = []
    print("cores | transport | particles per core | ghosts per core | compute us | exchange us | step us | efficiency | run hours")
    for p in (64, 256, 1024):
        for name, m in (("alltoallv", p - 1), ("neighbours", 26), ("staged", 6)):
            n, g, comp, comm, step = project(p, c, args.bytes_per_ghost, lat, bw, m)
            eff = c * n / step
            hours = step * STEPS / 3600
            rows.append([p, name, round(n), round(g), f"{comp * 1e6:.1f}", f"{comm * 1e6:.1f}",
                         f"{step * 1e6:.1f}", f"{eff:.2f}", f"{hours:.1f}"])
            print(" | ".join(str(x) for x in rows[-1]))
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["cores", "transport", "particles_per_core", "ghosts_per_core", "compute_us",
                        "exchange_us", "step_us", "efficiency", "run_hours"])
            w.writerows(rows)


if __name__ == "__main__":
    main()
