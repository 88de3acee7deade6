#!/usr/bin/env python3
"""Per-law means, their difference and its standard error, from a `cgdem validate` summary.json
of validation/suites/contact_law.toml (each run's law is its `tangential` field).

Usage: summarize.py OUT/summary.json > bulk_effect.csv (the runs to stdout as well: runs.csv
with --runs)."""
import csv
import json
import math
import sys

QUANTITIES = {
    "aor_hertz_smoke": ["repose_angle_deg", "runout_m"],
    "aor_hertz": ["repose_angle_deg", "runout_m"],
    "screw_feeder_hertz": ["mass_flow_kg_s", "fill_ratio"],
}


def base(case):
    return case[: -len("-coulomb")] if case.endswith("-coulomb") else case


def main():
    summary = json.load(open(sys.argv[1]))
    runs = [r for r in summary["runs"] if r["status"] == "ok"]
    if "--runs" in sys.argv:
        out = csv.writer(sys.stdout)
        out.writerow(["case", "tangential", "seed", "rpm", "repose_angle_deg", "runout_m",
                      "mass_flow_kg_s", "mass_flow_std_error_kg_s", "fill_ratio", "steps", "wall_s"])
        for r in runs:
            out.writerow([base(r["case"]), r.get("tangential"), r["seed"], r.get("rpm", ""),
                          r.get("repose_angle_deg", ""), r.get("runout_m", ""),
                          r.get("mass_flow_kg_s", ""), r.get("mass_flow_std_error_kg_s", ""),
                          r.get("fill_ratio", ""), r.get("steps", ""), r.get("wall_s", "")])
        return
    out = csv.writer(sys.stdout)
    out.writerow(["case", "quantity", "n_history", "mean_history", "sd_history", "n_coulomb",
                  "mean_coulomb", "sd_coulomb", "coulomb_minus_history", "std_error",
                  "n_paired", "paired_difference", "paired_std_error"])
    for case, quantities in QUANTITIES.items():
        for q in quantities:
            by_law = {}
            for r in runs:
                if base(r["case"]) == case and r.get(q) is not None:
                    by_law.setdefault(r.get("tangential"), []).append(r[q])
            by_seed = {}
            for r in runs:
                if base(r["case"]) == case and r.get(q) is not None:
                    by_seed.setdefault(r["seed"], {})[r.get("tangential")] = r[q]
            # The same insertion seed under both laws: the same grains dropped the same way.
            paired = [v["coulomb"] - v["history"] for v in by_seed.values() if len(v) == 2]
            h, c = by_law.get("history", []), by_law.get("coulomb", [])
            if not h or not c:
                continue
            stats = []
            for v in (h, c):
                m = sum(v) / len(v)
                sd = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1)) if len(v) > 1 else float("nan")
                stats.append((len(v), m, sd))
            (nh, mh, sh), (nc, mc, sc) = stats
            se = math.sqrt(sh ** 2 / nh + sc ** 2 / nc)
            npd = len(paired)
            pm = sum(paired) / npd if npd else float("nan")
            pse = (math.sqrt(sum((x - pm) ** 2 for x in paired) / (npd - 1) / npd)
                   if npd > 1 else float("nan"))
            out.writerow([case, q, nh, f"{mh:.6g}", f"{sh:.3g}", nc, f"{mc:.6g}", f"{sc:.3g}",
                          f"{mc - mh:.4g}", f"{se:.3g}", npd, f"{pm:.4g}", f"{pse:.3g}"])


main()
