#!/bin/bash
# The kernel's discharge of the 8 beds of the --kernel-law yade crosschecks (10 deg seeds 1-3, 30 deg seeds 1-3, 50 and
# 70 deg seed 1) with the crosscheck's kernel settings (4000 grains, the reduced silo, stiffness 1e-3, the rolling-free
# wheat) and YADE's Hertz-Mindlin, plus the options of one variant; the filling is the same whatever they are, so each
# variant discharges the same beds. One line per bed into OUT/results.txt: theta seed LABEL rate[g/s] batch_SE[g/s]
# cpu[s]. Usage: run_beds.sh OUT LABEL DEMCAL [demcal silo options of the variant ...]; BEDS="theta seed;..." runs
# other beds (the same settings).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out_dir=$(cd "$1" && pwd); label=$2; demcal=$3; shift 3
[ -f "$out_dir/results.txt" ] || echo "# theta seed variant rate[g/s] batch_SE[g/s] cpu[s] (run_beds.sh, $(date -u +%Y-%m-%d))" > "$out_dir/results.txt"
IFS=';' read -r -a beds <<< "${BEDS:-10 1;10 2;10 3;30 1;30 2;30 3;50 1;70 1}"
for case in "${beds[@]}"; do
  set -- $case "$@"
  theta=$1 seed=$2; shift 2
  out=$out_dir/t${theta}_s$seed
  "$demcal" silo --theta $theta --particles 4000 --stiffness-scale 1e-3 --seed $seed --max-time 5 --threads 1 \
    --no-plots --no-checkpoint --geometry "$here/../../silo/reduced_conical_70deg.json" \
    --material "$here/wheat_no_rolling.json" --contact-law yade "$@" --out "$out" > "$out.log"
  python3 -c "import json; s = json.load(open('$out/summary.json')); r = s['rate']; print('$theta $seed $label', round(r['rate_kg_s'] * 1000, 2), round(r['rate_batch_se_kg_s'] * 1000, 2), round(s.get('cpu_s', -1), 1))" | tee -a "$out_dir/results.txt"
done
