#!/usr/bin/env bash
# Hostile-input sweep of the commands added since the last hardening pass (issue 23): shear-run, shear --engine
# kernel, crosscheck shear, crosscheck silo (--fill, --kernel-law), scale, cutoff, vibration, silo --export-bed /
# --export-cloud, --forget-contact-history, --contact-law, --discharge-rotation (crosscheck --kernel-rotation),
# --discharge-wall-facets (--wall-facets), --start-as-yade-import (--kernel-start-as-yade-import), --export-final-bed and the --vibration-* options (--vibration-part, --part),
# diagnose silo-dem --max-runs.
# Then the examples the issue itself lists, on the older commands (predict, silo --fill-mass, status and resume on a
# store that is not demcal's, calibrate targets, enlarge).
# Each case runs the real demcal under `timeout` in a scratch folder and checks:
#   - the exit code (2 for bad input unless the case says otherwise), never a signal (>= 128) nor a timeout (124);
#   - the message names the option or field (EXPECT) and is short (a huge value is shortened, stderr < 4 kB);
#   - nothing was written: a before/after listing of the scratch folder and of the watched output locations.
# Usage: bash scripts/hostile_sweep.sh [BUILD_DIR]   (default build/); prints one line per case, exit 1 if any failed.
# DEMCAL_SWEEP_FILTER=REGEX runs only the cases whose name matches. Runtime: about 1-2 minutes (no case runs a
# simulation when demcal behaves; a hang costs the case's time limit, 20 s).
set -u
here="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${1:-$here/build}" 2>/dev/null && pwd)" || { echo "no build folder ${1:-$here/build}"; exit 1; }
demcal="$build/app/demcal"
[ -x "$demcal" ] || { echo "no demcal at $demcal (build first)"; exit 1; }
limit="${DEMCAL_SWEEP_TIMEOUT:-20}"
filter="${DEMCAL_SWEEP_FILTER:-.}"
work="$(mktemp -d /tmp/demcal-hostile.XXXXXX)"
trap 'rm -rf "$work"' EXIT
tiny="$here/examples/materials/sand-tiny.json"
wheat="$here/examples/materials/silo_wheat_table21.json"

# inputs that are bad in every place
huge="$(head -c 100000 /dev/zero | tr '\0' '7')"                      # a 100 kB number
hugestr="$(head -c 100000 /dev/zero | tr '\0' 'x')"                   # a 100 kB word
python3 -c "print('['*100000 + ']'*100000)" > "$work/deep.json"       # nested 100,000 deep
printf '{"a": 1, "a": 2}' > "$work/dup.json"
: > "$work/empty.json"
printf '{"density": 1e-320}' > "$work/subnormal.json"
mkdir -p "$work/folder.json"
# a valid shear params.json (the kernel engine's input), and damaged versions of it
python3 - "$tiny" "$work" <<'EOF'
import json, sys
m = json.load(open(sys.argv[1]))
m = {k: v for k, v in m.items() if not k.startswith("_")}
m.update(normal_stress=5e3, seed=1)
w = sys.argv[2]
json.dump(m, open(w + "/params.json", "w"))
for key, value in [("timestep_fraction", 1e-320), ("normal_stress", 1e308), ("seed", 2**64), ("samples", 10**12),
                   ("particle_radius", -1.0), ("box_length", "nan")]:
    bad = dict(m); bad[key] = value
    json.dump(bad, open("%s/params_%s.json" % (w, key), "w"))
t = json.dumps(m).replace("5000.0", "NaN")
open(w + "/params_nan_text.json", "w").write(t)
EOF
# the silo material with bad grain elongations
python3 - "$wheat" "$work" <<'EOF'
import json, sys
m = json.load(open(sys.argv[1]))
for name, value in [("subnormal", 1e-320), ("huge", 1e308), ("apart", 2.7), ("flat", 0.9), ("text", "long")]:
    m["grain"]["aspect_ratio"] = value
    json.dump(m, open("%s/aspect_%s.json" % (sys.argv[2], name), "w"))
EOF

pass=0; fail=0; failures=()

listing() {  # every file below the scratch and watched folders with its size and mtime, every folder by name
    # (a folder's own mtime changes when demcal tries whether it can create files in it: a probe it removes at once)
    find "$@" -xdev -type f -printf '%p %s %T@\n' 2>/dev/null | sort
    find "$@" -xdev -type d -printf '%p/\n' 2>/dev/null | sort
}

# run_case NAME RC EXPECT [WATCH...] -- demcal args...
#   RC: expected exit code; EXPECT: text the output must contain ('' for none); WATCH: extra paths to list.
run_case() {
    local name="$1" want_rc="$2" expect="$3"; shift 3
    local watch=()
    while [ "$1" != "--" ]; do watch+=("$1"); shift; done
    shift
    [[ "$name" =~ $filter ]] || return 0
    local dir="$work/case"; rm -rf "$dir"; mkdir -p "$dir"
    local before after rc out
    before="$(listing "$dir" "${watch[@]}")"
    (cd "$dir" && timeout -k 5 "$limit" "$demcal" "$@" > "$work/out" 2>&1); rc=$?
    after="$(listing "$dir" "${watch[@]}")"
    out="$(head -c 4000 "$work/out")"
    local why=""
    if [ "$rc" = 124 ] || [ "$rc" = 137 ]; then why="hang (killed after ${limit}s)";
    elif [ "$rc" -ge 128 ]; then why="crash (exit $rc, signal $((rc - 128)))";
    elif [ "$rc" != "$want_rc" ]; then why="exit $rc, expected $want_rc";
    elif [ -n "$expect" ] && ! grep -qF -- "$expect" "$work/out"; then why="message lacks '$expect'";
    elif [ "$(wc -c < "$work/out")" -gt 4000 ]; then why="message of $(wc -c < "$work/out") bytes (value not shortened)";
    elif [ "$before" != "$after" ]; then why="files written: $(diff <(echo "$before") <(echo "$after") | grep '^>' | head -3 | tr '\n' ' ')";
    fi
    if [ -z "$why" ]; then
        pass=$((pass + 1)); echo "ok    $name"
    else
        fail=$((fail + 1)); failures+=("$name: $why")
        echo "FAIL  $name: $why"; echo "$out" | tail -3 | cut -c1-300 | sed 's/^/        /'
    fi
}

ro="$work/readonly"; mkdir -p "$ro"
if mount -t tmpfs -o ro,size=64k tmpfs "$ro" 2>/dev/null; then trap 'umount "$ro" 2>/dev/null; rm -rf "$work"' EXIT
else ro=/proc; fi   # an existing folder nobody can create files in (also for root)

# ---- demcal shear-run PARAMS RESULT (the kernel engine's run) -------------------------------------------------------
P="$work/params.json"
run_case shear-run/missing-params    2 "no-such.json"   -- shear-run "$work/no-such.json" r.json
run_case shear-run/params-folder     2 "folder.json"    -- shear-run "$work/folder.json" r.json
run_case shear-run/params-empty      2 "params"         -- shear-run "$work/empty.json" r.json
run_case shear-run/params-deep       2 "nest"           -- shear-run "$work/deep.json" r.json
run_case shear-run/params-dup        2 "'a'"            -- shear-run "$work/dup.json" r.json
run_case shear-run/params-nan-text   2 "params"         -- shear-run "$work/params_nan_text.json" r.json
for k in timestep_fraction normal_stress seed samples particle_radius box_length; do
    run_case "shear-run/params-$k"   2 "$k"             -- shear-run "$work/params_$k.json" r.json
done
run_case shear-run/result-folder     2 "result"         -- shear-run "$P" "$work/folder.json"
run_case shear-run/result-no-folder  2 "result"         -- shear-run "$P" /no/such/folder/r.json
run_case shear-run/result-readonly   2 "result"  "$ro"  -- shear-run "$P" "$ro/r.json"
run_case shear-run/result-empty      2 "result"         -- shear-run "$P" ""
run_case shear-run/threads-0         2 "--threads"      -- shear-run "$P" r.json --threads 0
run_case shear-run/threads-nan       2 "--threads"      -- shear-run "$P" r.json --threads nan
run_case shear-run/threads-huge      2 "--threads"      -- shear-run "$P" r.json --threads "$huge"

# ---- demcal shear --engine kernel -----------------------------------------------------------------------------------
K=(shear "$tiny" --engine kernel --campaign camp)
run_case shear-kernel/stress-negative 2 "--normal-stress" -- "${K[@]}" -s 5e3,-1
run_case shear-kernel/stress-subnormal 2 "--normal-stress" -- "${K[@]}" -s 5e3,1e-320
run_case shear-kernel/stress-1e308   2 "--normal-stress" -- "${K[@]}" -s 5e3,1e308
run_case shear-kernel/stress-nan     2 "--normal-stress" -- "${K[@]}" -s 5e3,nan
run_case shear-kernel/stress-huge    2 "-s"             -- "${K[@]}" -s "$huge"
run_case shear-kernel/stress-empty   2 "--normal-stress" -- "${K[@]}" -s ""
run_case shear-kernel/replicates-huge 2 "replicates"    -- "${K[@]}" -s 5e3,1e4 -r 2000000000
run_case shear-kernel/replicates-0   2 "--replicates"   -- "${K[@]}" -s 5e3,1e4 -r 0
run_case shear-kernel/template       2 "template"       -- "${K[@]}" -s 5e3,1e4 --template "$here/yade_scripts/shear_box.py"
run_case shear-kernel/material-folder 2 "folder.json"   -- shear "$work/folder.json" --engine kernel -s 5e3,1e4 --campaign camp
run_case shear-kernel/material-deep  2 "nest"           -- shear "$work/deep.json" --engine kernel -s 5e3,1e4 --campaign camp
run_case shear-kernel/material-subnormal 2 "density"    -- shear "$work/subnormal.json" --engine kernel -s 5e3,1e4 --campaign camp
run_case shear-kernel/campaign-readonly 2 "campaign" "$ro" -- shear "$tiny" --engine kernel -s 5e3,1e4,2e4 --campaign "$ro/camp"
run_case shear-kernel/campaign-file  2 "campaign"       -- shear "$tiny" --engine kernel -s 5e3,1e4,2e4 --campaign "$tiny"
run_case shear-kernel/timeout-subnormal 2 "--timeout"   -- "${K[@]}" -s 5e3,1e4 --timeout 1e-320
run_case shear-kernel/timeout-huge   2 "--timeout"      -- "${K[@]}" -s 5e3,1e4 --timeout 1e99
run_case shear-kernel/retries-huge   2 "--retries"      -- "${K[@]}" -s 5e3,1e4 --retries 1e9
run_case shear-kernel/retries-many   2 "--retries"      -- "${K[@]}" -s 5e3,1e4 --retries 1000000000
run_case shear-kernel/jobs-huge      2 "--jobs"         -- "${K[@]}" -s 5e3,1e4 --jobs 1e9
run_case shear-kernel/engine-bad     2 "--engine"       -- shear "$tiny" --engine "$hugestr" -s 5e3,1e4 --campaign camp

# ---- demcal crosscheck shear ----------------------------------------------------------------------------------------
C=(crosscheck shear "$tiny" --campaign camp)
run_case crosscheck-shear/stress-nan 2 "--normal-stress" -- "${C[@]}" -s 5e3,nan
run_case crosscheck-shear/stress-one 2 "normal-stress"   -- "${C[@]}" -s 5e3
run_case crosscheck-shear/replicates-huge 2 "replicates" -- "${C[@]}" -s 5e3,1e4 -r 100000000
run_case crosscheck-shear/replicates-1 2 "replicates"    -- "${C[@]}" -s 5e3,1e4 -r 1
run_case crosscheck-shear/stress-same 2 "normal-stress"  -- "${C[@]}" -s 5e3,5e3,5e3
run_case crosscheck-shear/material-missing 2 "no-such"   -- crosscheck shear "$work/no-such.json" -s 5e3,1e4 --campaign camp
run_case crosscheck-shear/material-deep 2 "nest"         -- crosscheck shear "$work/deep.json" -s 5e3,1e4 --campaign camp
run_case crosscheck-shear/seed-huge  2 "--seed"          -- "${C[@]}" -s 5e3,1e4 --seed 99999999999999999999
run_case crosscheck-shear/campaign-readonly 2 "campaign" "$ro" -- crosscheck shear "$tiny" -s 5e3,1e4 -r 2 --campaign "$ro/c"

# ---- demcal crosscheck silo -----------------------------------------------------------------------------------------
S=(crosscheck silo --campaign camp --particles 100)
run_case crosscheck-silo/theta-nan   2 "theta"           -- "${S[@]}" --theta nan
run_case crosscheck-silo/kernel-law-unknown 2 "--kernel-law" -- "${S[@]}" --theta 30 --kernel-law lammps
run_case crosscheck-silo/kernel-law-rolling 2 "rolling_friction" -- "${S[@]}" --theta 30 --kernel-law yade
run_case crosscheck-silo/kernel-rotation-unknown 2 "--kernel-rotation" -- "${S[@]}" --theta 30 --kernel-rotation omelyan
run_case crosscheck-silo/kernel-rotation-empty 2 "--kernel-rotation" -- "${S[@]}" --theta 30 --kernel-rotation ""
run_case crosscheck-silo/wall-facets-few 2 "--wall-facets = 5" -- "${S[@]}" --theta 30 --wall-facets 5
run_case crosscheck-silo/wall-facets-huge 2 "--wall-facets" -- "${S[@]}" --theta 30 --wall-facets 3000
run_case crosscheck-silo/yade-start-value 2 "--kernel-start-as-yade-import" -- "${S[@]}" --theta 30 --kernel-start-as-yade-import=maybe
run_case crosscheck-silo/theta-subnormal 2 "theta"       -- "${S[@]}" --theta 1e-320
run_case crosscheck-silo/theta-90    2 "theta"           -- "${S[@]}" --theta 90
run_case crosscheck-silo/theta-huge  2 "theta"           -- "${S[@]}" --theta "$huge"
run_case crosscheck-silo/theta-many  2 "theta"           -- "${S[@]}" --theta "$(seq -s, 1 0.01 89)"
run_case crosscheck-silo/theta-dup   2 "theta"           -- "${S[@]}" --theta 30,30
run_case crosscheck-silo/tolerance-subnormal 2 "tolerance" -- "${S[@]}" --theta 30 --tolerance 1e-320
run_case crosscheck-silo/tolerance-nan 2 "tolerance"     -- "${S[@]}" --theta 30 --tolerance nan
run_case crosscheck-silo/max-time-1e99 2 "--max-time 1e+99"      -- "${S[@]}" --theta 30 --max-time 1e99
run_case crosscheck-silo/stiffness-1e99 2 "stiffness"    -- "${S[@]}" --theta 30 --stiffness-scale 1e99
run_case crosscheck-silo/material-folder 2 "folder.json" -- "${S[@]}" --theta 30 --material "$work/folder.json"
run_case crosscheck-silo/material-deep 2 "nest"          -- "${S[@]}" --theta 30 --material "$work/deep.json"
run_case crosscheck-silo/material-shear 2 "material"     -- "${S[@]}" --theta 30 --material "$tiny"
run_case crosscheck-silo/yade-material-missing 2 "no-such" -- "${S[@]}" --theta 30 --yade-material "$work/no-such.json"
run_case crosscheck-silo/geometry-dup 2 "'a'"            -- "${S[@]}" --theta 30 --geometry "$work/dup.json"
run_case crosscheck-silo/campaign-readonly 2 "campaign" "$ro" -- crosscheck silo --theta 30 --particles 100 --campaign "$ro/c"
run_case crosscheck-silo/campaign-file 2 "campaign"      -- crosscheck silo --theta 30 --particles 100 --campaign "$tiny"
run_case crosscheck-silo/timeout-subnormal 2 "--timeout" -- "${S[@]}" --theta 30 --timeout 1e-320
run_case crosscheck-silo/yade-folder 2 "yade"            -- "${S[@]}" --theta 30 --yade "$work/folder.json"
run_case crosscheck-silo/fill-unknown 2 "--fill"         -- "${S[@]}" --theta 30 --fill none
run_case crosscheck-silo/fill-empty  2 "--fill"           -- "${S[@]}" --theta 30 --fill ""
run_case crosscheck-silo/fill-number 2 "--fill"           -- "${S[@]}" --theta 30 --fill 1

# ---- demcal scale ---------------------------------------------------------------------------------------------------
R=(scale "$tiny" --dir camp -s 5e3,1e4,2e4)
run_case scale/radii-nan             2 "radi"            -- "${R[@]}" --radii 1e-3,nan,3e-3
run_case scale/radii-subnormal       2 "radi"            -- "${R[@]}" --radii 1e-3,1e-320,3e-3
run_case scale/radii-two             2 "radi"            -- "${R[@]}" --radii 1e-3,2e-3
run_case scale/radii-decreasing      2 "radi"            -- "${R[@]}" --radii 3e-3,2e-3,1e-3
run_case scale/radii-huge            2 "radi"            -- "${R[@]}" --radii "1e-3,2e-3,$huge"
run_case scale/radii-1e308           2 "radi"            -- "${R[@]}" --radii 1e-3,2e-3,1e308
run_case scale/levels-huge           2 "levels"          -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 --levels 2000000000
run_case scale/levels-1              2 "levels"          -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 --levels 1
run_case scale/replicates-huge       2 "replicates"      -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 -r 2000000000
run_case scale/max-evaluations-huge  2 "failure lines"     -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 --max-evaluations 2000000000
run_case scale/tol-nan               2 "tol"             -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 --tol nan
run_case scale/alpha-subnormal       2 "alpha"           -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 --alpha 1e-320
run_case scale/span-1e308            2 "span"            -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 --span 1e308
run_case scale/range-nan             2 "range"           -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 --range young_modulus=nan:1e8
run_case scale/range-subnormal       2 "range"           -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 --range young_modulus=1e-320:1e8
run_case scale/output-folder         2 "output"          -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 -o "$work/folder.json"
run_case scale/output-readonly       2 "output"  "$ro"   -- "${R[@]}" --radii 1e-3,1.5e-3,2e-3 -o "$ro/s.json"
run_case scale/dir-readonly          2 "campaign" "$ro"   -- scale "$tiny" -s 5e3,1e4,2e4 --radii 1e-3,1.5e-3,2e-3 --dir "$ro/c"
run_case scale/base-deep             2 "nest"            -- scale "$work/deep.json" --dir camp --radii 1e-3,1.5e-3,2e-3
run_case scale/base-folder           2 "folder.json"     -- scale "$work/folder.json" --dir camp --radii 1e-3,1.5e-3,2e-3

run_case calibrate/grid-huge          2 "evaluations"     -- calibrate --start "$tiny" --target mu_b=1.3,tau_c=800 --method grid --grid-points 1000 -s 5e3,1e4,2e4 --campaign camp

# ---- demcal cutoff --------------------------------------------------------------------------------------------------
run_case cutoff/bond-nan             2 "--bond-number"   -- cutoff --bond-number nan
run_case cutoff/bond-subnormal       2 "--bond-number"   -- cutoff --bond-number 1e-320
run_case cutoff/bond-huge            2 "--bond-number"   -- cutoff --bond-number "$huge"
run_case cutoff/bracket-nan          2 "bracket"         -- cutoff --bond-number 10 --bracket nan,400
run_case cutoff/bracket-subnormal    2 "bracket"         -- cutoff --bond-number 10 --bracket 1e-320,400
run_case cutoff/bracket-1e308        2 "bracket"         -- cutoff --bond-number 10 --bracket 0,1e308
run_case cutoff/bracket-huge         2 "bracket"         -- cutoff --bond-number 10 --bracket "0,$huge"
run_case cutoff/bracket-reversed     2 "bracket"         -- cutoff --bond-number 10 --bracket 400,0
run_case cutoff/tol-tiny             2 "tol"             -- cutoff --bond-number 10 --tol 1e-300
run_case cutoff/tol-subnormal        2 "--tol"           -- cutoff --bond-number 10 --tol 1e-320
run_case cutoff/seeds-many           2 "seeds"           -- cutoff --bond-number 10 --seeds "$(seq -s, 1 20000)"
run_case cutoff/seeds-negative       2 "--seeds"         -- cutoff --bond-number 10 --seeds -1
run_case cutoff/grains-huge          2 "--grains"        -- cutoff --bond-number 10 --grains 2000000000
run_case cutoff/window-nan           2 "--window"        -- cutoff --bond-number 10 --window nan
run_case cutoff/window-long          2 "--window"        -- cutoff --bond-number 10 --window 61
run_case cutoff/criterion-empty      2 "--criterion: an empty value" -- cutoff --bond-number 10 --criterion ""
run_case cutoff/json-folder          2 "--json"          -- cutoff --bond-number 10 --json "$work/folder.json"
run_case cutoff/json-readonly        2 "--json"  "$ro"   -- cutoff --bond-number 10 --json "$ro/c.json"
run_case cutoff/json-no-folder       2 "--json"          -- cutoff --bond-number 10 --json /no/such/c.json
meal="$here/examples/materials/silo_meal.json"
run_case cutoff/silo-tol-tiny        2 "--tol"           -- cutoff --tol 1e-300 -- --material "$meal" --theta 30
run_case cutoff/silo-dt-fraction     2 "--dt-fraction = "  -- cutoff -- --material "$meal" --theta 30 --dt-fraction 1e-300
run_case cutoff/silo-particles-nan   2 "--particles"     -- cutoff -- --material "$meal" --theta 30 --particles nan
run_case cutoff/silo-stiffness-sub   2 "--stiffness-scale" -- cutoff -- --material "$meal" --theta 30 --stiffness-scale 1e-320
run_case cutoff/silo-out             2 "--out"           -- cutoff -- --material "$meal" --theta 30 --out o
run_case cutoff/campaign-readonly    2 "campaign" "$ro"  -- cutoff --campaign "$ro/c" -- --material "$meal" --theta 30
run_case cutoff/campaign-file        2 "campaign"        -- cutoff --campaign "$tiny" -- --material "$meal" --theta 30
run_case cutoff/jobs-0               2 "--jobs"          -- cutoff --jobs 0 -- --material "$meal" --theta 30
run_case cutoff/jobs-hopper          2 "--jobs"          -- cutoff --bond-number 10 --jobs 2
run_case cutoff/executor-unknown     2 "--executor"      -- cutoff --executor cloud -- --material "$meal" --theta 30

# ---- demcal vibration -----------------------------------------------------------------------------------------------
V=(vibration --campaign camp --theta 30 --frequency 0,50 --amplitude 1e-4)
run_case vibration/theta-nan         2 "theta"           -- vibration --campaign camp --theta nan --frequency 0 --amplitude 1e-4
run_case vibration/frequency-subnormal 2 "frequency"     -- vibration --campaign camp --theta 30 --frequency 1e-320 --amplitude 1e-4
run_case vibration/frequency-1e308   2 "frequency"       -- vibration --campaign camp --theta 30 --frequency 1e308 --amplitude 1e-4
run_case vibration/part-bad          2 "--part"          -- vibration --campaign camp --theta 30 --frequency 50 --amplitude 1e-4 --part "$hugestr"
run_case vibration/part-as-silo-arg  2 "--vibration-part" -- vibration --campaign camp --theta 30 --frequency 50 --amplitude 1e-4 -- --vibration-part hopper
run_case vibration/amplitude-huge    2 "amplitude"       -- vibration --campaign camp --theta 30 --frequency 50 --amplitude "$huge"
run_case vibration/repeats-huge      2 "repeats"         -- "${V[@]}" --repeats 2000000000
run_case vibration/theta-list-huge   2 "--theta"         -- vibration --campaign camp --theta "$(seq -s, 5 0.01 85)" --frequency 0 --amplitude 1e-4
run_case vibration/cells-many        2 "runs"            -- vibration --campaign camp --theta "$(seq -s, 5 0.1 85)" --frequency "$(seq -s, 0 1 1000)" --amplitude 1e-4
run_case vibration/silo-args-bad     2 "--dt"            -- "${V[@]}" -- --dt 1e-320
run_case vibration/silo-args-vib     2 "vibration"       -- "${V[@]}" -- --vibration-frequency 5
run_case vibration/campaign-readonly 2 "campaign" "$ro"  -- vibration --campaign "$ro/c" --theta 30 --frequency 0 --amplitude 1e-4
run_case vibration/campaign-file     2 "campaign"        -- vibration --campaign "$tiny" --theta 30 --frequency 0 --amplitude 1e-4

# ---- demcal silo: --export-bed, --vibration-*, output paths ---------------------------------------------------------
L=(silo --theta 30 --particles 200 --no-plots --max-time 0.05 --fill-time 0.05)
run_case silo/aspect-subnormal        2 "grain.aspect_ratio' = 1e-320" -- "${L[@]}" --material "$work/aspect_subnormal.json"
run_case silo/aspect-huge             2 "grain.aspect_ratio' = 1e+308" -- "${L[@]}" --material "$work/aspect_huge.json"
run_case silo/aspect-apart            2 "grain.aspect_ratio = 2.7"    -- "${L[@]}" --material "$work/aspect_apart.json"
run_case silo/aspect-flat             2 "grain.aspect_ratio = 0.9"    -- "${L[@]}" --material "$work/aspect_flat.json"
run_case silo/aspect-text             2 "grain.aspect_ratio"          -- "${L[@]}" --material "$work/aspect_text.json"
run_case silo/export-bed-folder      2 "--export-bed"    -- "${L[@]}" --export-bed "$work/folder.json"
run_case silo/export-bed-no-folder   2 "--export-bed"    -- "${L[@]}" --export-bed /no/such/b.json
run_case silo/export-bed-readonly    2 "--export-bed" "$ro" -- "${L[@]}" --export-bed "$ro/b.json"
run_case silo/export-bed-empty       2 "--export-bed"    -- "${L[@]}" --export-bed ""
run_case silo/export-bed-resume      2 "--export-bed"    -- silo --resume somewhere --export-bed b.json
run_case silo/export-cloud-folder    2 "--export-cloud"  -- "${L[@]}" --export-cloud "$work/folder.json"
run_case silo/export-cloud-no-folder 2 "--export-cloud"  -- "${L[@]}" --export-cloud /no/such/c.json
run_case silo/export-cloud-readonly  2 "--export-cloud" "$ro" -- "${L[@]}" --export-cloud "$ro/c.json"
run_case silo/export-cloud-resume    2 "--export-cloud"  -- silo --resume somewhere --export-cloud c.json
run_case silo/forget-history-value   2 "--forget-contact-history" -- "${L[@]}" --forget-contact-history=maybe
run_case silo/forget-history-resume  2 "--forget-contact-history" -- silo --resume somewhere --forget-contact-history
run_case silo/contact-law-unknown     2 "--contact-law"   -- "${L[@]}" --contact-law lammps
run_case silo/contact-law-rolling     2 "grain_grain.rolling_friction = 0.01" -- "${L[@]}" --contact-law yade
run_case silo/contact-law-resume      2 "--contact-law"   -- silo --resume somewhere --contact-law yade
run_case silo/rotation-unknown        2 "--discharge-rotation" -- "${L[@]}" --discharge-rotation "$hugestr"
run_case silo/rotation-resume         2 "--discharge-rotation" -- silo --resume somewhere --discharge-rotation yade
run_case silo/wall-facets-few         2 "--discharge-wall-facets = 5" -- "${L[@]}" --discharge-wall-facets 5
run_case silo/wall-facets-huge        2 "--discharge-wall-facets" -- "${L[@]}" --discharge-wall-facets 99999999999999
run_case silo/wall-facets-text        2 "--discharge-wall-facets" -- "${L[@]}" --discharge-wall-facets many
run_case silo/wall-facets-resume      2 "--discharge-wall-facets" -- silo --resume somewhere --discharge-wall-facets 72
run_case silo/yade-start-and-forget   2 "--start-as-yade-import" -- "${L[@]}" --start-as-yade-import --forget-contact-history
run_case silo/yade-start-resume       2 "--start-as-yade-import" -- silo --resume somewhere --start-as-yade-import
run_case silo/final-bed-folder        2 "--export-final-bed" -- "${L[@]}" --export-final-bed "$work/folder.json"
run_case silo/final-bed-readonly      2 "--export-final-bed" "$ro" -- "${L[@]}" --export-final-bed "$ro/e.json"
run_case silo/final-bed-resume        2 "--export-final-bed" -- silo --resume somewhere --export-final-bed e.json
run_case silo/out-readonly           2 "out"     "$ro"   -- "${L[@]}" --out "$ro/o"
run_case silo/out-file               2 "out"             -- "${L[@]}" --out "$tiny"
run_case silo/vtk-readonly           2 "vtk"     "$ro"   -- "${L[@]}" --vtk "$ro/v"
run_case silo/vtk-file               2 "vtk"             -- "${L[@]}" --vtk "$tiny"
run_case silo/resume-readonly        2 "resume"  "$ro"   -- silo --resume "$ro"
run_case silo/vib-frequency-nan      2 "vibration-frequency" -- "${L[@]}" --vibration-frequency nan --vibration-amplitude 1e-4
run_case silo/vib-frequency-subnormal 2 "vibration-frequency" -- "${L[@]}" --vibration-frequency 1e-320 --vibration-amplitude 1e-4
run_case silo/vib-frequency-1e308    2 "vibration-frequency" -- "${L[@]}" --vibration-frequency 1e308 --vibration-amplitude 1e-4
run_case silo/vib-frequency-negative 2 "--vibration-frequency = -5" -- "${L[@]}" --vibration-frequency -5 --vibration-amplitude 1e-4
run_case silo/vib-amplitude-huge     2 "vibration-amplitude" -- "${L[@]}" --vibration-frequency 50 --vibration-amplitude "$huge"
run_case silo/vib-amplitude-alone    2 "vibration-amplitude" -- "${L[@]}" --vibration-amplitude 1e-4
run_case silo/vib-direction-bad      2 "vibration-direction" -- "${L[@]}" --vibration-frequency 50 --vibration-amplitude 1e-4 --vibration-direction "$hugestr"
run_case silo/vib-part-bad           2 "vibration-part" -- "${L[@]}" --vibration-frequency 50 --vibration-amplitude 1e-4 --vibration-part "$hugestr"
run_case silo/vib-part-no-vib        2 "vibration-part" -- "${L[@]}" --vibration-part hopper
run_case silo/vib-start-nan          2 "vibration-start" -- "${L[@]}" --vibration-frequency 50 --vibration-amplitude 1e-4 --vibration-start nan
run_case silo/vib-start-1e99         2 "--vibration-start = 1e+99" -- "${L[@]}" --vibration-frequency 50 --vibration-amplitude 1e-4 --vibration-start 1e99
run_case silo/vib-start-no-vib       2 "vibration-start" -- "${L[@]}" --vibration-start 1
run_case silo/dt-subnormal           2 "dt"              -- "${L[@]}" --dt 1e-320
run_case silo/dt-fraction-tiny       2 "--dt-fraction = "  -- "${L[@]}" --dt-fraction 1e-300
run_case silo/dt-tiny                2 "dt = 1e-300"    -- "${L[@]}" --dt 1e-300
run_case silo/vtk-every-tiny         2 "--vtk-every"     -- "${L[@]}" --vtk v --vtk-every 1e-300
run_case silo/particles-huge         2 "particles"       -- "${L[@]}" --particles 99999999999999
run_case silo/material-deep          2 "nest"            -- "${L[@]}" --material "$work/deep.json"
run_case silo/geometry-folder        2 "folder.json"     -- "${L[@]}" --geometry "$work/folder.json"

# ---- demcal diagnose --model silo-dem: the run-count guard -----------------------------------------------------------
printf 'theta_deg,rate_g_s\n30,160\n30,162\n50,120\n70,100\n' > "$work/rates.csv"
D=(diagnose --model silo-dem --data "$work/rates.csv" --material "$wheat" --campaign camp)
run_case diagnose-dem/max-runs-0     2 "--max-runs"      -- "${D[@]}" --max-runs 0 -- --particles 200
run_case diagnose-dem/max-runs-nan   2 "--max-runs"      -- "${D[@]}" --max-runs nan -- --particles 200
run_case diagnose-dem/max-runs-huge  2 "--max-runs"      -- "${D[@]}" --max-runs "$huge" -- --particles 200
run_case diagnose-dem/plan-too-big   2 "--max-runs = 100" -- "${D[@]}" --max-runs 100 --seeds 20 -- --particles 200
run_case diagnose-dem/max-runs-oldal 2 "--max-runs"      -- diagnose --model oldal --data "$work/rates.csv" --max-runs 5
run_case diagnose-dem/aspect-material 2 "grain.aspect_ratio = 2.7" -- diagnose --model silo-dem --data "$work/rates.csv" --material "$work/aspect_apart.json" --campaign camp -- --particles 200

# ---- the issue's own examples on the older commands (replayed 2026-12-03) --------------------------------------------
G="$work/geometry.json"
printf '{"geometry":"conical","D_m":0.105,"outlet_m":0.035,"theta_deg":30,"d_p_m":0.004,"rho_b_kg_m3":780}' > "$G"
sed 's/"theta_deg":30/"theta_deg":1e-320/' "$G" > "$work/geometry_theta_sub.json"
sed 's/"rho_b_kg_m3":780/"rho_b_kg_m3":1e308/' "$G" > "$work/geometry_rho_huge.json"
run_case predict/theta-subnormal     2 "theta_deg"       -- predict "$work/geometry_theta_sub.json"
run_case predict/density-1e308       2 "rho_b_kg_m3"     -- predict "$work/geometry_rho_huge.json"
run_case predict/geometry-deep       2 "nest"            -- predict "$work/deep.json"
run_case predict/json-folder         2 "folder.json"     -- predict "$G" --json "$work/folder.json"
run_case silo/fill-mass-0            2 "--fill-mass = 0" -- silo --theta 30 --fill-mass 0 --check
run_case silo/fill-mass-below-grain  2 "--fill-mass = "       -- silo --theta 30 --fill-mass 1e-9 --check
run_case silo/seed-2^64              2 "--seed"          -- silo --theta 30 --seed 18446744073709551616 --check
mkdir -p "$work/zero_store" "$work/foreign_store"
: > "$work/zero_store/campaign.sqlite"
python3 -c "import sqlite3,sys; c=sqlite3.connect(sys.argv[1]); c.execute('create table foo(x)'); c.commit()" \
  "$work/foreign_store/campaign.sqlite"
for store in zero_store foreign_store; do  # the folder is watched: not even a lock file may be left in it
    run_case "status/$store"         2 "not a demcal campaign store" "$work/$store" -- status "$work/$store"
    run_case "resume/$store"         2 "not a demcal campaign store" "$work/$store" -- resume "$work/$store"
done
run_case calibrate/tau-c-negative    2 "tau_c = -100"    -- calibrate --target mu_b=0.5,tau_c=-100 --start "$tiny" -c camp
run_case calibrate/measured-negative 2 "measured point 1" -- calibrate --measured -5000:3000,1e4:6e3,1.5e4:9e3 --start "$tiny" -c camp
python3 - "$tiny" "$work" <<'EOF2'
import json, sys
m = json.load(open(sys.argv[1]))
for r in (0.0025, 0.003):
    m.update(particle_radius=r, young_modulus=1e10 * r + 5e6, poisson_ratio=0.01 / r ** 0.5, box_height=0.05)
    json.dump(m, open("%s/enlarge_%g.json" % (sys.argv[2], r), "w"))
EOF2
run_case enlarge/same-radius-twice   2 "both have particle_radius" -- enlarge --no-plot -o e.json "$work/enlarge_0.0025.json" "$work/enlarge_0.003.json" "$work/enlarge_0.003.json"

# probe 57 (a helper's hostile pass of 650 cases): option names as values, void pairs, absurd targets, soft walls
run_case silo/out-is-option          2 "--out: '--check' is an option" -- silo --theta 30 --particles 200 --out --check
run_case cutoff/seeds-before-dashes  2 "--grains applies to the small hopper" -- cutoff --grains 100 --seeds 1 -- --theta 50
run_case cutoff/help-after-dashes    2 "-h/--help after --" -- cutoff --seeds 1 -- --theta 30 -h
run_case cutoff/max-window-short     2 "max_window = 2 s" -- cutoff --bond-number 10 --window 5 --max-window 2
run_case silo/dt-and-fraction        2 "--dt-fraction and --dt" -- silo --theta 30 --dt 1e-5 --dt-fraction 0.9 --out s
run_case calibrate/tau-c-zero        2 "tau_c = 0"       -- calibrate --target mu_b=0.5,tau_c=0 --start "$tiny" --engine kernel -o c.json
run_case calibrate/mu-b-huge         2 "below 85 deg"    -- calibrate --target mu_b=1e9 --start "$tiny" --engine kernel -o c.json
run_case calibrate/target-trailing   2 "empty item"      -- calibrate --target mu_b=0.55, --start "$tiny" --engine kernel -o c.json
run_case scale/radii-too-close       2 "differ by less than 1 %" -- scale "$tiny" --radii 1e-3,1.0000001e-3,1.0000002e-3 -c sc
run_case sensitivity/range-not-param 2 "not among --params" -- sensitivity "$tiny" --engine kernel --params young_modulus --range friction_coefficient=0.1:0.9 -c se
python3 - "$wheat" "$work" <<'EOF3'
import json, sys
m = json.load(open(sys.argv[1]))
m["wall"]["shear_modulus_Pa"] = 1e3
json.dump(m, open("%s/soft_wall.json" % sys.argv[2], "w"))
EOF3
run_case silo/soft-wall              2 "wall.shear_modulus_Pa" -- silo --theta 30 --particles 300 --stiffness-scale 0.01 --material "$work/soft_wall.json" --out s
printf 'sigma_Pa,tau_Pa\n5000,3000\n5000.0000001,3100\n5000.0000002,3050\n' > "$work/close.csv"
run_case diagnose/stresses-too-close 2 "sigma_Pa: 5000 to 5000" -- diagnose --model failure-line --data "$work/close.csv" --json d.json

echo
echo "hostile sweep: $pass passed, $fail failed"
for f in "${failures[@]}"; do echo "  $f"; done
[ "$fail" = 0 ]
