#!/bin/bash
# Makes a "measured" silo-dem set with the kernel itself: one `demcal silo` run with MATERIAL per angle and seed (JOBS
# at once, default 2), the rates gathered as theta_deg,rate_g_s,replicate. Use seeds that diagnose does not predict
# with (it starts at --first-seed 1). Finished runs are kept in WORKDIR and not run again.
# usage: make_silo_dem_set.sh DEMCAL MATERIAL.json OUT.csv WORKDIR "ANGLES" "SEEDS" [silo options...]
set -euo pipefail
demcal=$(realpath "$1"); material=$(realpath "$2"); out=$3; work=$4; angles=$5; seeds=$6; shift 6
mkdir -p "$work"
running=0
for theta in $angles; do
  for seed in $seeds; do
    dir="$work/theta${theta}_seed${seed}"
    [ -f "$dir/summary.json" ] && continue
    "$demcal" silo --theta "$theta" --seed "$seed" --material "$material" --out "$dir" "$@" > "$dir.log" 2>&1 &
    running=$((running + 1))
    if [ "$running" -ge "${JOBS:-2}" ]; then wait -n; running=$((running - 1)); fi
  done
done
wait
{
  echo "theta_deg,rate_g_s,replicate"
  for theta in $angles; do
    k=0
    for seed in $seeds; do
      k=$((k + 1))
      rate=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['rate']['rate_kg_s'] * 1e3)" \
             "$work/theta${theta}_seed${seed}/summary.json")
      echo "$theta,$rate,$k"
    done
  done
} > "$out"
echo "wrote $out"
