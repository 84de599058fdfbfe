#!/usr/bin/env bash
# Compares the speed of two antpose builds on one capture (`antpose bench measure`): both run at
# once, each pinned to a core of its own, then again with the cores swapped, ROUNDS times.
#
# On a shared or virtual machine the speed drifts by more than the difference worth measuring
# (a tenth within minutes), and its cores need not be alike: runs one after the other compare
# the machine's moments, not the builds. Run at once, both builds meet the same moment; swapped,
# the same cores. What this measures is one core's work, not the two-core wall time of the target.
#
#   bench/compare_measure.sh BUILD_A BUILD_B CAPTURE DEVICE.yaml [ROUNDS]
#
# Prints each run's wall time, both builds' medians and their ratio (a run the machine disturbed
# does not carry the median: use three rounds or more), and the answers where they differ.
set -euo pipefail

if [[ $# -lt 4 || $# -gt 5 ]]; then
  echo "usage: $0 BUILD_A BUILD_B CAPTURE DEVICE.yaml [ROUNDS]" >&2
  exit 2
fi
a=$1 b=$2 capture=$3 device=$4 rounds=${5:-3}
for exe in "$a" "$b"; do
  [[ -f $exe && -x $exe ]] || { echo "$0: '$exe' is not an executable antpose" >&2; exit 2; }
done
a=$(realpath "$a") b=$(realpath "$b")  # taskset would look a bare name up in PATH
[[ -d $capture ]] || { echo "$0: '$capture' is not a capture folder" >&2; exit 2; }
[[ -f $device ]] || { echo "$0: '$device' is not a device profile" >&2; exit 2; }
[[ $(nproc) -ge 2 ]] || { echo "$0: needs two cores" >&2; exit 2; }
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "$0: ROUNDS '$rounds' is not a positive whole number" >&2; exit 2; }

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# The site's wall time as `bench measure` reports it in its JSON ("seconds").
seconds() { grep -o '"seconds": *[0-9.]*' "$1" | head -n 1 | sed 's/.*: *//'; }
# The answers alone: each antenna's errors, σ, verdict and refusal.
answers() { grep -E '"((azimuth|downtilt|roll)_(error|sigma)_deg|verdict|refused)"' "$1"; }

run() {  # core build name
  taskset -c "$1" "$2" bench measure "$capture" --device "$device" --json "$out/$3.json" >"$out/$3.log" 2>&1 ||
    { echo "$0: $2 failed, see its output:" >&2; cat "$out/$3.log" >&2; exit 1; }
}

times_a=() times_b=()
for ((r = 1; r <= rounds; ++r)); do
  for swap in 0 1; do
    run "$swap" "$a" "a$r$swap" &
    pid_a=$!
    run "$((1 - swap))" "$b" "b$r$swap" &
    pid_b=$!
    wait "$pid_a" || { kill "$pid_b" 2>/dev/null; exit 1; }
    wait "$pid_b" || exit 1
    times_a+=("$(seconds "$out/a$r$swap.json")") times_b+=("$(seconds "$out/b$r$swap.json")")
    echo "round $r: A on core $swap ${times_a[-1]} s, B on core $((1 - swap)) ${times_b[-1]} s"
  done
done
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print (v[int((NR + 1) / 2)] + v[int(NR / 2) + 1]) / 2 }'; }
awk -v a="$(median "${times_a[@]}")" -v b="$(median "${times_b[@]}")" \
  'BEGIN { printf "median: A %.1f s, B %.1f s, B/A = %.3f\n", a, b, b / a }'
if diff <(answers "$out/a10.json") <(answers "$out/b10.json") >"$out/answers.diff"; then
  echo "the answers are the same"
else
  echo "the answers differ (< A, > B):"
  grep '^[<>]' "$out/answers.diff"
fi
