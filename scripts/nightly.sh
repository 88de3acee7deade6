#!/usr/bin/env bash
# The nightly validation: runs the nightly suite (cgdem and the reference codes) into
# reports/nightly/<date>-<commit>/, then adds it to the history in reports/nightly/
# (history.json, index.html with trends, and flags for metrics that moved beyond their
# tolerance since the previous night).
#
# Re-running on the same day and commit resumes an interrupted night (`--reuse`: finished
# runs are kept, the report is rebuilt). Exit status: 0; 1 if the suite is red, a cgdem
# stability run failed or a metric was flagged; 2 if the suite could not run; 3 if it is
# incomplete (a reference code missing) and nothing else is wrong. Usage: bash scripts/nightly.sh [extra `cgdem validate` options]
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    bash scripts/install-references.sh || echo "note: reference codes not installed; their runs will be marked skipped"
fi
cargo build --release --quiet
cgdem=target/release/cgdem

date=$(date +%F)
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
if [ -n "$(git status --porcelain --untracked-files=no 2>/dev/null)" ]; then
    commit="${commit}-dirty"
fi
night="reports/nightly/${date}-${commit}"
mkdir -p "$night"

# The speed guard, on the quiet machine before the suite: this build against the previous
# night's (kept in target/nightly-previous), alternating pairs on the heap bench and the
# shortened main job. A median ratio below 0.95, still below after as many pairs more (the
# guard's second look), is a flag on the history's first screen and in the night's report
# (history.rs reads speed_guard.json).
previous=target/nightly-previous
if [ -x "$previous/cgdem" ]; then
    started=$(date +%s)
    guard=0
    bash scripts/speed-guard.sh --json "$night/speed_guard.json" \
        --base-label "$(cat "$previous/commit" 2>/dev/null || echo previous)" --new-label "$commit" \
        "$previous/cgdem" "$cgdem" || guard=$?
    [ "$guard" = 2 ] && echo "note: the speed guard did not finish; the night has no build comparison"
    echo "speed guard: $(( $(date +%s) - started )) s wall time"
else
    echo "note: no previous night's build in $previous; the speed guard starts next night"
fi

started=$(date +%s)
# Its exit status is the night's verdict (0 green or amber, 1 red, 2 could not run, 3
# incomplete): kept, so that the history is still written on a red night.
suite_status=0
"$cgdem" validate --suite nightly --out "$night" --reuse --jobs 2 --history reports/nightly "$@" \
    || suite_status=$?
echo "nightly suite: $(( $(date +%s) - started )) s wall time, exit status $suite_status"
[ "$suite_status" = 2 ] && exit 2

# Throughput against LIGGGHTS and LAMMPS on the heap benchmark, side by side (three
# alternating repetitions at 1 and 2 threads/ranks): its medians and ratios join the history.
started=$(date +%s)
"$cgdem" bench validation/bench/heap.toml --pairs 3 --out "$night/bench" || echo "note: cgdem bench failed; the night has no throughput comparison"
echo "bench: $(( $(date +%s) - started )) s wall time"
find "$night/bench" -type f \( -name '*.dump' -o -name 'particles.data' -o -name 'timeseries.csv' \) -delete 2>/dev/null || true

# The stability suite (about a minute): a verdict per code and case; a cgdem "failed" fails
# the night (issue 6: cgdem must stop with a clear message or stay stable).
started=$(date +%s)
stability_status=0
"$cgdem" validate --suite stability --out "$night/stability" --reuse --quiet \
    || stability_status=$?
[ "$stability_status" = 2 ] && echo "note: the stability suite did not finish"
echo "stability suite: $(( $(date +%s) - started )) s wall time"
find "$night/stability/runs" -type f \( -name '*.dump' -o -name '*.vtu' -o -name '*.pvd' -o -name 'particles.data' \) -delete 2>/dev/null || true
stability_failed=$(python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print(sum(r['code']=='cgdem' and r['verdict']=='failed' for r in s.get('stability', [])))" "$night/stability/summary.json" 2>/dev/null || echo 1)

# The Chung & Ooi benchmark (seconds): no red criterion, and a planted change to the tangential law
# caught (scripts/chung-ooi.sh); either failing fails the night.
chung_ooi_failed=0
bash scripts/chung-ooi.sh "$night/chung_ooi" "$cgdem" || chung_ooi_failed=1

# Keep the night small: run directories hold dumps and VTK files; the report needs only
# its summaries, CSV and figures.
find "$night/runs" -type f \( -name '*.dump' -o -name '*.vtu' -o -name '*.pvd' -o -name 'particles.data' \) -delete

flags=$("$cgdem" history reports/nightly --add "$night" --date "$date" --commit "$commit")
# This build is the next night's base.
mkdir -p "$previous"
cp "$cgdem" "$previous/cgdem.tmp" && mv "$previous/cgdem.tmp" "$previous/cgdem"
echo "$commit" >"$previous/commit"
echo "$flags"
if [ "$stability_failed" != 0 ]; then
    echo "flag: stability: $stability_failed cgdem run(s) failed (see $night/stability/index.html)"
fi
if [ "$chung_ooi_failed" != 0 ]; then
    echo "flag: chung_ooi: a red criterion or the planted fault not caught (see $night/chung_ooi/index.html)"
fi
if [ "$suite_status" = 1 ] || [ "$stability_failed" != 0 ] || [ "$chung_ooi_failed" != 0 ] || grep -q '^flag:' <<<"$flags"; then
    exit 1
fi
if [ "$suite_status" = 3 ]; then
    echo "incomplete: some comparisons were not made (a reference code missing); see $night/index.html"
    exit 3
fi
