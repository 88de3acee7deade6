#!/usr/bin/env bash
# The Chung & Ooi (2011) benchmark (validation/suites/chung_ooi.toml, seconds): runs it, fails
# on any red criterion (amber, a law's declared known difference, is allowed), then plants a
# change to the tangential law in cgdem (its dashpot switched off under every law) and
# asserts that the suite turns red, so the verdicts can fail.
#
# usage: scripts/chung-ooi.sh OUT_DIR [CGDEM_BINARY]
# exit: 0 the unchanged run has no red criterion and the planted change has one; 1 otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/chung-ooi.sh OUT_DIR [CGDEM_BINARY]}
cgdem=${2:-target/release/cgdem}
rm -rf "$out"

red() {
    python3 - "$1/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
v = s.get("chung_ooi", [])
bad = [x for x in v if x["verdict"] == "fail"]
for x in bad:
    c = x["criterion"]
    print(f"  red: law {x['law']} test {x['test']}: {c['name']} = {c['value']:.3g} (tolerance {c['tolerance']})")
print(f"  {len(v)} criteria, {len(bad)} red")
sys.exit(0 if v and bad else 1)
PY
}

# Its exit status says the verdict too: 0 green or amber, 1 red.
"$cgdem" validate --suite chung_ooi --out "$out" --quiet
if red "$out"; then
    echo "chung_ooi: the unchanged run has red criteria"
    exit 1
fi
planted=0
"$cgdem" validate --suite chung_ooi --out "$out/planted-no-tangential-dashpot" --quiet \
    --fault contact.tangential_damping=false || planted=$?
if [ "$planted" != 1 ] || ! red "$out/planted-no-tangential-dashpot"; then
    echo "chung_ooi: the planted removal of the tangential dashpot did not turn the suite red"
    exit 1
fi
echo "chung_ooi: unchanged run green, planted removal of the tangential dashpot caught"
