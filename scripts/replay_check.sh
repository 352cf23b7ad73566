#!/usr/bin/env bash
# Replays a dataset folder (shared/data format) through launch/bag_replay.launch and checks
# that the scan matcher accepts every registration. Needs a built package (scripts/build.sh).
#   bash scripts/replay_check.sh ../shared/data/3dtk_slam6d_dat [T_ERR A_ERR]
# The bag's odometry is the folder's reference poses with uniform errors of +-T_ERR m and
# +-A_ERR deg on each increment (default 0.5 m, 5 deg), so the matcher has to correct them.
set -eo pipefail
DIR="$1"; T_ERR="${2:-0.5}"; A_ERR="${3:-5}"
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${CSM_BUILD_DIR:-$ROOT/build}"   # the build directory (CTest passes its own)
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
source "$BUILD/devel/setup.bash"
WORK="$(mktemp -d)"
trap 'kill $LAUNCH_PID 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$WORK"' EXIT
"$BUILD/devel/lib/cube_scan_matcher/clouds_to_bag" "$WORK/replay.bag" --dataset "$DIR" \
  --odometry-error "$T_ERR" "$A_ERR" --rate 0.5 > "$WORK/bag.log"
N=$(grep -c " points at " "$WORK/bag.log")
export ROS_MASTER_URI=http://localhost:$((11400 + RANDOM % 500))
roslaunch -p "${ROS_MASTER_URI##*:}" cube_scan_matcher bag_replay.launch bag:="$WORK/replay.bag" \
  > "$WORK/launch.log" 2>&1 &
LAUNCH_PID=$!
for _ in $(seq 60); do rostopic list > /dev/null 2>&1 && break; sleep 0.5; done
timeout 120 rostopic echo -n "$N" -p /scan_matcher/status/reason_text > "$WORK/status.csv" || true
echo "replay_check $(basename "$DIR"): $N clouds, statuses:"
sed 1d "$WORK/status.csv" | cut -d, -f2 | sed 's/^/  /'
ACCEPTED=$(sed 1d "$WORK/status.csv" | grep -c accepted || true)
if [ "$ACCEPTED" -ne $((N - 1)) ]; then
  echo "replay_check: FAILED: $ACCEPTED of $((N - 1)) registrations accepted"; tail -20 "$WORK/launch.log"; exit 1
fi
echo "replay_check: OK: $ACCEPTED of $((N - 1)) registrations accepted"
