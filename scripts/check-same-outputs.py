#!/usr/bin/env python3
"""Compare two output trees (e.g. the smoke suite's report written by two builds) file by
file, byte for byte, and show what differs in the files that are not identical, so that a
restructure can be shown to change no output.

Usage: python3 scripts/check-same-outputs.py DIR_A DIR_B [--same A=B ...] [--ignore KEY ...]

--same A=B   text A on side a is text B on side b (output paths, worktree paths, binary
             paths): replaced before two differing text files are compared again.
--ignore KEY a JSON key whose values are not compared (wall times, dates, commits), at any
             depth; a differing JSON file equal without these keys counts as "equal but for
             the ignored keys", listed with the keys that differed.

Every file is reported in one of: identical (bytes), equal after --same, equal but for the
ignored keys, different (with the JSON keys or the lines that differ), or on one side only.
Exit status 1 when a file differs or is on one side only.
"""
import argparse
import difflib
import json
import sys
from pathlib import Path


def flatten(value, prefix=""):
    """A JSON value as {key path: leaf}."""
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            out.update(flatten(v, f"{prefix}.{k}" if prefix else k))
        return out
    if isinstance(value, list):
        out = {}
        for i, v in enumerate(value):
            out.update(flatten(v, f"{prefix}[{i}]"))
        return out
    return {prefix: value}


def ignored(path, keys):
    last = path.rsplit(".", 1)[-1].split("[", 1)[0]
    return last in keys


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("a", type=Path)
    parser.add_argument("b", type=Path)
    parser.add_argument("--same", action="append", default=[])
    parser.add_argument("--ignore", action="append", default=[])
    parser.add_argument("--show", type=int, default=20, help="lines or keys shown per file")
    args = parser.parse_args()
    same = [tuple(s.split("=", 1)) for s in args.same]

    def files(root):
        return {str(p.relative_to(root)) for p in root.rglob("*") if p.is_file()}

    fa, fb = files(args.a), files(args.b)
    verdicts = {"identical": [], "equal after --same": [], "equal but for ignored keys": [],
                "different": []}
    details = {}
    for rel in sorted(fa & fb):
        ba, bb = (args.a / rel).read_bytes(), (args.b / rel).read_bytes()
        if ba == bb:
            verdicts["identical"].append(rel)
            continue
        try:
            ta, tb = ba.decode(), bb.decode()
        except UnicodeDecodeError:
            verdicts["different"].append(rel)
            details[rel] = [f"binary: {len(ba)} and {len(bb)} bytes"]
            continue
        for x, y in same:
            ta, tb = ta.replace(x, "<same>"), tb.replace(y, "<same>")
        if ta == tb:
            verdicts["equal after --same"].append(rel)
            continue
        if rel.endswith(".json"):
            try:
                ja, jb = flatten(json.loads(ta)), flatten(json.loads(tb))
            except json.JSONDecodeError:
                ja = jb = None
            if ja is not None:
                keys = sorted(k for k in set(ja) | set(jb) if ja.get(k, "<none>") != jb.get(k, "<none>"))
                kept = [k for k in keys if not ignored(k, args.ignore)]
                if not kept:
                    verdicts["equal but for ignored keys"].append(rel)
                    details[rel] = sorted({k.rsplit(".", 1)[-1] for k in keys})
                else:
                    verdicts["different"].append(rel)
                    details[rel] = [f"{k}: {ja.get(k, '<none>')!r} -> {jb.get(k, '<none>')!r}" for k in kept]
                continue
        verdicts["different"].append(rel)
        lines = [l for l in difflib.unified_diff(ta.splitlines(), tb.splitlines(), lineterm="", n=0)
                 if not l.startswith(("---", "+++", "@@"))]
        details[rel] = [l[:300] for l in lines]

    kinds = {}
    for verdict, rels in verdicts.items():
        for rel in rels:
            kinds.setdefault(Path(rel).suffix or Path(rel).name, {}).setdefault(verdict, 0)
            kinds[Path(rel).suffix or Path(rel).name][verdict] += 1
    print(f"{len(fa)} files in {args.a}, {len(fb)} in {args.b}")
    for verdict, rels in verdicts.items():
        print(f"{verdict}: {len(rels)}")
    print(f"only in {args.a}: {len(fa - fb)}; only in {args.b}: {len(fb - fa)}")
    print("by kind:", json.dumps(kinds, sort_keys=True))
    for rel in sorted(fa - fb):
        print(f"only in {args.a}: {rel}")
    for rel in sorted(fb - fa):
        print(f"only in {args.b}: {rel}")
    for verdict in ("equal but for ignored keys", "different"):
        for rel in verdicts[verdict]:
            print(f"\n{verdict}: {rel}")
            for line in details[rel][: args.show]:
                print(f"  {line}")
            if len(details[rel]) > args.show:
                print(f"  ... {len(details[rel]) - args.show} more")
    bad = verdicts["different"] or (fa ^ fb)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
