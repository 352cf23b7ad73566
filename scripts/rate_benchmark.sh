#!/usr/bin/env bash
# The nodelet at robot rates (a benchmark, not a test): rate_feeder publishes
# simulated 65k-point sweeps with fresh stamps at RATE Hz for SECONDS s into the scan matcher
# nodelet in its own manager (launch/scan_matcher.launch, config/scan_matcher.yaml), and
# prints the data age (stamp -> published pose), latency, registration time, drops and the
# reference grids' memory; then the manager's peak resident memory. Needs a built package.
# Exits non-zero if fewer than MIN_ANSWERED clouds were answered (CTest rate_benchmark_smoke).
#   [CSM_SIMD=avx2] [CSM_CONFIG=my.yaml] bash scripts/rate_benchmark.sh [RATE=20] [SECONDS=60] [MIN_ANSWERED=1]
set -eo pipefail
RATE="${1:-20}"; SECONDS_="${2:-60}"; MIN_ANSWERED="${3:-1}"
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
SETUP="${CSM_SETUP:-$ROOT/build/devel/setup.bash}"
source "$SETUP"
WORK="$(mktemp -d)"
PORT=$((12900 + RANDOM % 500))
export ROS_MASTER_URI=http://localhost:$PORT
CONFIG="${CSM_CONFIG:-$ROOT/config/scan_matcher.yaml}"
roslaunch -p "$PORT" cube_scan_matcher scan_matcher.launch cloud:=cloud config:="$CONFIG" > "$WORK/launch.log" 2>&1 &
LAUNCH=$!
trap 'kill -INT $LAUNCH 2>/dev/null || true; wait $LAUNCH 2>/dev/null || true; rm -rf "$WORK"' EXIT
for _ in $(seq 60); do rostopic list > /dev/null 2>&1 && break; sleep 0.5; done
echo "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); $(nproc) cores; CSM_SIMD=${CSM_SIMD:-auto}; config $CONFIG"
"$(dirname "$SETUP")/lib/cube_scan_matcher/rate_feeder" _rate:="$RATE" _duration:="$SECONDS_" _min_answered:="$MIN_ANSWERED"
MANAGER=$(pgrep -f "__name:=scan_matcher_manager" | head -1 || true)
if [ -n "$MANAGER" ]; then
  grep -E "VmHWM|VmRSS" /proc/"$MANAGER"/status | tr -s ' \t' ' ' | sed 's/^/nodelet manager /'
fi
grep -m1 "SIMD path" "$WORK/launch.log" || true
