#!/usr/bin/env python3
"""The rotating drum's measurements (Dosta et al. 2024, case 2) from a run's frames.

Usage: python3 scripts/drum_measure.py RUN_DIR [--out drum.csv] [--ymax 0.01]
       python3 scripts/drum_measure.py FILE.data [FILE.data ...]

Reads LAMMPS data files as cgdem writes them (`[output] write_data = true`:
RUN_DIR/vtk/particles_*.data, the frame's time in the title line; or the case's
a settled bed written by `data_at_stage_ends`), atom type 1 = M1, 2 = M2, the drum's axis on y
through the origin and gravity along -z, and writes one row per frame, by time:

  time_s                     the frame's time
  zone1_m1, zone1_m2         grains with centre at x > 0, z > 0 (the upper quadrant on the
                             side where the wall rises, MercuryDPM's zone 1)
  zone2_m1, zone2_m2         grains with centre at x < 0, z < 0 (MercuryDPM's zone 2)
  com_angle_deg              atan(x_cm / -z_cm) of all grains' mass, positive towards +x
  surface_angle_deg, surface_r2
                             the free surface's slope: the highest grain top (z + radius) in
                             bins of 4 mm along x, a least-squares line through the bins
                             between 20% and 80% of the occupied chord; positive when the
                             surface rises towards +x; with --ymax only grains |y| < ymax
  lacey_index                Lacey's index of the M2 volume fraction in 10 mm cubic cells
                             with at least 10 grains: (S0^2 - S^2) / (S0^2 - Sr^2), 0 for
                             segregated layers, 1 for a random mixture
  lacey_cells                the cells it used

The definitions are reference/DRUM.md's ("Measurement"). No physics here beyond counting.
"""
import argparse
import glob
import math
import os
import re
import sys

import numpy as np

TITLE_TIME = re.compile(r"t = ([-+0-9.eE]+) s")


def read_frame(path):
    """(time, type, diameter, density, xyz) of a LAMMPS `Atoms # sphere` data file."""
    with open(path) as f:
        lines = f.read().splitlines()
    m = TITLE_TIME.search(lines[0])
    time = float(m.group(1)) if m else 0.0
    start = next(i for i, l in enumerate(lines) if l.startswith("Atoms"))
    rows = []
    for line in lines[start + 1 :]:
        cols = line.split()
        if not cols:
            if rows:
                break
            continue
        if not cols[0].lstrip("-").isdigit():
            break
        rows.append([float(c) for c in cols[:7]])
    a = np.array(rows)
    return time, a[:, 1].astype(int), a[:, 2], a[:, 3], a[:, 4:7]


def zone_counts(types, xyz):
    x, z = xyz[:, 0], xyz[:, 2]
    z1 = (x > 0) & (z > 0)
    z2 = (x < 0) & (z < 0)
    return [int(np.sum(zone & (types == t))) for zone in (z1, z2) for t in (1, 2)]


def surface_angle(diam, xyz, ymax, bin_width=4e-3):
    keep = np.abs(xyz[:, 1]) < ymax if ymax else np.ones(len(xyz), bool)
    x, top = xyz[keep, 0], xyz[keep, 2] + 0.5 * diam[keep]
    if len(x) == 0:
        return float("nan"), float("nan")
    bins = np.floor(x / bin_width).astype(int)
    heights = {}
    for b, h in zip(bins, top):
        if h > heights.get(b, -np.inf):
            heights[b] = h
    occupied = sorted(heights)
    lo, hi = occupied[0], occupied[-1] + 1
    span = hi - lo
    chosen = [b for b in occupied if lo + 0.2 * span <= b + 0.5 <= lo + 0.8 * span]
    if len(chosen) < 3:
        return float("nan"), float("nan")
    bx = (np.array(chosen) + 0.5) * bin_width
    bz = np.array([heights[b] for b in chosen])
    slope, intercept = np.polyfit(bx, bz, 1)
    fit = slope * bx + intercept
    ss = np.sum((bz - bz.mean()) ** 2)
    r2 = 1.0 - np.sum((bz - fit) ** 2) / ss if ss > 0 else float("nan")
    return math.degrees(math.atan(slope)), r2


def lacey(types, diam, xyz, cell=10e-3, min_grains=10):
    vol = math.pi / 6.0 * diam**3
    keys = np.floor(xyz / cell).astype(int)
    _, index, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    index = index.ravel()
    v_all = np.bincount(index, weights=vol)
    v_m2 = np.bincount(index, weights=vol * (types == 2))
    kept = counts >= min_grains
    if kept.sum() < 2:
        return float("nan"), int(kept.sum())
    c = v_m2[kept] / v_all[kept]
    w = v_all[kept]
    p = v_m2[kept].sum() / w.sum()
    s2 = np.sum(w * (c - p) ** 2) / w.sum()
    s0 = p * (1.0 - p)
    sr = s0 / counts[kept].mean()
    return (s0 - s2) / (s0 - sr), int(kept.sum())


def measure(path, ymax):
    time, types, diam, dens, xyz = read_frame(path)
    mass = dens * math.pi / 6.0 * diam**3
    cm = (mass[:, None] * xyz).sum(axis=0) / mass.sum()
    angle, r2 = surface_angle(diam, xyz, ymax)
    m, cells = lacey(types, diam, xyz)
    return [time] + zone_counts(types, xyz) + [
        math.degrees(math.atan2(cm[0], -cm[2])),
        angle,
        r2,
        m,
        cells,
    ]


COLUMNS = "time_s,zone1_m1,zone1_m2,zone2_m1,zone2_m2,com_angle_deg,surface_angle_deg,surface_r2,lacey_index,lacey_cells"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("inputs", nargs="+", help="a run directory, or data files")
    ap.add_argument("--out", help="CSV to write (default: standard output)")
    ap.add_argument("--ymax", type=float, default=None, help="surface from grains with |y| < ymax only")
    args = ap.parse_args()
    files = []
    for item in args.inputs:
        if os.path.isdir(item):
            files += glob.glob(os.path.join(item, "vtk", "particles_*.data"))
        else:
            files.append(item)
    if not files:
        sys.exit("no data files (a run needs `[output] write_data = true` and vtk_interval > 0)")
    rows = sorted(measure(f, args.ymax) for f in files)
    out = open(args.out, "w") if args.out else sys.stdout
    out.write(COLUMNS + "\n")
    for r in rows:
        out.write(
            "%.6g,%d,%d,%d,%d,%.4f,%.4f,%.4f,%.4f,%d\n" % tuple(r)
        )


if __name__ == "__main__":
    main()
