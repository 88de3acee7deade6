#!/usr/bin/env bash
# Re-run every reference check in reference/ (serial, a few seconds in total).
# Needs: lmp, liggghts (scripts/install-references.sh), python3 with numpy.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
mt=$(python3 -c "import math; print(1370*math.pi/6*1.35e-3**3/(2*1e-8))")  # m/(2 dt) at lambda=1

cd "${here}/lammps"
for t in headon oblique; do
    lmp -in "seed_${t}.in" -log "seed_${t}.log" >/dev/null
    echo "== seed_${t}"; python3 verify_seed.py "seed_${t}.dump"
done
echo "== WCA energy (lj/cut shift yes)"; python3 check_wca_energy.py seed_headon.dump
echo "== seed_headon, lambda = 2 (dt = 2e-8)"
lmp -in seed_headon.in -var lambda 2 -var dt 2e-8 -var tag seed_headon_l2 -log none >/dev/null
python3 verify_seed.py --lambda 2 --dt 2e-8 seed_headon_l2.dump
echo "== seed_headon, dashpot only for r < d (dgran d)"
lmp -in seed_headon.in -var dgran d -var tag seed_headon_dgran_d -log none >/dev/null
python3 verify_seed.py --dgran d seed_headon_dgran_d.dump
echo "== seed_oblique, x_gamma_t = 2"
lmp -in seed_oblique.in -var xgt 2 -var tag seed_oblique_x2 -log none >/dev/null
python3 verify_seed.py --xgt 2 seed_oblique_x2.dump
echo "== seed_oblique, mu = 0.1 (cap binds; cap = mu |dashpot normal force|)"
lmp -in seed_oblique.in -var mu 0.1 -var tag seed_oblique_mu01 -log none >/dev/null
python3 verify_seed.py --mu 0.1 seed_oblique_mu01.dump
for v in 0.5 2.0; do
    echo "== seed_wall vt = ${v}: LAMMPS (dashpot-only friction cap)"
    lmp -in seed_wall.in -var vt "${v}" -var tag "seed_wall_vt${v}" -log none >/dev/null
    python3 verify_seed.py --wall --gamma-t-wall "${mt}" "seed_wall_vt${v}.dump"
    echo "-- same initial state, cgdem law (cap mu (WCA + dashpot)); mismatch expected"
    python3 verify_seed.py --wall --full-normal-cap --gamma-t-wall "${mt}" "seed_wall_vt${v}.dump" \
        | grep -E "^python:" || true
done
echo "== seed_wall_region (wall/region lj126 + wall/gran/region, then unfix)"
lmp -in seed_wall_region.in -log seed_wall_region.log | grep -E "^AFTER"
python3 verify_seed.py --wall --gamma-t-wall "${mt}" seed_wall_region.dump

cd "${here}/hertz"
liggghts -in hertz_liggghts.in -log hertz_liggghts.log >/dev/null
lmp -in hertz_lammps.in -log hertz_lammps.log >/dev/null
lmp -in hertz_lammps.in -var q 0.5 -var tag hertz_lammps_q_is_e -log none >/dev/null
echo "== Hertz head-on, LIGGGHTS vs LAMMPS (mapped q) vs LAMMPS (naive q = e)"
python3 hertz_mapping.py 5e6 0.3 0.5
python3 compare_hertz.py hertz_liggghts.dump hertz_lammps.dump hertz_lammps_q_is_e.dump
