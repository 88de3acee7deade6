#!/usr/bin/env bash
# The MPI transport of the decomposed step (issue 23): installs OpenMPI (as root with apt),
# builds cgdem with `--features mpi` in the workspace's target directory, and checks that
# the tiny Hertz collapse on 2 MPI ranks (and on 4 oversubscribed ranks) writes bitwise the
# CSVs the same --grid writes on threads in one process, that `validate --np 2` runs the
# harness's cgdem runs as ranks with the same CSVs, and that its ranks resume a killed run
# from the restart files threads or ranks wrote (`--checkpoint-every`, `--reuse`), bitwise.
# A few seconds beyond the build (none when given a binary built with MPI).
# Usage: bash scripts/mpi-check.sh [--prepare | BINARY]
#   --prepare: only install what the MPI build needs; exit 0 when it is there, 1 when not
#   (scripts/test.sh then builds everything once with --features mpi, or without).
#   BINARY: a cgdem built with --features mpi (scripts/test.sh passes the one its tests
#   built); without it the script builds one. `cargo build` resolves the dependencies'
#   features apart from `cargo test`, so building here after the tests recompiles everything.
set -euo pipefail
cd "$(dirname "$0")/.."
prepare=${1:-}

export DEBIAN_FRONTEND=noninteractive
PACKAGES=(libopenmpi-dev openmpi-bin libclang-dev pkg-config)
missing=()
for pkg in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "${pkg}" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("${pkg}")
    fi
done
if ((${#missing[@]} > 0)); then
    if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
        echo "note: ${missing[*]} missing and cannot be installed without root and apt; MPI check skipped"
        [ "$prepare" = --prepare ] && exit 1
        exit 0
    fi
    echo "installing: ${missing[*]}"
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
[ "$prepare" = --prepare ] && exit 0

if [ -n "$prepare" ]; then
    bin=$prepare
    [ -x "$bin" ] || { echo "mpi-check: $bin is not an executable cgdem" >&2; exit 2; }
    "$bin" --version | grep -q "built with MPI" || {
        echo "mpi-check: $bin was built without MPI ('$("$bin" --version)'); build it with --features mpi" >&2
        exit 2
    }
else
    cargo build --release --features mpi
    bin=target/release/cgdem
fi
out=target/mpi-check
rm -rf "$out"
case_file=tests/data/tiny_hertz_collapse.toml
# The decomposition tests' shortening of the collapse: 2384 steps.
# `--balance 1.0`: the cut planes move at most rebuilds (bisection on counts summed over the
# ranks), so the ranks must find the same planes bit for bit.
set_args=(--set 'stage[0].min_duration=0.15' --set 'stage[0].max_duration=0.15'
    --set 'stage[1].duration=0.1' --set 'repose.at_times=[0.05]' --balance 1.0 --quiet)
mpirun=(mpirun --allow-run-as-root --oversubscribe)

check() { # GRID RANKS
    local grid=$1 ranks=$2
    "$bin" run "$case_file" "${set_args[@]}" --grid "$grid" --threads 2 --out "$out/threads-$grid" >/dev/null
    "${mpirun[@]}" -np "$ranks" "$bin" run "$case_file" "${set_args[@]}" --grid "$grid" --threads 1 \
        --out "$out/ranks$ranks-$grid" >/dev/null
    for f in timeseries.csv repose.csv profile.csv; do
        cmp "$out/threads-$grid/$f" "$out/ranks$ranks-$grid/$f"
    done
    grep -q '"shifts": [1-9]' "$out/threads-$grid/summary.json" || {
        echo "--grid $grid: the planes never moved; the check would not cover the balance"
        exit 1
    }
    echo "--grid $grid: $ranks MPI ranks write bitwise the CSVs of 2 threads"
}
check 2x1x1 2
check 2x1x2 4

# The harness's ranks (`validate --np`): the scene it builds, handed to the ranks as
# scene.json, gives bitwise the CSVs of the same grid on threads.
suite=tests/data/tiny_suite.toml
"$bin" validate --suite "$suite" --grid 2x1x1 --balance 1.0 --threads 2 --quiet \
    --out "$out/validate-threads" >/dev/null
"$bin" validate --suite "$suite" --grid 2x1x1 --balance 1.0 --np 2 --threads 2 --quiet \
    --out "$out/validate-ranks" >/dev/null
run=runs/tiny_hertz_collapse-short/cgdem-lambda1-seed1
grep -q '"ranks": 2' "$out/validate-ranks/$run/summary.json" || {
    echo "validate --np 2: the run in $out/validate-ranks/$run did not run as 2 ranks"
    exit 1
}
for f in timeseries.csv repose.csv profile.csv; do
    cmp "$out/validate-threads/$run/$f" "$out/validate-ranks/$run/$f"
done
echo "validate --np 2: the harness's runs as MPI ranks write bitwise the CSVs of 2 threads"

# Restart files under `validate --np` (`--checkpoint-every`, then `--reuse`): a run whose
# restart files the harness's threads wrote, and one whose files the ranks wrote, each as a
# kill after a checkpoint leaves it (no summary, the newest file gone, so the resume starts
# before the end), go on as 2 ranks to bitwise the CSVs of the uninterrupted run.
resume_check() { # WRITER_ARGS...
    local dir=$out/validate-resume
    rm -rf "$dir"
    "$bin" validate --suite "$suite" --grid 2x1x1 --balance 1.0 --threads 2 --quiet \
        --checkpoint-every 0.04 --out "$dir" "$@" >/dev/null
    [ -f "$dir/$run/restart.prev.cgr" ] || {
        echo "validate --checkpoint-every $*: no restart files in $dir/$run"
        exit 1
    }
    rm "$dir/$run/summary.json"
    mv "$dir/$run/restart.prev.cgr" "$dir/$run/restart.cgr"
    "$bin" validate --suite "$suite" --grid 2x1x1 --balance 1.0 --np 2 --threads 2 --quiet \
        --checkpoint-every 0.04 --reuse --out "$dir" >"$dir/resume.log" 2>&1
    grep -q "resuming" "$dir/$run/stdout.txt" || {
        echo "validate --np 2 --reuse: the ranks did not resume $dir/$run (see its stdout.txt)"
        exit 1
    }
    grep -q '"ranks": 2' "$dir/$run/summary.json"
    for f in timeseries.csv repose.csv profile.csv; do
        cmp "$out/validate-threads/$run/$f" "$dir/$run/$f"
    done
}
resume_check
resume_check --np 2
echo "validate --np 2 --checkpoint-every: ranks resume from restart files threads or ranks wrote, bitwise"
