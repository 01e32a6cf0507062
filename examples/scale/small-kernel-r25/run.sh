#!/bin/bash
# The kernel-engine enlargement study of examples/scale/README.md, section 6: section 5's cohesionless sand with the
# reference at 2.5 mm and five radii 2.5-3.5 mm (about 17 min wall, 25 CPU-min on 2 cores; resumable: run it again
# after Ctrl-C). Usage: bash examples/scale/small-kernel-r25/run.sh [DIR] (default campaigns/scale-kernel-r25)
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
exec "$ROOT/build/app/demcal" scale "$ROOT/examples/materials/sand-scale-small.json" \
  --radii 2.5e-3,2.75e-3,3e-3,3.25e-3,3.5e-3 --normal-stress 6e3,10e3,14e3 --replicates 60 --levels 3 --span 0.5 \
  --max-evaluations 12 --max-runs 20000 --bounds poisson_ratio=0.03:0.49 young_modulus=5e6:4e7 --strict \
  --engine kernel --jobs 2 --dir "${1:-campaigns/scale-kernel-r25}"
