#!/bin/bash
# The kernel with every modelled piece YADE's: YADE's Hertz-Mindlin, YADE's clump rotation, silo.py's 72-facet walls,
# and YADE's start (demcal silo --start-as-yade-import: the contacts afresh, their springs advanced in the first force
# evaluation, a whole first kick, as YADE's run of the exported bed starts), from the same beds. From such a start the
# two codes follow one trajectory until chaos parts them (tests/kernel/test_silo_yade_trajectory.cpp).
# Usage: bash run.sh [DEMCAL] (writes t*/ and results.txt here).
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/../run_beds.sh" "$here" yade-start "${1:-$here/../../../../build/app/demcal}" \
  --discharge-rotation yade --discharge-wall-facets 72 --start-as-yade-import
