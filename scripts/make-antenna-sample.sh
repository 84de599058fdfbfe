#!/usr/bin/env bash
# Regenerates examples/antenna-sample and examples/antenna-phone.yaml (the README's main job):
# one simulated typical phone with a 12 MP camera (device seed 21) is calibrated as a user would
# (scripts/calibrate-simulated-phone.sh), then photographs a rooftop antenna site (scene seed 31).
# Usage: scripts/make-antenna-sample.sh [path/to/antpose]
set -euo pipefail
cd "$(dirname "$0")/.."
A=${1:-./build/apps/antpose/antpose}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
scripts/calibrate-simulated-phone.sh 21 "$W/phone.yaml" "$A"
$A simulate capture -o "$W/antenna" --scenario antenna --distribution classic --seed 31 --device-seed 21 --setting rooftop --antennas 1 \
  --photos 8 --jpeg-quality 85 --width 4000 --height 3000 --supersampling 2
rm -rf examples/antenna-sample
cp -r "$W/antenna" examples/antenna-sample
sed 's/id: phone21$/id: sample-phone/' "$W/phone.yaml" > examples/antenna-phone.yaml
grep -A1 "roi:" examples/antenna-sample/truth/scene.yaml
