#!/usr/bin/env bash
# README command 2 (and CI): installs what demcal needs, builds it, runs every test with ctest.
# The YADE tests run real YADE; the SLURM test starts (and stops) a real single-node SLURM, so it needs root.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
cd build
ctest --output-on-failure --timeout 1500 "$@"
# The readers' fuzz tests again under AddressSanitizer + UndefinedBehaviorSanitizer (build-fuzz/; the whole sanitized
# suite is scripts/sanitize.sh, too long for CI)
cd ..
bash scripts/sanitize.sh --fuzz
