#!/bin/bash
# The kernel with every modelled piece YADE's (law, clump rotation, 72-facet walls, YADE's start: as ../yade-start/)
# after the removal fix (2026-12-04: a removal no longer evaluates every force again), from the same 8 beds.
# Usage: bash run.sh [DEMCAL] (writes t*/ and results.txt here).
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/../run_beds.sh" "$here" removal-fix "${1:-$here/../../../../build/app/demcal}" \
  --discharge-rotation yade --discharge-wall-facets 72 --start-as-yade-import
