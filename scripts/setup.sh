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
  libsqlite3-dev libssl-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libfmt-dev \
  zlib1g-dev libpugixml-dev libexiv2-dev libgtest-dev libgmock-dev libbenchmark-dev
# A unity build (eight sources per unit) compiles the templates its units share (Eigen, OpenCV,
# gtest) once per batch: a fresh build takes 41 % less CPU (docs/architecture.md).
# Incremental work is quicker without it: configure a second folder without the flag.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON
cmake --build build -j2
# The main job on the bundled samples: the non-contact measurement of a rooftop antenna from
# photos with the board in view (examples/README.md gives the truth), then the contact
# measurement of an antenna plate after calibrating the phone's magnetometer from its tumble.
./build/apps/antpose/antpose measure examples/antenna-sample --device examples/antenna-phone.yaml \
  --model thesis-1310x159x80 --roi images/img_0004.jpg:1467,1522,559,120 --report build/antenna-report --force
./build/apps/antpose/antpose calibrate imu examples/imu-calibration-sample --sensors mag -o build/sample-device.yaml --force
./build/apps/antpose/antpose contact examples/contact-sample --imu-calibration build/sample-device.yaml
