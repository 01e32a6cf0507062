#!/bin/bash
# Issue 22's speed item: YADE and the kernel on the same beds of the reduced silo (4000 grains), the settings of the
# one-trajectory comparison (YADE's law, rotation, 72-facet walls and start in the kernel), one campaign per seed, one
# run at a time, the CPU of the discharge in each code (the kernel's summary.json splits its CPU at the opening).
# Usage: bash run.sh DEMCAL OUT (about 8 min per seed: YADE 150-330 s per discharge, the kernel 15-24 s per case),
# then: python3 table.py OUT/seed4 OUT/seed5 ...
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
demcal=$1; out=$2
mkdir -p "$out"
for seed in ${SEEDS:-4 5 6 7}; do
  "$demcal" crosscheck silo --theta 10,30 --seed "$seed" --particles 4000 --stiffness-scale 1e-3 \
    --geometry "$here/../../../silo/reduced_conical_70deg.json" --max-time 5 \
    --material "$here/../wheat_no_rolling.json" --kernel-law yade --kernel-rotation yade --wall-facets 72 \
    --kernel-start-as-yade-import -j 1 -c "$out/seed$seed" > "$out/seed$seed.log" 2>&1
done
