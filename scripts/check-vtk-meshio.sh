#!/usr/bin/env bash
# The VTK series read by an independent reader (meshio, from PyPI) and checked against
# cgdem's own state (scripts/check_vtk_meshio.py says what): the seed's WCA collapse
# (aor_smoke at lambda 8, 0.12 s), a Hertz collapse with rotation (tiny_hertz_collapse, every
# bead started spinning, 0.1 s) and the SDF screw feeder with its three bodies (lambda 16,
# 8 ms, the screw turning from 4 ms). About 15 s.
# usage: scripts/check-vtk-meshio.sh [CGDEM_BINARY] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/cgdem}
out=${2:-target/vtk-meshio}
[ -x "$bin" ] || cargo build --release --quiet
python3 -c 'import meshio, numpy' 2>/dev/null \
    || python3 -m pip install --quiet meshio numpy \
    || python3 -m pip install --quiet --break-system-packages meshio numpy
rm -rf "$out"
mkdir -p "$out"
run() { name=$1; shift; "$bin" run "$@" --out "$out/$name" --quiet --threads 1 \
    --set output.write_data=true > "$out/$name.log" 2>&1 || { cat "$out/$name.log"; exit 1; }; }
run collapse validation/cases/aor_smoke.toml --lambda 8 \
    --set 'stage[0].min_duration=0.1' --set 'stage[0].max_duration=0.1' \
    --set 'stage[1].duration=0.02' --set 'repose.at_times=[0.01]' --set output.vtk_interval=0.03
run hertz_spin tests/data/tiny_hertz_collapse.toml \
    --set 'stage[0].min_duration=0.05' --set 'stage[0].max_duration=0.05' \
    --set 'stage[1].duration=0.05' --set 'repose.at_times=[0.02]' --set output.vtk_interval=0.02 \
    --set 'insert[0].omega=[0.0, 30.0, 0.0]'
run screw validation/cases/screw_feeder.toml --lambda 16 \
    --set 'stage[0].duration=0.004' --set 'stage[1].duration=0.004' \
    --set output.vtk_interval=0.002 --set output.timeseries_interval=0.002
python3 scripts/check_vtk_meshio.py "$out/collapse" validation/cases/aor_smoke.toml
python3 scripts/check_vtk_meshio.py "$out/hertz_spin" tests/data/tiny_hertz_collapse.toml
python3 scripts/check_vtk_meshio.py "$out/screw" validation/cases/screw_feeder.toml
echo "vtk-meshio: 3 cases read by meshio $(python3 -c 'import meshio; print(meshio.__version__)') and checked"
