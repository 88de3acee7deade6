#!/usr/bin/env bash
# Runs the short comparison cases of a redesign (the heap, both collapses, the packing and the
# three screws) with one cgdem binary into OUT/<case>/; compare two such folders with
# scripts/cmp-outputs.sh. Usage: bash scripts/bitwise-outputs.sh BIN OUT [--no-wca-screw]
# RUN_ARGS replaces the runs' `--threads 1`, e.g. RUN_ARGS="--grid 2x1x1 --threads 2".
set -u
cd "$(dirname "$0")/.."
BIN=$1; OUT=$2; SKIP_WCA=${3:-}
S="--set stage[0].duration=0.2 --set stage[1].duration=0.1 --keep-going"
run() { name=$1; shift; "$BIN" run "$@" --out "$OUT/$name" --quiet ${RUN_ARGS:---threads 1} > "$OUT/$name.log" 2>&1; echo "$name exit $?"; }
mkdir -p "$OUT"
run heap validation/bench/heap.toml --set 'stage[0].duration=0.06'
run aor_smoke validation/cases/aor_smoke.toml --lambda 8
run aor_hertz_smoke validation/cases/aor_hertz_smoke.toml --lambda 2
run packing validation/cases/packing_vdw.toml --set 'stage[0].max_duration=0.05' --set 'stage[0].min_duration=0.01'
run screw_mesh validation/cases/screw_feeder_hertz.toml $S
run screw_particles validation/cases/screw_feeder_hertz_particles.toml $S
# The seed's WCA screw at lambda 1 takes over an hour on this machine.
[ "$SKIP_WCA" = --no-wca-screw ] || run screw_wca validation/cases/screw_feeder.toml $S
