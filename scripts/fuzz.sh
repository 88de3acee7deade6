#!/usr/bin/env bash
# Generated bad input for every parser (scene TOML, STL ASCII/binary, LAMMPS/LIGGGHTS dumps
# and logs, the nightly history): PROPTEST_CASES cases per parser (default 100000; `cargo
# test` runs 64). Prints one `FUZZ | parser | N cases | 0 panics` line per parser; exits
# non-zero on the first failure, with proptest's minimal failing input (make it a named
# regression test beside the parser). Nightly: scripts/nightly.sh may call this.
set -euo pipefail
cd "$(dirname "$0")/.."
export PROPTEST_CASES="${PROPTEST_CASES:-100000}"
log="${FUZZ_LOG:-reports/fuzz.log}"
mkdir -p "$(dirname "$log")"
cargo test --release -p cgdem-core --test fuzz -- --nocapture 2>&1 | tee "$log"
cargo test --release -p cgdem-harness --test fuzz -- --nocapture 2>&1 | tee -a "$log"
echo "fuzz: $(grep -c '^FUZZ |' "$log") parsers at $PROPTEST_CASES cases each; log in $log"
grep '^FUZZ |' "$log"
