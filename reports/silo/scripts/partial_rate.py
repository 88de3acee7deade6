#!/usr/bin/env python3
"""Discharge rate of a (possibly unfinished) run, by the harness's method (crate::silo):
least-squares slope of M(t) from `discard` after the gate opens to the last sample, standard
error of `blocks` equal blocks (their rates' sd / sqrt(B)). M = m_grain (N0 - N(t)).
Usage: partial_rate.py cgdem RUN_DIR | partial_rate.py dump RUN_DIR GATE_STEP DT"""
import sys, math, re
M_GRAIN = 2500 * math.pi / 6 * 0.004 ** 3

def cgdem(d):
    rows = [l.strip().split(',') for l in open(d + '/timeseries.csv')][1:]
    series, n0, start = [], None, None
    for r in rows:
        t, stage, n = float(r[0]), r[1], float(r[4])
        if stage != 'discharge':
            before, tb = n, t
            continue
        if n0 is None:
            n0, start = before, tb  # the gate opens at the fill's last row (within 0.01 s)
            series.append((0.0, 0.0))
        series.append((t - start, M_GRAIN * (n0 - n)))
    return series

def dump(d, gate, dt):
    series, n0 = [], None
    step = None
    with open(d + '/traj.dump') as f:
        for line in f:
            if line.startswith('ITEM: TIMESTEP'):
                step = int(next(f))
            elif line.startswith('ITEM: NUMBER OF ATOMS'):
                n = int(next(f))
                if step <= gate:
                    n0 = n
                    continue
                if not series:
                    series.append((0.0, 0.0))
                series.append(((step - gate) * dt, M_GRAIN * (n0 - n)))
    return series

def rate(series, discard=0.1, blocks=5):
    w = [(t, m) for t, m in series if t >= discard - 1e-9]
    t = [a for a, _ in w]; m = [b for _, b in w]
    n = len(t); mt = sum(t) / n; mm = sum(m) / n
    slope = sum((a - mt) * (b - mm) for a, b in w) / sum((a - mt) ** 2 for a in t)
    last = n - 1
    bounds = [round(j * last / blocks) for j in range(blocks + 1)]
    br = [(m[b] - m[a]) / (t[b] - t[a]) for a, b in zip(bounds, bounds[1:])]
    mean = sum(br) / blocks
    se = math.sqrt(sum((x - mean) ** 2 for x in br) / (blocks - 1) / blocks)
    return slope, se, (t[0], t[-1]), br

if __name__ == '__main__':
    s = cgdem(sys.argv[2]) if sys.argv[1] == 'cgdem' else dump(sys.argv[2], int(sys.argv[3]), float(sys.argv[4]))
    r, se, win, br = rate(s)
    print(f"rate {r:.4f} +- {se:.4f} kg/s ({r / M_GRAIN:.0f} grains/s), window {win[0]:.3f}-{win[1]:.3f} s, blocks " + ' '.join(f'{b:.3f}' for b in br))
