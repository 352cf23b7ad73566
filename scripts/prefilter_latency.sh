#!/usr/bin/env bash
# The demo (input:=sweeps: the prefilter takes no sweep assembled in odom) with and without the
# pcl_ros prefilter (CropBox + VoxelGrid in the matcher's manager): median latency (arrival to
# publish), data age (stamp to publish), registration time and points per sweep from ~status.
# Needs a built package.
#   bash scripts/prefilter_latency.sh [SWEEPS] [SCENE]
set -eo pipefail
SWEEPS="${1:-15}"; SCENE="${2:-urban}"
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
source "${CSM_SETUP:-$ROOT/build/devel/setup.bash}"
WORK="$(mktemp -d)"
for prefilter in false true; do
  export ROS_MASTER_URI=http://localhost:$((12400 + RANDOM % 500))
  roslaunch -p "${ROS_MASTER_URI##*:}" cube_scan_matcher demo.launch input:=sweeps scene:="$SCENE" \
    sweeps:="$SWEEPS" prefilter:="$prefilter" > "$WORK/launch_$prefilter.log" 2>&1 &
  PID=$!
  for _ in $(seq 60); do rostopic list > /dev/null 2>&1 && break; sleep 0.5; done
  timeout 120 rostopic echo -n "$SWEEPS" /scan_matcher/status > "$WORK/status_$prefilter.yaml" || true
  kill -INT $PID 2>/dev/null || true; wait $PID 2>/dev/null || true
  /usr/bin/python3 - "$WORK/status_$prefilter.yaml" "$prefilter" <<'PY'
import re, statistics, sys
rows = []
for doc in open(sys.argv[1]).read().split("\n---")[1:]:  # the first scan is not registered
    rows.append(dict(re.findall(r"^(\w+): (\S+)$", doc, re.M)))
rows = [r for r in rows if "latency" in r]
med = lambda k: statistics.median(float(r[k]) for r in rows)
print("prefilter %-5s: %d sweeps, points in %.0f, valid %.0f, used %.0f; median latency %.1f ms, "
      "data age %.1f ms, registration %.1f ms; accepted %d/%d" % (
      sys.argv[2], len(rows), med("points_in"), med("points_valid"), med("points_used"),
      1e3 * med("latency"), 1e3 * med("data_age"), 1e3 * med("registration_time"),
      sum(r["accepted"] == "True" for r in rows), len(rows)))
PY
done
rm -rf "$WORK"
