#!/usr/bin/env bash
# The runs behind docs/method.md ("Without odometry: a planar grid search") and
# docs/experiments.md ("Without odometry: the planar grid's alternatives"): 500 m of each
# simulated world and the shared real sequence without odometry (constant velocity), cubes
# only, with the planar grid (the default, summary_on.csv), without it (--no-odometry-grid 0:0,
# summary_off.csv), with a yaw half width of 90 deg (summary_yaw90.csv: park, natural, real)
# and without the grid but with dense points for every search (summary_off_dense4.csv: park,
# hall). One run at a time, the variants of a world one after the other, so that their times
# compare. Writes each run's per-scan CSV and log, the summaries, and run.txt (commit, tree,
# CPU, vector path) into OUT_DIR.
#   usage: bash scripts/no_odometry_grid.sh DATA_DIR [OUT_DIR (default docs/sequence/no_odometry_grid)]
set -euo pipefail
if [ $# -lt 1 ] || [ ! -d "$1" ]; then
  echo "usage: bash scripts/no_odometry_grid.sh DATA_DIR [OUT_DIR]" >&2
  exit 2
fi
DATA="$(cd "$1" && pwd)"
cd "$(dirname "$0")/.."
OUT="${2:-docs/sequence/no_odometry_grid}"
SEQ="$DATA/balm_os0_hall_seq_a"
[ -f "$SEQ/poses.tum" ] || { echo "no_odometry_grid: $SEQ/poses.tum not found" >&2; exit 2; }
commit="$(git rev-parse HEAD)"
tree="$(git status --porcelain --untracked-files=no -- . ":(exclude)$OUT")"
source scripts/env.sh  # install, build, ROS environment
BIN=build/devel/lib/cube_scan_matcher/sequence_benchmark
mkdir -p "$OUT"
rm -f "$OUT"/*.csv "$OUT"/*.log "$OUT"/run.txt
started="$(date -u '+%Y-%m-%d %H:%M:%S UTC')"

run() {  # NAME SUMMARY ARGS...: one cubes-only run without odometry
  local name="$1" summary="$2"
  shift 2
  echo "== $name: sequence_benchmark $* --odometry cv --methods cubes"
  "$BIN" "$@" --odometry cv --methods cubes --csv "$OUT/$name.csv" \
    --summary "$OUT/$summary" > "$OUT/$name.log" 2>&1
  grep -h "verdicts against" "$OUT/$name.log"
}
for world in park natural hall urban; do
  sim=(--scene "$world" --length 500)
  run "sim_cv_$world" summary_on.csv "${sim[@]}"
  run "sim_cv_${world}_off" summary_off.csv "${sim[@]}" --no-odometry-grid 0:0
  case "$world" in
    park | natural) run "sim_cv_${world}_yaw90" summary_yaw90.csv "${sim[@]}" --no-odometry-grid 2:90 ;;
  esac
  case "$world" in
    park | hall)
      run "sim_cv_${world}_off_dense4" summary_off_dense4.csv "${sim[@]}" --no-odometry-grid 0:0 \
        --dense-points 4
      ;;
  esac
done
run real_cv summary_on.csv --dir "$SEQ"
run real_cv_off summary_off.csv --dir "$SEQ" --no-odometry-grid 0:0
run real_cv_yaw90 summary_yaw90.csv --dir "$SEQ" --no-odometry-grid 2:90
{
  echo "commit: $commit"
  if [ -z "$tree" ]; then echo "tree: clean"; else echo "tree: dirty:"; echo "$tree"; fi
  echo "started: $started"
  echo "finished: $(date -u '+%Y-%m-%d %H:%M:%S UTC')"
  echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'), $(nproc) cores"
  echo "SIMD paths (logs: path):"
  grep -ho 'SIMD path: [a-z0-9]*' "$OUT"/*.log | sort | uniq -c
} > "$OUT/run.txt"
cat "$OUT/run.txt"
