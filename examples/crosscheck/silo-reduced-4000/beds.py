"""Shared by compare_variants.py and more-beds/compare.py: the kernel's rates of a variant (its results.txt), YADE's
rate of each bed (the --kernel-law yade crosschecks: yade-law/ for seed 1, yade-law-theta<t>-seed<s>/ for seeds 2
and 3) and the mean with its SD and SE."""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def kernel_rates(results_txt):
    """{(theta, seed, variant label): rate [g/s]} from a results.txt."""
    out = {}
    for line in open(results_txt):
        if line.startswith("#") or not line.strip():
            continue
        theta, seed, variant, rate = line.split()[:4]
        out[(int(theta), int(seed), variant)] = float(rate)
    return out


def yade_rate(theta, seed):
    """YADE's rate [g/s] of the bed (theta, seed), from its crosscheck report."""
    folder = "yade-law" if seed == 1 else "yade-law-theta%d-seed%d" % (theta, seed)
    report = json.load(open(os.path.join(HERE, folder, "crosscheck_silo.json")))
    for a in report["angles"]:
        if a["theta_deg"] == theta:
            return a["yade"]["rate_kg_s"] * 1000
    raise KeyError((theta, seed))


def mean_sd_se(xs):
    m = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1))
    return m, sd, sd / math.sqrt(len(xs))


def mean_cell(xs):
    return "%.3f (%.3f; %.3f)" % mean_sd_se(xs)


def print_paired_table(before, after, yade_title, before_title, after_title, paired_title):
    """A Markdown table of the beds both variants ran: YADE's rate, each variant's, YADE / each, after / before on the
    same bed, and the means. before, after: (rates of kernel_rates, variant label)."""
    (rates_b, label_b), (rates_a, label_a) = before, after
    cases = sorted((t, s) for t, s, v in rates_a if v == label_a and (t, s, label_b) in rates_b)
    print("| theta [deg], seed | %s [g/s] | %s [g/s] | %s [g/s] | YADE / kernel (%s) | YADE / kernel (%s) | %s |"
          % (yade_title, before_title, after_title, before_title, after_title, paired_title))
    print("|---|---|---|---|---|---|---|")
    on_before, on_after, paired = [], [], []
    for t, s in cases:
        y, kb, ka = yade_rate(t, s), rates_b[(t, s, label_b)], rates_a[(t, s, label_a)]
        on_before.append(y / kb)
        on_after.append(y / ka)
        paired.append(ka / kb)
        print("| %d, %d | %.1f | %.2f | %.2f | %.3f | %.3f | %.3f |" % (t, s, y, kb, ka, y / kb, y / ka, ka / kb))
    print("| mean (SD; SE) | | | | %s | %s | %s |" % tuple(mean_cell(v) for v in (on_before, on_after, paired)))
