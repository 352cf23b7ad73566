#!/usr/bin/env bash
# Soak (RELIABILITY.md): records a demo bag (the simulated tilting scanner's stop-and-go sweeps,
# input:=sweeps, ground truth, tf), then replays it in a loop at RATE x through
# launch/bag_replay.launch into the nodelet for MINUTES, while soak_monitor tracks the manager's
# resident memory, latency, drops and every registration against the truth. Fails if the
# manager dies, memory grows (second half's maximum beyond 110 % of the first half's), nothing
# is registered, an accepted increment is off the truth by 10 cm or 1 deg or more, or fewer
# than 90 % of the registrations are accepted. Needs a built package.
#   bash scripts/soak.sh [MINUTES] [RATE] [SWEEPS]     (defaults 10, 5, 30)
set -eo pipefail
MINUTES="${1:-10}"; RATE="${2:-5}"; SWEEPS="${3:-30}"
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${CSM_BUILD_DIR:-$ROOT/build}"
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
source "$BUILD/devel/setup.bash"
WORK="$(mktemp -d)"
PORT=$((11900 + RANDOM % 500))
export ROS_MASTER_URI=http://localhost:$PORT
cleanup() {
  [ -n "${LAUNCH_PID:-}" ] && kill -INT "$LAUNCH_PID" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT

echo "soak: recording $SWEEPS demo sweeps (urban, big odometry errors) into a bag"
roslaunch -p "$PORT" cube_scan_matcher demo.launch input:=sweeps sweeps:="$SWEEPS" record:="$WORK/demo.bag" \
  > "$WORK/record.log" 2>&1 || true
for _ in $(seq 20); do [ -f "$WORK/demo.bag" ] && break; sleep 0.5; done
[ -f "$WORK/demo.bag" ] || { echo "soak: no bag recorded"; tail -20 "$WORK/record.log"; exit 1; }
rosbag info "$WORK/demo.bag" | grep -E "duration|assembled_cloud|ground_truth" | sed 's/^/  /'

echo "soak: replaying it in a loop at ${RATE}x for $MINUTES min"
roslaunch -p "$PORT" cube_scan_matcher bag_replay.launch bag:="$WORK/demo.bag" loop:=true \
  rate:="$RATE" > "$WORK/replay.log" 2>&1 &
LAUNCH_PID=$!
PID=""
for _ in $(seq 60); do
  PID=$(pgrep -f "__name:=scan_matcher_manager" | head -1 || true)
  [ -n "$PID" ] && break
  sleep 0.5
done
[ -n "$PID" ] || { echo "soak: the nodelet manager did not start"; tail -20 "$WORK/replay.log"; exit 1; }
rc=0
"$BUILD/devel/lib/cube_scan_matcher/soak_monitor" _duration:="$(awk "BEGIN { print $MINUTES * 60 }")" _pid:="$PID" || rc=$?
if grep -qE "Segmentation|process has died|core dumped" "$WORK/replay.log"; then
  echo "soak: FAILED: a process died"; grep -E "Segmentation|has died|core dumped" "$WORK/replay.log"; rc=1
fi
exit $rc
