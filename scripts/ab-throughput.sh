#!/usr/bin/env bash
# A/B of cgdem builds on the heap benchmark: each binary in turn, REPS times, cgdem only,
# 5000 steps from the state at 0.15 s; prints particle-steps/s per run (reports/PERFORMANCE.md).
# Usage: bash scripts/ab-throughput.sh REPS OUT THREADS BINARY...
set -euo pipefail
cd "$(dirname "$0")/.."
reps=$1; out=$2; threads=$3; shift 3
mkdir -p "$out"
for r in $(seq 1 "$reps"); do
  for bin in "$@"; do
    v=$("$bin" bench validation/bench/heap.toml --out "$out/tmp" --pairs 1 --threads "$threads" \
        --steps 5000 --prepare 0.15 --no-outcome --codes cgdem 2>&1 | grep "rep=0" \
        | grep -o "[0-9.e]* particle-steps" | cut -d' ' -f1)
    echo "$r $(basename "$bin") $v" | tee -a "$out/results.txt"
  done
done
