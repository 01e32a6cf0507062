#!/usr/bin/env bash
exec nice /work/main/build/app/demcal vibration --theta 10,30,60 --frequency 0,145 --amplitude 1.1e-4 --part hopper --repeats 3 --campaign /work/runs/vib27/hopper -- --geometry /work/main/examples/silo/reduced_conical_70deg.json --particles 2000 --stiffness-scale 1 --fill-time 0.5 --threads 1 --no-plots
