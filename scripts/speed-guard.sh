#!/usr/bin/env bash
# Is a build slower than the one before it? Alternating pairs of two cgdem builds (A B, B A,
# ...) on the heap bench (cgdem alone, 5000 steps from the state at 0.15 s, one thread) and on
# the main job shortened to a 0.3 s collapse (validation/cases/aor_collapse.toml, lambda 8,
# one thread: with two workers on a shared 2-core machine a pair's ratio scattered from 0.76
# to 1.54, with one from 0.99 to 1.01). Each pair gives the ratio new / base (throughput on the heap, inverse
# wall time of the step loop on the main job); the medians over the pairs are the verdict.
# A median below the threshold is measured again before it is called: as many pairs more
# (--confirm), and the verdict takes the medians over all of them. On this shared host one
# build against itself gave main-job ratios from 0.91 to 1.17 and a 5-pair median of 0.952
# (reports/PERFORMANCE.md, "The speed guard's second look"): a single look would call one
# quiet night in several red for nothing, while a real slowdown stays below on the second.
#
# Usage: bash scripts/speed-guard.sh [options] BASE NEW
#   BASE, NEW: a cgdem binary, or a git commit (built into target/speed-guard/<commit>).
#   --base-label, --new-label NAME  how the result names them (default: as given)
#   --pairs N      alternating pairs (default 5; quote medians, the machine is shared)
#   --threshold R  a median ratio below R is a flag (default 0.95)
#   --confirm N    pairs more when a median falls below R, before the verdict (default: as
#                  --pairs; 0 calls it on the first look)
#   --json FILE    also write the figures there (scripts/nightly.sh: speed_guard.json)
# Exit status: 0, 1 if a median ratio is below the threshold, 2 on bad input or a failed run.
set -euo pipefail
cd "$(dirname "$0")/.."

pairs=5 threshold=0.95 json="" base_label="" new_label="" confirm=""
while [ $# -gt 2 ]; do
    case $1 in
        --pairs) pairs=$2; shift 2 ;;
        --confirm) confirm=$2; shift 2 ;;
        --threshold) threshold=$2; shift 2 ;;
        --json) json=$2; shift 2 ;;
        --base-label) base_label=$2; shift 2 ;;
        --new-label) new_label=$2; shift 2 ;;
        *) echo "speed-guard: unknown option $1 (allowed: --pairs N, --confirm N, --threshold R, --json FILE, --base-label NAME, --new-label NAME)" >&2; exit 2 ;;
    esac
done
[ $# -eq 2 ] || { echo "usage: bash scripts/speed-guard.sh [--pairs N] [--confirm N] [--threshold R] [--json FILE] [--base-label NAME] [--new-label NAME] BASE NEW" >&2; exit 2; }
base_label=${base_label:-$1}
new_label=${new_label:-$2}
[[ $pairs =~ ^[1-9][0-9]*$ ]] || { echo "speed-guard: --pairs must be a whole number >= 1, not '$pairs'" >&2; exit 2; }
confirm=${confirm:-$pairs}
[[ $confirm =~ ^[0-9]+$ ]] || { echo "speed-guard: --confirm must be a whole number >= 0, not '$confirm'" >&2; exit 2; }
[[ $threshold =~ ^[0-9]*\.?[0-9]+$ ]] || { echo "speed-guard: --threshold must be a positive number such as 0.95, not '$threshold'" >&2; exit 2; }

# Where builds and runs go ($SPEED_GUARD_WORK: the tests' scratch directory).
work=${SPEED_GUARD_WORK:-target/speed-guard}
mkdir -p "$work"

# binary_of SPEC: SPEC itself if it is an executable file, else the build of that commit.
binary_of() {
    local spec=$1
    if [ -f "$spec" ] && [ -x "$spec" ]; then
        echo "$spec"
        return
    fi
    local commit
    commit=$(git rev-parse --verify --quiet "$spec^{commit}") || {
        echo "speed-guard: '$spec' is neither an executable file nor a git commit" >&2
        return 2
    }
    local dir="$work/$commit"
    if [ ! -x "$dir/cgdem" ]; then
        echo "speed-guard: building $spec ($commit)" >&2
        rm -rf "$dir/src"
        git worktree add --detach --force "$dir/src" "$commit" >/dev/null 2>&1 || {
            echo "speed-guard: cannot check out $commit" >&2
            return 2
        }
        (cd "$dir/src" && cargo build --release --quiet --target-dir "../target") >&2 || {
            echo "speed-guard: the build of $commit failed" >&2
            return 2
        }
        cp "$dir/target/release/cgdem" "$dir/cgdem"
        git worktree remove --force "$dir/src" >/dev/null 2>&1 || true
    fi
    echo "$dir/cgdem"
}

base=$(binary_of "$1") || exit 2
new=$(binary_of "$2") || exit 2
base=$(realpath "$base")
new=$(realpath "$new")

# heap BIN: particle-steps/s of one timed cgdem run on the heap bench.
heap() {
    local out="$work/heap-run"
    rm -rf "$out"
    "$1" bench validation/bench/heap.toml --codes cgdem --pairs 1 --threads 1 --steps 5000 \
        --prepare 0.15 --no-outcome --out "$out" >/dev/null 2>&1 || return 2
    python3 -c 'import json,sys; b=json.load(open(sys.argv[1])); print(b["medians"][0]["median_particle_steps_per_s"])' "$out/bench.json"
}

# mainjob BIN: wall time of the step loop of the shortened main job, seconds.
mainjob() {
    local out="$work/mainjob-run"
    rm -rf "$out"
    "$1" run validation/cases/aor_collapse.toml --lambda 8 --threads 1 --quiet --out "$out" \
        --set 'stage[1].max_duration=0.3' --set 'stage[1].min_duration=0.3' \
        --set 'repose.at_times=[0.25]' >/dev/null 2>&1 || return 2
    python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["wall_s"])' "$out/summary.json"
}

rows="$work/pairs.csv"
echo "pair,order,heap_base,heap_new,mainjob_base_s,mainjob_new_s" >"$rows"
# run_pairs FIRST LAST: pairs FIRST..LAST appended to $rows.
run_pairs() {
    local p order which bin
    for p in $(seq "$1" "$2"); do
        # Alternate which build goes first, so a drift of the machine falls on both.
        if [ $((p % 2)) = 1 ]; then order="base new"; else order="new base"; fi
        declare -A h=() m=()
        for which in $order; do
            bin=$base
            [ "$which" = new ] && bin=$new
            h[$which]=$(heap "$bin") || { echo "speed-guard: the heap bench failed with $bin" >&2; exit 2; }
            m[$which]=$(mainjob "$bin") || { echo "speed-guard: the main job failed with $bin" >&2; exit 2; }
        done
        echo "$p,${order// /-},${h[base]},${h[new]},${m[base]},${m[new]}" >>"$rows"
        echo "pair $p ($order): heap ${h[base]} -> ${h[new]} particle-steps/s, main job ${m[base]} -> ${m[new]} s" >&2
    done
}

# The verdict over the pairs so far: exit 1 when a median ratio is below the threshold;
# `report` also prints the figures and writes the JSON, `quiet` only decides.
verdict=$(cat <<'PY'
import csv, json, statistics, sys
rows_path, threshold, json_path, base_spec, new_spec, base_bin, new_bin, confirmed, mode = sys.argv[1:]
threshold = float(threshold)
rows = list(csv.DictReader(open(rows_path)))
heap = [float(r["heap_new"]) / float(r["heap_base"]) for r in rows]
main = [float(r["mainjob_base_s"]) / float(r["mainjob_new_s"]) for r in rows]
result = {
    "base": base_spec, "new": new_spec, "base_binary": base_bin, "new_binary": new_bin,
    "pairs": len(rows), "second_look_pairs": int(confirmed), "threshold": threshold,
    "heap_ratio_median": statistics.median(heap), "heap_ratios": heap,
    "mainjob_ratio_median": statistics.median(main), "mainjob_ratios": main,
}
result["flagged"] = min(result["heap_ratio_median"], result["mainjob_ratio_median"]) < threshold
if mode == "quiet":
    sys.exit(1 if result["flagged"] else 0)
for name, r in (("heap bench", heap), ("main job", main)):
    print(f"{name}: new / base = {statistics.median(r):.3f} (median of {len(r)}; "
          + " ".join(f"{x:.3f}" for x in r) + ")")
if result["flagged"]:
    print(f"flag: speed: {new_spec} is slower than {base_spec} (a median below {threshold})")
else:
    print(f"speed: {new_spec} is not slower than {base_spec} (every median at least {threshold})")
if json_path:
    with open(json_path, "w") as f:
        json.dump(result, f, indent=2)
sys.exit(1 if result["flagged"] else 0)
PY
)

run_pairs 1 "$pairs"
confirmed=0
if [ "$confirm" -gt 0 ] && ! python3 -c "$verdict" "$rows" "$threshold" "" "$base_label" "$new_label" "$base" "$new" 0 quiet; then
    echo "speed-guard: a median is below $threshold after $pairs pairs; $confirm pairs more before the verdict" >&2
    run_pairs $((pairs + 1)) $((pairs + confirm))
    confirmed=$confirm
fi

python3 -c "$verdict" "$rows" "$threshold" "$json" "$base_label" "$new_label" "$base" "$new" "$confirmed" report
