#!/bin/bash
# The kernel's rate with the contacts' history kept and forgotten at the opening (demcal silo
# --forget-contact-history), with the crosscheck's kernel settings (4000 grains, reduced silo, stiffness 1e-3, seed 1),
# for the Table 2.1 wheat and the rolling-free one. Usage: bash run.sh [DEMCAL] (from this folder; writes t*/ here).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
demcal=${1:-$here/../../../../build/app/demcal}
G=$here/../../../silo/reduced_conical_70deg.json
NR=$here/../wheat_no_rolling.json
for T in 10 30 50 70; do
  for M in default norolling; do
    mat=(); [ $M = norolling ] && mat=(--material "$NR")
    for H in keep forget; do
      f=(); [ $H = forget ] && f=(--forget-contact-history)
      "$demcal" silo --theta $T --particles 4000 --stiffness-scale 1e-3 --seed 1 --max-time 5 --threads 1 --no-plots \
        --no-checkpoint --geometry "$G" "${mat[@]}" "${f[@]}" --out "$here/t${T}_${M}_${H}" > "$here/t${T}_${M}_${H}.log"
    done
  done
done
