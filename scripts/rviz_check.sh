#!/usr/bin/env bash
# Starts the demo with RViz (rviz/scan_matcher.rviz) on a virtual display (Xvfb), saves a
# screenshot and checks that the 3-D view shows the registered clouds: enough saturated
# (coloured) pixels, which the grey grid and the dark background are not.
#   bash scripts/rviz_check.sh [OUTPUT.png] [SCENE]      (needs a built package)
set -eo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
# The devel space's setup: CTest passes its own (build/devel in a plain build, the workspace's
# devel/ under catkin_make), else this checkout's build/devel.
SETUP="${CSM_SETUP:-$ROOT/build/devel/setup.bash}"
OUT="${1:-$ROOT/build/rviz_check.png}"; SCENE="${2:-urban}"
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
[ -f "$SETUP" ] || { echo "rviz_check: $SETUP not found (build the package first)"; exit 1; }
source "$SETUP"
export ROS_MASTER_URI=http://localhost:$((11900 + RANDOM % 500))
LOG="$(mktemp)"
xvfb-run -a -s "-screen 0 1280x800x24" bash -c "
  roslaunch -p ${ROS_MASTER_URI##*:} cube_scan_matcher demo.launch rviz:=true sweeps:=0 scene:=$SCENE > '$LOG' 2>&1 &
  PID=\$!
  sleep 25
  import -window root '$OUT'
  kill -INT \$PID; wait \$PID || true
"
# Fraction of pixels with HSL saturation above 35% in the 3-D panel (right of the displays
# panel, below the toolbar).
FRACTION=$(convert "$OUT" -crop 900x650+360+80 +repage -colorspace HSL -channel G -separate \
  -threshold 35% -format "%[fx:mean]" info:)
echo "rviz_check: $OUT, coloured fraction of the 3-D view: $FRACTION"
if awk -v f="$FRACTION" 'BEGIN { exit !(f > 0.02) }'; then
  echo "rviz_check: OK (registered clouds visible)"
else
  echo "rviz_check: FAILED: the 3-D view looks empty"; tail -20 "$LOG"; exit 1
fi
