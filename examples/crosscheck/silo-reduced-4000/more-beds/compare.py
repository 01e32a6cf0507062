"""YADE / kernel on more beds (yade_rates.txt: YADE's rate and the kernel's before the removal fix, from the
crosschecks; results.txt: the kernel after the fix, run.sh)."""
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, ".."))
from beds import kernel_rates, mean_cell  # noqa: E402

after = kernel_rates(os.path.join(here, "results.txt"))
print("| theta [deg], seed | YADE [g/s] | kernel before the fix [g/s] | kernel after the fix [g/s] | YADE / kernel (before) "
      "| YADE / kernel (after) |")
print("|---|---|---|---|---|---|")
before_ratio, after_ratio = [], []
for line in open(os.path.join(here, "yade_rates.txt")):
    if line.startswith("#") or not line.strip():
        continue
    theta, seed, yade, kernel_before = line.split()[:4]
    key = (int(theta), int(seed), "removal-fix")
    if key not in after:
        continue
    y, kb, ka = float(yade), float(kernel_before), after[key]
    before_ratio.append(y / kb)
    after_ratio.append(y / ka)
    print("| %s, %s | %.2f | %.2f | %.2f | %.3f | %.3f |" % (theta, seed, y, kb, ka, y / kb, y / ka))
print("| mean (SD; SE) | | | | %s | %s |" % (mean_cell(before_ratio), mean_cell(after_ratio)))
