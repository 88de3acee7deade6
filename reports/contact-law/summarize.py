#!/usr/bin/env python3
"""Per-law means, their difference and its standard error, from a `cgdem validate` summary.json
of validation/suites/contact_law.toml or contact_preset.toml. A run's law is its case's
variant (`aor_hertz-coulomb`, `aor_hertz-chung-ooi`), `history` without one.

Usage: summarize.py OUT/summary.json [--law coulomb|chung-ooi] > bulk_effect.csv (the law
compared with history; default coulomb), or with --runs: the runs (runs.csv)."""
import csv
import json
import math
import sys

QUANTITIES = {
    "aor_hertz_smoke": ["repose_angle_deg", "runout_m"],
    "aor_hertz": ["repose_angle_deg", "runout_m"],
    "screw_feeder_hertz": ["mass_flow_kg_s", "fill_ratio"],
}


LAWS = ["coulomb", "chung-ooi"]


def base(case):
    for law in LAWS:
        if case.endswith("-" + law):
            return case[: -len(law) - 1]
    return case


def law_of(case):
    return next((law for law in LAWS if case.endswith("-" + law)), "history")


def main():
    summary = json.load(open(sys.argv[1]))
    runs = [r for r in summary["runs"] if r["status"] == "ok"]
    law = sys.argv[sys.argv.index("--law") + 1] if "--law" in sys.argv else "coulomb"
    if law not in LAWS:
        sys.exit(f"summarize.py: --law must be one of {', '.join(LAWS)}, not {law!r}")
    if "--runs" in sys.argv:
        out = csv.writer(sys.stdout)
        out.writerow(["case", "law", "seed", "rpm", "repose_angle_deg", "runout_m",
                      "mass_flow_kg_s", "mass_flow_std_error_kg_s", "fill_ratio", "steps", "wall_s"])
        for r in runs:
            out.writerow([base(r["case"]), law_of(r["case"]), r["seed"], r.get("rpm", ""),
                          r.get("repose_angle_deg", ""), r.get("runout_m", ""),
                          r.get("mass_flow_kg_s", ""), r.get("mass_flow_std_error_kg_s", ""),
                          r.get("fill_ratio", ""), r.get("steps", ""), r.get("wall_s", "")])
        return
    out = csv.writer(sys.stdout)
    out.writerow(["case", "quantity", "n_history", "mean_history", "sd_history", f"n_{law}",
                  f"mean_{law}", f"sd_{law}", f"{law}_minus_history", "std_error",
                  "n_paired", "paired_difference", "paired_std_error"])
    for case, quantities in QUANTITIES.items():
        for q in quantities:
            by_law = {}
            for r in runs:
                if base(r["case"]) == case and r.get(q) is not None:
                    by_law.setdefault(law_of(r["case"]), []).append(r[q])
            by_seed = {}
            for r in runs:
                if base(r["case"]) == case and r.get(q) is not None:
                    by_seed.setdefault(r["seed"], {})[law_of(r["case"])] = r[q]
            # The same insertion seed under both laws: the same grains dropped the same way.
            paired = [v[law] - v["history"] for v in by_seed.values() if law in v and "history" in v]
            h, c = by_law.get("history", []), by_law.get(law, [])
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
