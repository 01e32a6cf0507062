"""The paired table of one variant folder against the variant it changed (the same beds): each variant's kernel rates
(its results.txt), YADE's rate of each bed, YADE / each, after / before on the same bed and the means.
Usage: python3 compare_variants.py FOLDER, FOLDER one of the keys below."""
import os
import sys

from beds import kernel_rates, print_paired_table

HERE = os.path.dirname(os.path.abspath(__file__))
# folder: (the folder it is compared with, its label in that results.txt, this folder's label, YADE's column title,
#          the two variants' titles, the paired column's title)
VARIANTS = {
    "yade-law-yade-rotation": ("yade-law-yade-rotation", "richardson", "yade", "YADE", "own rotation",
                               "YADE's rotation", "YADE's rotation / own (same bed)"),
    "yade-law-yade-rotation-facets": ("yade-law-yade-rotation", "yade", "facets72", "YADE (72 facets)", "exact walls",
                                      "72 facets", "facets / exact (same bed)"),
    "yade-start": ("yade-law-yade-rotation-facets", "facets72", "yade-start", "YADE", "contacts kept", "YADE's start",
                   "YADE's start / kept (same bed)"),
    "removal-fix": ("yade-start", "yade-start", "removal-fix", "YADE", "before the fix", "after the fix",
                    "after / before (same bed)"),
}

if len(sys.argv) != 2 or sys.argv[1].strip("/") not in VARIANTS:
    sys.exit("usage: python3 compare_variants.py FOLDER (one of: %s)" % ", ".join(VARIANTS))
folder = sys.argv[1].strip("/")
before, label_b, label_a, yade_title, before_title, after_title, paired_title = VARIANTS[folder]
print_paired_table((kernel_rates(os.path.join(HERE, before, "results.txt")), label_b),
                   (kernel_rates(os.path.join(HERE, folder, "results.txt")), label_a),
                   yade_title, before_title, after_title, paired_title)
