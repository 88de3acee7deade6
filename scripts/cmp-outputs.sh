#!/usr/bin/env bash
# Compares every CSV of two folders written by scripts/bitwise-outputs.sh, byte for byte.
# Usage: bash scripts/cmp-outputs.sh DIR_A DIR_B
A=$1; B=$2; bad=0; n=0
for f in $(cd "$A" && find . -name '*.csv' | sort); do
  n=$((n+1)); if ! cmp -s "$A/$f" "$B/$f"; then echo "DIFF $f"; bad=$((bad+1)); fi
done
echo "$n csv files, $bad differ"
[ "$bad" = 0 ]
