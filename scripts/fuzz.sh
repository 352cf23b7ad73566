#!/usr/bin/env bash
# The fuzz stage (RELIABILITY.md): builds the libFuzzer harnesses of test/fuzz with Debian's
# clang-14 (ASan + UBSan) into build-fuzz/ and runs each for SECONDS, starting from the
# committed seed corpus (test/fuzz/corpus/<harness>, copied: the run's corpus grows in
# build-fuzz/). Prints each harness's executions and result; fails on any crash, hang
# (-timeout 10 s per input), leak or sanitizer report (libFuzzer then writes the input to
# build-fuzz/artifacts/ to reproduce with `build-fuzz/<harness> ARTIFACT`).
#   usage: scripts/fuzz.sh [SECONDS] [HARNESS...]   (default 60 s each, all harnesses)
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-60}"
shift || true
HARNESSES=("$@")
if [ ${#HARNESSES[@]} -eq 0 ]; then
  HARNESSES=(fuzz_cloud_io fuzz_dataset fuzz_cloud_conversion fuzz_registration)
fi
bash scripts/install_deps.sh
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
OUT=build-fuzz
mkdir -p "$OUT/artifacts"
touch "$OUT/CATKIN_IGNORE"  # build outputs, not package files (catkin_lint)
CXX=clang++-14
FLAGS=(-std=c++17 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
       -fno-omit-frame-pointer -Iinclude -isystem /usr/include/eigen3)
CORE=(src/core/*.cpp)

build() {  # HARNESS
  local h="$1" extra=()
  case "$h" in
    fuzz_cloud_io) extra=(src/io/cloud_io.cpp) ;;
    fuzz_dataset) extra=(src/io/dataset.cpp) ;;
    fuzz_cloud_conversion) extra=(src/ros/cloud_conversion.cpp -lrostime -lcpp_common) ;;
    fuzz_registration) extra=(-fopenmp-simd "${CORE[@]}" -lpthread) ;;
    *) echo "fuzz: unknown harness $h" >&2; exit 2 ;;
  esac
  echo "== fuzz: building $h"
  "$CXX" "${FLAGS[@]}" "test/fuzz/$h.cpp" "${extra[@]}" -o "$OUT/$h" > "$OUT/$h.build.log" 2>&1 ||
    { cat "$OUT/$h.build.log"; exit 1; }
}

status=0
summary=()
for h in "${HARNESSES[@]}"; do
  build "$h"
  corpus="$OUT/corpus/$h"
  mkdir -p "$corpus"
  cp -n test/fuzz/corpus/"$h"/* "$corpus"/ 2>/dev/null || true
  echo "== fuzz: running $h for $SECONDS_EACH s"
  log="$OUT/$h.log"
  rc=0
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "$OUT/$h" "$corpus" -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$OUT/artifacts/$h-" > "$log" 2>&1 || rc=$?
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  units=$(find "$corpus" -type f | wc -l)
  if [ "$rc" -eq 0 ]; then
    line="$h: $SECONDS_EACH s, $execs executions, corpus $units inputs: no crash, no hang, no report"
  else
    line="$h: FAILED (exit $rc) after $execs executions; see $log and $OUT/artifacts/"
    grep -m5 -E 'ERROR|SUMMARY|runtime error|Test unit written' "$log" || true
    status=1
  fi
  echo "   $line"
  summary+=("$line")
done
echo "== fuzz summary"
printf '   %s\n' "${summary[@]}"
exit $status
