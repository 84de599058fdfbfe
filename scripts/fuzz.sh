#!/usr/bin/env bash
# Fuzzes every reader of outside data under AddressSanitizer and UndefinedBehaviorSanitizer:
#   scripts/fuzz.sh [SECONDS_PER_TARGET (default 600)] [TARGET ...]
# Builds build-fuzz/ with clang (Debian's clang: apt-get install clang), seeds each target's corpus
# from fuzz/seeds/ and from the repository's own sample files, runs each target for the given
# time (one job per core) and writes build-fuzz/fuzz-report.txt: executions, coverage and corpus
# per target. A crash, leak, timeout (10 s per input) or input using more than 2 GB stops that
# target, leaves its reproducer (crash-*, leak-*, timeout-*, oom-*) in build-fuzz/findings/ and
# makes the script exit 1.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET=${1:-600}
shift || true
BUILD=build-fuzz
ALL=(fuzz_csv fuzz_capture_yaml fuzz_board_yaml fuzz_device_yaml fuzz_mesh fuzz_box_file fuzz_cof fuzz_thesis_xml fuzz_photo)
[ $# -gt 0 ] && TARGETS=("$@") || TARGETS=("${ALL[@]}")

cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_UNITY_BUILD=ON -DANTPOSE_BUILD_FUZZERS=ON -DANTPOSE_BUILD_TESTS=OFF -DANTPOSE_BUILD_BENCH=OFF >/dev/null
cmake --build "$BUILD" -j"$(nproc)" --target "${TARGETS[@]}"

# Seeds: the hand-written ones, and files of the repository that each reader reads in real use.
seed() {  # seed TARGET FILE...
  mkdir -p "$BUILD/corpus/$1"
  local target=$1; shift
  for f in "$@"; do [ -f "$f" ] && cp "$f" "$BUILD/corpus/$target/seed-$(basename "$(dirname "$f")")-$(basename "$f")"; done
}
for t in "${TARGETS[@]}"; do mkdir -p "$BUILD/corpus/$t"; [ -d "fuzz/seeds/$t" ] && cp fuzz/seeds/"$t"/* "$BUILD/corpus/$t/"; done
head -c 4000 examples/contact-sample/sensors/accelerometer.csv > "$BUILD/corpus/fuzz_csv/seed-accelerometer.csv"
gzip -c "$BUILD/corpus/fuzz_csv/seed-accelerometer.csv" > "$BUILD/corpus/fuzz_csv/seed-accelerometer.csv.gz"
seed fuzz_capture_yaml examples/*/capture.yaml
seed fuzz_board_yaml examples/antenna-sample/board.yaml
seed fuzz_device_yaml examples/antenna-phone.yaml tests/data/phone401.yaml
seed fuzz_cof data/geomag/WMM2025.COF

mkdir -p "$BUILD/findings"
run() {  # run TARGET: its log in $BUILD/logs/TARGET.log
  local t=$1
  mkdir -p "$BUILD/logs"
  (cd "$BUILD/findings" && ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "../fuzz/$t" "../corpus/$t" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$t-" >"../logs/$t.log" 2>&1) && echo "$t ok" || echo "$t FAILED"
}
export -f run
export BUILD SECONDS_PER_TARGET
printf '%s\n' "${TARGETS[@]}" | xargs -P"$(nproc)" -I{} bash -c 'run {}' | tee "$BUILD/fuzz-status.txt"

{
  echo "fuzzing $(git describe --always --dirty), ${SECONDS_PER_TARGET} s per target, ASan+UBSan, $(date -u +%FT%TZ)"
  for t in "${TARGETS[@]}"; do
    log="$BUILD/logs/$t.log"
    runs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | awk '{print $2}' || true)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | awk '{print $2}' || true)
    ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | awk '{print $2}' || true)
    corpus=$(ls "$BUILD/corpus/$t" | wc -l)
    status=$(grep "^$t " "$BUILD/fuzz-status.txt" | awk '{print $2}' || true)
    printf '%-20s %-7s executions %-10s coverage (edges) %-6s features %-7s corpus %s\n' "$t" "$status" "${runs:-?}" "${cov:-?}" "${ft:-?}" "$corpus"
  done
} | tee "$BUILD/fuzz-report.txt"
! grep -q FAILED "$BUILD/fuzz-status.txt"
