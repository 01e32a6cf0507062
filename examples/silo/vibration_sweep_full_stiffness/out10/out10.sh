#!/usr/bin/env bash
# the outlet's density and speed at 10 deg (bed inside the hopper), still and 145 Hz, whole bin, 3 seeds
exec nice /work/main/build/app/demcal vibration --theta 10 --frequency 0,145 --amplitude 1.1e-4 --repeats 3 --campaign /work/runs/vib27/out10 -- --geometry /work/main/examples/silo/reduced_conical_70deg.json --particles 2000 --stiffness-scale 1 --fill-time 0.5 --threads 1 --no-plots
