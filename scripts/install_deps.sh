#!/usr/bin/env bash
# Installs every build, run and test dependency by Debian 12 package name (idempotent; run as
# root, or with sudo available). Debian 12's own archive ships ROS 1; no rosdep keys needed.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
PKGS=(
  build-essential cmake catkin libeigen3-dev libpcl-dev libgtest-dev catkin-lint
  libroscpp-dev libnodeletlib-dev libnodelet-dev libnodeletlib-tools pluginlib-dev
  libtf2-ros-dev libtf2-eigen-dev libtf2-geometry-msgs-dev libtf2-sensor-msgs-dev libpcl-ros-dev
  liblaser-geometry-dev
  ros-sensor-msgs ros-geometry-msgs ros-nav-msgs ros-std-srvs ros-message-generation
  ros-message-runtime libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libdiagnostic-updater-dev librostest-dev python3-rostest python3-roslaunch python3-rosmaster
  python3-rostopic rosbash librosbag-dev python3-rosbag python3-matplotlib
  libnav-msgs-dev libstd-srvs-dev libsensor-msgs-dev libgeometry-msgs-dev libdiagnostic-msgs-dev
  python3-rospy python3-nav-msgs python3-sensor-msgs python3-geometry-msgs python3-std-srvs
  python3-tf2-ros python3-diagnostic-msgs python3-numpy
  rviz xvfb xauth imagemagick procps
  clang-14 libfuzzer-14-dev libopen3d-dev
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PKGS[@]} packages already installed"
  exit 0
fi
echo "install_deps: installing ${#missing[@]} packages: ${missing[*]}"
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
