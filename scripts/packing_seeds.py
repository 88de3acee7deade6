#!/usr/bin/env python3
"""Mean and spread of the packing diameter sweep over insertion seeds.

Usage: python3 scripts/packing_seeds.py SWEEP_DIR [SWEEP_DIR ...] > table.md

Each SWEEP_DIR is the --out of one `cgdem run validation/cases/packing_vdw.toml --sweep
diameter=... --seed S`. Per diameter: the porosity of each seed, their mean and sample standard
deviation, the published value where there is one, and whether every run settled by the
kinetic-energy threshold. Also writes SWEEP_DIR[0]/../porosity_vs_diameter_seeds.csv.
"""
import csv, os, statistics, sys


def main(dirs):
    table = {}
    for d in dirs:
        for r in csv.DictReader(open(os.path.join(d, "porosity_vs_diameter.csv"))):
            row = table.setdefault(float(r["diameter_um"]), {"porosity": [], "settled": [], "published": r["published_porosity"], "wall": []})
            if r["porosity"]:
                row["porosity"].append(float(r["porosity"]))
            row["settled"].append(r["settled"] == "true")
            row["wall"].append(float(r["wall_s"]))
    out = os.path.join(os.path.dirname(os.path.abspath(dirs[0])), "porosity_vs_diameter_seeds.csv")
    with open(out, "w") as f:
        f.write("diameter_um,seeds,porosity_mean,porosity_sd,porosity_each,published_porosity,all_settled\n")
        print("| d (um) | porosity per seed | mean +- sd | published | settled |")
        print("| --- | --- | --- | --- | --- |")
        for d in sorted(table):
            row = table[d]
            p = row["porosity"]
            mean = statistics.mean(p)
            sd = statistics.stdev(p) if len(p) > 1 else float("nan")
            each = " ".join(f"{x:.3f}" for x in p)
            f.write(f"{d:g},{len(p)},{mean:.4f},{sd:.4f},{each},{row['published']},{all(row['settled'])}\n")
            print(f"| {d:g} | {each} | {mean:.3f} +- {sd:.3f} | {row['published'] or '-'} | {sum(row['settled'])}/{len(row['settled'])} |")
    print(f"\n(written {out})", file=sys.stderr)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
