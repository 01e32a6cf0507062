# -*- coding: utf-8 -*-
"""The random numbers yade_scripts/shear_box.py draws, printed for tests: SpherePack.makeCloud's spheres and Python's
random.Random values for one seed. The kernel reproduces both number for number (kernel/cases/yade_random.hpp);
tests/kernel/test_yade_random.cpp compares them with the files this script wrote (tests/data/yade_random/).

Run:  yade -n -j1 -x random_numbers.py SEED OUT.txt
"""
import random
import sys

from yade import pack

seed, out_path = int(sys.argv[1]), sys.argv[2]
cloud = pack.SpherePack()
# A box, radii and count like a small shear box's cloud; a second call continues the same (static) generator.
placed = cloud.makeCloud(minCorner=Vector3(0.001, 0.002, 0.003), maxCorner=Vector3(0.02, 0.015, 0.03), rMean=0.0012,
                         rRelFuzz=0.3, num=60, seed=seed)
again = pack.SpherePack()
placed_again = again.makeCloud(minCorner=Vector3(0, 0, 0), maxCorner=Vector3(0.01, 0.01, 0.01), rMean=0.001,
                               rRelFuzz=0.1, num=400, seed=seed)
rng = random.Random(seed)
with open(out_path, "w") as f:
    f.write("placed %d\n" % placed)
    for c, r in cloud:
        f.write("%.17g %.17g %.17g %.17g\n" % (c[0], c[1], c[2], r))
    f.write("placed %d\n" % placed_again)
    for c, r in again:
        f.write("%.17g %.17g %.17g %.17g\n" % (c[0], c[1], c[2], r))
    for k in range(20):
        f.write("random %.17g\n" % rng.random())
    for k in range(5):
        f.write("uniform %.17g\n" % rng.uniform(-1, 1))
