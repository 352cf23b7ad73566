#!/usr/bin/env bash
# Builds the package in a catkin_make workspace (devel/ beside build/, not inside it) and runs
# the tests that find the package through the workspace: the RViz screenshot and a roslaunch
# file check. A plain `cmake -S . -B build` build cannot show a path that only works there.
# Then installs it (catkin_make install) and, with only the install space on the path, checks
# that the package is found there, runs the launch-file check and the demo from it, and builds
# a downstream consumer (test/consumer) against the installed headers with GCC 9's default
# standard (-std=gnu++14), which the exported C++17 requirement must override.
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

cd "$WS"
catkin_make install -DCMAKE_BUILD_TYPE=Release -j2 > "$WS/install.log" 2>&1 ||
  { tail -30 "$WS/install.log"; echo "workspace_check: FAILED: catkin_make install"; exit 1; }
# A shell that has seen neither the devel space nor this one's variables.
env -i HOME="$HOME" PATH=/usr/sbin:/usr/bin:/sbin:/bin ROOT="$ROOT" WS="$WS" bash -c '
  set -eo pipefail
  source /opt/ros/*/setup.bash 2>/dev/null || true
  source "$WS/install/setup.bash"
  fail() { echo "workspace_check: FAILED (install space): $*"; exit 1; }
  found="$(rospack find cube_scan_matcher)"
  [ "$found" = "$WS/install/share/cube_scan_matcher" ] || fail "rospack finds $found"
  echo "workspace_check: install space: rospack finds $found"
  bash "$ROOT/test/launch/yaml_respected.sh" > "$WS/install_launch.log" 2>&1 ||
    { tail -20 "$WS/install_launch.log"; fail "launch files (test/launch/yaml_respected.sh)"; }
  echo "workspace_check: install space: launch files keep the YAML values"
  PORT=$((12400 + RANDOM % 500))
  timeout 240 roslaunch -p "$PORT" cube_scan_matcher demo.launch sweeps:=3 > "$WS/install_demo.log" 2>&1 || true
  grep -q "summary over 2 increments" "$WS/install_demo.log" ||
    { tail -20 "$WS/install_demo.log"; fail "the demo did not register its sweeps"; }
  grep "summary over" "$WS/install_demo.log" | sed "s/^/  demo from the install space: /"
  cmake -S "$ROOT/test/consumer" -B "$WS/consumer" -DCMAKE_CXX_FLAGS=-std=gnu++14 \
    -DCMAKE_PREFIX_PATH="$WS/install" > "$WS/consumer.log" 2>&1 &&
    make -C "$WS/consumer" >> "$WS/consumer.log" 2>&1 ||
    { tail -20 "$WS/consumer.log"; fail "the downstream consumer did not build"; }
  "$WS/consumer/csm_consumer" | grep -q "C++ 201703" || fail "the consumer is not C++17"
  echo "workspace_check: install space: a consumer with -std=gnu++14 builds (C++17 carried by the CMake extras)"
  # Without the extras the headers do not compile as C++14: the requirement is real.
  if g++ -std=gnu++14 -fsyntax-only -I"$WS/install/include" -I/usr/include/eigen3 \
       "$ROOT/test/consumer/consumer.cpp" > "$WS/consumer_cxx14.log" 2>&1; then
    fail "the headers compile as C++14: the C++17 extras are not needed any more"
  fi
  echo "workspace_check: install space: plain g++ -std=gnu++14 fails as expected ($(grep -m1 -o "error: .*" "$WS/consumer_cxx14.log"))"
' || exit 1
echo "workspace_check: OK (install space)"
