#!/usr/bin/env bash
# The full-stiffness vibration campaigns of examples/silo/README.md (2026-12-02), from the repository's root:
#   bash examples/silo/vibration_sweep_full_stiffness/run.sh OUT [campaign ...]
# Each is a resumable `demcal vibration` campaign in OUT/<name>; the same command continues it. Then
#   python3 examples/silo/vibration_sweep_full_stiffness/pairs.py OUT/<still source> OUT/<campaign> ...
# pairs each vibrating run with the still run of the same angle and seed found in the first campaign (the same bed).
set -euo pipefail
out=${1:?OUT directory}; shift
demcal=${DEMCAL:-build/app/demcal}
silo=(--geometry examples/silo/reduced_conical_70deg.json --stiffness-scale 1 --fill-time 0.5 --threads 1 --no-plots)
run() { local name=$1; shift; nice "$demcal" vibration "$@" --campaign "$out/$name"; }
for c in "${@:-full_a full_b hopper amp055 out10 deep20_bin deep20_hopper}"; do
  for name in $c; do
    case $name in
      # 0 and 145 Hz at 0.11 mm, the whole bin (the first sweep, its outputs one folder up)
      full_a) run full_a --theta 10,30,60 --frequency 0,145 --amplitude 1.1e-4 --repeats 3 -- "${silo[@]}" --particles 2000 ;;
      # 50 and 100 Hz (paired against the still runs of full_a or hopper: the same beds)
      full_b) run full_b --theta 10,30,60 --frequency 50,100 --amplitude 1.1e-4 --repeats 3 -- "${silo[@]}" --particles 2000 ;;
      # the hopper alone vibrating, the body still
      hopper) run hopper --theta 10,30,60 --frequency 0,145 --amplitude 1.1e-4 --part hopper --repeats 3 -- "${silo[@]}" --particles 2000 ;;
      # half the amplitude at 145 Hz
      amp055) run amp055 --theta 10,30,60 --frequency 145 --amplitude 5.5e-5 --repeats 3 -- "${silo[@]}" --particles 2000 ;;
      # 10 deg again, with the outlet meter
      out10) run out10 --theta 10 --frequency 0,145 --amplitude 1.1e-4 --repeats 3 -- "${silo[@]}" --particles 2000 ;;
      # 20 deg, 5000 grains: the bed 3 cm into the body; whole bin and hopper alone; stop at 85 % out
      deep20_bin) run deep20_bin --theta 20 --frequency 0,145 --amplitude 1.1e-4 --part bin --repeats 2 -- "${silo[@]}" --particles 5000 --stop-fraction 0.85 ;;
      deep20_hopper) run deep20_hopper --theta 20 --frequency 145 --amplitude 1.1e-4 --part hopper --repeats 2 -- "${silo[@]}" --particles 5000 --stop-fraction 0.85 ;;
      *) echo "unknown campaign $name" >&2; exit 2 ;;
    esac
  done
done
