#!/usr/bin/env bash
# The README's first command: installs, builds and runs the built-in demo (a simulated tilting
# scanner in a procedural scene; each sweep registered to the previous one). Extra arguments
# go to simulate_and_register (see --help), e.g. --scene park --sweeps 10.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
exec build/devel/lib/cube_scan_matcher/simulate_and_register "$@"
