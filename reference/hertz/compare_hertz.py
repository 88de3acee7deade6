#!/usr/bin/env python3
"""Compare the head-on Hertz collision in LIGGGHTS and LAMMPS dumps (hertz_*.in).
usage: compare_hertz.py [liggghts.dump] [lammps.dump] [more lammps dumps...]"""
import sys

import numpy as np

D, DT = 2.0e-3, 1.0e-7


def read_dump(path):
    frames = []
    lines = open(path).read().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: TIMESTEP"):
            n = int(lines[i + 3])
            frames.append(np.array([[float(x) for x in lines[i + 9 + k].split()] for k in range(n)]))
            i += 9 + n
        else:
            i += 1
    return np.array(frames)  # frame, atom, [id x y z vx vy vz]


def observables(fr):
    r = fr[:, 1, 1] - fr[:, 0, 1]
    vrel0 = fr[0, 1, 4] - fr[0, 0, 4]
    vrel1 = fr[-1, 1, 4] - fr[-1, 0, 4]
    return -vrel1 / vrel0, (r < D).sum() * DT, D - r.min()


def main():
    paths = sys.argv[1:] or ["hertz_liggghts.dump", "hertz_lammps.dump"]
    ref = read_dump(paths[0])
    for p in paths:
        fr = read_dump(p)
        e, tc, dmax = observables(fr)
        n = min(len(fr), len(ref))
        dx = np.max(np.abs(fr[:n, :, 1] - ref[:n, :, 1]))
        dv = np.max(np.abs(fr[:n, :, 4] - ref[:n, :, 4]))
        print(f"{p}: e = {e:.12f}  contact time = {tc:.4e} s  max overlap = {dmax:.6e} m  "
              f"max|dx| vs {paths[0]} = {dx:.2e} m  max|dv| = {dv:.2e} m/s")


if __name__ == "__main__":
    main()
