"""The kernel's rates of results.txt (run.sh) against YADE's of the same beds (the --kernel-law yade crosschecks:
../yade-law/ for seed 1, ../yade-law-theta<t>-seed<s>/ for seeds 2 and 3). Prints a Markdown table and the means."""
import json
import math
import os

here = os.path.dirname(os.path.abspath(__file__))
kernel = {}
for line in open(os.path.join(here, "results.txt")):
    if line.startswith("#") or not line.strip():
        continue
    theta, seed, scheme, rate, se, cpu = line.split()
    kernel[(int(theta), int(seed), scheme)] = float(rate)


def yade_rate(theta, seed):
    folder = "yade-law" if seed == 1 else "yade-law-theta%d-seed%d" % (theta, seed)
    report = json.load(open(os.path.join(here, "..", folder, "crosscheck_silo.json")))
    for a in report["angles"]:
        if a["theta_deg"] == theta:
            return a["yade"]["rate_kg_s"] * 1000
    raise KeyError((theta, seed))


def mean_sd_se(xs):
    m = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1))
    return m, sd, sd / math.sqrt(len(xs))


cases = sorted({(t, s) for t, s, _ in kernel if (t, s, "yade") in kernel and (t, s, "richardson") in kernel})
print("| theta [deg], seed | YADE [g/s] | kernel, own rotation [g/s] | kernel, YADE's rotation [g/s] | "
      "YADE / kernel (own) | YADE / kernel (YADE's) | YADE's rotation / own (same bed) |")
print("|---|---|---|---|---|---|---|")
own_ratio, yade_ratio, paired = [], [], []
for t, s in cases:
    y, ko, ky = yade_rate(t, s), kernel[(t, s, "richardson")], kernel[(t, s, "yade")]
    own_ratio.append(y / ko)
    yade_ratio.append(y / ky)
    paired.append(ky / ko)
    print("| %d, %d | %.1f | %.2f | %.2f | %.3f | %.3f | %.3f |" % (t, s, y, ko, ky, y / ko, y / ky, ky / ko))
cells = ["%.3f (%.3f; %.3f)" % mean_sd_se(v) for v in (own_ratio, yade_ratio, paired)]
print("| mean (SD; SE) | | | | %s | %s | %s |" % tuple(cells))
