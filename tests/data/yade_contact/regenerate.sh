#!/bin/sh
# Re-runs YADE (2023.02a, one thread, niced) on every params file here and rewrites CASE.csv and CASE.csv.meta.json.
# Usage: tests/data/yade_contact/regenerate.sh [CASE ...]     (default: all); then python3 yade_scripts/check_single_contact.py
set -e
here=$(cd "$(dirname "$0")" && pwd)
scripts="$here/../../../yade_scripts"
cd "$here"
cases="$*"
[ -n "$cases" ] || cases=$(ls *.json | grep -v '\.meta\.json$' | sed 's/\.json$//')
for c in $cases; do
    nice yade -n -j1 -x "$scripts/run_clean.py" "$scripts/single_contact.py" "$c.json" "$c.csv" 2>&1 | grep '^single_contact:'
done
