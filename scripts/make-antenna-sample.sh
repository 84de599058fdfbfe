#!/usr/bin/env bash
# Regenerates examples/antenna-sample and examples/antenna-phone.yaml (the README's main job):
# one simulated typical phone with a 12 MP camera (device seed 21) is calibrated as a user would (IMU poses and a
# tumble, camera, camera-IMU), then photographs a rooftop antenna site (scene seed 31).
# Usage: scripts/make-antenna-sample.sh [path/to/antpose]
set -euo pipefail
cd "$(dirname "$0")/.."
A=${1:-./build/apps/antpose/antpose}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
$A simulate imu -o "$W/poses" --preset static-poses --phone typical --seed 21
$A simulate imu -o "$W/tumble" --preset tumble --phone typical --seed 1021
$A calibrate imu "$W/poses" --device "$W/phone.yaml" --sensors acc,gyro
$A calibrate imu "$W/tumble" --device "$W/phone.yaml" --sensors mag
$A simulate capture -o "$W/camera" --scenario camera-calibration --seed 21 --width 4000 --height 3000 --supersampling 2
$A calibrate camera "$W/camera" --device "$W/phone.yaml"
$A simulate capture -o "$W/joint" --scenario joint-calibration --seed 21 --width 4000 --height 3000 --supersampling 2
$A calibrate joint "$W/joint" --device "$W/phone.yaml" --method reference-free --param gyro_trapezoid=1
$A simulate capture -o "$W/antenna" --scenario antenna --seed 31 --device-seed 21 --setting rooftop --antennas 1 \
  --photos 8 --jpeg-quality 85 --width 4000 --height 3000 --supersampling 2
rm -rf examples/antenna-sample
cp -r "$W/antenna" examples/antenna-sample
sed 's/id: phone$/id: sample-phone/' "$W/phone.yaml" > examples/antenna-phone.yaml
grep -A1 "roi:" examples/antenna-sample/truth/scene.yaml
