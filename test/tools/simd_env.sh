#!/usr/bin/env bash
# The vector-path switch as a user meets it, through a tool (point_scaling, two 10k-point sweeps;
# at 5k points 15-17 of 20 registrations succeed, too sparse for a check that must not be luck):
#  - CSM_SIMD=portable: the header names the portable path and the registrations succeed;
#  - CSM_SIMD=<unknown>: a warning on stderr names the value, the run goes on, on the fastest
#    supported path (a typo in a robot's environment must not stop its manager);
#  - --simd <unknown>: exit code 1 and a message naming the value and the accepted ones.
#   usage: simd_env.sh BIN_DIR
set -uo pipefail
BIN="$1"
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
status=0
fail() { echo "simd_env: FAILED: $*"; status=1; }
RUN=("$BIN/point_scaling" --points 10000 --trials 2 --require-success 2)

CSM_SIMD=portable "${RUN[@]}" > "$OUT/out" 2> "$OUT/err" || fail "CSM_SIMD=portable: exit $?"
grep -q "SIMD path: portable" "$OUT/out" || fail "CSM_SIMD=portable: header: $(head -1 "$OUT/out")"

CSM_SIMD=avx3 "${RUN[@]}" > "$OUT/out" 2> "$OUT/err" || fail "CSM_SIMD=avx3: exit $?"
grep -q "CSM_SIMD.*avx3" "$OUT/err" || fail "CSM_SIMD=avx3: no warning naming it: $(cat "$OUT/err")"
grep -q "SIMD path: " "$OUT/out" || fail "CSM_SIMD=avx3: no header"

"${RUN[@]}" --simd avx3 > "$OUT/out" 2> "$OUT/err"
rc=$?
[ "$rc" -eq 1 ] || fail "--simd avx3: exit $rc, expected 1"
grep -q "avx3" "$OUT/err" && grep -q "portable" "$OUT/err" ||
  fail "--simd avx3: message does not name the value and the paths: $(cat "$OUT/err")"

[ "$status" -eq 0 ] && echo "simd_env: all checks passed"
exit $status
