#!/usr/bin/env bash
# The README's test command: installs, builds and runs the whole test suite through CTest.
# With DATA_DIR (a folder laid out like shared/data: sub-folders with pairs.txt; one without
# any is refused before the build), it also runs
# the real-data accuracy check. Its bounds are near twice the figures measured on the shared
# data (named below), so a real regression fails:
#  - the cube method with the default settings succeeds (Es < 0.10 m and Ea < 1 deg) in 25 of
#    25 trials from +-1 m / +-8 deg on every pair (measured 25/25), and its repeatability (the
#    trials' median distance to their median pose) is <= 0.7 mm / 0.006 deg on every pair
#    (measured at most 0.34 mm / 0.0030 deg);
#  - every folder, written into a bag with clouds_to_bag (odometry off by +-0.5 m / +-5 deg),
#    replays through launch/bag_replay.launch with every registration accepted;
#  - a folder that is a sequence (poses.tum) is chained by sequence_benchmark from odometry
#    with the "big" errors: every scan accepted, drift <= 0.65 % and <= 0.025 deg/m over its
#    longest segments (measured 0.32 % and 0.0117 deg/m over 10 m).
#   usage: scripts/test.sh [DATA_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
DATA_DIR="${1:-}"
if [ -n "$DATA_DIR" ]; then
  if [ ! -d "$DATA_DIR" ]; then
    echo "test: DATA_DIR '$DATA_DIR' is not a directory" >&2
    exit 2
  fi
  # A DATA_DIR without a single data folder would check nothing and pass: refuse it.
  if ! compgen -G "$DATA_DIR/*/pairs.txt" > /dev/null; then
    echo "test: DATA_DIR '$DATA_DIR' holds no data folder (no sub-folder with pairs.txt)" >&2
    exit 2
  fi
fi
source scripts/env.sh  # install, build, ROS environment
status=0
if [ -n "$DATA_DIR" ]; then
  echo "== real-data accuracy check on $DATA_DIR"
  for d in "$DATA_DIR"/*/; do
    [ -f "$d/pairs.txt" ] || continue
    build/devel/lib/cube_scan_matcher/benchmark "$d" --methods cubes --trials 25 \
      --require-success 25 --check-repeatability 0.0007 0.006 \
      --csv "build/accuracy_$(basename "$d").csv" 2>/dev/null || status=1
    bash scripts/replay_check.sh "$d" || status=1
    if [ -f "$d/poses.tum" ]; then
      build/devel/lib/cube_scan_matcher/sequence_benchmark --dir "$d" --methods cubes \
        --odometry big --csv "build/sequence_$(basename "$d").csv" --check-pct 0.65 \
        --check-deg-m 0.025 --check-rejected 0 --check-accepted-wrong 0 2>&1 |
        grep -v "^scan " || status=1
    fi
  done
else
  echo "== real-data accuracy check NOT run: no DATA_DIR given (CI passes ../shared/data)"
fi
echo "== unit and integration tests (CTest)"
(cd build && ctest --no-tests=error --output-on-failure) || status=1
exit $status
