#!/usr/bin/env bash
# A/B of the online step's time: the cube method of sequence_benchmark on a real sequence, built
# from BASE (any git revision, in a worktree beside the repo) and from this tree, run
# alternately, ROUNDS rounds, with "big" odometry and without odometry (cv), on one vector path.
# Writes each run's per-scan CSV and log into OUT_DIR and prints (and writes to
# OUT_DIR/summary.txt) each side's median and p95 time per scan, the ratios, and whether the two
# sides' poses and evaluations are identical; with both sides' CSVs carrying the stage columns,
# also the median coarse, refine and polish time per scan.
#
# The base's worktree stays for the next comparison; `git worktree prune` after removing it.
#
# With NEW_OPTIONS, the new side runs with those sequence_benchmark options (BASE = HEAD: an
# option against the defaults, in the same code).
#
# usage: bash scripts/online_ab.sh BASE SEQUENCE_DIR OUT_DIR [ROUNDS=2] [SIMD=avx2] [NEW_OPTIONS]
#        bash scripts/online_ab.sh --summarize OUT_DIR [ROUNDS=2]   (the summary of runs made)
#   e.g. bash scripts/online_ab.sh origin/main ../shared/data/balm_os0_hall_seq_a /tmp/ab
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: bash scripts/online_ab.sh BASE SEQUENCE_DIR OUT_DIR [ROUNDS=2] [SIMD=avx2] [NEW_OPTIONS] | --summarize OUT_DIR [ROUNDS=2]"
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
if [ "${1:-}" = --summarize ]; then
  [ $# -ge 2 ] || { echo "$usage" >&2; exit 2; }
  OUT="$(cd "$2" && pwd)" ROUNDS="${3:-2}"
  head -4 "$OUT/summary.txt" > "$OUT/summary.tmp" && mv "$OUT/summary.tmp" "$OUT/summary.txt"
else
[ $# -ge 3 ] || { echo "$usage" >&2; exit 2; }
BASE="$1" SEQ="$(cd "$2" && pwd)" OUT="$3" ROUNDS="${4:-2}" SIMD="${5:-avx2}" NEW_OPTIONS="${6:-}"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
base_rev="$(git rev-parse --verify "$BASE^{commit}")"
WT="$(pwd)/../.online_ab_${base_rev:0:12}"
if [ ! -x "$WT/build/devel/lib/cube_scan_matcher/sequence_benchmark" ]; then
  rm -rf "$WT"
  git worktree add -f --detach "$WT" "$base_rev" > /dev/null
  echo "building $base_rev in $WT (log: $WT/build.log)"
  cmake -S "$WT" -B "$WT/build" -DCMAKE_BUILD_TYPE=Release > "$WT/build.log" 2>&1
  make -C "$WT/build" -j"$(nproc)" sequence_benchmark >> "$WT/build.log" 2>&1
fi
make -C build -j"$(nproc)" sequence_benchmark > /dev/null
declare -A BIN=([base]="$WT/build/devel/lib/cube_scan_matcher/sequence_benchmark"
                [new]="build/devel/lib/cube_scan_matcher/sequence_benchmark")
{
  echo "base: $base_rev"
  echo "new: $(git rev-parse HEAD)$(git diff --quiet HEAD -- src include || echo ' + uncommitted changes')${NEW_OPTIONS:+, options: $NEW_OPTIONS}"
  echo "sequence: $SEQ; vector path: $SIMD; rounds: $ROUNDS (base and new alternate)"
  echo "cpu: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores"
} > "$OUT/summary.txt"
for round in $(seq 1 "$ROUNDS"); do
  for side in base new; do
    for odometry in big cv; do
      name="${side}_${odometry}_${round}"
      options=()
      [ "$side" = new ] && read -r -a options <<< "$NEW_OPTIONS"
      "${BIN[$side]}" --dir "$SEQ" --odometry "$odometry" --methods cubes --simd "$SIMD" \
        "${options[@]}" --csv "$OUT/$name.csv" > "$OUT/$name.log" 2>&1
      echo "ran $name"
    done
  done
done
fi
/usr/bin/python3 - "$OUT" "$ROUNDS" >> "$OUT/summary.txt" <<'EOF'
import csv, os, statistics, sys
out, rounds = sys.argv[1], int(sys.argv[2])

def rows(name):
    with open(os.path.join(out, name + ".csv"), newline="") as fh:
        return [r for r in csv.DictReader(fh) if r["method"] == "cubes"]

def quantile(v, q):  # the tools' quantile: the element at index floor(q n) of the sorted values
    v = sorted(v)
    return v[min(len(v) - 1, int(q * len(v)))]

for odometry in ("big", "cv"):
    med, p95 = {}, {}
    for side in ("base", "new"):
        runs = [[float(r["time_s"]) for r in rows("%s_%s_%d" % (side, odometry, k))]
                for k in range(1, rounds + 1)]
        med[side] = [quantile(t, 0.5) for t in runs]
        p95[side] = [quantile(t, 0.95) for t in runs]
    key = lambda r: (r["scan"], r["x"], r["y"], r["z"], r["yaw_deg"], r["evaluations"])
    same = all([key(r) for r in rows("base_%s_%d" % (odometry, k))] ==
               [key(r) for r in rows("new_%s_%d" % (odometry, k))] for k in range(1, rounds + 1))
    ms = lambda v: "/".join("%.1f" % (1e3 * x) for x in v)
    print("odometry %s: median per scan base %s ms, new %s ms (ratio of the medians over rounds "
          "%.2f); p95 base %s ms, new %s ms (ratio %.2f); poses and evaluations %s" % (
              odometry, ms(med["base"]), ms(med["new"]),
              statistics.median(med["new"]) / statistics.median(med["base"]),
              ms(p95["base"]), ms(p95["new"]),
              statistics.median(p95["new"]) / statistics.median(p95["base"]),
              "identical" if same else "DIFFERENT"))
    stages = ("coarse_s", "refine_s", "polish_s")
    if all(st in rows("%s_%s_1" % (side, odometry))[0] for side in ("base", "new") for st in stages):
        parts = []
        for st in stages:
            per_side = {}
            for side in ("base", "new"):
                per_side[side] = [quantile([float(r[st]) for r in rows("%s_%s_%d" % (side, odometry, k))
                                            if float(r["polish_s"] or 0) > 0], 0.5)
                                  for k in range(1, rounds + 1)]
            parts.append("%s base %s ms, new %s ms" % (st[:-2], ms(per_side["base"]), ms(per_side["new"])))
        print("  stages (median over the scans that polished): " + "; ".join(parts))
EOF
cat "$OUT/summary.txt"
