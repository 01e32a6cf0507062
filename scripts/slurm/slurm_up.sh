#!/bin/bash
# Starts a single-node SLURM on loopback (munge, slurmctld, slurmd) without systemd, for demcal's SLURM tests and
# for trying the SLURM executor on one machine. Run as root; packages come from scripts/setup.sh.
# The node gets this machine's cores and memory. Stop with slurm_down.sh.
set -e
HERE=$(cd "$(dirname "$0")" && pwd)
CPUS=$(nproc)
MEM_MB=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024 ))
mkdir -p /etc/slurm
sed -e "s/^NodeName=.*/NodeName=localhost NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM_MB State=UNKNOWN/" \
  "$HERE/slurm.conf" > /etc/slurm/slurm.conf
# SLURM_MAX_ARRAY_SIZE=N: a cluster that takes arrays of at most N tasks (demcal's test of splitting a large batch)
if [ -n "${SLURM_MAX_ARRAY_SIZE:-}" ]; then echo "MaxArraySize=$SLURM_MAX_ARRAY_SIZE" >> /etc/slurm/slurm.conf; fi
mkdir -p /run/munge /run/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
chown munge:munge /run/munge; chown slurm:slurm /var/spool/slurmctld /var/log/slurm
[ -s /etc/munge/munge.key ] || { mungekey -c -f; chown munge:munge /etc/munge/munge.key; }
munge -n >/dev/null 2>&1 || runuser -u munge -- /usr/sbin/munged
pgrep -x slurmctld >/dev/null || /usr/sbin/slurmctld          # daemonizes, drops to SlurmUser
pgrep -x slurmd >/dev/null || /usr/sbin/slurmd -N localhost   # the node name is not the hostname, so pass -N
for i in $(seq 100); do sinfo -h -o %T 2>/dev/null | grep -qE '^idle|^mixed' && break; sleep 0.2; done
sinfo -h -o %T | grep -qE '^idle|^mixed' || { echo "slurm_up: node not idle:"; sinfo; exit 1; }
