#!/usr/bin/env bash
# Shows that the speed guard (scripts/speed-guard.sh) fires: it builds HEAD twice, once as
# it is and once with a planted slowdown (a spin loop at the top of the pair force, SPINS
# iterations per listed pair), then runs the guard on the unchanged build against itself
# (it must pass) and on the planted build against the unchanged one (it must flag).
# Usage: bash scripts/speed-guard-planted.sh [PAIRS] [SPINS]   (defaults 5 and 64)
# Exit status 0 when both verdicts are as expected. Time it on a quiet machine.
set -euo pipefail
cd "$(dirname "$0")/.."
pairs=${1:-5}
spins=${2:-64}
work=target/speed-guard/planted
mkdir -p "$work"
rm -rf "$work/src"
git worktree prune
git worktree add --detach --force "$work/src" HEAD >/dev/null
trap 'git worktree remove --force "$work/src" >/dev/null 2>&1 || true' EXIT

(cd "$work/src" && cargo build --release --quiet --target-dir ../target)
cp "$work/target/release/cgdem" "$work/cgdem-unchanged"

force="$work/src/crates/cgdem-core/src/force.rs"
marker='    let d = owner.position - position_j;'
grep -qxF "$marker" "$force" || { echo "planted: cannot find the pair force's first line in $force" >&2; exit 2; }
sed -i "s|^$marker\$|    for k in 0..$spins { std::hint::black_box(k); } // planted slowdown\n$marker|" "$force"
(cd "$work/src" && cargo build --release --quiet --target-dir ../target)
cp "$work/target/release/cgdem" "$work/cgdem-planted"

status=0
echo "== the unchanged build against itself (must pass)"
if bash scripts/speed-guard.sh --pairs "$pairs" --json "$work/unchanged.json" \
    --base-label unchanged --new-label unchanged "$work/cgdem-unchanged" "$work/cgdem-unchanged"; then
    echo "as expected: no flag"
else
    echo "UNEXPECTED: the guard flagged (or failed on) the unchanged build"
    status=1
fi
echo "== the build with $spins spins per pair against the unchanged one (must flag)"
guard=0
bash scripts/speed-guard.sh --pairs "$pairs" --json "$work/planted.json" \
    --base-label unchanged --new-label "planted-$spins" "$work/cgdem-unchanged" "$work/cgdem-planted" || guard=$?
if [ "$guard" = 1 ]; then
    echo "as expected: flagged"
else
    echo "UNEXPECTED: the guard did not flag the planted slowdown (exit $guard)"
    status=1
fi
exit $status
