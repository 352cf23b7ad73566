#!/usr/bin/env bash
# tilting_laser.launch respawn:=true: when the nodelet manager dies (kill -9), roslaunch starts
# it again and the loaders load both nodelets into it again: both publish diagnostics again.
# (With respawn:=false they do not: the check fails.)
#   bash test/launch/respawn_check.sh [true|false]   (CSM_SETUP=devel or install setup.bash)
set -uo pipefail
RESPAWN="${1:-true}"
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
set +u; source "${CSM_SETUP:?CSM_SETUP: the setup.bash of a devel or install space}"; set -u
WORK="$(mktemp -d)"
PORT=$((12900 + RANDOM % 400))
export ROS_MASTER_URI=http://localhost:$PORT
roslaunch -p "$PORT" cube_scan_matcher tilting_laser.launch tilt_reference_frame:=laser_mount \
  respawn:="$RESPAWN" > "$WORK/launch.log" 2>&1 &
LAUNCH_PID=$!
trap 'kill -INT $LAUNCH_PID 2>/dev/null; wait 2>/dev/null; rm -rf "$WORK"' EXIT
# up: both nodelets loaded and running: their diagnostics (each publishes every second)
waitUp() {
  for _ in $(seq "$1"); do
    timeout 3 rostopic echo -p /diagnostics > "$WORK/diag.txt" 2>/dev/null
    if grep -q "scan_matcher: registration" "$WORK/diag.txt" &&
       grep -q "sweep_assembler: sweep assembly" "$WORK/diag.txt"; then return 0; fi
  done
  return 1
}
waitUp 60 || { echo "respawn_check: FAILED: the nodelets did not start"; tail -20 "$WORK/launch.log"; exit 1; }
MANAGER="$(pgrep -f "__name:=scan_matcher_manager" | head -1)"
[ -n "$MANAGER" ] || { echo "respawn_check: FAILED: no manager process"; exit 1; }
kill -9 "$MANAGER"
echo "respawn_check: killed the manager (pid $MANAGER)"
sleep 1
if waitUp 30 && [ -n "$(pgrep -f "__name:=scan_matcher_manager")" ] &&
   [ "$(pgrep -f "__name:=scan_matcher_manager" | head -1)" != "$MANAGER" ]; then
  echo "respawn_check: OK: manager restarted, both nodelets loaded again (respawn:=$RESPAWN)"
  exit 0
fi
echo "respawn_check: FAILED: the nodelets did not come back after the manager died (respawn:=$RESPAWN)"
tail -20 "$WORK/launch.log"
exit 1
