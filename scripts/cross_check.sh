#!/usr/bin/env bash
# Portable build check: compiles every ROS-free source (core, simulator, io) for
# aarch64 with Debian's cross compiler, to object code (-O2 -c: GCC reports a bad target
# attribute only at code generation), with the package's warnings as errors. The x86-only
# function clones of the hot loop must stay behind their guard.
#   usage: scripts/cross_check.sh [TRIPLET]     (default aarch64-linux-gnu)
set -euo pipefail
cd "$(dirname "$0")/.."
TRIPLET="${1:-aarch64-linux-gnu}"
CXX="$TRIPLET-g++"
if ! command -v "$CXX" > /dev/null; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "g++-$TRIPLET" > /dev/null
fi
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
n=0; failed=0
for src in src/core/*.cpp src/sim/*.cpp src/io/*.cpp; do
  if "$CXX" -std=c++17 -O2 -fopenmp-simd -Wall -Wextra -Wpedantic -Werror -Iinclude \
      -isystem /usr/include/eigen3 -c "$src" -o "$OUT/$(basename "$src").o"; then
    n=$((n + 1))
  else
    echo "cross_check: FAILED: $src for $TRIPLET"; failed=$((failed + 1))
  fi
done
echo "cross_check: $n sources compiled for $TRIPLET, $failed failed ($("$CXX" --version | head -1))"
[ "$failed" -eq 0 ]
