"""The kernel started as YADE's import of the bed (results.txt, run.sh) against the same kernel keeping its contacts at
the opening (../yade-law-yade-rotation-facets/: the same law, rotation and walls) and against YADE."""
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, ".."))
from beds import kernel_rates, print_paired_table  # noqa: E402

kept = kernel_rates(os.path.join(here, "..", "yade-law-yade-rotation-facets", "results.txt"))
start = kernel_rates(os.path.join(here, "results.txt"))
print_paired_table((kept, "facets72"), (start, "yade-start"), "YADE", "contacts kept", "YADE's start",
                   "YADE's start / kept (same bed)")
