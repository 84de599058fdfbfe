#!/usr/bin/env bash
# Benchmark-only dependencies: PCL and Open3D, to compare antpose's registration with theirs
# (build/bench/antpose_bench_registration). antpose itself never links them, and CI does not
# install them (about 300 packages). Then re-run cmake (scripts/setup.sh does).
set -euo pipefail
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends libpcl-dev libopen3d-dev
