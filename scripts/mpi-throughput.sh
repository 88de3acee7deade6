#!/usr/bin/env bash
# Threads against MPI ranks on one decomposed case (issue 23): `cgdem bench` times cgdem on
# `--grid G` on 1 and 2 threads and as 2 MPI ranks (`--np 2`), alternating in each round,
# all from the bench's prepared state (the references are left out; add them with
# `--codes cgdem,liggghts,lammps`). BIN must be built with `--features mpi`. Extra arguments
# go to `cgdem bench` (e.g. `--steps 25000`). On a machine busy with other work,
# `OMPI_MCA_mpi_yield_when_idle=1` in the environment keeps waiting ranks from spinning
# (it applies to every mpirun the bench starts, the reference codes' too).
# Usage: bash scripts/mpi-throughput.sh BIN ROUNDS OUT CASE GRID [cgdem bench options...]
set -euo pipefail
bin=$1; rounds=$2; out=$3; case=$4; grid=$5; shift 5
"$bin" bench "$case" --codes cgdem --grid "$grid" --threads 1,2 --np 2 --pairs "$rounds" \
  --no-outcome --cgdem-bin "$bin" --out "$out" "$@"
