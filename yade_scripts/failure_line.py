#!/usr/bin/env python3
"""Runs shear_box.py at several normal stresses and fits the failure line tau = mu_b * sigma + tau_c.

A check of the YADE template without the C++ orchestrator (the numbers in README.md come from it):
  python3 yade_scripts/failure_line.py examples/materials/sand.json --stresses 5000 10000 15000 20000 \
      --seed 1 --jobs 2 --workdir /tmp/demcal-failure-line
Each run gets its own directory (a copy of shear_box.py and params.json = material + normal_stress + seed) and is run
as `yade -n -j1 -x shear_box.py params.json result.json`, at most --jobs at a time. Prints one line per run and the
least-squares lines through the peak and the residual stresses.
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DOCUMENTATION_KEYS = ("name", "description")


def fit_line(xs, ys):
    """Least squares y = slope x + intercept; returns slope, intercept, R^2."""
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    sxy = sum((x - mx) * (y - my) for x, y in zip(xs, ys))
    slope = sxy / sxx
    intercept = my - slope * mx
    ss_tot = sum((y - my) ** 2 for y in ys)
    ss_res = sum((y - slope * x - intercept) ** 2 for x, y in zip(xs, ys))
    return slope, intercept, (1 - ss_res / ss_tot) if ss_tot > 0 else 1.0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("material", help="material JSON (all shear_box.py keys except normal_stress and seed)")
    ap.add_argument("--stresses", type=float, nargs="+", default=[5000, 10000, 15000, 20000], help="normal stresses [Pa]")
    ap.add_argument("--seed", type=int, default=1, help="packing seed, the same for every stress")
    ap.add_argument("--jobs", type=int, default=2, help="YADE processes at a time (one core each)")
    ap.add_argument("--workdir", default="demcal-failure-line", help="directory for the run directories")
    ap.add_argument("--yade", default="yade", help="YADE launcher")
    args = ap.parse_args()
    if len(args.stresses) < 2:
        sys.exit("--stresses: at least 2 normal stresses are needed for a line, got %d" % len(args.stresses))

    with open(args.material) as f:
        material = {k: v for k, v in json.load(f).items() if k not in DOCUMENTATION_KEYS}
    runs = []
    for sigma in args.stresses:
        d = os.path.join(args.workdir, "sigma_%g" % sigma)
        os.makedirs(d, exist_ok=True)
        shutil.copy(os.path.join(HERE, "shear_box.py"), d)
        with open(os.path.join(d, "params.json"), "w") as f:
            json.dump(dict(material, normal_stress=sigma, seed=args.seed), f, indent=1)
        runs.append({"sigma": sigma, "dir": d})

    pending, running = list(runs), []
    env = dict(os.environ, OMP_WAIT_POLICY="passive")
    while pending or running:
        while pending and len(running) < args.jobs:
            r = pending.pop(0)
            r["out"] = open(os.path.join(r["dir"], "stdout.log"), "w")
            r["err"] = open(os.path.join(r["dir"], "stderr.log"), "w")
            r["start"] = time.time()
            r["proc"] = subprocess.Popen([args.yade, "-n", "-j1", "-x", "shear_box.py", "params.json", "result.json"],
                                         cwd=r["dir"], stdout=r["out"], stderr=r["err"], env=env)
            running.append(r)
        time.sleep(0.5)
        for r in list(running):
            if r["proc"].poll() is None:
                continue
            running.remove(r)
            r["wall"] = time.time() - r["start"]
            r["out"].close()
            r["err"].close()
            r["rc"] = r["proc"].returncode

    ok = []
    for r in runs:
        if r["rc"] != 0:
            with open(os.path.join(r["dir"], "stderr.log")) as f:
                lines = [l for l in f.read().splitlines() if "DEMCAL_FAILURE" in l]
            print("sigma %8.0f Pa: exit %d %s" % (r["sigma"], r["rc"], lines[-1] if lines else ""))
            continue
        with open(os.path.join(r["dir"], "result.json")) as f:
            res = json.load(f)
        ok.append((r["sigma"], res))
        print("sigma %8.0f Pa: peak %8.1f Pa at %.4f m, residual %8.1f +/- %6.1f Pa, held %8.1f Pa (max dev %.2f), "
              "porosity %.4f, %d particles / %d spheres, %d steps, %.1f s wall" %
              (r["sigma"], res["peak_shear_stress"], res["peak_displacement"], res["residual_shear_stress"],
               res["residual_shear_stress_std"], res["normal_stress_held"], res["normal_stress_rel_dev"],
               res["porosity"], res["particle_count"], res["sphere_count"], res["steps"], r["wall"]))
    if len(ok) < 2:
        sys.exit("fewer than 2 successful runs: no line")
    for label, key in (("peak", "peak_shear_stress"), ("residual", "residual_shear_stress")):
        xs = [res["normal_stress_held"] for _, res in ok]  # the stress actually held, not the target
        ys = [res[key] for _, res in ok]
        mu, tau_c, r2 = fit_line(xs, ys)
        print("%-8s failure line: mu_b = %.4f (phi = %.1f deg), tau_c = %.1f Pa, R^2 = %.4f" %
              (label, mu, math.degrees(math.atan(mu)), tau_c, r2))


if __name__ == "__main__":
    main()
