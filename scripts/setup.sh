#!/usr/bin/env bash
# Installs every Debian package demcal needs (build, tests, YADE, LIGGGHTS for benchmarks, SLURM for the cluster tests).
# Idempotent: packages already present are skipped by apt. Run as root (or with sudo available).
set -euo pipefail
PKGS=(
  build-essential cmake pkg-config ninja-build
  libeigen3-dev libgsl-dev libnlopt-dev libnlopt-cxx-dev nlohmann-json3-dev catch2 libsqlite3-dev sqlite3 libcli11-dev
  libssl-dev gnuplot-nox
  yade python3
  slurmctld slurmd slurm-client munge
)
# liggghts and mpi are only for bench/ (peer comparison); opt in with DEMCAL_BENCH_DEPS=1
if [ "${DEMCAL_BENCH_DEPS:-0}" = 1 ]; then PKGS+=(liggghts openmpi-bin time); fi
SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
missing=()
for p in "${PKGS[@]}"; do dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -q >/dev/null
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
fi
echo "setup: all packages present"
