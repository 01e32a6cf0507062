#!/usr/bin/env bash
# Shear-box benchmark: one run of the same box (the same params.json, the same cloud) on YADE (yade_scripts/
# shear_box.py, 1 thread) and on the kernel engine (`demcal shear-run`, 1 thread), REPS alternations (order reversed
# every other one), medians and the ratio reported. Both engines measured side by side in one run.
#   bash bench/shear/run.sh                                      # sand.json at 10 kPa, seed 1, REPS=3
#   MATERIAL=examples/materials/sand-tiny.json STRESS=4e3 REPS=1 bash bench/shear/run.sh
# Output: logs/<engine>_<rep>.{log,time,json} (raw), logs/summary.md (medians, ratio, the results side by side).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
MATERIAL="${MATERIAL:-$ROOT/examples/materials/sand.json}"
STRESS="${STRESS:-10e3}"
SEED="${SEED:-1}"
REPS="${REPS:-3}"
BUILD="${BUILD_DIR:-$ROOT/build}"
LOGS="${LOGS:-$HERE/logs}"
for tool in yade /usr/bin/time python3; do
  command -v "$tool" >/dev/null || { echo "run.sh: $tool missing: bash scripts/setup.sh" >&2; exit 2; }
done
DEMCAL="$(cd "$BUILD" && pwd)/app/demcal"
[ -x "$DEMCAL" ] || { echo "run.sh: $DEMCAL not built: cmake --build $BUILD --target demcal" >&2; exit 2; }
mkdir -p "$LOGS" && LOGS="$(cd "$LOGS" && pwd)"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
python3 - "$MATERIAL" "$STRESS" "$SEED" "$WORK/params.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
for k in ("name", "description"):
    m.pop(k, None)
m["normal_stress"] = float(sys.argv[2]); m["seed"] = int(sys.argv[3])
json.dump(m, open(sys.argv[4], "w"), indent=1)
PY
cp "$WORK/params.json" "$LOGS/params.json"
run_one() {  # engine rep
  local engine="$1" rep="$2" dir="$WORK/$1_$2"
  mkdir -p "$dir" && cp "$WORK/params.json" "$dir/"
  if [ "$engine" = yade ]; then
    (cd "$dir" && OMP_NUM_THREADS=1 /usr/bin/time -f "%e %U %S %M" -o "$LOGS/${engine}_${rep}.time" \
      yade -n -j1 -x "$ROOT/yade_scripts/run_clean.py" "$ROOT/yade_scripts/shear_box.py" params.json result.json \
      > "$LOGS/${engine}_${rep}.log" 2>&1)
  else
    (cd "$dir" && OMP_NUM_THREADS=1 /usr/bin/time -f "%e %U %S %M" -o "$LOGS/${engine}_${rep}.time" \
      "$DEMCAL" shear-run params.json result.json > "$LOGS/${engine}_${rep}.log" 2>&1)
  fi
  cp "$dir/result.json" "$LOGS/${engine}_${rep}.json"
  echo "$engine rep $rep: $(cat "$LOGS/${engine}_${rep}.time") (wall s, user s, sys s, max RSS kB)"
}
for rep in $(seq 1 "$REPS"); do
  if [ $((rep % 2)) -eq 1 ]; then run_one yade "$rep"; run_one kernel "$rep"; else run_one kernel "$rep"; run_one yade "$rep"; fi
done
python3 - "$LOGS" "$REPS" <<'PY' | tee "$LOGS/summary.md"
import json, statistics, sys
logs, reps = sys.argv[1], int(sys.argv[2])
def rows(engine):
    out = []
    for r in range(1, reps + 1):
        wall, user, sys_, rss = open("%s/%s_%d.time" % (logs, engine, r)).read().split()
        res = json.load(open("%s/%s_%d.json" % (logs, engine, r)))
        out.append(dict(wall=float(wall), cpu=float(user) + float(sys_), rss=int(rss), res=res))
    return out
y, k = rows("yade"), rows("kernel")
med = lambda rs, key: statistics.median(r[key] for r in rs)
print("| engine | median wall s | median CPU s | max RSS MB | particles | steps | peak tau [Pa] | residual tau [Pa] | porosity |")
print("|---|---|---|---|---|---|---|---|---|")
for name, rs in (("yade", y), ("kernel", k)):
    r0 = rs[0]["res"]
    print("| %s | %.1f | %.1f | %.0f | %d | %d | %.0f | %.0f | %.4f |" % (name, med(rs, "wall"), med(rs, "cpu"),
          max(r["rss"] for r in rs) / 1024, r0["particle_count"], r0["steps"], r0["peak_shear_stress"],
          r0["residual_shear_stress"], r0["porosity"]))
print()
print("YADE / kernel: wall %.1fx, CPU %.1fx (medians of %d alternations; the same params.json and cloud)" %
      (med(y, "wall") / med(k, "wall"), med(y, "cpu") / med(k, "cpu"), reps))
print("per step: YADE %.3g ms, kernel %.3g ms (CPU)" % (1e3 * med(y, "cpu") / y[0]["res"]["steps"],
      1e3 * med(k, "cpu") / k[0]["res"]["steps"]))
PY
