#!/usr/bin/env python3
"""Every shipped case, shortened, on its default grid: one thread, two threads, and (with a
cgdem built with `--features mpi` and `mpirun` present) 2 and 4 MPI ranks write bitwise the
same CSVs. Where the default grid has fewer subdomains than the ranks, the run must stop at
once with a message saying so (and not hang).

Each stage is cut to STEPS steps: a first run of no steps reads the case's time step from
its summary.json, then every stage gets `duration` (or `min_duration` = `max_duration`)
STEPS * dt. Usage:

    python3 scripts/bitwise-threads-ranks.py BIN OUT [--steps N] [--no-ranks] [CASE ...]

CASE: `file.toml` or `file.toml@LAMBDA`; default: the list below. Exit status 1 if any
comparison differs or a run fails.
"""
import argparse
import filecmp
import json
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

# The shipped cases at levels of a few hundred to a few thousand particles.
CASES = [
    "validation/cases/aor_collapse.toml@8",
    "validation/cases/aor_smoke.toml@8",
    "validation/cases/aor_hertz.toml@1",
    "validation/cases/aor_hertz_smoke.toml@2",
    "validation/cases/hertz_settle.toml@1",
    "validation/cases/packing_vdw.toml@1",
    "validation/cases/screw_feeder.toml@16",
    "validation/cases/screw_feeder_nightly.toml@16",
    "validation/cases/screw_feeder_particles.toml@16",
    "validation/cases/screw_feeder_hertz.toml@1",
    "validation/cases/screw_feeder_hertz_particles.toml@1",
    "validation/bench/heap.toml@1",
    "validation/bench/heap_wca.toml@1",
]
MPIRUN = ["mpirun", "--allow-run-as-root", "--oversubscribe", "--mca", "mpi_yield_when_idle", "1"]


def stage_overrides(case: Path, seconds: float) -> list[str]:
    """`--set` arguments that give every stage of `case` the length `seconds`."""
    scene = tomllib.loads(case.read_text())
    args = []
    for k, stage in enumerate(scene.get("stage", [])):
        if "duration" in stage:
            args += ["--set", f"stage[{k}].duration={seconds!r}"]
        else:
            args += ["--set", f"stage[{k}].min_duration={seconds!r}"]
            args += ["--set", f"stage[{k}].max_duration={seconds!r}"]
    # Outputs due within the short run (the observers that read the particles run too).
    output = scene.get("output", {})
    if "timeseries_interval" in output:
        args += ["--set", f"output.timeseries_interval={seconds / 4!r}"]
    if "vtk_interval" in output:
        args += ["--set", "output.vtk_interval=0.0"]
    if "repose" in scene and "at_times" in scene["repose"]:
        args += ["--set", f"repose.at_times=[{seconds / 2!r}]"]
    if "packing" in scene:
        # Measured at the stage's end, over a bed still in the air: coarse voxels.
        args += ["--set", "packing.voxels_per_diameter=10"]
    if "conveying" in scene:
        args += ["--set", f"conveying.discard={seconds / 2!r}"]
    return args


def run(cmd: list[str], out: Path, timeout: int = 1800) -> subprocess.CompletedProcess:
    shutil.rmtree(out, ignore_errors=True)
    return subprocess.run(cmd + ["--out", str(out), "--quiet"], capture_output=True, text=True,
                          timeout=timeout)


def csvs(d: Path) -> list[str]:
    return sorted(p.name for p in d.glob("*.csv"))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("bin")
    ap.add_argument("out")
    ap.add_argument("cases", nargs="*")
    ap.add_argument("--steps", type=int, default=1500)
    ap.add_argument("--no-ranks", action="store_true")
    a = ap.parse_args()
    os.chdir(Path(__file__).resolve().parent.parent)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    ranks = not a.no_ranks and shutil.which("mpirun") is not None
    failed = []
    for spec in a.cases or CASES:
        path, _, lam = spec.partition("@")
        case = Path(path)
        name = f"{case.stem}-lambda{lam or 1}"
        # --keep-going: a stage cut to a few thousand steps can leave a guard to fire (the
        # Hertz screws' filling, cut short, drops grains onto the screw too fast); the
        # comparison is of the outputs, which must be the same bits either way.
        base = [a.bin, "run", str(case), "--lambda", lam or "1", "--keep-going"]
        probe = run(base + stage_overrides(case, 1e-12) + ["--threads", "1"], out / name / "probe")
        if probe.returncode != 0:
            failed.append(f"{name}: the probe run failed: {probe.stderr.strip()[-400:]}")
            continue
        summary = json.loads((out / name / "probe" / "summary.json").read_text())
        dt, grid = summary["dt_s"], summary["decomposition"]["grid"]
        subdomains = grid[0] * grid[1] * grid[2]
        short = base + stage_overrides(case, a.steps * dt)
        variants = [("threads1", short + ["--threads", "1"]), ("threads2", short + ["--threads", "2"])]
        if ranks:
            for n in (2, 4):
                variants.append((f"ranks{n}", MPIRUN + ["-np", str(n)] + short + ["--threads", "1"]))
        reference = None
        for label, cmd in variants:
            d = out / name / label
            try:
                r = run(cmd, d)
            except subprocess.TimeoutExpired:
                failed.append(f"{name} {label}: did not finish (hung?)")
                continue
            n_ranks = int(label[5:]) if label.startswith("ranks") else 1
            if n_ranks > subdomains:
                clear = "MPI ranks need at least as many subdomains" in r.stderr
                if r.returncode == 0 or not clear:
                    failed.append(f"{name} {label}: {subdomains} subdomain(s) but no clear refusal: {r.stderr.strip()[-300:]}")
                else:
                    print(f"{name} {label}: refused as it should ({subdomains} subdomains)")
                continue
            if r.returncode != 0:
                failed.append(f"{name} {label}: exit {r.returncode}: {r.stderr.strip()[-400:]}")
                continue
            s = json.loads((d / "summary.json").read_text())
            if reference is None:
                reference = d
                print(f"{name}: grid {'x'.join(map(str, grid))}, {s['n_particles']} particles, {s['steps']} steps, CSVs {csvs(d)}")
                continue
            differ = [f for f in csvs(reference) if not filecmp.cmp(reference / f, d / f, shallow=False)]
            if csvs(d) != csvs(reference) or differ:
                failed.append(f"{name} {label}: differs from threads1 in {differ or 'the set of CSVs'}")
            else:
                print(f"{name} {label}: bitwise the CSVs of threads1")
    for f in failed:
        print("FAILED", f)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
