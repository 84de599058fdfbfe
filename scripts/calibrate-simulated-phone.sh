#!/usr/bin/env bash
# Calibrates one simulated typical phone with a 12 MP camera as a user would, through the command
# line: the IMU from 18 held poses and a tumble, the camera from 20 board photos, the camera–IMU
# rotation and time offset from six board placements. Writes the device profile antpose's own
# calibrations produced (not the simulator's truth); its device id is phone<SEED>. Given a work
# folder, keeps the captures there (each with its truth/) and the joint step's result in
# joint.json; otherwise works in a temporary folder.
# Usage: scripts/calibrate-simulated-phone.sh DEVICE_SEED OUT.yaml [path/to/antpose [WORK_DIR]]
set -euo pipefail
SEED=$1
OUT=$2
A=${3:-./build/apps/antpose/antpose}
if [ -n "${4:-}" ]; then
  W=$4
  mkdir -p "$W"
else
  W=$(mktemp -d)
  trap 'rm -rf "$W"' EXIT
fi
P="$W/phone$SEED.yaml"
CAMERA="--width 4000 --height 3000 --supersampling 2"
$A simulate imu -o "$W/poses" --preset static-poses --phone typical --seed "$SEED"
$A simulate imu -o "$W/tumble" --preset tumble --phone typical --seed $((SEED + 1000))
$A calibrate imu "$W/poses" --device "$P" --sensors acc,gyro
$A calibrate imu "$W/tumble" --device "$P" --sensors mag
$A simulate capture -o "$W/camera" --scenario camera-calibration --seed "$SEED" $CAMERA
$A calibrate camera "$W/camera" --device "$P"
$A simulate capture -o "$W/joint" --scenario joint-calibration --seed "$SEED" $CAMERA
$A calibrate joint "$W/joint" --device "$P" --solver reference-free --param gyro_trapezoid=1 --json "$W/joint.json"
cp "$P" "$OUT.tmp"
mv "$OUT.tmp" "$OUT"
