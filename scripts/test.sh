#!/usr/bin/env bash
# The project's test command (README quick start; CI runs it through .ci/run).
# Installs what the tests need, then checks formatting, lints and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."

# Reference codes: the golden tests against LAMMPS/LIGGGHTS run whenever they are present.
# Installing them needs root and apt; without them those tests report themselves skipped.
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    bash scripts/install-references.sh || echo "note: reference codes not installed; their tests will be skipped"
fi

cargo fmt --all -- --check
cargo clippy --release --all-targets -- -D warnings
cargo test --release
