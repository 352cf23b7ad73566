#!/usr/bin/env bash
# The sanitizer stage (RELIABILITY.md): two more builds of the package, each in its own folder.
#  1. ASan + UBSan (build-asan): the core, io and conversion gtests, the bad-file corpus through
#     the tools, and the rostests with the nodelet loaded into a manager that has the ASan
#     runtime preloaded (and scan_matcher_node, itself instrumented).
#  2. TSan (build-tsan): the tests whose code runs on several threads (parallel starts, the
#     planar grid, refine candidates, grid builds, concurrent align(), setReference()/setSettings()
#     during align()).
# Every sanitizer report goes to a log file; the stage fails unless there is none (and every
# test passes). Installs what it needs (Debian's GCC ships the sanitizer runtimes).
#   usage: scripts/sanitize.sh [asan|tsan|all]   (default all)
set -euo pipefail
cd "$(dirname "$0")/.."
WHAT="${1:-all}"
bash scripts/install_deps.sh
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
ROOT="$(pwd)"
REPORTS="$ROOT/build-sanitizer-reports"
rm -rf "$REPORTS" && mkdir -p "$REPORTS"
status=0

configure() {  # DIR FLAGS
  cmake -S . -B "$1" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS="$2 -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="$2" -DCMAKE_SHARED_LINKER_FLAGS="$2" > "$1.log" 2>&1 ||
    { cat "$1.log"; exit 1; }
}

# step NAME CMD...: runs a step, records a failure without stopping the stage. A step also
# fails when its output holds a sanitizer report (GCC's UBSan prints to stderr even with
# log_path, and a preloaded manager's report would not fail the rostest by itself).
step() {
  local name="$1" out
  shift
  out="$REPORTS/../build-sanitizer-step.log"
  echo "== sanitize: $name"
  local rc=0
  "$@" > "$out" 2>&1 || rc=$?
  cat "$out"
  if grep -qE 'runtime error:|ERROR: (Address|Leak|Thread)Sanitizer|WARNING: ThreadSanitizer' "$out"; then
    echo "   sanitizer report in the output of: $name"
    rc=1
  fi
  if [ "$rc" -eq 0 ]; then echo "   ok: $name"; else echo "   FAILED: $name"; status=1; fi
}

reports_clean() {  # the log files the runtimes wrote
  local n
  n=$(find "$REPORTS" -type f | wc -l)
  if [ "$n" -ne 0 ]; then
    echo "sanitize: $n sanitizer report file(s):"
    for f in "$REPORTS"/*; do echo "--- $f"; head -40 "$f"; done
    return 1
  fi
  echo "sanitize: no sanitizer report"
}

if [ "$WHAT" = asan ] || [ "$WHAT" = all ]; then
  FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all"
  configure build-asan "$FLAGS"
  echo "== sanitize: building build-asan (log in build-asan.log)"
  make -C build-asan -j"$(nproc)" test_core test_io test_cloud_conversion register_clouds \
    benchmark clouds_to_bag scan_matcher_node cube_scan_matcher_nodelet \
    cube_scan_matcher_assembler_nodelet test_scan_matcher_ros test_faults test_unload \
    >> build-asan.log 2>&1 || { tail -40 build-asan.log; exit 1; }
  BIN="$ROOT/build-asan/devel/lib/cube_scan_matcher"
  export ASAN_OPTIONS="log_path=$REPORTS/asan:detect_leaks=1:abort_on_error=0:exitcode=86"
  export UBSAN_OPTIONS="log_path=$REPORTS/ubsan:print_stacktrace=1:halt_on_error=1:exitcode=87"
  export LSAN_OPTIONS="suppressions=$ROOT/test/sanitizer/lsan.supp:print_suppressions=0"
  step "test_core (ASan+UBSan)" "$BIN/test_core"
  step "test_io (ASan+UBSan)" "$BIN/test_io"
  step "test_cloud_conversion (ASan+UBSan)" "$BIN/test_cloud_conversion"
  step "bad-file corpus through the tools (ASan+UBSan)" bash test/tools/bad_files.sh "$BIN"
  # The rostests: scan_matcher_node is instrumented itself; the manager (Debian's nodelet
  # binary) gets the ASan runtime preloaded, so the instrumented nodelet can load into it.
  set +u
  source build-asan/devel/setup.bash
  set -u
  LIBASAN="$(gcc -print-file-name=libasan.so)"
  step "rostest scan_matcher_node.test (ASan+UBSan)" \
    rostest cube_scan_matcher scan_matcher_node.test
  step "rostest scan_matcher_nodelet.test (ASan+UBSan, manager preloaded)" \
    rostest cube_scan_matcher scan_matcher_nodelet.test prefix:="env LD_PRELOAD=$LIBASAN"
  step "rostest bad_param.test (ASan+UBSan, manager preloaded)" \
    rostest cube_scan_matcher bad_param.test prefix:="env LD_PRELOAD=$LIBASAN"
  step "rostest faults.test (ASan+UBSan, manager preloaded)" \
    rostest cube_scan_matcher faults.test prefix:="env LD_PRELOAD=$LIBASAN"
  step "rostest unload.test (ASan+UBSan: nodelets destroyed after their unload)" \
    rostest cube_scan_matcher unload.test
  step "rostest slow_registration.test (ASan+UBSan, manager preloaded)" \
    rostest cube_scan_matcher slow_registration.test iterations:=3000 \
    prefix:="env LD_PRELOAD=$LIBASAN"
  unset ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS
fi

if [ "$WHAT" = tsan ] || [ "$WHAT" = all ]; then
  configure build-tsan "-fsanitize=thread"
  echo "== sanitize: building build-tsan (log in build-tsan.log)"
  make -C build-tsan -j"$(nproc)" test_core cube_scan_matcher_nodelet test_scan_matcher_ros \
    >> build-tsan.log 2>&1 || { tail -40 build-tsan.log; exit 1; }
  export TSAN_OPTIONS="log_path=$REPORTS/tsan:halt_on_error=0:exitcode=88"
  # The threaded code: parallel starts and refine candidates (every default-mode registration
  # runs them on two threads), grid builds, concurrent align(), setReference()/setSettings()
  # during align(), the thread runner itself.
  # Its own libraries first (the ASan part may have sourced build-asan's environment).
  export LD_LIBRARY_PATH="$ROOT/build-tsan/devel/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  step "test_core threaded tests (TSan)" "$ROOT/build-tsan/devel/lib/cube_scan_matcher/test_core" \
    --gtest_filter='Registration.*:Parallel.*:CoarseSearch.*:PlanarGrid.*:RefineSearch.*:ReferenceGrids.*:GridWorkspace.*:OnlineMatcher.*:ModesAndScenes/SyntheticRegistration.*/default_urban_*'
  # The nodelet's threads (the worker, the manager's callbacks, the map -> odom timer,
  # diagnostics) in a manager with the TSan runtime preloaded, while a slow registration runs
  # and services, reconfigure and clouds arrive. Debian's ROS libraries are not instrumented,
  # so TSan also reports what their own locks order: these reports go to a folder of their own,
  # and only a race with the package's sources in both stacks fails the step.
  TSAN_ROS="$ROOT/build-sanitizer-tsan-ros"
  rm -rf "$TSAN_ROS" && mkdir -p "$TSAN_ROS"
  set +u
  source build-tsan/devel/setup.bash
  set -u
  export LD_LIBRARY_PATH="$ROOT/build-tsan/devel/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  export TSAN_OPTIONS="log_path=$TSAN_ROS/tsan:halt_on_error=0:exitcode=0"
  LIBTSAN="$(gcc -print-file-name=libtsan.so)"
  step "rostest slow_registration.test (TSan, manager preloaded)" \
    rostest cube_scan_matcher slow_registration.test iterations:=1500 \
    prefix:="env LD_PRELOAD=$LIBTSAN"
  unset TSAN_OPTIONS
  # (the step's own output check above ignores these reports: they are in files)
  step "races in the nodelet's own code (TSan)" \
    bash -c 'shopt -s nullglob; f=("$1"/tsan*); /usr/bin/python3 test/sanitizer/own_races.py "$2" "${f[@]}" /dev/null' \
    _ "$TSAN_ROS" "$ROOT"
fi

step "sanitizer reports" reports_clean
[ "$status" -eq 0 ] && echo "sanitize: passed" || echo "sanitize: FAILED"
exit $status
