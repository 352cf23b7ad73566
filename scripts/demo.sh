#!/usr/bin/env bash
# The README's first command: installs, builds and runs the built-in demo: launch/demo.launch
# (simulated tilting 2D scanner -> ScanMatcherNodelet -> evaluator against the exact truth),
# headless, 10 sweeps with the paper's "big" odometry errors, then a summary. Extra arguments
# go to roslaunch, e.g. scene:=park sweeps:=20 rviz:=true odometry_error:=drift.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
set +u  # ROS setup scripts read unset variables
source build/devel/setup.bash
set -u
exec roslaunch cube_scan_matcher demo.launch "$@"
