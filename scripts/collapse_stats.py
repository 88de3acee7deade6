#!/usr/bin/env python3
"""Mean and spread of a collapse case over runs (cgdem or `cgdem reference lammps` outputs).

Usage: python3 scripts/collapse_stats.py RUN_DIR [RUN_DIR ...]

Per run: the repose angle at each sampled time after the collapse stage began (summary.json),
and t_half, the time after the gate removal at which the front has covered half of its final
advance: front(t) - front(0) >= 0.5 (front(end) - front(0)), from timeseries.csv. (Half the
final run-out itself is already reached at the gate, the column being half as wide as the
final heap.) Then the mean and the sample standard deviation over the runs.
"""
import csv, json, statistics, sys


def run_stats(d):
    s = json.load(open(f"{d}/summary.json"))
    stage = s["stages"][-1]
    rows = [r for r in csv.DictReader(open(f"{d}/timeseries.csv")) if r["stage"] == stage["name"] and r["front_m"]]
    t = [float(r["time_s"]) - stage["start_s"] for r in rows]
    front = [float(r["front_m"]) for r in rows]
    # the front at the gate removal: the last row of the stage before
    before = [r for r in csv.DictReader(open(f"{d}/timeseries.csv")) if r["stage"] != stage["name"] and r["front_m"]]
    f0 = float(before[-1]["front_m"]) if before else front[0]
    half = f0 + 0.5 * (front[-1] - f0)
    t_half = next((ti for ti, f in zip(t, front) if f >= half), None)
    angles = {x["time_after_start_s"]: x["repose_angle_deg"] for x in s["repose_samples"]}
    return s["code"], angles, t_half, front[-1] - f0, t[-1] if t else 0.0


def mean_sd(v):
    v = [x for x in v if x is not None]
    if not v:
        return "-"
    return f"{statistics.mean(v):.2f} +- {statistics.stdev(v):.2f} (n={len(v)})" if len(v) > 1 else f"{v[0]:.3f} (n=1)"


runs = [run_stats(d) for d in sys.argv[1:]]
for d, (code, angles, t_half, advance, t_end) in zip(sys.argv[1:], runs):
    print(f"{d}: {code} angles {angles} t_half {t_half} s, front advance {advance:.4f} m, stage reached {t_end:.3f} s")
times = sorted({t for r in runs for t in r[1]})
for t in times:
    print(f"angle at {t} s: {mean_sd([r[1].get(t) for r in runs])} deg")
print(f"t_half: {mean_sd([r[2] for r in runs])} s")
