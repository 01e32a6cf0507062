#!/bin/bash
# The kernel on YADE's Hertz-Mindlin (demcal silo --contact-law yade) discharging with YADE's clump rotation
# (--discharge-rotation yade) and with its own (richardson), from the same beds: the crosscheck's kernel settings (4000
# grains, reduced silo, stiffness 1e-3, the rolling-free wheat) and the beds of the --kernel-law yade crosschecks (10
# deg seeds 1-3, 30 deg seeds 1-3, 50 and 70 deg seed 1). The filling runs the kernel's scheme either way, so each
# pair shares its bed: the difference measures the integrators alone. Usage: bash run.sh [DEMCAL] (from anywhere;
# writes t*/ and results.txt here).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
demcal=${1:-$here/../../../../build/app/demcal}
G=$here/../../../silo/reduced_conical_70deg.json
NR=$here/../wheat_no_rolling.json
for case in "10 1" "10 2" "10 3" "30 1" "30 2" "30 3" "50 1" "70 1"; do
  set -- $case
  for R in yade richardson; do
    out=$here/t$1_s$2_$R
    "$demcal" silo --theta $1 --particles 4000 --stiffness-scale 1e-3 --seed $2 --max-time 5 --threads 1 --no-plots \
      --no-checkpoint --geometry "$G" --material "$NR" --contact-law yade --discharge-rotation $R --out "$out" > "$out.log"
    python3 -c "import json; s = json.load(open('$out/summary.json')); r = s['rate']; print('$1 $2 $R', round(r['rate_kg_s'] * 1000, 2), round(r['rate_batch_se_kg_s'] * 1000, 2), round(s['cpu_s'] if 'cpu_s' in s else -1, 1))" | tee -a "$here/results.txt"
  done
done
