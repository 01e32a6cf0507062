#!/usr/bin/env bash
# How long a silo run takes to stop after SIGTERM (a batch system's time limit, scancel): the seed's 50,000 grains on
# one thread, the signal sent WAIT seconds into the run (while it fills), the time from the signal to the exit
# (status 75 expected: suspended, its checkpoint written). Not a test: a measurement, results in RESULTS.md.
# Usage: bash bench/silo/sigterm_latency.sh [DEMCAL] [WAIT_S]   (default build/app/demcal, 90 s)
set -euo pipefail
DEMCAL="${1:-build/app/demcal}"
WAIT="${2:-90}"
OUT="$(mktemp -d)/silo"
trap 'rm -rf "$(dirname "$OUT")"' EXIT
"$DEMCAL" silo --theta 30 --particles 50000 --out "$OUT" --no-plots --threads 1 > "$OUT.log" 2>&1 &
pid=$!
sleep "$WAIT"
t0=$(date +%s.%N)
kill -TERM "$pid"
rc=0
wait "$pid" || rc=$?
t1=$(date +%s.%N)
echo "exit status $rc, $(echo "$t1 - $t0" | bc) s from SIGTERM to exit; the run's last lines:"
tail -n 4 "$OUT.log"
ls -l "$OUT/checkpoint.bin"
