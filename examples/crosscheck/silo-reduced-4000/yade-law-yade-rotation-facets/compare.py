"""The kernel's rates on silo.py's facet walls (results.txt, run.sh) against its rates on exact walls from the same
beds (../yade-law-yade-rotation/, YADE's rotation) and YADE's."""
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, ".."))
from beds import kernel_rates, print_paired_table  # noqa: E402

exact = kernel_rates(os.path.join(here, "..", "yade-law-yade-rotation", "results.txt"))
facets = kernel_rates(os.path.join(here, "results.txt"))
print_paired_table((exact, "yade"), (facets, "facets72"), "YADE (72 facets)", "exact walls", "72 facets",
                   "facets / exact (same bed)")
