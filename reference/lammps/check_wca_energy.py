#!/usr/bin/env python3
"""Check that lj/cut + 'pair_modify shift yes' at rc = 2^(1/6) sigma is the WCA potential of
paper A Eq. 2: sum of per-atom PE (c_pe column) in a dump against phi(r) at every frame in contact.
usage: check_wca_energy.py DUMP [lambda]"""
import sys
import numpy as np
from verify_seed import read_dump, SIGMA0, EPS0

lam = float(sys.argv[2]) if len(sys.argv) > 2 else 1.0
sigma, eps = lam * SIGMA0, lam**3 * EPS0
rc = 2.0 ** (1.0 / 6.0) * sigma
cols, frames = read_dump(sys.argv[1])
ci = {c: k for k, c in enumerate(cols)}
worst, n, pmax = 0.0, 0, 0.0
for _, fr in frames:
    r = np.linalg.norm(fr[0, [ci["x"], ci["y"], ci["z"]]] - fr[1, [ci["x"], ci["y"], ci["z"]]])
    phi = 4 * eps * ((sigma / r) ** 12 - (sigma / r) ** 6 + 0.25) if r < rc else 0.0
    pe = fr[:, ci["c_pe"]].sum()
    pmax = max(pmax, phi)
    worst = max(worst, abs(pe - phi))
    n += r < rc
print(f"{n} frames in contact, max phi = {pmax:.6e} J, max |PE_lammps - phi_WCA| = {worst:.3e} J "
      f"(relative to max phi: {worst / pmax:.2e})")
