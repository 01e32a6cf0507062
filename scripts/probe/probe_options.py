#!/usr/bin/env python3
"""Hostile-value probe of every value-taking option of every demcal command (issue 23): each option of a valid
command line in turn gets "", subnormal, huge, negative, NaN, inf, 0, -0, hex, padded, list, 2^63, a 100 kB word,
folders and devices, and paths holding a newline, shell quoting or UTF-8 (PROBE_VALUES='["a", "b"]' tries others,
PROBE_OPTIONS=REGEX only the options it matches). Each case runs under a 4 s limit, then SIGTERM (a command that does not stop within 20 s, or that
leaves processes behind, is flagged NOSTOP). One line per case: exit code, flags (SIGNAL, NOSTOP, RC<n> for an exit
other than 0/2, UNNAMED for a refusal not naming the option, NOTONELINE for one that is not one line beginning
"demcal: error: " (or the worker's DEMCAL_FAILURE), LONG for > 4 kB of output, WROTE for files left by a
refusal, RAN for a value accepted and run until the limit: review those by hand), the last message line.
Usage: python3 scripts/probe/probe_options.py build/app/demcal . [COMMAND] > out.txt   (J=2 parallel; about 25 min)
Not a test: a probe for a person to read; its findings become tests (tests/orchestrator/test_hostile_cli.cpp)."""
import time, json, os, re, shutil, subprocess, sys, tempfile, concurrent.futures as cf
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from probe_common import not_one_line, run_bounded, setup  # noqa: E402
demcal, repo, only, WORK, FIX = setup(sys.argv)
ex = repo + "/examples"
base = {
 "shear": ["shear", ex+"/materials/sand-tiny.json", "--normal-stress", "5000,8000,11000", "--engine", "kernel", "--campaign", "camp", "--replicates", "1"],
 "shear-run": ["shear-run", "PARAMS", "result.json"],
 "crosscheck shear": ["crosscheck", "shear", ex+"/materials/sand-tiny.json", "--normal-stress", "5000,8000,11000", "--replicates", "1", "--campaign", "cc"],
 "crosscheck silo": ["crosscheck", "silo", "--particles", "20", "--theta", "30", "--campaign", "cs"],
 "silo": ["silo", "--theta", "30", "--particles", "100", "--max-time", "0.01", "--fill-time", "0.01", "--no-plots", "--out", "o"],
 "cutoff": ["cutoff", "--grains", "10"],
 "vibration": ["vibration", "--theta", "30", "--frequency", "10", "--campaign", "v", "--repeats", "1", "--amplitude", "1e-4", "--", "--particles", "100", "--max-time", "0.01", "--fill-time", "0.01"],
 "predict": ["predict", ex+"/diagnose/silo_105mm_wheat.json"],
 "diagnose": ["diagnose", "--model", "beverloo", "--data", ex+"/diagnose/beverloo_hopper_angle.csv", "--no-plots"],
 "sensitivity": ["sensitivity", ex+"/materials/sand-tiny.json", "--engine", "kernel", "--replicates", "1", "--campaign", "sc"],
 "calibrate": ["calibrate", "--target", "mu_b=0.5,tau_c=100", "--start", ex+"/materials/sand-tiny.json", "--engine", "kernel", "--campaign", "cal"],
 "enlarge": ["enlarge", FIX + "/E1.json", FIX + "/E2.json", FIX + "/E3.json", "--no-plot", "--allow-unconverged"],
 "scale": ["scale", ex+"/materials/sand-tiny.json", "--radii", "1e-3,1.5e-3,2e-3", "--engine", "kernel", "--campaign", "scl"],
}
vals = ["", "1e-320", "1e308", "-1", "nan", "inf", "0", "-0", "5abc", "0x10", " 5", "1,2", "9223372036854775808",
        "x" * 100000, "/", "/dev/null", "nonexist/x.json", "1e-5", "3.5", "@", "-5e-3",
        "new\nline", "sp ace'q\"$(x)", "\u00fcml\u00e4ut.json"]  # paths: a control character, shell quoting, UTF-8
if os.environ.get("PROBE_VALUES"):  # a comma-free Python list of the values to try instead (a second pass on a few)
    vals = eval(os.environ["PROBE_VALUES"])
def options(cmd):
    out = subprocess.run([demcal] + cmd.split() + ["--help"], capture_output=True, text=True).stdout
    opts = []
    for line in out.split("\n"):
        m = re.match(r"\s+((?:-\w,)?--[\w-]+(?:,--[\w-]+)*)\s+(\S+)", line)
        if not m: continue
        names, typ = m.group(1), m.group(2)
        if not re.match(r"(INT|FLOAT|TEXT)", typ): continue
        longname = [n for n in names.split(",") if n.startswith("--")][0]
        if longname == "--help": continue
        opts.append(longname)
    return opts
# (the base command lines spell their options as --help lists them, so that a probed option replaces its value
# instead of being given twice)
def run(cmd, opt, val):
    d = tempfile.mkdtemp(dir=WORK)
    argv = list(base[cmd])
    if "PARAMS" in argv:
        shutil.copy(FIX + "/params.json", d + "/params.json"); argv[argv.index("PARAMS")] = "params.json"
    # replace an option already in the base line
    if opt in argv:
        i = argv.index(opt); argv[i + 1] = val
    elif "--" in argv:
        i = argv.index("--"); argv[i:i] = [opt, val]
    else:
        argv += [opt, val]
    rc, err, new = run_bounded([demcal] + argv, d)
    if rc == 124 and not err.startswith("ORPHANS"):
        err = ""
    shutil.rmtree(d, ignore_errors=True)
    return cmd, opt, val, rc, err, new
jobs = []
for cmd in base:
    if only and cmd != only: continue
    for opt in options(cmd):
        if not re.fullmatch(os.environ.get("PROBE_OPTIONS", ".*"), opt): continue  # e.g. PROBE_OPTIONS='--campaign'
        for v in vals:
            jobs.append((cmd, opt, v))
print(len(jobs), "cases", file=sys.stderr)
with cf.ThreadPoolExecutor(int(os.environ.get("J", "2"))) as pool:
    for cmd, opt, val, rc, err, new in pool.map(lambda a: run(*a), jobs):
        v = val if len(val) < 30 else val[:10] + "...(%d)" % len(val)
        first = err.strip().split("\n")[0][:200] if err.strip() else ""
        flags = []
        if rc >= 128 or rc < 0: flags.append("SIGNAL")
        if rc == 124: flags.append("RAN")
        if rc == 125 or err.startswith("ORPHANS"): flags.append("NOSTOP")
        if rc == 2 and opt.lstrip("-") not in err and opt not in err: flags.append("UNNAMED")
        if not_one_line(rc, err): flags.append("NOTONELINE")
        if len(err) > 4000: flags.append("LONG")
        if rc not in (0, 2, 124): flags.append("RC%d" % rc)
        if rc != 0 and new and rc != 124: flags.append("WROTE:" + ",".join(new))
        print("%-16s %-22s %-22r rc=%-3d %-16s %s" % (cmd, opt, v, rc, " ".join(flags), first), flush=True)
shutil.rmtree(WORK, ignore_errors=True)
