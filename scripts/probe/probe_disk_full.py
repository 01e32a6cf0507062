#!/usr/bin/env python3
"""Probe of issue 23's "nothing is lost or half-written" when the disk fills up under a command.

Every command that writes files runs with its outputs on a small tmpfs (a few sizes, from one page up), so that a
write fails part way with ENOSPC. Then, for each case:
  - the exit code is never a signal or the time limit; exit 0 only with every declared output present and readable;
  - a failure names the lack of space on one line of stderr;
  - nothing half-written is left: no temporary file, no empty or unparsable JSON, a campaign store that passes
    SQLite's integrity check;
  - after the tmpfs is grown (a remount keeps its files) the same command, or `demcal resume`, finishes with exit 0
    and valid outputs: nothing of what was done is lost.
Needs root (mount). Usage: python3 scripts/probe/probe_disk_full.py BUILD/app/demcal REPO [SIZES]
(SIZES: comma-separated tmpfs sizes, default 4k,16k,64k,256k,1m). Prints one line per case and size; exit 1 if any
case was flagged. Runtime: a few minutes (small kernel runs only).
"""
import json
import os
import sqlite3
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import probe_common  # noqa: E402

demcal, repo = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
sizes = (sys.argv[3] if len(sys.argv) > 3 else "4k,16k,64k,256k,1m").split(",")
ex = lambda p: os.path.join(repo, "examples", p)
scratch = tempfile.mkdtemp(prefix="demcal-diskfull.")

# inputs outside the tmpfs
params = probe_common.tiny_shear_params(repo)
params_file = os.path.join(scratch, "params.json")
json.dump(params, open(params_file, "w"))
enlarge_inputs = []
for r in (0.001, 0.0012, 0.0015, 0.002):  # within sand-tiny's box (4 particle lengths high)
    m = dict(params)
    m.pop("normal_stress"); m.pop("seed")
    m.update(particle_radius=r, young_modulus=1e10 * r + 5e6, poisson_ratio=0.01 / r ** 0.5)
    f = os.path.join(scratch, "m%g.json" % r)
    json.dump(m, open(f, "w"))
    enlarge_inputs.append(f)

SMALL_SILO = probe_common.small_silo_args(repo) + ["--no-plots"]

SELECT = os.environ.get("PROBE_CASES", "")  # a regular expression over the case names
# name, arguments ({o}: the tmpfs), outputs that exit 0 promises (relative to the tmpfs), the command that finishes it
CASES = [
    ("predict --json", ["predict", ex("diagnose/silo_105mm_wheat.json"), "--json", "{o}/p.json"], ["p.json"], None),
    ("diagnose --report --json", ["diagnose", "--model", "oldal", "--data", ex("diagnose/oldal_clean.csv"),
                                  "--report", "{o}/r.md", "--json", "{o}/r.json"], ["r.md", "r.json"], None),
    ("enlarge -o", ["enlarge", "-o", "{o}/e.json"] + enlarge_inputs, ["e.json"], None),
    ("shear-run", ["shear-run", params_file, "{o}/result.json"], ["result.json"], None),
    ("shear --engine kernel", ["shear", ex("materials/sand-tiny.json"), "--engine", "kernel", "--normal-stress",
                               "5e3,1e4,2e4", "--replicates", "1", "--jobs", "2", "--campaign", "{o}/camp"],
     ["camp/campaign.sqlite"], ["resume", "{o}/camp"]),
    ("silo", ["silo"] + SMALL_SILO + ["--out", "{o}/silo"], ["silo/summary.json", "silo/discharge.csv"], None),
    ("shear (YADE)", ["shear", ex("materials/sand-tiny.json"), "--normal-stress", "5e3,1e4,2e4", "--replicates", "1",
                      "--jobs", "2", "--campaign", "{o}/camp"], ["camp/campaign.sqlite"], ["resume", "{o}/camp"]),
    ("vibration", ["vibration", "--theta", "70", "--frequency", "0,100", "--amplitude", "1e-4", "--repeats", "1",
                   "--jobs", "2", "--campaign", "{o}/vib", "--"] + SMALL_SILO,
     ["vib/vibration.json"], None),
    ("cutoff --json", ["cutoff", "--bond-number", "10", "--grains", "200", "--bracket", "0,400", "--tol", "200",
                       "--seeds", "1", "--json", "{o}/c.json"], ["c.json"], None),
    ("scale --engine kernel", ["scale", ex("materials/sand-scale-tiny.json"), "--radii", "2e-3,3e-3,4e-3",
                               "--normal-stress", "4e3,6e3,8e3", "--replicates", "1", "--max-evaluations", "2",
                               "--engine", "kernel", "--allow-unconverged", "--jobs", "2", "--dir", "{o}/scale",
                               "-o", "{o}/scale.json"], ["scale.json"], None),
]
# sizes at which a campaign gets past its start (the kernel engine copies the demcal binary, about 6 MB, into it)
# and the disk fills while its runs and report are written
LATE_SIZES = {"shear --engine kernel": ["6300k", "6600k", "7m"], "vibration": ["64k", "256k", "1m", "4m"],
              "scale --engine kernel": ["6400k", "6700k", "7m", "8m"]}


def run(args, o, limit=600):
    a = [x.replace("{o}", o) for x in args]
    try:
        p = subprocess.run([demcal] + a, capture_output=True, text=True, timeout=limit, cwd=scratch)
        return p.returncode, p.stderr
    except subprocess.TimeoutExpired:
        return 124, "(time limit)"


def damaged_files(o):
    """Files a failure may not leave: temporaries, empty or unparsable JSON, a store that fails its check."""
    bad = []
    for root, _, files in os.walk(o):
        for f in files:
            p = os.path.join(root, f)
            rel = os.path.relpath(p, o)
            if ".tmp" in f:
                bad.append(rel + " (a temporary file)")
            elif f.endswith(".json"):
                try:
                    json.load(open(p))
                except Exception as e:
                    bad.append(rel + " (not JSON: %s)" % str(e)[:60])
            elif f.endswith(".sqlite"):
                try:
                    c = sqlite3.connect("file:%s?mode=ro" % p, uri=True)
                    ok = c.execute("PRAGMA integrity_check").fetchone()[0]
                    c.close()
                    if ok != "ok":
                        bad.append(rel + " (integrity: %s)" % ok[:60])
                except Exception as e:
                    bad.append(rel + " (store: %s)" % str(e)[:60])
    return bad


def check_outputs(o, outputs):
    missing = [f for f in outputs if not os.path.isfile(os.path.join(o, f)) or
               os.path.getsize(os.path.join(o, f)) == 0]
    return missing


flagged = 0
import re
for name, args, outputs, finish in CASES:
    if SELECT and not re.search(SELECT, name):
        continue
    for size in LATE_SIZES.get(name, []) + sizes if len(sys.argv) <= 3 else sizes:
        o = tempfile.mkdtemp(prefix="full.", dir=scratch)
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=" + size, "tmpfs", o], check=True)
        try:
            rc, err = run(args, o)
            notes = []
            if rc == 124 or rc < 0 or rc >= 128:
                notes.append("rc=%d (signal or time limit)" % rc)
            lines = [line for line in err.splitlines() if line.strip()]
            last = lines[-1] if lines else ""
            if rc == 0:
                missing = check_outputs(o, outputs)
                if missing:
                    notes.append("exit 0 without " + ", ".join(missing))
            elif "space" not in err and "No space" not in err and rc != 2:
                notes.append("failure does not name the lack of space")
            damaged = damaged_files(o)
            if damaged:
                notes.append("left: " + "; ".join(damaged[:4]))
            # grow the file system (a remount keeps its files): a failed command, run again (or resumed where it
            # left a campaign), must finish, and nothing it did before is lost
            subprocess.run(["mount", "-o", "remount,size=256m", o], check=True)
            if rc != 0:
                again = finish if finish and os.path.exists(os.path.join(o, outputs[0])) else args
                rc2, err2 = run(again, o)
                if rc2 != 0:
                    notes.append("after growing: rc=%d: %s" % (rc2, (err2.strip().splitlines() or [""])[-1][:160]))
                else:
                    missing = check_outputs(o, outputs)
                    damaged = damaged_files(o)
                    if missing or damaged:
                        notes.append("after growing: missing %s, left %s" % (missing, damaged[:3]))
            status = "FLAG" if notes else "ok"
            flagged += bool(notes)
            print("%-4s %-26s %-5s rc=%d  %s | %s" % (status, name, size, rc, last[:150], "; ".join(notes)),
                  flush=True)
        finally:
            subprocess.run(["umount", "-l", o])
            os.rmdir(o)
sys.exit(1 if flagged else 0)
