"""The kernel after the removal fix (results.txt, run.sh) against the same kernel before it (../yade-start/: the same
law, rotation, walls and start) and against YADE."""
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, ".."))
from beds import kernel_rates, print_paired_table  # noqa: E402

before = kernel_rates(os.path.join(here, "..", "yade-start", "results.txt"))
after = kernel_rates(os.path.join(here, "results.txt"))
print_paired_table((before, "yade-start"), (after, "removal-fix"), "YADE", "before the fix", "after the fix",
                   "after / before (same bed)")
