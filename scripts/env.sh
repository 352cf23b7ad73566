# Sourced by demo.sh and test.sh: installs the dependencies, builds, and enters the build's
# ROS environment (Debian's python3 first on PATH, as every ROS step needs).
bash scripts/install_deps.sh
bash scripts/build.sh
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
set +u  # ROS setup scripts read unset variables
source build/devel/setup.bash
set -u
