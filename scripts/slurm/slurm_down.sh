#!/bin/bash
# Stops what slurm_up.sh started (by pid; there is no systemd).
for f in /run/slurm/slurmd.pid /run/slurm/slurmctld.pid; do [ -s $f ] && kill "$(cat $f)" 2>/dev/null; done
[ -s /run/munge/munged.pid ] && kill "$(cat /run/munge/munged.pid)" 2>/dev/null
sleep 1; pgrep -ax 'slurmctld|slurmd|munged' || echo "all stopped"
