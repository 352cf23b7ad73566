#!/usr/bin/env bash
# Builds the package in a catkin_make workspace (devel/ beside build/, not inside it) and runs
# the tests that find the package through the workspace: the RViz screenshot and a roslaunch
# file check. A plain `cmake -S . -B build` build cannot show a path that only works there.
#   bash scripts/workspace_check.sh [WORKSPACE]        (default: a temporary folder)
set -eo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
WS="${1:-$(mktemp -d)}"
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
source /opt/ros/*/setup.bash 2>/dev/null || true
mkdir -p "$WS/src"
ln -sfn "$ROOT" "$WS/src/cube_scan_matcher"
cd "$WS"
catkin_make -DCMAKE_BUILD_TYPE=Release -j2 > "$WS/catkin_make.log" 2>&1 ||
  { tail -30 "$WS/catkin_make.log"; echo "workspace_check: FAILED: catkin_make"; exit 1; }
[ -f "$WS/devel/setup.bash" ] || { echo "workspace_check: FAILED: no $WS/devel/setup.bash"; exit 1; }
[ ! -e "$WS/build/devel" ] || { echo "workspace_check: FAILED: not a catkin_make layout"; exit 1; }
cd "$WS/build"
TESTS="rviz_screenshot|roslaunch-check_launch_scan_matcher"
# Both tests must exist: a renamed one would otherwise leave the other passing alone.
found="$(ctest -N -R "$TESTS" | sed -n 's/^Total Tests: //p')"
[ "$found" = 2 ] || { echo "workspace_check: FAILED: $found tests match '$TESTS', expected 2"; exit 1; }
ctest -R "$TESTS" --no-tests=error --output-on-failure
echo "workspace_check: OK ($WS: devel/ beside build/)"
