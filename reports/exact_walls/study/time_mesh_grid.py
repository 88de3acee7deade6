#!/usr/bin/env python3
"""Times walls met on their triangles against SDF grids, in alternating pairs (one run of each
per round, the order swapped every round), on the two cases of reports/exact_walls/NOTE.md:

- the reduced silo's discharge through 40 mm: 0.05 s (4000 steps) from a settled fill read
  with `read_data`, so that the grains press on the hopper and stream past the rim, as in the
  timed part of the case; the silo on its triangles (the case's) and on a 0.5 mm grid;
- the shipped screw at 100 rpm, 0.1 s of each stage, on its grids (the case's 4 and 5 mm
  cells) and on its triangles.

Each run gives two times: the whole run as the process takes it (set-up included: the grid's
build is the grid's cost) and its stepping (summary.json's `wall_s`, which starts after the
set-up). Prints every round and the medians of the ratios mesh / grid. One thread,
`--keep-going`.

Usage: python3 reports/exact_walls/study/time_mesh_grid.py CGDEM_BINARY ROUNDS [WORK_DIR]
Stop every other job on the machine while it runs (SIGSTOP): the ratios are of wall times."""
import json
import os
import re
import statistics
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ beside the report's scripts
from mesh_cases import with_mesh_contact  # noqa: E402  (beside this file)

here = os.path.dirname(os.path.abspath(__file__))
repo = os.path.normpath(os.path.join(here, "..", "..", ".."))
cases = os.path.join(repo, "validation", "cases")


def run(cgdem, scene, out, sets):
    """Runs a scene; returns the process's wall time and the stepping's (summary.json), in s,
    and its peak resident memory in MB."""
    args = [cgdem, "run", scene, "--quiet", "--threads", "1", "--keep-going", "--out", out]
    for s in sets:
        args += ["--set", s]
    started = time.perf_counter()
    child = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(child.pid, 0)
    whole = time.perf_counter() - started
    if status != 0:
        sys.exit(f"{' '.join(args)} failed (wait status {status})")
    stepping = json.load(open(os.path.join(out, "summary.json")))["wall_s"]
    return whole, stepping, usage.ru_maxrss / 1024


def discharge_from_fill(text, fill):
    """The silo case's text starting from a settled fill: no insertion, no fill stage."""
    text = re.sub(r"\[\[insert\]\]\n(?:[^\[\n][^\n]*\n|\n)*", "", text)
    text = re.sub(r'\[\[stage\]\]\nname = "fill"\n(?:[^\[\n][^\n]*\n|\n)*', "", text)
    text = re.sub(r'data_at_stage_ends = \[[^\]]*\][^\n]*\n', "", text)
    # read_data is a top-level key: before the first table.
    first_table = text.index("\n[")
    return text[:first_table] + f'\nread_data = "{fill}"\n' + text[first_table:]


def main():
    cgdem, rounds = os.path.abspath(sys.argv[1]), int(sys.argv[2])
    work = os.path.abspath(sys.argv[3] if len(sys.argv) > 3 else "/tmp/time_mesh_grid")
    os.makedirs(work, exist_ok=True)

    # The settled fill both silo variants start from: the case (met on its triangles), seed 1.
    silo_case = os.path.join(cases, "silo_reduced.toml")
    fill = os.path.join(work, "fill", "stage_fill_end.data")
    if not os.path.exists(fill):
        print("settling the fill (one run of the fill stage) ...", flush=True)
        run(cgdem, silo_case, os.path.join(work, "fill"), ["stage[1].duration=1.25e-5"])

    # The silo's geometry is built in and the fill's path absolute: the scene can live here.
    silo_discharge = os.path.join(work, "silo_discharge.toml")
    open(silo_discharge, "w").write(discharge_from_fill(open(silo_case).read(), fill))
    scenes = {
        ("silo", "mesh"): (silo_discharge, ["stage[0].duration=0.05"]),
        ("silo", "grid"): (silo_discharge, ["stage[0].duration=0.05", "body[0].cell_size=5e-4"]),
    }
    screw_text = open(os.path.join(cases, "screw_feeder_hertz.toml")).read()
    screw_mesh = os.path.join(work, "screw_feeder_hertz_mesh.toml")
    open(screw_mesh, "w").write(with_mesh_contact(screw_text))
    short = ["stage[0].duration=0.1", "stage[1].duration=0.1"]
    scenes[("screw", "grid")] = (os.path.join(cases, "screw_feeder_hertz.toml"), short)
    scenes[("screw", "mesh")] = (screw_mesh, short)

    rows = []
    for r in range(rounds):
        for case in ("silo", "screw"):
            order = ("grid", "mesh") if r % 2 == 0 else ("mesh", "grid")
            for contact in order:
                scene, sets = scenes[(case, contact)]
                whole, stepping, rss = run(cgdem, scene, os.path.join(work, f"{case}_{contact}"), sets)
                rows.append((r, case, contact, whole, stepping))
                print(f"round {r + 1} {case} {contact}: whole {whole:.1f} s, stepping {stepping:.1f} s, "
                      f"peak memory {rss:.0f} MB", flush=True)

    print()
    for case in ("silo", "screw"):
        for what, pick in (("whole run", lambda w, s: w), ("stepping", lambda w, s: s)):
            ratios, grids, meshes = [], [], []
            for r in range(rounds):
                g = [pick(w, s) for (rr, c, k, w, s) in rows if rr == r and c == case and k == "grid"][0]
                m = [pick(w, s) for (rr, c, k, w, s) in rows if rr == r and c == case and k == "mesh"][0]
                ratios.append(m / g)
                grids.append(g)
                meshes.append(m)
            print(f"{case} {what}: mesh / grid median {statistics.median(ratios):.2f} "
                  f"({' '.join(f'{x:.2f}' for x in ratios)}); grid median {statistics.median(grids):.1f} s, "
                  f"mesh median {statistics.median(meshes):.1f} s")


if __name__ == "__main__":
    t0 = time.time()
    main()
    print(f"({time.time() - t0:.0f} s in all)")
