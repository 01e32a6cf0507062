#!/usr/bin/env bash
# Peer benchmark: LIGGGHTS (1 process, 2 MPI ranks), YADE (1 thread) and demcal's kernel (1 and 2 threads) on the
# same case (../shared/reference/peer-case), side by side in one run, REPS alternations (order reversed every other
# one), medians reported. Installs nothing: `DEMCAL_BENCH_DEPS=1 bash scripts/setup.sh` installs liggghts,
# openmpi-bin and time; yade comes with the base setup.
#   bash bench/peer/run.sh                 # REPS=3 STEPS=2000, logs in bench/peer/logs/
#   REPS=1 STEPS=500 YADE_J2=1 bash bench/peer/run.sh
# Output: logs/<code>_<rep>.{log,time} (raw), logs/summary.json and logs/summary.md (medians, ratios, memory).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
PEER="${PEER_CASE:-$ROOT/../shared/reference/peer-case}"
REPS="${REPS:-3}"
STEPS="${STEPS:-2000}"
BUILD="${BUILD_DIR:-$ROOT/build}"
LOGS="${LOGS:-$HERE/logs}"
mkdir -p "$LOGS" && LOGS="$(cd "$LOGS" && pwd)"  # the runs cd into a scratch folder
for tool in liggghts mpirun yade /usr/bin/time python3; do
  command -v "$tool" >/dev/null || { echo "run.sh: $tool missing: DEMCAL_BENCH_DEPS=1 bash scripts/setup.sh" >&2; exit 2; }
done
[ -f "$PEER/in.peer" ] || { echo "run.sh: peer case not found in $PEER (set PEER_CASE)" >&2; exit 2; }
if [ ! -x "$BUILD/bench/peer/demcal_peer" ]; then
  cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$BUILD" -j2 --target demcal_peer >/dev/null
fi
DEMCAL="$(cd "$BUILD" && pwd)/bench/peer/demcal_peer"  # absolute: the runs cd into a scratch folder
# OpenMP threads sleep at barriers instead of spinning: on this 2-core machine shared with other jobs, spinning
# threads steal the core the other thread needs (measured: 2.6e6 vs 7.1e6 particle-steps/s with 2 threads under load)
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
mkdir -p "$LOGS"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
cp "$PEER/in.peer" "$PEER/yade_peer.py" "$WORK/"

run_one() {  # name rep command...  (a failed run is retried once, then left out of the medians)
  local name="$1" rep="$2"; shift 2
  for attempt in 1 2; do
    echo "[$(date -u +%H:%M:%S)] rep $rep: $name (attempt $attempt)" >&2
    if (cd "$WORK" && /usr/bin/time -v -o "$LOGS/${name}_$rep.time" "$@" >"$LOGS/${name}_$rep.log" 2>&1); then
      return 0
    fi
    echo "run.sh: $name failed (attempt $attempt; see $LOGS/${name}_$rep.log)" >&2
    cp "$LOGS/${name}_$rep.log" "$LOGS/${name}_$rep.failed$attempt.log"
  done
  rm -f "$LOGS/${name}_$rep.log"
}
runs=(${RUNS:-lig1 lig2 yade1 dem1 dem2})  # RUNS="lig1 lig2 dem1 dem2": a subset (e.g. after a kernel change)
[ "${YADE_J2:-0}" = 1 ] && runs+=(yade2)
# SUMMARY_ONLY=1: recompute the summary from the logs already in $LOGS
[ "${SUMMARY_ONLY:-0}" = 1 ] && REPS_RUN=0 || REPS_RUN="$REPS"
for rep in $(seq 1 "$REPS_RUN"); do
  order=("${runs[@]}")
  if [ $((rep % 2)) = 0 ]; then order=(); for ((k=${#runs[@]}-1; k>=0; k--)); do order+=("${runs[k]}"); done; fi
  for r in "${order[@]}"; do
    case "$r" in
      lig1) run_one lig1 "$rep" sh -c "liggghts -in in.peer -var STEPS $STEPS -echo none -screen none -log log.lig1 && cat log.lig1" ;;
      lig2) run_one lig2 "$rep" sh -c "mpirun --allow-run-as-root -np 2 liggghts -in in.peer -var STEPS $STEPS -echo none -screen none -log log.lig2 && cat log.lig2" ;;
      yade1) run_one yade1 "$rep" yade -n -j1 -x yade_peer.py "$STEPS" ;;
      yade2) run_one yade2 "$rep" yade -n -j2 -x yade_peer.py "$STEPS" ;;
      dem1) run_one dem1 "$rep" "$DEMCAL" "$STEPS" 1 ;;
      dem2) run_one dem2 "$rep" "$DEMCAL" "$STEPS" 2 ;;
    esac
  done
done

python3 - "$LOGS" "$REPS" "$STEPS" "${runs[@]}" <<'PY'
import json, re, statistics, sys, os, platform, subprocess
logs, reps, steps, runs = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4:]
def maxrss(path):
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(path).read())
    return int(m.group(1)) if m else None
def cpu_seconds(path):  # user + system time of the whole process tree (setup and warm-up included)
    t = open(path).read()
    u = re.search(r"User time \(seconds\): ([0-9.]+)", t); s = re.search(r"System time \(seconds\): ([0-9.]+)", t)
    return float(u.group(1)) + float(s.group(1)) if u and s else None
res = {}
for r in runs:
    rows = []
    for k in range(1, reps + 1):
        if not os.path.exists(f"{logs}/{r}_{k}.log"):
            continue  # failed twice (see the .failed logs)
        text = open(f"{logs}/{r}_{k}.log").read()
        row = {"maxrss_kb": maxrss(f"{logs}/{r}_{k}.time")}
        if r.startswith("lig"):
            n = int(re.search(r"Created (\d+) atoms", text).group(1))
            loops = re.findall(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps", text)
            t, procs, st = float(loops[-1][0]), int(loops[-1][1]), int(loops[-1][2])
            thermo = re.findall(r"^\s+(\d+)\s+(\d+)\s+([0-9.eE+-]+)\s+[0-9.eE+-]+\s*$", text, re.M)
            row.update(particles=n, workers=procs, seconds=t, rate=n * st / t, ke=float(thermo[-1][2]) if thermo else None)
        else:
            j = json.loads([l for l in text.splitlines() if l.startswith("{")][-1])
            n = j["spheres"]
            row.update(particles=n, workers=j["threads"], seconds=j["wall_s"], rate=j["particle_steps_per_s"],
                       ke=j.get("kinetic_energy_J"), mean_z=j.get("mean_z_m"))
        row["bytes_per_particle"] = 1024.0 * row["maxrss_kb"] / row["particles"] if row["maxrss_kb"] else None
        cpu = cpu_seconds(f"{logs}/{r}_{k}.time")
        # particle-steps per CPU second over the whole process (200 warm-up steps and the setup included): robust to
        # the load of other jobs, but a cost, not a speed, for runs with 2 workers
        row["cpu_rate"] = row["particles"] * (steps + 200) / cpu if cpu else None
        row["rep"] = k
        rows.append(row)
    if not rows:
        continue
    rates = [x["rate"] for x in rows]
    res[r] = {"runs_ok": len(rows), "median_rate": statistics.median(rates), "min_rate": min(rates), "max_rate": max(rates),
              "rates": rates, "particles": rows[0]["particles"], "workers": rows[0]["workers"],
              "median_bytes_per_particle": statistics.median([x["bytes_per_particle"] for x in rows]),
              "ke_J": rows[-1]["ke"], "median_cpu_rate": statistics.median([x["cpu_rate"] for x in rows]),
              "by_rep": {x["rep"]: x["rate"] for x in rows}}
ratio = lambda a, b: res[a]["median_rate"] / res[b]["median_rate"] if a in res and b in res else None
summary = {"steps": steps, "reps": reps, "host": platform.node(), "cpus": os.cpu_count(),
           "load_avg_end": os.getloadavg(), "runs": res,
           "ratios": {"demcal1/liggghts1": ratio("dem1", "lig1"), "demcal2/liggghts2": ratio("dem2", "lig2"),
                      "demcal1/yade1": ratio("dem1", "yade1"), "demcal2/yade1": ratio("dem2", "yade1")}}
def per_rep(a, b):  # ratio within each alternation (similar load), then the median
    if a not in res or b not in res: return None
    common = sorted(set(res[a]["by_rep"]) & set(res[b]["by_rep"]))
    return statistics.median([res[a]["by_rep"][k] / res[b]["by_rep"][k] for k in common]) if common else None
summary["ratios_per_rep_median"] = {k: per_rep(*{"demcal1/liggghts1": ("dem1", "lig1"), "demcal2/liggghts2": ("dem2", "lig2"),
    "demcal1/yade1": ("dem1", "yade1"), "demcal2/yade1": ("dem2", "yade1")}[k]) for k in summary["ratios"]}
cpu_ratio = lambda a, b: res[a]["median_cpu_rate"] / res[b]["median_cpu_rate"] if a in res and b in res else None
summary["cpu_time_ratios"] = {"demcal1/liggghts1": cpu_ratio("dem1", "lig1"), "demcal1/yade1": cpu_ratio("dem1", "yade1")}
json.dump(summary, open(f"{logs}/summary.json", "w"), indent=1)
names = {"lig1": "LIGGGHTS, 1 process", "lig2": "LIGGGHTS, 2 MPI ranks", "yade1": "YADE, 1 thread",
         "yade2": "YADE, 2 threads", "dem1": "demcal kernel, 1 thread", "dem2": "demcal kernel, 2 threads"}
out = ["| code | particles | runs | median particle-steps/s | min - max | per CPU second (whole process) | peak RSS / particle (B) | KE at the end (J) |",
       "| --- | --- | --- | --- | --- | --- | --- | --- |"]
for r in runs:
    if r not in res:
        out.append(f"| {names[r]} | - | 0 | failed | - | - | - | - |"); continue
    x = res[r]
    out.append(f"| {names[r]} | {x['particles']} | {x['runs_ok']} | {x['median_rate']:.3g} | {x['min_rate']:.3g} - {x['max_rate']:.3g} | "
               f"{x['median_cpu_rate']:.3g} | {x['median_bytes_per_particle']:.0f} | {x['ke_J'] if x['ke_J'] is not None else '-'} |")
out.append("")
for k, v in summary["ratios"].items():
    if v is not None:
        out.append(f"- {k}: {v:.2f} (ratio of medians); {summary['ratios_per_rep_median'][k]:.2f} (median of the per-alternation ratios)")
for k, v in summary["cpu_time_ratios"].items():
    if v is not None: out.append(f"- {k} per CPU second (whole process): {v:.2f}")
out.append(f"- load average when summarised: {' '.join('%.2f' % l for l in summary['load_avg_end'])}")
open(f"{logs}/summary.md", "w").write("\n".join(out) + "\n")
print("\n".join(out))
PY
