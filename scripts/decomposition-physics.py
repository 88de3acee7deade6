#!/usr/bin/env python3
"""Same physics under domain decomposition, and load balance on the seed collapse (issue 23).

Runs cgdem on each case undecomposed and split into subdomains (`--grid`, on threads and on
MPI ranks), reads what each run measured and writes one CSV per item into OUT
(reports/decomposition by default). A run whose directory holds a summary.json written by the
same command is not run again, so an interrupted item resumes. Run the script itself at low
priority (`chrt -i 0 nice -n 19 python3 ...`); the runs inherit it.

Usage: python3 scripts/decomposition-physics.py ITEM [options]

Items:
  heap       the heap bench case (validation/bench/heap.toml, 0.5 s) at 1, 2 and 4 subdomains:
             threads (2x1x1, 2x2x1, 4x1x1 on 2 threads), MPI ranks (2x1x1 on 2, 2x2x1 on 4
             oversubscribed ranks, --mpi-bin); height and flank slope of the final heap
             (analysis::conical_heap, ported below) against the spread LIGGGHTS and LAMMPS show
             against each other in `cgdem bench ... --grid 2x1x1` run from one prepared state.
  hertz      the Hertz collapse (validation/cases/aor_hertz.toml) on 1 and 2 (2x1x1)
             subdomains, --seeds; repose angle against the seed spread.
  screw      the mesh screw and the particle-built screw (validation/cases/
             screw_feeder_hertz*.toml) at --rpm (as `validate`'s rpms do: discard and convey
             stage scaled to the same turns), 1 and 2 (2x1x1) subdomains, --seeds; mean mass
             flow over the seeds against the standard error of the difference.
  stability  the stability suite (validation/suites/stability.toml), cgdem's verdicts
             undecomposed and with `validate --grid 2` (each scene split by the grid of least
             ghost surface).
  balance    the seed's collapse (validation/cases/aor_collapse.toml, lambda 8, seed 1) on
             2x1x1 and 4x1x1 with `--balance 1.1` and `--balance off`; summary.json's
             imbalance figures.
"""
import argparse
import csv
import json
import math
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HEAP_CASE = "validation/bench/heap.toml"


def sh(cmd):
    return " ".join(f"'{c}'" if (" " in c or "[" in c) else c for c in cmd)


def run_cgdem(cmd, out, label):
    """Runs `cmd` (which writes into `out`) unless `out` already holds a finished run of the
    same command. Returns (summary or None, error message or None)."""
    out = Path(out)
    stamp = out / "command.txt"
    if (out / "summary.json").exists() and stamp.exists() and stamp.read_text() == sh(cmd):
        return json.loads((out / "summary.json").read_text()), None
    out.mkdir(parents=True, exist_ok=True)
    print(f"[{time.strftime('%H:%M:%S')}] {label}: {sh(cmd)}", flush=True)
    started = time.time()
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    (out / "stderr.txt").write_text(p.stderr)
    print(f"    exit {p.returncode} after {time.time() - started:.0f} s", flush=True)
    if p.returncode != 0 or not (out / "summary.json").exists():
        return None, (p.stderr.strip().splitlines() or [f"exit {p.returncode}"])[-1]
    stamp.write_text(sh(cmd))
    return json.loads((out / "summary.json").read_text()), None


def mpirun(ranks):
    # Waiting ranks yield instead of spinning: the machine is shared (results do not change).
    return ["mpirun", "--allow-run-as-root", "--oversubscribe", "--mca", "mpi_yield_when_idle", "1",
            "-np", str(ranks)]


def write_csv(path, header, rows):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for r in rows:
            w.writerow([fmt(r.get(h)) for h in header])
    print(f"wrote {path}")


def fmt(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, bool):
        return "yes" if v else "no"
    return str(v)


# ---- heap ----------------------------------------------------------------------------------


def conical_heap(particles, axis, floor_z, ring_width):
    """analysis::conical_heap (crates/cgdem-core/src/analysis/conical_heap.rs), line for line:
    the highest particle top per ring about the axis; height at the centre ring; edge = the
    outermost ring at least two diameters high; slope = least-squares line through the rings
    between 20% and 80% of the edge radius."""
    surface, max_d = [], 0.0
    for x, y, z, r in particles:
        max_d = max(max_d, 2.0 * r)
        ring = int(math.hypot(x - axis[0], y - axis[1]) / ring_width)
        if ring >= len(surface):
            surface.extend([floor_z] * (ring + 1 - len(surface)))
        surface[ring] = max(surface[ring], z + r)
    if not surface:
        return None
    height = surface[0] - floor_z
    high = [k for k, top in enumerate(surface) if top - floor_z >= 2.0 * max_d]
    if not high:
        return None
    edge_radius = (high[-1] + 1.0) * ring_width
    lo, hi = 0.2 * edge_radius, 0.8 * edge_radius
    pts = [((k + 0.5) * ring_width, top) for k, top in enumerate(surface)]
    pts = [(r, z) for r, z in pts if lo <= r <= hi]
    if len(pts) < 3:
        return None
    mr = sum(p[0] for p in pts) / len(pts)
    mz = sum(p[1] for p in pts) / len(pts)
    sxy = sum((r - mr) * (z - mz) for r, z in pts)
    sxx = sum((r - mr) ** 2 for r, _ in pts)
    return {
        "height_mm": height * 1e3,
        "edge_radius_mm": edge_radius * 1e3,
        "slope_deg": math.degrees(math.atan(-sxy / sxx)),
        "fit_rings": len(pts),
    }


def check_conical_heap():
    """The Rust unit test's cone: spheres of radius 1 mm filling a 30 degree cone of radius
    50 mm on a 2 mm grid give 30 +- 2 deg and the cone's height within 3 mm."""
    r, tan = 1e-3, math.tan(math.radians(30))
    ps = []
    for i in range(-25, 26):
        for j in range(-25, 26):
            x, y = i * 2e-3, j * 2e-3
            top = (0.05 - math.hypot(x, y)) * tan
            z = r
            while z + r <= top:
                ps.append((x, y, z, r))
                z += 2e-3
    h = conical_heap(ps, (0.0, 0.0), 0.0, 2e-3)
    assert abs(h["slope_deg"] - 30.0) < 2.0 and abs(h["height_mm"] - 50 * tan) < 3.0, h


def read_data(path):
    """(title, [(type, x, y, z, radius)]) of a LAMMPS data file written by cgdem."""
    lines = Path(path).read_text().splitlines()
    atoms, in_atoms = [], False
    for line in lines[1:]:
        s = line.split("#")[0].strip()
        if line.startswith("Atoms"):
            in_atoms = True
            continue
        if in_atoms and re.match(r"^[A-Z]", line):
            break
        if in_atoms and s:
            f = s.split()
            atoms.append((int(f[1]), float(f[4]), float(f[5]), float(f[6]), 0.5 * float(f[2])))
    return lines[0], atoms


def heap_of_run(out):
    """The heap in the run's last data frame, about the mobile particles' centre at t = 0
    (the bench takes the centre of its prepared state), rings one diameter (2 mm) wide."""
    frames = sorted((Path(out) / "vtk").glob("particles_*.data"))
    if len(frames) < 2:
        return None, "no data frames (output.write_data)"
    _, first = read_data(frames[0])
    title, last = read_data(frames[-1])
    mobile0 = [a for a in first if a[0] == 2]
    axis = (sum(a[1] for a in mobile0) / len(mobile0), sum(a[2] for a in mobile0) / len(mobile0))
    mobile = [a[1:] for a in last if a[0] == 2]
    t = float(re.search(r"t = (\S+) s", title).group(1))
    h = conical_heap(mobile, axis, 0.0, 2e-3)
    if h:
        h["time_s"] = t
    return h, None


def item_heap(a):
    check_conical_heap()
    runs, out = Path(a.runs) / "heap", Path(a.out)
    sets = ["--set", "output.vtk_interval=0.5", "--set", "output.write_data=true"]
    configs = [
        # (label, transport, grid, ranks, threads)
        ("1 subdomain", "threads", None, 1, 1),
        ("2 subdomains", "threads", "2x1x1", 1, 2),
        ("4 subdomains", "threads", "2x2x1", 1, 2),
        ("4 subdomains", "threads", "4x1x1", 1, 2),
        ("2 subdomains", "MPI ranks", "2x1x1", 2, 1),
        ("4 subdomains", "MPI ranks (oversubscribed)", "2x2x1", 4, 1),
    ]
    if a.only is not None:
        configs = [c for c in configs if (c[2] or "none") in a.only.split(",")]
    rows = []
    for label, transport, grid, ranks, threads in configs:
        name = f"{'ranks' if ranks > 1 else 'threads'}-{grid or 'none'}"
        bin_ = a.mpi_bin if ranks > 1 else a.bin
        if ranks > 1 and not bin_:
            print(f"skipped {name}: no --mpi-bin")
            continue
        cmd = ([*mpirun(ranks)] if ranks > 1 else []) + [bin_, "run", HEAP_CASE, *sets, "--quiet",
                                                         "--threads", str(threads)]
        if grid:
            cmd += ["--grid", grid]
        cmd += ["--out", str(runs / name)]
        s, err = run_cgdem(cmd, runs / name, f"heap {name}")
        row = {"subdomains": label, "transport": transport, "grid": grid or "none",
               "ranks": ranks, "threads": threads, "run": str(runs / name)}
        if s is None:
            row["status"] = f"failed: {err}"
            rows.append(row)
            continue
        h, err = heap_of_run(runs / name)
        row.update(h or {})
        row["status"] = "ok" if h else f"no heap: {err}"
        row["wall_s"] = s["wall_s"]
        d = s.get("decomposition") or {}
        row["shifts"] = d.get("shifts")
        row["imbalance_end"] = d.get("imbalance")
        rows.append(row)
    # The bench: LIGGGHTS, LAMMPS, cgdem and cgdem on 2x1x1 from one state prepared by cgdem
    # (0.15 s), each run to the scene's end (0.35 s more): the reference codes' spread.
    bench_dir = runs / "bench"
    bench_cmd = [a.bin, "bench", HEAP_CASE, "--codes", "cgdem,liggghts,lammps", "--grid",
                 "2x1x1", "--pairs", "1", "--steps", "100", "--threads", "1", "--out", str(bench_dir)]
    stamp = bench_dir / "command.txt"
    if not a.no_bench and not ((bench_dir / "bench.json").exists() and stamp.exists()
                               and stamp.read_text() == sh(bench_cmd)):
        print(f"[{time.strftime('%H:%M:%S')}] heap bench: {sh(bench_cmd)}", flush=True)
        p = subprocess.run(bench_cmd, cwd=ROOT, capture_output=True, text=True)
        (bench_dir / "stderr.txt").write_text(p.stderr)
        if p.returncode == 0:
            stamp.write_text(sh(bench_cmd))
    outcomes = {}
    if (bench_dir / "bench.json").exists():
        for o in json.loads((bench_dir / "bench.json").read_text())["outcomes"]:
            key = f"{o['code']}" + ("-grid2x1x1" if o["case"].endswith("-grid2x1x1") else "")
            if o.get("heap"):
                outcomes[key] = o["heap"]
                rows.append({"subdomains": "bench outcome", "transport": key, "grid": "",
                             "height_mm": o["heap"]["height_m"] * 1e3,
                             "edge_radius_mm": o["heap"]["edge_radius_m"] * 1e3,
                             "slope_deg": o["heap"]["slope_deg"],
                             "fit_rings": o["heap"]["fit_rings"], "time_s": 0.15 + o["simulated_s"],
                             "status": o["status"], "run": str(bench_dir)})
    spread = {}
    if "liggghts" in outcomes and "lammps" in outcomes:
        spread["height_mm"] = abs(outcomes["liggghts"]["height_m"] - outcomes["lammps"]["height_m"]) * 1e3
        spread["slope_deg"] = abs(outcomes["liggghts"]["slope_deg"] - outcomes["lammps"]["slope_deg"])
    base = next((r for r in rows if r.get("grid") == "none" and "height_mm" in r), None)
    for r in rows:
        if base is None or r is base or r["subdomains"] == "bench outcome" or "height_mm" not in r:
            continue
        for q in ("height_mm", "slope_deg"):
            r[f"d_{q}"] = r[q] - base[q]
            if q in spread:
                r[f"within_{q}"] = abs(r[f"d_{q}"]) <= spread[q]
    for q, v in spread.items():
        print(f"LIGGGHTS - LAMMPS spread of {q}: {v:.3f}")
    if "cgdem" in outcomes and "cgdem-grid2x1x1" in outcomes:
        print("bench, cgdem 2x1x1 - cgdem: height "
              f"{(outcomes['cgdem-grid2x1x1']['height_m'] - outcomes['cgdem']['height_m']) * 1e3:.3f} mm, slope "
              f"{outcomes['cgdem-grid2x1x1']['slope_deg'] - outcomes['cgdem']['slope_deg']:.3f} deg")
    for r in rows:
        r["spread_height_mm"] = spread.get("height_mm")
        r["spread_slope_deg"] = spread.get("slope_deg")
    write_csv(out / "heap.csv",
              ["subdomains", "transport", "grid", "ranks", "threads", "status", "time_s",
               "height_mm", "slope_deg", "edge_radius_mm", "fit_rings", "d_height_mm", "d_slope_deg",
               "spread_height_mm", "spread_slope_deg", "within_height_mm", "within_slope_deg",
               "shifts", "imbalance_end", "wall_s", "run"], rows)


# ---- Hertz collapse -----------------------------------------------------------------------


def two_means(a, b):
    """Means and seed standard deviations of two samples (at least two values each), and the
    standard error of the difference of the means."""
    m1, m2 = statistics.mean(a), statistics.mean(b)
    s1, s2 = statistics.stdev(a), statistics.stdev(b)
    return m1, s1, m2, s2, math.sqrt(s1 ** 2 / len(a) + s2 ** 2 / len(b))


def item_hertz(a):
    runs, out = Path(a.runs) / "hertz", Path(a.out)
    rows = []
    # Seed by seed, both decompositions of a seed one after the other: a shortened series
    # (--seeds 1,2) still pairs them.
    for seed in a.seeds:
        for grid in a.grids:
            name = f"{grid or 'none'}-seed{seed}"
            cmd = [a.bin, "run", "validation/cases/aor_hertz.toml", "--seed", str(seed), "--quiet",
                   "--threads", str(a.threads if grid else 1)]
            if grid:
                cmd += ["--grid", grid]
            cmd += ["--out", str(runs / name)]
            s, err = run_cgdem(cmd, runs / name, f"hertz {name}")
            row = {"grid": grid or "none", "subdomains": 2 if grid else 1, "seed": seed,
                   "run": str(runs / name)}
            if s is None:
                row["status"] = f"failed: {err}"
            else:
                row["status"] = "ok"
                row["repose_angle_deg"] = s["repose_angle_deg"]
                for x in s["repose_samples"][:3]:
                    row[f"angle_at_{x['time_after_start_s']:g}s"] = x["repose_angle_deg"]
                row["collapse_s"] = s["stages"][-1]["end_s"] - s["stages"][-1]["start_s"]
                row["wall_s"] = s["wall_s"]
                row["stopped_by"] = s.get("stopped_by")
            rows.append(row)
    stats = {}
    for g in ("none", "2x1x1"):
        v = [r["repose_angle_deg"] for r in rows if r["grid"] == g and "repose_angle_deg" in r]
        stats[g] = v
        if len(v) > 1:
            print(f"grid {g}: {statistics.mean(v):.3f} +- {statistics.stdev(v):.3f} deg (n={len(v)})")
    summary = []
    if len(stats["none"]) > 1 and len(stats["2x1x1"]) > 1:
        m1, s1, m2, s2, se = two_means(stats["none"], stats["2x1x1"])
        summary.append({"grid": "none", "n": len(stats["none"]), "mean_deg": m1, "seed_sd_deg": s1})
        summary.append({"grid": "2x1x1", "n": len(stats["2x1x1"]), "mean_deg": m2, "seed_sd_deg": s2,
                        "d_mean_deg": m2 - m1, "se_of_difference_deg": se,
                        "within_seed_sd": abs(m2 - m1) <= s1})
        print(f"difference of means {m2 - m1:+.3f} deg; seed sd (1 subdomain) {s1:.3f}; "
              f"standard error of the difference {se:.3f}")
    cols = ["grid", "subdomains", "seed", "status", "repose_angle_deg", "angle_at_0.25s",
            "angle_at_0.5s", "angle_at_1s", "collapse_s", "stopped_by", "wall_s", "run"]
    write_csv(out / "hertz_collapse.csv", cols, rows)
    write_csv(out / "hertz_collapse_summary.csv",
              ["grid", "n", "mean_deg", "seed_sd_deg", "d_mean_deg", "se_of_difference_deg",
               "within_seed_sd"], summary)


# ---- screws --------------------------------------------------------------------------------


def item_screw(a):
    runs, out = Path(a.runs) / "screw", Path(a.out)
    # As validate's `rpms` (sweep::at_speed): the screw at rpm, the discarded turn and the
    # conveying stage scaled from the case's 100 rpm to the same number of turns.
    factor = 100.0 / a.rpm
    sets = ["--set", f"body[0].rpm={-float(a.rpm)!r}", "--set", f"conveying.discard={0.6 * factor!r}",
            "--set", f"stage[1].duration={1.8 * factor!r}"]
    rows, summary = [], []
    for case in ["screw_feeder_hertz", "screw_feeder_hertz_particles"]:
        # Seed by seed, both decompositions of a seed one after the other (see item_hertz).
        for seed in a.seeds:
            for grid in a.grids:
                name = f"{case}-rpm{a.rpm}-{grid or 'none'}-seed{seed}"
                cmd = [a.bin, "run", f"validation/cases/{case}.toml", *sets, "--seed", str(seed),
                       "--keep-going", "--quiet", "--threads", str(a.threads if grid else 1)]
                if grid:
                    cmd += ["--grid", grid]
                cmd += ["--out", str(runs / name)]
                s, err = run_cgdem(cmd, runs / name, f"screw {name}")
                row = {"case": case, "rpm": a.rpm, "grid": grid or "none", "seed": seed,
                       "run": str(runs / name)}
                if s is None or not s.get("conveying"):
                    row["status"] = f"failed: {err}" if s is None else "no conveying section"
                else:
                    c = s["conveying"]
                    row.update(status="ok", mass_flow_kg_s=c["mass_flow_kg_s"],
                               std_error_kg_s=c["mass_flow_std_error_kg_s"],
                               blocks=" ".join(f"{b:.4f}" for b in c["block_mass_flow_kg_s"]),
                               fill_ratio=c["fill_ratio"], rpm_read=c["rpm"], wall_s=s["wall_s"],
                               overlap_peak=(s.get("guard_peaks") or {}).get("overlap_fraction"))
                rows.append(row)
        # A split changes the summation order, so each split run is another realisation of
        # the same flow: the means over seeds are compared, with the standard error of their
        # difference from the seed-to-seed spread (the blocks of one run are correlated).
        flows = {g: [r["mass_flow_kg_s"] for r in rows
                     if r["case"] == case and r["grid"] == g and "mass_flow_kg_s" in r]
                 for g in ("none", "2x1x1")}
        if all(len(v) > 1 for v in flows.values()):
            m1, s1, m2, s2, se = two_means(flows["none"], flows["2x1x1"])
            summary.append({"case": case, "grid": "none", "n": len(flows["none"]),
                            "mean_kg_s": m1, "seed_sd_kg_s": s1})
            summary.append({"case": case, "grid": "2x1x1", "n": len(flows["2x1x1"]),
                            "mean_kg_s": m2, "seed_sd_kg_s": s2, "d_mean_kg_s": m2 - m1,
                            "d_mean_fraction": (m2 - m1) / m1, "se_of_difference_kg_s": se,
                            "within_2_se": abs(m2 - m1) <= 2 * se})
            print(f"{case}: {m1:.4f} +- {s1:.4f} undecomposed, {m2:.4f} +- {s2:.4f} on 2x1x1 "
                  f"(seed sd); difference {m2 - m1:+.4f} kg/s, standard error {se:.4f}")
    write_csv(out / "screw.csv",
              ["case", "rpm", "grid", "seed", "status", "mass_flow_kg_s", "std_error_kg_s", "blocks",
               "fill_ratio", "rpm_read", "overlap_peak", "wall_s", "run"], rows)
    write_csv(out / "screw_summary.csv",
              ["case", "grid", "n", "mean_kg_s", "seed_sd_kg_s", "d_mean_kg_s", "d_mean_fraction",
               "se_of_difference_kg_s", "within_2_se"], summary)


# ---- stability -----------------------------------------------------------------------------


def item_stability(a):
    runs, out = Path(a.runs) / "stability", Path(a.out)
    runs.mkdir(parents=True, exist_ok=True)
    # The suite with cgdem alone: the reference codes' verdicts do not depend on --grid.
    text = (ROOT / "validation/suites/stability.toml").read_text()
    text = re.sub(r"^codes\s*=.*$\n?", "", text, flags=re.M)
    text = text.replace("[[stability]]\n", '[[stability]]\ncodes = ["cgdem"]\n')
    text = text.replace('name = "stability"', 'name = "stability-cgdem"', 1)
    # Its scenes are named relative to the suite file; this copy lives elsewhere.
    text = text.replace('file = "../', f'file = "{ROOT}/validation/')
    suite = runs / "stability-cgdem.toml"
    suite.write_text(text)
    verdicts = {}
    for label, extra in [("undecomposed", []), (f"grid {a.stability_grid}", ["--grid", a.stability_grid])]:
        report = runs / label.replace(" ", "-")
        cmd = [a.bin, "validate", "--suite", str(suite), "--out", str(report), "--quiet",
               "--threads", str(a.threads), *extra]
        stamp = report / "command.txt"
        if not ((report / "stability.csv").exists() and stamp.exists() and stamp.read_text() == sh(cmd)):
            print(f"[{time.strftime('%H:%M:%S')}] stability {label}: {sh(cmd)}", flush=True)
            started = time.time()
            p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
            report.mkdir(parents=True, exist_ok=True)
            (report / "stderr.txt").write_text(p.stderr)
            print(f"    exit {p.returncode} after {time.time() - started:.0f} s", flush=True)
            if (report / "stability.csv").exists():
                stamp.write_text(sh(cmd))
        with open(report / "stability.csv") as f:
            for r in csv.DictReader(f):
                verdicts.setdefault(r["case"], {})[label] = r
    rows = []
    labels = ["undecomposed", f"grid {a.stability_grid}"]
    for case, by in verdicts.items():
        u, g = by.get(labels[0], {}), by.get(labels[1], {})
        rows.append({"case": case, "verdict_undecomposed": u.get("verdict"),
                     "verdict_grid": g.get("verdict"), "same": u.get("verdict") == g.get("verdict"),
                     "message_undecomposed": u.get("message", "")[:200],
                     "message_grid": g.get("message", "")[:200]})
    changed = [r["case"] for r in rows if not r["same"]]
    print(f"{len(rows)} cases, verdicts changed under --grid {a.stability_grid}: {changed or 'none'}")
    write_csv(out / "stability.csv", ["case", "verdict_undecomposed", "verdict_grid", "same",
                                      "message_undecomposed", "message_grid"], rows)


# ---- load balance --------------------------------------------------------------------------


def item_balance(a):
    runs, out = Path(a.runs) / "balance", Path(a.out)
    rows = []
    # The balanced runs first: their summary also gives what the start's planes would give.
    # --collapse-s cuts the collapse stage (it starts at the gate's removal) to that length.
    cut = ["--set", f"stage[1].max_duration={a.collapse_s!r}"] if a.collapse_s else []
    for balance in a.balances:
        for grid in a.balance_grids:
            name = f"{grid}-balance-{balance}" + (f"-collapse{a.collapse_s:g}s" if a.collapse_s else "")
            cmd = [a.bin, "run", "validation/cases/aor_collapse.toml", "--lambda", "8", "--seed", "1",
                   "--quiet", "--threads", str(a.threads), "--grid", grid, "--balance", balance,
                   "--set", "output.vtk_interval=0.0", *cut, "--out", str(runs / name)]
            s, err = run_cgdem(cmd, runs / name, f"balance {name}")
            row = {"grid": grid, "balance": balance, "collapse_cut_s": a.collapse_s, "run": str(runs / name)}
            if s is None:
                row["status"] = f"failed: {err}"
            else:
                d = s["decomposition"]
                row.update(status="ok", n_particles=s["n_particles"], simulated_s=s["simulated_s"],
                           steps=s["steps"], stopped_by=s.get("stopped_by"),
                           stages=" ".join(f"{st['name']} {st['end_s'] - st['start_s']:.3f} s" for st in s["stages"]),
                           shifts=d["shifts"], imbalance_end=d["imbalance"],
                           imbalance_max_after_first_shift=d.get("imbalance_max_after_first_shift"),
                           static_imbalance_end=d["static_imbalance"],
                           static_imbalance_max=d["static_imbalance_max"],
                           subdomain_particles_end=" ".join(map(str, d["subdomain_particles"])),
                           repose_angle_deg=s.get("repose_angle_deg"), wall_s=s["wall_s"])
                after = row["imbalance_max_after_first_shift"]
                if balance != "off" and after is not None:
                    row["balanced_within_1.1"] = after <= 1.1
            rows.append(row)
    write_csv(out / "balance.csv",
              ["grid", "balance", "collapse_cut_s", "status", "n_particles", "simulated_s", "steps", "stages", "stopped_by",
               "shifts", "imbalance_max_after_first_shift", "imbalance_end", "static_imbalance_max",
               "static_imbalance_end", "balanced_within_1.1", "subdomain_particles_end",
               "repose_angle_deg", "wall_s", "run"], rows)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("item", choices=["heap", "hertz", "screw", "stability", "balance"])
    p.add_argument("--bin", default=str(ROOT / "target/release/cgdem"), help="cgdem for threaded runs")
    p.add_argument("--mpi-bin", help="cgdem built with --features mpi (heap: the MPI rows)")
    p.add_argument("--runs", default=str(ROOT / "target/decomposition-runs"), help="run directories")
    p.add_argument("--out", default=str(ROOT / "reports/decomposition"), help="CSV directory")
    p.add_argument("--threads", type=int, default=2, help="threads of the decomposed runs")
    p.add_argument("--seeds", type=lambda s: [int(x) for x in s.split(",")], default=[1, 2, 3])
    p.add_argument("--rpm", type=int, default=140)
    p.add_argument("--only", help="heap: only these grids (none,2x1x1,...; empty: only the bench)")
    p.add_argument("--no-bench", action="store_true", help="heap: do not run the bench")
    p.add_argument("--grids", type=lambda s: [None if g == "none" else g for g in s.split(",")],
                   default=[None, "2x1x1"],
                   help="hertz, screw: the grids to run (none: the scene's own grid, no --grid)")
    p.add_argument("--stability-grid", default="2")
    p.add_argument("--balance-grids", type=lambda s: s.split(","), default=["2x1x1", "4x1x1"])
    p.add_argument("--balances", type=lambda s: s.split(","), default=["1.1", "off"])
    p.add_argument("--collapse-s", type=float, help="balance: end the collapse this long after the gate")
    a = p.parse_args()
    a.bin = str(Path(a.bin).resolve())
    if a.mpi_bin:
        a.mpi_bin = str(Path(a.mpi_bin).resolve())
    {"heap": item_heap, "hertz": item_hertz, "screw": item_screw, "stability": item_stability,
     "balance": item_balance}[a.item](a)


if __name__ == "__main__":
    main()
