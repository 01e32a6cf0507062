#!/usr/bin/env python3
"""Hostile-value probe of every field of every JSON input demcal reads (issue 23): each leaf field of a valid file in
turn gets "", null, true, [], {}, subnormal, huge, -1, 0, -0, "nan", a 100 kB string, 2^64, small and list values, is
deleted, and an unknown field is added. Each case runs under a 4 s limit, then SIGTERM. One line per case: exit code,
flags (as scripts/probe/probe_options.py), the last output line.
Usage: python3 scripts/probe/probe_json_fields.py build/app/demcal . [KIND] > out.txt   (J=2 parallel; about 15 min)
Not a test: a probe for a person to read; its findings become tests (tests/orchestrator/test_hostile_cli.cpp)."""
import copy, json, os, shutil, subprocess, sys, tempfile, time, concurrent.futures as cf
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from probe_common import not_one_line, run_bounded, setup  # noqa: E402
demcal, repo, only, WORK, FIX = setup(sys.argv)
ex = repo + "/examples"
kinds = {  # name: (source file, argv with FILE for the mutated copy)
 "shear-material": (ex + "/materials/sand-tiny.json", ["shear", "FILE", "-s", "5000,8000,11000", "--engine", "kernel", "-c", "camp"]),
 "shear-run-params": (FIX + "/params.json", ["shear-run", "FILE", "result.json"]),
 "silo-material": (ex + "/materials/silo_wheat_table21.json", ["silo", "--theta", "30", "--material", "FILE", "--check"]),
 "silo-geometry": (ex + "/silo/seed_conical_30deg.json", ["silo", "--geometry", "FILE", "--check"]),
 "predict-geometry": (ex + "/diagnose/silo_105mm_wheat.json", ["predict", "FILE", "--json", "out.json"]),
 "enlarge-material": (FIX + "/E2.json", ["enlarge", FIX + "/E1.json", "FILE", FIX + "/E3.json", "--no-plot", "--allow-unconverged", "-o", "en.json"]),
 "sensitivity-file": (ex + "/calibration/kernel-sand-bonded-far/sensitivity.json", ["calibrate", "--target", "mu_b=0.5,tau_c=100", "--start", FIX + "/sens_base.json", "--sensitivity", "FILE", "--engine", "kernel", "-c", "cal"]),
 "calibrate-start": (ex + "/materials/sand-tiny.json", ["calibrate", "--target", "mu_b=0.5,tau_c=100", "--start", "FILE", "--engine", "kernel", "-c", "cal"]),
}
vals = ["", None, True, [], {}, 1e-320, 1e308, -1, 0, -0.0, "nan", "x" * 100000, 2**64, 0.5, 3, [1, 2], "1e3"]
DEL = object()
def leaves(j, path=()):
    if isinstance(j, dict):
        for k, v in j.items():
            yield from leaves(v, path + (k,))
    else:
        yield path
def setp(j, path, v):
    for k in path[:-1]: j = j[k]
    if v is DEL: del j[path[-1]]
    else: j[path[-1]] = v
def run(kind, path, val):
    src, argv = kinds[kind]
    d = tempfile.mkdtemp(dir=WORK)
    j = json.load(open(src))
    if path == ("+unknown",):
        j["bogus_field"] = 1
    else:
        setp(j, path, val if val is DEL else copy.deepcopy(val))
    json.dump(j, open(d + "/in.json", "w"))
    argv = [a if a != "FILE" else "in.json" for a in argv]
    rc, out, new = run_bounded([demcal] + argv, d)
    shutil.rmtree(d, ignore_errors=True)
    return kind, path, val, rc, out, new
jobs = []
for kind, (src, _) in kinds.items():
    if only and kind != only: continue
    j = json.load(open(src))
    for path in leaves(j):
        if path[-1] in ("name", "description", "_comment"): continue
        for v in vals + [DEL]: jobs.append((kind, path, v))
    jobs.append((kind, ("+unknown",), None))
print(len(jobs), "cases", file=sys.stderr)
with cf.ThreadPoolExecutor(int(os.environ.get("J", "2"))) as pool:
    for kind, path, val, rc, out, new in pool.map(lambda a: run(*a), jobs):
        v = "DELETED" if val is DEL else json.dumps(val)
        v = v if len(v) < 25 else v[:10] + "...(%d)" % len(v)
        field = ".".join(path)
        first = out.strip().split("\n")[-1][:220] if out.strip() else ""
        flags = []
        if rc >= 128 or rc < 0: flags.append("SIGNAL")
        if rc == 124: flags.append("RAN")
        if rc == 125 or out.startswith("ORPHANS"): flags.append("NOSTOP")
        if rc == 2 and path[-1] not in out and "bogus" not in out: flags.append("UNNAMED")
        if not_one_line(rc, out): flags.append("NOTONELINE")
        if len(out) > 4000: flags.append("LONG")
        if rc not in (0, 2, 124): flags.append("RC%d" % rc)
        if rc == 2 and new: flags.append("WROTE:" + ",".join(new))
        print("%-17s %-28s %-22s rc=%-3d %-14s %s" % (kind, field, v, rc, " ".join(flags), first), flush=True)
shutil.rmtree(WORK, ignore_errors=True)
