#!/bin/bash
# The kernel on YADE's Hertz-Mindlin (demcal silo --contact-law yade) with the contacts' history kept and forgotten at
# the opening (--forget-contact-history), with the crosscheck's kernel settings (4000 grains, reduced silo, stiffness
# 1e-3, the rolling-free wheat): the beds of the --kernel-law yade crosschecks (10 deg seeds 1-3, 30 deg seeds 1-3,
# 50 and 70 deg seed 1). Usage: bash run.sh [DEMCAL] (from this folder; writes t*/ and results.txt here).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
demcal=${1:-$here/../../../../build/app/demcal}
G=$here/../../../silo/reduced_conical_70deg.json
NR=$here/../wheat_no_rolling.json
for case in "10 1" "10 2" "10 3" "30 1" "50 1" "70 1" "30 2" "30 3"; do
  set -- $case
  for H in keep forget; do
    f=(); [ $H = forget ] && f=(--forget-contact-history)
    out=$here/t$1_s$2_$H
    "$demcal" silo --theta $1 --particles 4000 --stiffness-scale 1e-3 --seed $2 --max-time 5 --threads 1 --no-plots \
      --no-checkpoint --geometry "$G" --material "$NR" --contact-law yade "${f[@]}" --out "$out" > "$out.log"
    python3 -c "import json; r = json.load(open('$out/summary.json'))['rate']; print('$1 $2 $H', round(r['rate_kg_s'] * 1000, 2), round(r['rate_batch_se_kg_s'] * 1000, 2))" | tee -a "$here/results.txt"
  done
done
