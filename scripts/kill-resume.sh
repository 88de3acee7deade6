#!/usr/bin/env bash
# Kill test of restart files (issue 25): each case runs once uninterrupted with
# --checkpoint-every, then N times killed with SIGKILL at a random moment and resumed with
# `cgdem run --resume`; every output file must equal the uninterrupted run's byte for byte
# (cmp), summary.json after removing its wall-clock fields (wall_s, particle_steps_per_s),
# which differ between any two runs. The killed runs use 2 threads, the others 1: the
# restart file does not depend on the thread count. The *_grid cases (run them by name)
# do the same on subdomains (--grid).
# Usage: bash scripts/kill-resume.sh [BIN] [OUT] [N] [CASE...]
set -u
cd "$(dirname "$0")/.."
BIN=${1:-target/release/cgdem}; OUT=${2:-/tmp/cgdem-kill-resume}; N=${3:-10}
shift $(( $# < 3 ? $# : 3 ))
S="--set stage[0].duration=0.2 --set stage[1].duration=0.1 --keep-going"
declare -A ARGS=(
  [aor_smoke]="validation/cases/aor_smoke.toml --lambda 8 --checkpoint-every 0.05"
  [aor_hertz_smoke]="validation/cases/aor_hertz_smoke.toml --lambda 2 --checkpoint-every 0.05"
  [packing]="validation/cases/packing_vdw.toml --set stage[0].max_duration=0.05 --set stage[0].min_duration=0.01 --checkpoint-every 0.005"
  [screw_mesh]="validation/cases/screw_feeder_hertz.toml $S --checkpoint-every 0.02"
  # Decomposed (--grid): the restart file holds the subdomains; named on the command line.
  [tiny_grid]="tests/data/tiny_hertz_collapse.toml --checkpoint-every 0.03 --grid 2x1x1"
  [screw_grid]="validation/cases/screw_feeder_hertz.toml $S --checkpoint-every 0.02 --grid 2x1x1"
)
CASES=("$@"); [ ${#CASES[@]} -gt 0 ] || CASES=(aor_smoke aor_hertz_smoke packing screw_mesh)
mkdir -p "$OUT"
# summary.json without the wall-clock fields.
strip() { python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); [d.pop(k,None) for k in ("wall_s","particle_steps_per_s")]; print(json.dumps(d,indent=1,sort_keys=True))' "$1"; }
# Every output file of the uninterrupted run A equal in B (and B has no extra ones).
same() {
  local a=$1 b=$2 bad=0 f
  for f in $(cd "$a" && find . -type f ! -name 'restart*.cgr' ! -name summary.json | sort); do
    cmp -s "$a/$f" "$b/$f" || { echo "    DIFF $f" >&2; bad=1; }
  done
  for f in $(cd "$b" && find . -type f ! -name 'restart*.cgr' ! -name summary.json | sort); do
    [ -e "$a/$f" ] || { echo "    EXTRA $f" >&2; bad=1; }
  done
  cmp -s <(strip "$a/summary.json") <(strip "$b/summary.json") || { echo "    DIFF summary.json" >&2; bad=1; }
  return $bad
}
pass=0; total=0
printf '%-16s %-4s %-9s %-26s %s\n' case kill after_s resumed_from result
for name in "${CASES[@]}"; do
  ref=$OUT/$name/ref; rm -rf "$OUT/$name"; mkdir -p "$OUT/$name"
  t0=$(date +%s.%N)
  # shellcheck disable=SC2086
  "$BIN" run ${ARGS[$name]} --out "$ref" --quiet --threads 1 > "$OUT/$name/ref.log" 2>&1 || { echo "$name: uninterrupted run failed, see $OUT/$name/ref.log"; continue; }
  wall=$(echo "$(date +%s.%N) - $t0" | bc)
  for m in $(seq 1 "$N"); do
    dir=$OUT/$name/kill$m
    # shellcheck disable=SC2086
    "$BIN" run ${ARGS[$name]} --out "$dir" --quiet --threads 2 > "$dir.log" 2>&1 &
    pid=$!
    start=$(date +%s.%N)
    # The first restart file is written once the particles are inserted; then a moment
    # uniformly within the rest of the run (after its end: the resume only finishes).
    while [ ! -e "$dir/restart.cgr" ] && kill -0 "$pid" 2>/dev/null; do sleep 0.01; done
    first=$(echo "$(date +%s.%N) - $start" | bc)
    pause=$(python3 -c "import random; print(round(random.uniform(0, max($wall - $first, 0.05)), 3))")
    sleep "$pause"
    kill -9 "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
    after=$(printf '%.2f' "$(echo "$(date +%s.%N) - $start" | bc)")
    if [ ! -e "$dir/restart.cgr" ] && [ ! -e "$dir/restart.prev.cgr" ]; then
      total=$((total+1))
      printf '%-16s %-4s %-9s %-26s %s\n' "$name" "$m" "$after" "-" "NO RESTART FILE"; continue
    fi
    "$BIN" run --resume "$dir" --quiet --threads 1 > "$dir.resume.log" 2>&1
    rc=$?
    from=$(grep -o 'resuming from .*' "$dir.resume.log" | head -1 | sed 's/.*\///')
    total=$((total+1))
    if [ $rc = 0 ] && same "$ref" "$dir" 2>> "$OUT/$name/diffs.log"; then result=equal; pass=$((pass+1)); else result="DIFFERS (rc $rc)"; fi
    printf '%-16s %-4s %-9s %-26s %s\n' "$name" "$m" "$after" "$from" "$result"
  done
done
echo "$pass of $total resumed runs bitwise equal to the uninterrupted run"
[ "$pass" = "$total" ]
