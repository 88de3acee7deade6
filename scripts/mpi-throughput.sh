#!/usr/bin/env bash
# Threads against MPI ranks on one decomposed case (issue 23): alternating rounds of
# `--grid G` on 1 thread, on 2 threads and on 2 MPI ranks (1 thread each), printing each
# run's particle-steps/s from its summary.json. Needs a binary built with `--features mpi`.
# `cgdem bench` cannot launch ranks (it starts every code from one prepared state), so this
# times whole runs of the case from its start: compare the three columns with each other.
# Usage: bash scripts/mpi-throughput.sh BIN ROUNDS OUT CASE GRID [--set ...]
set -euo pipefail
bin=$1; rounds=$2; out=$3; case=$4; grid=$5; shift 5
mkdir -p "$out"
rate() { python3 -c "import json,sys; print('%.4g' % json.load(open(sys.argv[1]))['particle_steps_per_s'])" "$1/summary.json"; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
for r in $(seq 1 "$rounds"); do
  "$bin" run "$case" "$@" --grid "$grid" --threads 1 --out "$out/t1" > /dev/null
  a=$(rate "$out/t1")
  "$bin" run "$case" "$@" --grid "$grid" --threads 2 --out "$out/t2" > /dev/null
  b=$(rate "$out/t2")
  mpirun -np 2 --mca mpi_yield_when_idle 1 "$bin" run "$case" "$@" --grid "$grid" --threads 1 \
    --out "$out/r2" > /dev/null
  c=$(rate "$out/r2")
  echo "round $r: 1 thread $a, 2 threads $b, 2 ranks $c" | tee -a "$out/results.txt"
done
