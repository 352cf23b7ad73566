#!/usr/bin/env bash
# Reruns every benchmark behind a section of BENCHMARK.md on the shipped defaults (no tuning
# option is given to any tool) and writes each run's CSV and stdout log into
# OUT_DIR/<section>/ under fixed names, plus OUT_DIR/<section>/run.txt: the commit (and whether
# the tree had changes), the dates, the CPU, the core count and the vector paths the tools
# reported.
# scripts/benchmark_tables.py prints BENCHMARK.md's tables from OUT_DIR.
#   usage: scripts/benchmarks.sh quick|full DATA_DIR [OUT_DIR [SECTION...]]
# DATA_DIR is laid out like shared/data (sub-folders with pairs.txt; a sequence also has
# poses.tum); OUT_DIR defaults to docs/results. full: the runs BENCHMARK.md quotes; quick:
# reduced simulated runs (every tool runs, a first look), and no rate benchmark.
# Sections (folders of OUT_DIR): real_pairs (accuracy, speed per vector path, stage times),
# scenes, sequences, sweeps, rate; all of them unless some are named after OUT_DIR (so the
# timed sections can run on a quiet machine apart from the long untimed ones). Each section's
# folder is emptied before it runs, so one
# OUT_DIR never mixes two runs. Steps run one at a time, as the times are part of the results;
# a failing step does not stop the others: the script lists the failed ones and exits 1.
set -euo pipefail

usage() {
  echo "usage: scripts/benchmarks.sh quick|full DATA_DIR [OUT_DIR (default docs/results)" \
    "[SECTION... (real_pairs scenes sequences sweeps covariance rate; default all)]]" >&2
  exit 2
}
if [ $# -lt 2 ]; then usage; fi
MODE="$1"
case "$MODE" in quick | full) ;; *) usage ;; esac
if [ ! -d "$2" ]; then
  echo "benchmarks: DATA_DIR '$2' is not a directory" >&2
  exit 2
fi
# Paths given are relative to the caller's directory; the script then works from the repo root.
DATA_DIR="$(cd "$2" && pwd)"
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
OUT_DIR="${3:-$ROOT/docs/results}"
SECTIONS=(real_pairs scenes sequences sweeps covariance rate)
if [ $# -gt 3 ]; then
  SECTIONS=("${@:4}")
  for s in "${SECTIONS[@]}"; do
    case "$s" in real_pairs | scenes | sequences | sweeps | covariance | rate) ;; *)
      echo "benchmarks: unknown section '$s'" >&2
      usage
      ;;
    esac
  done
fi
mkdir -p "$OUT_DIR"
OUT_DIR="$(cd "$OUT_DIR" && pwd)"
cd "$ROOT"
# The commit and the tree's state before the build, which builds whatever the tree holds
# (changes to OUT_DIR's own files, earlier results, do not count).
COMMIT="$(git rev-parse HEAD)"
not_results=()
[[ "$OUT_DIR" == "$ROOT"/* ]] && not_results=(":(exclude)${OUT_DIR#"$ROOT/"}")
TREE_CHANGES="$(git status --porcelain --untracked-files=no -- . "${not_results[@]}")"

source scripts/env.sh  # install, build, ROS environment (as scripts/test.sh)
BIN=build/devel/lib/cube_scan_matcher
# The shipped default vector path is the fastest one the CPU runs: no CSM_SIMD override,
# except where a section measures a named path (recorded in run.txt).
CSM_SIMD_GIVEN="${CSM_SIMD:-}"
unset CSM_SIMD

FAILED=()  # the steps that failed, listed at the end
STEPS=()   # every step's outcome and time, for run.txt

cpu_has() {  # cpu_has FLAG: the CPU reports FLAG (x86 /proc/cpuinfo flags)
  grep -m1 '^flags' /proc/cpuinfo 2>/dev/null | grep -qw -- "$1"
}

# Open3D's peers exist only in builds with libopen3d-dev; the tools refuse them otherwise
# while reading their options, before any work (here: before finding no such folder).
OPEN3D=false
o3d_probe="$("$BIN/benchmark" /nonexistent/folder --methods o3d-p2pl-voxel 2>&1 || true)"
[[ "$o3d_probe" == *"no Open3D"* ]] || OPEN3D=true

# step SECTION NAME COMMAND...: prints a header, runs COMMAND and times it. The log
# OUT_DIR/SECTION/NAME.log starts with the command and the load average before it, then
# COMMAND's stdout; its stderr (progress) goes to the terminal and, when the step fails, stays
# in NAME.stderr.log beside it.
step() {
  local section="$1" name="$2"
  shift 2
  local log="$OUT_DIR/$section/$name.log" err="$OUT_DIR/$section/$name.stderr.log"
  local shown="${*//"$ROOT/"/}"
  echo "== $section/$name: $shown"
  printf '$ %s\nload average before: %s\n' "$shown" "$(cut -d' ' -f1-3 /proc/loadavg)" > "$log"
  local start=$SECONDS rc=0
  { "$@" 2>&1 >&3 3>&- | tee "$err" >&2 3>&-; } 3>> "$log" || rc=$?
  local took=$((SECONDS - start))
  if [ "$rc" -eq 0 ]; then
    rm -f "$err"
    echo "   ok, $took s"
    STEPS+=("$section/$name: ok, $took s")
  else
    echo "   FAILED (exit $rc), $took s; stderr in ${err#"$ROOT/"}"
    FAILED+=("$section/$name (exit $rc)")
    STEPS+=("$section/$name: FAILED (exit $rc), $took s")
  fi
}

fresh_section() {  # fresh_section NAME: an empty OUT_DIR/NAME for this run's files
  rm -rf -- "${OUT_DIR:?}/$1"
  mkdir -p "$OUT_DIR/$1"
}

# The folders of DATA_DIR holding FILE (pairs.txt or poses.tum), without a trailing slash
# (sequence_benchmark names a run after the folder's last path component).
data_folders() {
  local d
  for d in "$DATA_DIR"/*/; do
    [ -f "$d/$1" ] && echo "${d%/}"
  done
  return 0
}

# Accuracy on real pairs, speed per vector path and where the time goes: the paper's protocol
# (25 seeded guesses within +-1 m / +-8 deg per pair) on every folder with pairs.txt.
#  - <folder>.csv: the cube method and every peer (PCL ICP, NDT, GICP on 0.2 m voxel copies;
#    Open3D's point-to-plane ICP and GICP when built) on the default vector path, same guesses;
#  - <folder>_<path>_t<threads>.csv: the cube method alone per vector path and thread count
#    (AVX-512 and AVX2 where the CPU has them), as BENCHMARK.md's per-path table; the AVX2,
#    2-thread run also gives the stage times;
#  - full only, <folder>_seed<N>.csv: the cube method from trial seeds 2-7 (seed 1 is
#    <folder>.csv), the successes README quotes for seeds 1-7.
real_pairs() {
  fresh_section real_pairs
  local out="$OUT_DIR/real_pairs" methods=cubes,gicp-voxel,ndt-voxel,icp-voxel
  $OPEN3D && methods+=,o3d-p2pl-voxel,o3d-gicp-voxel
  local paths=()
  cpu_has avx512f && paths+=(avx512:2)
  cpu_has avx2 && paths+=(avx2:2)
  paths+=(portable:2)
  cpu_has avx2 && paths+=(avx2:1)
  paths+=(portable:1)
  local folders d name p seed
  mapfile -t folders < <(data_folders pairs.txt)
  if [ ${#folders[@]} -eq 0 ]; then
    echo "== real_pairs: no folder of $DATA_DIR has pairs.txt"
    FAILED+=("real_pairs (no folder with pairs.txt)")
    return
  fi
  for d in "${folders[@]}"; do
    name="$(basename "$d")"
    step real_pairs "$name" "$BIN/benchmark" "$d" --trials 25 --methods "$methods" \
      --csv "$out/$name.csv"
    for p in "${paths[@]}"; do
      step real_pairs "${name}_${p%:*}_t${p#*:}" "$BIN/benchmark" "$d" --trials 25 \
        --methods cubes --simd "${p%:*}" --threads "${p#*:}" \
        --csv "$out/${name}_${p%:*}_t${p#*:}.csv"
    done
    if [ "$MODE" = full ]; then
      for seed in 2 3 4 5 6 7; do
        step real_pairs "${name}_seed$seed" "$BIN/benchmark" "$d" --trials 25 --methods cubes \
          --trial-seed "$seed" --csv "$out/${name}_seed$seed.csv"
      done
    fi
  done
}

# Many simulated worlds: the paper's four scene types (trial seed 2); the six robot worlds
# and all ten types with the sensor's artefacts (trial seeds 2 and 3, pooled in the tables;
# quick: seed 2 only); and the repeatability (each pair from many starts; only its log holds
# the figures).
scenes() {
  fresh_section scenes
  local out="$OUT_DIR/scenes" S="$BIN/scene_benchmark" paper robot artefacts repeat seeds seed sfx
  if [ "$MODE" = full ]; then
    paper=(--worlds 20 --trials 5) robot=(--worlds 20 --trials 5)
    artefacts=(--worlds 10 --trials 5) repeat=(--worlds 4 --trials 1 --repeat 25) seeds=(2 3)
  else
    paper=(--worlds 2 --trials 2) robot=(--worlds 2 --trials 2)
    artefacts=(--worlds 2 --trials 2) repeat=(--worlds 2 --trials 2 --repeat 5) seeds=(2)
  fi
  step scenes scenes_default "$S" "${paper[@]}" --trial-seed 2 --csv "$out/scenes_default.csv"
  for seed in "${seeds[@]}"; do
    sfx=""
    [ "$seed" = 2 ] || sfx="_seed$seed"
    step scenes "scenes_robot$sfx" "$S" --scenes robot "${robot[@]}" --trial-seed "$seed" \
      --csv "$out/scenes_robot$sfx.csv"
    step scenes "scenes_artefacts$sfx" "$S" --scenes all --artefacts "${artefacts[@]}" \
      --trial-seed "$seed" --csv "$out/scenes_artefacts$sfx.csv"
  done
  step scenes scenes_repeat "$S" "${repeat[@]}" --trial-seed 2 --csv "$out/scenes_repeat.csv"
}

# Drift over sequences: OnlineMatcher over 500 m (quick: 100 m) of each paper scene type with
# "big" odometry errors, against PCL GICP and Open3D's ICPs (quick: the cube method alone);
# the same without odometry (the planar grid and constant velocity); and every real sequence
# (a folder with poses.tum) with "big" odometry, the cube method and every peer, and without
# odometry, the cube method.
# --summary appends, so each run has its own (the section's folder starts empty).
sequences() {
  fresh_section sequences
  local out="$OUT_DIR/sequences" Q="$BIN/sequence_benchmark" length=500 scene d name folders
  local sim_methods=cubes,gicp real_methods=cubes,gicp,ndt,icp
  if $OPEN3D; then
    sim_methods+=,o3d-p2pl,o3d-gicp
    real_methods+=,o3d-p2pl,o3d-gicp
  fi
  if [ "$MODE" = quick ]; then
    length=100
    sim_methods=cubes
  fi
  for scene in park natural hall urban; do
    step sequences "sim_big_$scene" "$Q" --scene "$scene" --length "$length" --odometry big \
      --methods "$sim_methods" --csv "$out/sim_big_$scene.csv" \
      --summary "$out/sim_big_${scene}_summary.csv"
  done
  for scene in park natural hall urban; do
    step sequences "sim_cv_$scene" "$Q" --scene "$scene" --length "$length" --odometry cv \
      --methods cubes --csv "$out/sim_cv_$scene.csv" --summary "$out/sim_cv_${scene}_summary.csv"
  done
  mapfile -t folders < <(data_folders poses.tum)
  for d in "${folders[@]}"; do
    name="$(basename "$d")"
    step sequences "real_$name" "$Q" --dir "$d" --odometry big --methods "$real_methods" \
      --csv "$out/real_$name.csv" --summary "$out/real_${name}_summary.csv"
    step sequences "real_cv_$name" "$Q" --dir "$d" --odometry cv --methods cubes \
      --csv "$out/real_cv_$name.csv" --summary "$out/real_cv_${name}_summary.csv"
  done
}

# Sweeps taken while driving: static (stop-and-go baseline), rigid and de-skewed
# registration, "big" and "drift" odometry. full: the paper's four scenes, world 1, the
# tool's default grid (0.5/1/2 m/s at 10/20/30 deg/s, sweeps of 1/2/4 s, 5 sweeps per run);
# quick: the grid of the CTest sweep_motion_deskew (1 m/s, 20 deg/s, 2 s, 4 sweeps).
sweeps() {
  fresh_section sweeps
  local grid=(--worlds 1)
  [ "$MODE" = quick ] && grid=(--worlds 1 --motions 1:20 --durations 2 --sweeps 4)
  step sweeps sweep_motion "$BIN/sweep_motion_benchmark" "${grid[@]}" --odometry big,drift \
    --modes static,rigid,deskew --csv "$OUT_DIR/sweeps/sweep_motion.csv"
}

# The covariances a navigation filter receives, on worlds and seeds the chain's settings were
# not tuned on (they were on worlds 1-2 of park, natural, hall and urban): the chain's
# (sequence_benchmark --consistency: at every keyframe, the share of errors within 1 and
# beyond 3 predicted sd per axis, and the NEES), with "small" and "drift" odometry, and the
# chain tied to the odometry (the NAME-anchored rows) with "drift" and "dgps" odometry; and a
# single registration's, on worlds 101-110 of every type with the sensor's artefacts
# (scene_benchmark's >3sd column; the scenes section uses worlds 1-20).
covariance() {
  fresh_section covariance
  local out="$OUT_DIR/covariance" Q="$BIN/sequence_benchmark" length=300 seed world odo
  local seeds=(3 4) worlds=(park natural hall urban square slope forest)
  local unseen=(--worlds 10 --trials 5)
  if [ "$MODE" = quick ]; then
    length=100 seeds=(3) worlds=(park hall) unseen=(--worlds 1 --trials 2)
  fi
  for seed in "${seeds[@]}"; do
    for world in "${worlds[@]}"; do
      for odo in small drift dgps; do
        step covariance "chain_${odo}_${world}_$seed" "$Q" --scene "$world" --world-seed "$seed" \
          --length "$length" --odometry "$odo" --methods cubes --label "${world}_$seed" \
          --csv "$out/chain_${odo}_${world}_$seed.csv" --summary "$out/chain_summary.csv" \
          --consistency "$out/chain_consistency.csv"
      done
    done
  done
  step covariance scenes_unseen "$BIN/scene_benchmark" --scenes all --artefacts "${unseen[@]}" \
    --first-world 101 --trial-seed 4 --csv "$out/scenes_unseen.csv"
}

# The nodelet at robot rates: scripts/rate_benchmark.sh feeds 65k-point sweeps at 20 Hz for
# 60 s into the nodelet (config/scan_matcher.yaml) on the AVX2 path, as BENCHMARK.md quotes;
# three runs, as one run on a shared machine says little. It prints, and writes no CSV: its
# log is the record. Skipped in quick mode (three minutes, and only meaningful when the
# machine is quiet).
rate() {
  fresh_section rate
  if [ "$MODE" = quick ]; then
    echo "== rate: skipped in quick mode (run full for the 20 Hz figures)"
    echo "rate benchmark skipped: quick mode (scripts/benchmarks.sh full runs it)" \
      > "$OUT_DIR/rate/skipped.txt"
    STEPS+=("rate: skipped (quick mode)")
    return
  fi
  local simd=() run
  cpu_has avx2 && simd=(CSM_SIMD=avx2)
  for run in 1 2 3; do
    step rate "rate_20hz_run$run" env "${simd[@]}" bash scripts/rate_benchmark.sh 20 60
  done
}

# SECTION/run.txt, written after the section ran: what its figures were measured on (sections
# run on different days each say their own commit and dates).
run_header() {
  echo "mode: $MODE"
  echo "data: $DATA_DIR"
  echo "commit: $COMMIT"
  if [ -z "$TREE_CHANGES" ]; then
    echo "tree: clean (no change to tracked files)"
  else
    echo "tree: dirty (tracked files changed, built as they were):"
    echo "$TREE_CHANGES" | sed 's/^/  /'
  fi
  echo "started: $1"
  echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //' || true)"
  echo "cores: $(nproc)"
  echo "cpu vector flags: $(grep -m1 '^flags' /proc/cpuinfo | tr ' ' '\n' |
    grep -E '^(sse2|avx2|fma|avx512[a-z_0-9]*)$' | tr '\n' ' ' || true)"
  echo "os: $(. /etc/os-release && echo "$PRETTY_NAME"); $(uname -r)"
  echo "compiler: $(c++ --version 2>/dev/null | head -1 || true)"
  echo "open3d peers: $OPEN3D"
  echo "CSM_SIMD in the environment: ${CSM_SIMD_GIVEN:-unset} (not passed on: each tool ran" \
    "on its default path unless its step names one)"
}

# The vector paths the section's tools reported (the benchmarks' "SIMD path:" line, the
# nodelet's start message), with the number of logs reporting each, and its steps.
run_footer() {
  local section="$1" first_step="$2"
  echo "finished: $(date -u '+%Y-%m-%d %H:%M:%S UTC')"
  echo "SIMD paths reported (logs: path):"
  grep -ho "SIMD path:\? [a-z0-9]* (supported here:[a-z0-9 ]*)" "$OUT_DIR/$section"/*.log \
    2>/dev/null | sed 's/SIMD path:\? //' | sort | uniq -c |
    awk '{n = $1; $1 = ""; print "  " n " logs:" $0}' || true
  echo "steps:"
  printf '  %s\n' "${STEPS[@]:$first_step}"
}

for section in "${SECTIONS[@]}"; do
  first_step=${#STEPS[@]}
  started="$(date -u '+%Y-%m-%d %H:%M:%S UTC')"
  "$section"  # empties OUT_DIR/section first
  { run_header "$started"; run_footer "$section" "$first_step"; } > "$OUT_DIR/$section/run.txt"
done

echo "== results in ${OUT_DIR#"$ROOT/"} (SECTION/run.txt: commit, machine, steps)"
if [ ${#FAILED[@]} -gt 0 ]; then
  echo "== ${#FAILED[@]} step(s) failed:" >&2
  printf '   %s\n' "${FAILED[@]}" >&2
  exit 1
fi
echo "== every step passed; the tables:" \
  "/usr/bin/python3 scripts/benchmark_tables.py ${OUT_DIR#"$ROOT/"}"
