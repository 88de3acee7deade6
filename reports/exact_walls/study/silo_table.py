#!/usr/bin/env python3
"""The silo study's table (reports/exact_walls/NOTE.md): for every variant of a
`cgdem validate --suite reports/exact_walls/study/silo_study.toml --out DIR` run, each seed's
discharge rate by the harness's method (reports/silo/scripts/partial_rate.py), the mean, the
seeds' standard deviation and the mean's difference from the exact contact's at the same
orifice. Unfinished runs (no summary.json) are left out and counted.

Usage: python3 reports/exact_walls/study/silo_table.py DIR"""
import glob
import os
import re
import statistics
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "..", "silo", "scripts"))
sys.dont_write_bytecode = True  # no __pycache__ beside the report's scripts
import partial_rate  # noqa: E402

# The suite's variant names, as the table says them.
CONTACTS = {"mesh": "exact (mesh)", "grid05mm": "grid 0.5 mm", "grid075mm": "grid 0.75 mm", "grid15mm": "grid 1.5 mm"}

runs = os.path.join(sys.argv[1], "runs")
rates = {}
unfinished = 0
for run in sorted(glob.glob(os.path.join(runs, "silo_reduced-*", "cgdem-lambda1-seed*"))):
    if not os.path.exists(os.path.join(run, "summary.json")):
        unfinished += 1
        continue
    variant = os.path.basename(os.path.dirname(run))[len("silo_reduced-"):]
    seed = int(re.search(r"seed(\d+)$", run).group(1))
    rate, se, _, _ = partial_rate.rate(partial_rate.cgdem(run))
    rates.setdefault(variant, {})[seed] = (rate, se)

print("| orifice | contact | seed 1 | seed 2 | seed 3 | mean | seed SD | mean against exact |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
order = lambda v: (v.split("-")[0], v.split("-")[1] != "mesh", v)
for variant in sorted(rates, key=order):
    orifice, contact = variant.split("-", 1)
    seeds = rates[variant]
    cells = [f"{seeds[s][0]:.4f}" if s in seeds else "-" for s in (1, 2, 3)]
    values = [r for r, _ in seeds.values()]
    mean = statistics.mean(values)
    sd = f"{statistics.stdev(values):.4f}" if len(values) > 1 else "-"
    exact = rates.get(f"{orifice}-mesh")
    against = "-"
    if exact and contact != "mesh":
        reference = statistics.mean(r for r, _ in exact.values())
        against = f"{100 * (mean / reference - 1):+.1f}%"
    name = CONTACTS.get(contact, contact)
    print(f"| {orifice[1:]} mm | {name} | {' | '.join(cells)} | {mean:.4f} | {sd} | {against} |")
if unfinished:
    print(f"\n({unfinished} runs unfinished, left out)")
