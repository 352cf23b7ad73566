#!/usr/bin/env bash
# The README's first command: installs, builds and runs the built-in demo: launch/demo.launch
# (simulated tilting 2D scanner's LaserScan lines while driving -> SweepAssemblerNodelet ->
# ScanMatcherNodelet -> evaluator against the exact truth), headless, 10 sweeps with the
# paper's "big" odometry errors, then a summary. Extra arguments go to roslaunch, e.g.
# scene:=park sweeps:=20 rviz:=true odometry_error:=drift input:=sweeps.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh  # install, build, ROS environment
exec roslaunch cube_scan_matcher demo.launch "$@"
