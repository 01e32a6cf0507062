"""The kernel's rates of results.txt (run.sh), its own clump rotation and YADE's, against YADE's of the same beds."""
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, ".."))
from beds import kernel_rates, print_paired_table  # noqa: E402

kernel = kernel_rates(os.path.join(here, "results.txt"))
print_paired_table((kernel, "richardson"), (kernel, "yade"), "YADE", "own rotation", "YADE's rotation",
                   "YADE's rotation / own (same bed)")
