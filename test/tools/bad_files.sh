#!/usr/bin/env bash
# Every file of the bad-file corpus (test/data/bad_clouds, expected.txt), plus a directory, a
# missing file and an unreadable file, through every tool that reads clouds: register_clouds,
# benchmark (as a pair of a dataset folder) and clouds_to_bag. Each must exit with code 1 within
# 10 s and print one line naming the file and the problem. Fails on the first miss.
#   usage: bad_files.sh BIN_DIR
set -uo pipefail
BIN="$1"
HERE="$(cd "$(dirname "$0")/../data/bad_clouds" && pwd)"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
chmod 755 "$WORK"
status=0
checked=0

# run TOOL-LABEL FILE PHRASE CMD...: exit code 1, one stderr line with FILE's name and PHRASE.
run() {
  local label="$1" file="$2" phrase="$3"
  shift 3
  local err="$WORK/err" rc
  timeout 10 "$@" > /dev/null 2> "$err"
  rc=$?
  local lines
  lines=$(grep -c . "$err")
  if [ "$rc" -ne 1 ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$(basename "$file")" "$err" ||
     ! grep -qF -- "$phrase" "$err"; then
    echo "FAIL $label $(basename "$file"): exit $rc, expected 1 and one line with '$phrase'; got:"
    sed 's/^/    /' "$err" | head -5
    status=1
  else
    echo "ok   $label $(basename "$file"): $(cat "$err")"
  fi
  checked=$((checked + 1))
}

check_file() {  # FILE PHRASE
  local file="$1" phrase="$2"
  run register_clouds "$file" "$phrase" "$BIN/register_clouds" "$HERE/good.pcd" "$file"
  local ds="$WORK/dataset"
  rm -rf "$ds" && mkdir -p "$ds"
  cp "$HERE/good.pcd" "$ds/good.pcd"
  if [ -e "$file" ]; then ln -s "$file" "$ds/$(basename "$file")"; fi
  echo "$(basename "$file") good.pcd 0 0 0 0 0 0 1" > "$ds/pairs.txt"
  run benchmark "$file" "$phrase" "$BIN/benchmark" "$ds" --methods cubes --trials 1 --csv "$WORK/b.csv"
  run clouds_to_bag "$file" "$phrase" "$BIN/clouds_to_bag" "$WORK/out.bag" "$HERE/good.pcd" "$file"
}

while IFS=$'\t' read -r name phrase; do
  case "$name" in ''|'#'*) continue ;; esac
  check_file "$HERE/$name" "$phrase"
done < "$HERE/expected.txt"

# A directory, a missing file, and a file its reader may not open.
mkdir -p "$WORK/a_directory.pcd"
check_file "$WORK/a_directory.pcd" "is a directory"
check_file "$WORK/missing.pcd" "no such file"
cp "$HERE/good.pcd" "$WORK/unreadable.pcd"
chmod 000 "$WORK/unreadable.pcd"
if [ "$(id -u)" -eq 0 ]; then
  # root reads any file: run the tool as 'nobody', who cannot.
  run "register_clouds(nobody)" "$WORK/unreadable.pcd" "cannot open" \
    setpriv --reuid=nobody --regid=nogroup --clear-groups "$BIN/register_clouds" \
    "$HERE/good.pcd" "$WORK/unreadable.pcd"
else
  run register_clouds "$WORK/unreadable.pcd" "cannot open" "$BIN/register_clouds" "$HERE/good.pcd" "$WORK/unreadable.pcd"
fi

# The good files are read by every tool (the corpus is not refused wholesale).
timeout 60 "$BIN/register_clouds" "$HERE/good.pcd" "$HERE/good.ply" > /dev/null 2> "$WORK/err" ||
  { echo "FAIL register_clouds good.pcd good.ply:"; cat "$WORK/err"; status=1; }
echo "bad_files: $checked checks"
[ "$status" -eq 0 ] && echo "$checked passed, 0 failed" || echo "bad_files: FAILED"
exit $status
