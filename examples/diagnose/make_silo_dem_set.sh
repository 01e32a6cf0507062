#!/bin/bash
# Makes a "measured" silo-dem set with the kernel itself: one `demcal silo` run with MATERIAL per angle and seed (JOBS
# at once, default 2), the rates gathered as theta_deg,rate_g_s,replicate. Use seeds that diagnose does not predict
# with (it starts at --first-seed 1). Finished runs are kept in WORKDIR and not run again.
# OUTLETS="0.03 0.022" (metres) runs every angle and seed at each outlet and adds an outlet_m column.
# usage: [OUTLETS="..."] make_silo_dem_set.sh DEMCAL MATERIAL.json OUT.csv WORKDIR "ANGLES" "SEEDS" [silo options...]
set -euo pipefail
demcal=$(realpath "$1"); material=$(realpath "$2"); out=$3; work=$4; angles=$5; seeds=$6; shift 6
outlets=${OUTLETS:-}
mkdir -p "$work"
run_dir() { echo "$work/${1:+outlet${1}_}theta${2}_seed${3}"; }
running=0
for outlet in ${outlets:-""}; do
  for theta in $angles; do
    for seed in $seeds; do
      dir=$(run_dir "$outlet" "$theta" "$seed")
      [ -f "$dir/summary.json" ] && continue
      "$demcal" silo --theta "$theta" --seed "$seed" --material "$material" --out "$dir" \
        ${outlet:+--outlet "$outlet"} "$@" > "$dir.log" 2>&1 &
      running=$((running + 1))
      if [ "$running" -ge "${JOBS:-2}" ]; then wait -n; running=$((running - 1)); fi
    done
  done
done
wait
{
  echo "theta_deg,${outlets:+outlet_m,}rate_g_s,replicate"
  for outlet in ${outlets:-""}; do
    for theta in $angles; do
      k=0
      for seed in $seeds; do
        k=$((k + 1))
        rate=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['rate']['rate_kg_s'] * 1e3)" \
               "$(run_dir "$outlet" "$theta" "$seed")/summary.json")
        echo "$theta,${outlet:+$outlet,}$rate,$k"
      done
    done
  done
} > "$out"
echo "wrote $out"
