#!/usr/bin/env bash
# Orchestrator overhead: a demcal campaign of N small YADE shear runs on 2 workers against the same generated
# scripts run by `xargs -P2 yade -n -x`. Both sides run the identical run directories (same scripts, same params).
# Usage: bench/orchestrator/overhead.sh [N=8] [MATERIAL=examples/materials/sand-tiny.json]
# Prints both wall times and the overhead, and keeps the printout in bench/orchestrator/logs/ (RESULTS.md cites it).
set -euo pipefail
cd "$(dirname "$0")/../.."
N=${1:-8}
MATERIAL=${2:-examples/materials/sand-tiny.json}
DEMCAL=./build/app/demcal
WORK=$(mktemp -d /tmp/demcal-overhead.XXXX)
stresses=$(python3 -c "print(','.join(str(2000+500*i) for i in range($N)))")

# 1. Generate the run directories once (demcal writes them), with a run we then discard.
$DEMCAL shear "$MATERIAL" --normal-stress "$stresses" --jobs 2 --campaign "$WORK/gen" >/dev/null || true  # a failed run is the same work on both sides
run_xargs() {
  rm -rf "$WORK/x"; mkdir -p "$WORK/x"; cp -r "$WORK/gen/runs/." "$WORK/x/"
  find "$WORK/x" -name result.json -delete
  local t0=$(date +%s.%N)
  ls -d "$WORK"/x/*/ | xargs -P2 -I{} sh -c 'cd {} && yade -n -j1 -x shear_box.py params.json result.json >stdout.log 2>stderr.log'
  python3 -c "print($(date +%s.%N) - $t0)"
}
run_demcal() {
  rm -rf "$WORK/d"
  local t0=$(date +%s.%N)
  $DEMCAL shear "$MATERIAL" --normal-stress "$stresses" --jobs 2 --campaign "$WORK/d" >/dev/null || true
  python3 -c "print($(date +%s.%N) - $t0)"
}
# Alternate the two, twice, so drift on a noisy machine falls on both.
tx1=$(run_xargs); td1=$(run_demcal); td2=$(run_demcal); tx2=$(run_xargs)
mkdir -p bench/orchestrator/logs
log=bench/orchestrator/logs/overhead-$(date -u +%Y%m%dT%H%M).log
python3 - "$N" "$tx1" "$tx2" "$td1" "$td2" <<'PY' | tee "$log"
import sys
n, tx1, tx2, td1, td2 = int(sys.argv[1]), *map(float, sys.argv[2:])
tx, td = (tx1 + tx2) / 2, (td1 + td2) / 2
print(f"runs: {n} on 2 workers")
print(f"xargs -P2 yade : {tx1:.2f} s, {tx2:.2f} s (mean {tx:.2f} s)")
print(f"demcal shear   : {td1:.2f} s, {td2:.2f} s (mean {td:.2f} s)")
print(f"overhead       : {100 * (td / tx - 1):+.1f} %")
PY
rm -rf "$WORK"
