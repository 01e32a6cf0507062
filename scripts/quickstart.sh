#!/usr/bin/env bash
# README command 1: installs what demcal needs, builds it, and runs the main job on the embedded defaults:
# a direct-shear campaign of the default sand-like material at four normal stresses in YADE (local pool, SQLite
# store in campaigns/quickstart), ending with the fitted failure line and its plot.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
./build/app/demcal shear examples/materials/sand.json --normal-stress 5e3,10e3,15e3,20e3 \
  --jobs "$(nproc)" --campaign campaigns/quickstart
