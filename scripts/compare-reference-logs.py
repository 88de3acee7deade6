#!/usr/bin/env python3
"""The reference codes' logs (`log.lammps`, `log.liggghts`, `stdout.txt`) of two output trees
of `cgdem validate`, compared without what differs from run to run of one binary: loop and
section timings, CPU use, LIGGGHTS's run date, and mpirun's "Forwarding signal N to job"
notices (printed when a run is stopped and continued, and written into the middle of the
codes' output lines). `scripts/check-same-outputs.py` compares everything else.

Usage: python3 scripts/compare-reference-logs.py A B [--same OLD=NEW ...]
  --same OLD=NEW  a path written in A's logs that B's logs write as NEW (the worktree)
Exit status 1 if any log differs beyond those lines.
"""
import argparse
import difflib
import re
import sys
from pathlib import Path

LOGS = ("stdout.txt", "log.lammps", "log.liggghts")
TIMING = re.compile(
    r"Loop time|Performance:|CPU use|Total wall time|read_data CPU|Setting up run at"
    r"|^\s*(Pair|Neigh|Comm|Output|Modify|Other|Bond|Kspace)\s*\|"
    r"|^\s*(Nlocal|Nghost|Neighs)\s*:|Ave special|Histogram|^Section \||^-{5}"
)
SIGNAL = re.compile(r"\(null\): Forwarding signal \d+ to job\n?")


def kept_lines(path, same):
    text = SIGNAL.sub("", path.read_text(errors="replace"))
    for old, new in same:
        text = text.replace(old, new)
    return [line for line in text.split("\n") if not TIMING.search(line)]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("a", type=Path)
    parser.add_argument("b", type=Path)
    parser.add_argument("--same", action="append", default=[])
    args = parser.parse_args()
    same = [tuple(s.split("=", 1)) for s in args.same]
    compared = differing = 0
    for log in sorted(p for p in args.a.rglob("*") if p.name in LOGS):
        other = args.b / log.relative_to(args.a)
        compared += 1
        if not other.exists():
            print(f"only in {args.a}: {log.relative_to(args.a)}")
            differing += 1
            continue
        a, b = kept_lines(log, same), kept_lines(other, [])
        if a != b:
            differing += 1
            print(log.relative_to(args.a))
            diff = difflib.unified_diff(a, b, n=0, lineterm="")
            print("\n".join(d for d in list(diff)[2:12]))
    print(f"{compared} reference-code logs compared; {differing} differ beyond timings, dates and signal notices")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())
