#!/usr/bin/env bash
# The joint (mu_b, tau_c) recovery of README.md on the kernel engine, 40 packings per stress (120 runs per line):
# the hidden material's line is the target (point targets, --tol 0.05, --strict), the study of ../kernel-sand-bonded-far
# reused (--sensitivity), then the calibrated material's line on YADE. Usage: run.sh [DEMCAL] [DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/../../.." && pwd)"
demcal=${1:-$root/build/app/demcal}
dir=${2:-campaigns/kernel-sand-bonded-far-40}
stresses=5e3,12.5e3,20e3
mkdir -p "$dir"
"$demcal" shear "$root/examples/calibration/hidden-sand-bonded-far.json" --engine kernel -s $stresses -r 40 -j 2 \
  -c "$dir/target" | tee "$dir/target.log"
target=$(python3 -c "
import json,glob
j=json.load(open(glob.glob('$dir/target/failure_line_*.json')[0]))['peak_failure_line']
print('mu_b=%.6g,tau_c=%.6g' % (j['mu_b'], j['tau_c_Pa']))")
"$demcal" calibrate --target "$target" --start "$root/examples/materials/sand-bonded.json" --strict --tol 0.05 \
  -s $stresses -r 40 -j 2 --engine kernel \
  --sensitivity "$root/examples/calibration/kernel-sand-bonded-far/sensitivity.json" --campaign "$dir/loop" \
  --max-evaluations 8 | tee "$dir/loop.log"
"$demcal" shear "$dir/loop/calibrated_material.json" -s $stresses -r 10 -j 2 -c "$dir/yade_final" | tee "$dir/yade_final.log"
