#!/usr/bin/env bash
# A raw robot bag through launch/bag_replay.launch input:=lines: records the demo's LaserScan
# lines of the simulated tilting laser while it drives ("big" odometry errors, tf per line),
# then replays the bag through the sweep assembler and the matcher (tilting_laser.launch) on
# simulated time, with the evaluator comparing every increment with the bag's ground truth.
# Fails unless every sweep after the first is accepted within 0.10 m / 1 deg of the truth.
# Needs a built package.
#   bash scripts/replay_lines_check.sh [SWEEPS]      (default 6)
set -eo pipefail
SWEEPS="${1:-6}"
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
SETUP="${CSM_SETUP:-$ROOT/build/devel/setup.bash}"   # the devel space (CTest passes its own)
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
source "$SETUP"
WORK="$(mktemp -d)"
PORT=$((12500 + RANDOM % 400))
export ROS_MASTER_URI=http://localhost:$PORT
trap 'kill -INT $LAUNCH_PID 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$WORK"' EXIT

roslaunch -p "$PORT" cube_scan_matcher demo.launch input:=lines sweeps:="$SWEEPS" \
  record:="$WORK/lines.bag" > "$WORK/record.log" 2>&1 || true
for _ in $(seq 20); do [ -f "$WORK/lines.bag" ] && break; sleep 0.5; done
[ -f "$WORK/lines.bag" ] || { echo "replay_lines_check: FAILED: no bag recorded"; tail -20 "$WORK/record.log"; exit 1; }
rosbag info "$WORK/lines.bag" | grep -E "duration|scan |ground_truth" | sed 's/^/  /'

roslaunch -p "$PORT" cube_scan_matcher bag_replay.launch bag:="$WORK/lines.bag" input:=lines \
  tilt_reference_frame:=laser_mount start_delay:=4 > "$WORK/replay.log" 2>&1 &
LAUNCH_PID=$!
for _ in $(seq 60); do rostopic list > /dev/null 2>&1 && break; sleep 0.5; done
# The evaluator prints one line per sweep and a summary, then exits.
timeout 180 "$(dirname "$SETUP")/lib/cube_scan_matcher/sim_evaluator" _sweeps:="$SWEEPS" \
  > "$WORK/eval.log" 2>&1 || true
sed 's/^/  /' "$WORK/eval.log" | grep -v "^\s*$" | tail -$((SWEEPS + 3))
SUMMARY="$(grep "summary over" "$WORK/eval.log" || true)"
EXPECTED=$((SWEEPS - 1))
if ! grep -q "success (Es < 0.10 m, Ea < 1 deg) $EXPECTED/$EXPECTED, accepted $EXPECTED/$EXPECTED" <<< "$SUMMARY"; then
  echo "replay_lines_check: FAILED: expected $EXPECTED of $EXPECTED increments accepted and right"
  tail -20 "$WORK/replay.log"
  exit 1
fi
echo "replay_lines_check: OK: the raw lines bag replayed, $EXPECTED of $EXPECTED increments accepted and right"
