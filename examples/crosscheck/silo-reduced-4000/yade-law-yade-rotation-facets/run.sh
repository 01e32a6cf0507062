#!/bin/bash
# The kernel on YADE's Hertz-Mindlin and YADE's clump rotation discharging between silo.py's own walls: the cone and
# cylinder as 72-sided polygons of triangular facets with YADE's facet contact (demcal silo --discharge-wall-facets
# 72), from the same beds as ../yade-law-yade-rotation/ (the filling runs on the exact walls either way).
# Usage: bash run.sh [DEMCAL] (writes t*/ and results.txt here).
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/../run_beds.sh" "$here" facets72 "${1:-$here/../../../../build/app/demcal}" \
  --discharge-rotation yade --discharge-wall-facets 72
