#!/usr/bin/env bash
# A full disk while writing outputs (issue 25): on a 300 KiB tmpfs a run with a VTK series
# must stop with an error naming the file it could not write and "No space left on device",
# leave no temporary file, and keep every frame and CSV written before intact. Needs root
# (mount); without it the check says so and passes.
# Usage: bash scripts/check-full-disk.sh [CGDEM_BINARY]
set -euo pipefail
cd "$(dirname "$0")/.."
cgdem=${1:-target/release/cgdem}
if [ "$(id -u)" != 0 ]; then
    echo "note: not root, cannot mount a small tmpfs: full-disk check skipped"
    exit 0
fi
mnt=$(mktemp -d)
if ! mount -t tmpfs -o size=300k tmpfs "$mnt" 2>/dev/null; then
    rmdir "$mnt"
    echo "note: cannot mount a tmpfs here (no CAP_SYS_ADMIN?): full-disk check skipped"
    exit 0
fi
trap 'umount "$mnt"; rmdir "$mnt"' EXIT
set +e
"$cgdem" run validation/cases/aor_hertz_smoke.toml --lambda 2 --out "$mnt/run" --quiet \
    --threads 1 --set output.vtk_interval=0.005 2> "$mnt/../full-disk-stderr.$$"
code=$?
set -e
err=$(cat "$mnt/../full-disk-stderr.$$"); rm -f "$mnt/../full-disk-stderr.$$"
fail() { echo "full-disk check: $1" >&2; echo "$err" >&2; exit 1; }
[ "$code" != 0 ] || fail "the run succeeded on a full disk"
echo "$err" | grep -q "No space left on device" || fail "the error does not say the disk is full"
echo "$err" | grep -q "$mnt/run/" || fail "the error does not name the file"
leftover=$(find "$mnt/run" -name '*.tmp' | head -1)
[ -z "$leftover" ] || fail "temporary file left behind: $leftover"
frames=$(find "$mnt/run/vtk" -name 'particles_*.vtu' | wc -l)
[ "$frames" -ge 2 ] || fail "expected the frames written before the disk filled, found $frames"
# Every frame written before is whole: the closing tag of a VTK XML file ends it.
for f in "$mnt"/run/vtk/particles_*.vtu; do
    tail -c 20 "$f" | grep -q "</VTKFile>" || fail "frame $f is not whole"
done
rows=$(wc -l < "$mnt/run/timeseries.csv")
[ "$rows" -ge 2 ] || fail "timeseries.csv lost its rows"
echo "full-disk check: exit $code, error names the file, $frames whole frames and $rows time-series lines kept, no temporary file"
