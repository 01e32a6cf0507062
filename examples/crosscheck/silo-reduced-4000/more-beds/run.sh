#!/bin/bash
# More beds (seeds 4-8 at 10 and 30 deg) for YADE / kernel with every piece YADE's in the kernel, after the removal
# fix. YADE's rates of these beds (yade_rates.txt) come from `demcal crosscheck silo --theta 10,30 --seed S
# --particles 4000 --stiffness-scale 1e-3 --geometry ../../silo/reduced_conical_70deg.json --max-time 5 --material
# wheat_no_rolling.json --kernel-law yade --kernel-rotation yade --wall-facets 72 --kernel-start-as-yade-import -j 1`
# (one campaign per seed, 2026-12-04), whose kernel runs were made before the fix (their rates: the kernel_before
# column). This script makes the kernel's runs after the fix. Usage: bash run.sh [DEMCAL].
here=$(cd "$(dirname "$0")" && pwd)
BEDS="10 4;30 4;10 5;30 5;10 6;30 6;10 7;30 7;10 8;30 8" exec bash "$here/../run_beds.sh" "$here" removal-fix \
  "${1:-$here/../../../../build/app/demcal}" --discharge-rotation yade --discharge-wall-facets 72 --start-as-yade-import
