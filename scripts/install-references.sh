#!/usr/bin/env bash
# Install the reference DEM codes (LIGGGHTS, LAMMPS, Open MPI) from Debian and print versions.
# Idempotent: apt-get runs only when a package is missing.
set -euo pipefail

export DEBIAN_FRONTEND=noninteractive
PACKAGES=(liggghts lammps openmpi-bin)

SUDO=""
if [[ ${EUID} -ne 0 ]]; then
    SUDO="sudo"
fi

missing=()
for pkg in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "${pkg}" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("${pkg}")
    fi
done

if ((${#missing[@]} > 0)); then
    echo "installing: ${missing[*]}"
    ${SUDO} apt-get update
    ${SUDO} apt-get install -y --no-install-recommends "${missing[@]}"
else
    echo "all reference packages already installed: ${PACKAGES[*]}"
fi

# Versions. Neither code has a --version flag that exits without an input; both print a
# banner line and stop when given an empty input on stdin ("LIGGGHTS (Version ...)",
# "LAMMPS (29 Sep 2021 ...)"). -log none keeps them from writing log files.
tmp=$(mktemp -d)
trap 'rm -rf "${tmp}"' EXIT
(cd "${tmp}" && liggghts -log none -echo none </dev/null 2>&1 | head -n 1) || true
(cd "${tmp}" && lmp -log none -echo none </dev/null 2>&1 | head -n 1) || true
for pkg in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Package} ${Version}\n' "${pkg}"
done
