#!/usr/bin/env python3
"""Probe: does a user's locale change what demcal reads or writes?

A user in Hungary or Germany has LANG=hu_HU.UTF-8 or de_DE.UTF-8, where the decimal sign is a comma. demcal, and
what it runs (YADE, gnuplot, sbatch), inherit that environment. Each case below runs twice, in the C locale and in
LOCALE (default de_DE.UTF-8, built with localedef into a scratch LOCPATH when the system lacks it), and its exit code,
its messages and its output files are compared, with wall and CPU times and the hashes over them left out.

usage: probe_locale.py DEMCAL REPO [LOCALE]"""
import json
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import probe_common  # noqa: E402

demcal, repo = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
locale_name = sys.argv[3] if len(sys.argv) > 3 else "de_DE.UTF-8"
ex = lambda p: os.path.join(repo, "examples", p)
scratch = tempfile.mkdtemp(prefix="demcal-locale.")

env_locale = dict(os.environ)
probe = subprocess.run(["locale", "-a"], capture_output=True, text=True).stdout.lower().replace("-", "")
if locale_name.lower().replace("-", "") not in probe:
    locpath = os.path.join(scratch, "locales")
    os.makedirs(locpath)
    lang, charmap = locale_name.split(".")
    subprocess.run(["localedef", "-i", lang, "-f", charmap, os.path.join(locpath, locale_name)], check=True)
    env_locale["LOCPATH"] = locpath
for k in ("LANG", "LC_ALL", "LC_NUMERIC", "LC_TIME", "LC_MESSAGES"):
    env_locale[k] = locale_name
env_c = dict(os.environ, LC_ALL="C", LANG="C")
check = subprocess.run(["python3", "-c", "import locale; locale.setlocale(locale.LC_ALL, ''); print(locale.str(0.5))"],
                       env=env_locale, capture_output=True, text=True).stdout.strip()
print("locale %s formats 0.5 as %r" % (locale_name, check))

params_file = os.path.join(scratch, "params.json")
json.dump(probe_common.tiny_shear_params(repo), open(params_file, "w"))
SMALL_SILO = probe_common.small_silo_args(repo)
CASES = [
    ("predict", ["predict", ex("diagnose/silo_105mm_wheat.json"), "--json", "{o}/p.json"]),
    ("diagnose", ["diagnose", "--model", "oldal", "--data", ex("diagnose/oldal_clean.csv"), "--report",
                  "{o}/r.md", "--json", "{o}/r.json"]),
    ("shear-run (kernel)", ["shear-run", params_file, "{o}/result.json"]),
    ("shear (YADE)", ["shear", ex("materials/sand-tiny.json"), "--normal-stress", "5e3,1e4,2e4", "--replicates",
                      "1", "--jobs", "2", "--campaign", "{o}/camp"]),
    ("silo", ["silo"] + SMALL_SILO + ["--out", "{o}/silo"]),
    ("cutoff", ["cutoff", "--bond-number", "10", "--grains", "200", "--bracket", "0,400", "--tol", "200", "--seeds",
                "1", "--json", "{o}/c.json"]),
]
SELECT = os.environ.get("PROBE_CASES", "")
VOLATILE = re.compile(r"(wall|cpu)(_time)?_s|sha256|started|finished|elapsed[a-z_]*|time_s|created|date")


def normalised(path, o):
    """A file's content with what differs from run to run anyway taken out (times, the case's own folder)."""
    data = open(path, "rb").read()
    if path.endswith(".png") or path.endswith(".sqlite"):
        return None  # compared through what they were made from
    text = data.decode("utf-8", "replace").replace(o, "OUT")
    if path.endswith(".json"):
        try:
            def strip(v):
                if isinstance(v, dict):
                    return {k: strip(x) for k, x in v.items() if not VOLATILE.fullmatch(k)}
                if isinstance(v, list):
                    return [strip(x) for x in v]
                return v
            return json.dumps(strip(json.loads(text)), sort_keys=True)
        except ValueError:
            return text
    text = re.sub(r"\d+(\.\d+)? ?(s|min|h) (of )?(wall|CPU|cpu)", "T", text)
    text = re.sub(r"\d{4}-\d\d-\d\dT?[ \d:.Z+-]*", "DATE", text)
    return text


def run_case(name, args, env, tag):
    o = os.path.join(scratch, tag, re.sub(r"\W+", "_", name))
    os.makedirs(o)
    p = subprocess.run([demcal] + [a.replace("{o}", o) for a in args], env=env, cwd=o, capture_output=True,
                       text=True, errors="replace", timeout=900)
    files = {}
    for root, _, names in os.walk(o):
        for n in names:
            f = os.path.join(root, n)
            if "/runs/" in f or n.endswith((".log", ".lock")):  # a run's own folder: YADE's logs, timings
                continue
            files[os.path.relpath(f, o)] = normalised(f, o)
    return p.returncode, p.stdout + p.stderr, files


differences = 0
for name, args in CASES:
    if SELECT and not re.search(SELECT, name):
        continue
    rc_c, out_c, files_c = run_case(name, args, env_c, "C")
    rc_l, out_l, files_l = run_case(name, args, env_locale, "L")
    notes = []
    if rc_c != rc_l:
        notes.append("exit %d in C, %d in %s" % (rc_c, rc_l, locale_name))
    if set(files_c) != set(files_l):
        notes.append("files differ: %s" % sorted(set(files_c) ^ set(files_l)))
    for f in sorted(set(files_c) & set(files_l)):
        if files_c[f] != files_l[f]:
            notes.append("%s differs" % f)
    commas = re.findall(r"\d,\d+", out_l)
    if len(commas) > len(re.findall(r"\d,\d+", out_c)):
        notes.append("decimal commas in the messages: %s" % commas[:5])
    differences += bool(notes)
    print("%-20s exit %d/%d  %s" % (name, rc_c, rc_l, "; ".join(notes) or "same"))
    sys.stdout.flush()
print("%d case(s) differ; scratch %s" % (differences, scratch))
sys.exit(1 if differences else 0)
