#!/usr/bin/env bash
# Installs every dependency from Debian 12 packages, builds antpose (Release, -j2) and runs
# the main job on the bundled sample capture. Run from the repository root, as root or with sudo.
set -euo pipefail
cd "$(dirname "$0")/.."
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
  build-essential cmake ninja-build pkg-config git \
  libeigen3-dev libceres-dev libopencv-dev libopencv-contrib-dev libnanoflann-dev libtbb-dev \
  libsqlite3-dev libssl-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libfmt-dev libspdlog-dev \
  zlib1g-dev libpugixml-dev libgtest-dev libgmock-dev libbenchmark-dev
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2
# The main job on the bundled sample: calibrate the phone's magnetometer from its tumble
# recording, then measure the antenna plate in contact mode.
./build/apps/antpose/antpose calibrate imu examples/imu-calibration-sample --sensors mag -o build/sample-device.yaml --force
./build/apps/antpose/antpose contact examples/contact-sample --imu-calibration build/sample-device.yaml
