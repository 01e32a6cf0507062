"""The speed table of issue 22 from crosscheck_silo.json files (run.sh): per bed, the kernel's CPU (whole run and
discharge), YADE's (discharge), the ratios, and the wall times. Usage: python3 table.py FOLDER..."""
import json
import os
import sys
print("| theta [deg], seed | rate YADE / kernel | kernel CPU [s] whole (discharge) | YADE CPU [s] (discharge) | "
      "YADE / kernel CPU: discharge | YADE / kernel CPU: whole kernel run | kernel wall [s] | YADE wall [s] | YADE / kernel wall (whole kernel run) |")
print("|---|---|---|---|---|---|---|---|---|")
for folder in sys.argv[1:]:
    r = json.load(open(folder + "/crosscheck_silo.json"))
    for a in r["angles"]:
        k, y = a["kernel"], a["yade"]
        print("| %d, %s | %.3f | %.1f (%.1f) | %.0f | %.1f | %.1f | %.1f | %.0f | %.1f |" % (
            a["theta_deg"], os.path.basename(folder.rstrip("/")).replace("seed", ""), a["rate_ratio_yade_over_kernel"], k["cpu_s"],
            k["discharge_cpu_s"], y["cpu_s"], a["discharge_cpu_ratio_yade_over_kernel"], a["cpu_ratio_yade_over_kernel"],
            k["wall_s"], y["wall_s"], y["wall_s"] / k["wall_s"]))
