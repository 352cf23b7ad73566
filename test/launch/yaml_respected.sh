#!/usr/bin/env bash
# The launch files never replace a value the user's YAML sets: a frame, axis, role or duration
# argument overrides the config only when it is given. Checked on the parameters each launch
# file would set (roslaunch --dump-params, no master needed) and on the loaders' command lines
# (the manager argument, respawn, the filter-chain hook, bag_replay's input:=lines).
#   bash test/launch/yaml_respected.sh   (in a sourced devel or install space, or CSM_SETUP=its setup.bash)
set -uo pipefail
if [ -n "${CSM_SETUP:-}" ]; then
  export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
  set +u; source "$CSM_SETUP"; set -u
fi
HERE="$(cd "$(dirname "$0")" && pwd)"
WORK="$(mktemp -d)"; trap 'rm -rf "$WORK"' EXIT
FAILED=0

cat > "$WORK/matcher.yaml" <<'YAML'
base_frame: base_footprint
odom_frame: odom_combined
map_frame: world
role: anchored
YAML
cat > "$WORK/assembler.yaml" <<'YAML'
fixed_frame: odom_combined
tilt_reference_frame: servo_mount
tilt_axis: y
sweep_duration: 2.5
YAML

# check LABEL FILE "KEY: VALUE"... -- ROSLAUNCH ARGS...
check() {
  local label="$1"; shift
  local expected=()
  while [ "$1" != "--" ]; do expected+=("$1"); shift; done
  shift
  local dump
  dump="$(roslaunch --dump-params "$@" 2>&1)" || { echo "FAIL $label: roslaunch --dump-params $*"; echo "$dump" | tail -5; FAILED=1; return; }
  for line in "${expected[@]}"; do
    if ! grep -qxF "$line" <<< "$dump"; then
      echo "FAIL $label: expected '$line', got: $(grep -F "${line%%:*}:" <<< "$dump" | tr '\n' ' ')"
      FAILED=1
    else
      echo "ok   $label: $line"
    fi
  done
}
# check_args LABEL NODE "TEXT"... -- ROSLAUNCH ARGS...: TEXT in NODE's command line
check_args() {
  local label="$1" node="$2"; shift 2
  local expected=()
  while [ "$1" != "--" ]; do expected+=("$1"); shift; done
  shift
  local cmd
  cmd="$(roslaunch --args "$node" "$@" 2>&1)" || { echo "FAIL $label: roslaunch --args $node $*"; echo "$cmd" | tail -5; FAILED=1; return; }
  for text in "${expected[@]}"; do
    if grep -qF -- "$text" <<< "$cmd"; then echo "ok   $label: $node has '$text'"
    else echo "FAIL $label: $node's command line lacks '$text': $cmd"; FAILED=1; fi
  done
}
M=(/scan_matcher/base_frame:\ base_footprint /scan_matcher/odom_frame:\ odom_combined
   /scan_matcher/map_frame:\ world /scan_matcher/role:\ anchored)
A=(/sweep_assembler/fixed_frame:\ odom_combined /sweep_assembler/tilt_reference_frame:\ servo_mount
   /sweep_assembler/tilt_axis:\ y /sweep_assembler/sweep_duration:\ 2.5)

# The shipped configs' values when nothing is given.
check "defaults" /scan_matcher/base_frame:\ base_link /scan_matcher/odom_frame:\ odom \
  /scan_matcher/map_frame:\ map /scan_matcher/role:\ messages -- cube_scan_matcher scan_matcher.launch
# A user's YAML wins over every launch default.
check "scan_matcher.launch" "${M[@]}" -- cube_scan_matcher scan_matcher.launch config:="$WORK/matcher.yaml"
check "sweep_assembler.launch" "${A[@]}" -- cube_scan_matcher sweep_assembler.launch config:="$WORK/assembler.yaml"
check "tilting_laser.launch" "${M[@]}" "${A[@]}" -- cube_scan_matcher tilting_laser.launch \
  matcher_config:="$WORK/matcher.yaml" assembler_config:="$WORK/assembler.yaml"
check "bag_replay.launch" "${M[@]}" -- cube_scan_matcher bag_replay.launch bag:=x.bag config:="$WORK/matcher.yaml"
check "bag_replay.launch input:=lines" "${M[@]}" /sweep_assembler/tilt_reference_frame:\ laser_mount -- \
  cube_scan_matcher bag_replay.launch bag:=x.bag input:=lines config:="$WORK/matcher.yaml" tilt_reference_frame:=laser_mount
# An argument that is given overrides the config.
check "argument given" /scan_matcher/base_frame:\ chassis /sweep_assembler/tilt_axis:\ z \
  /sweep_assembler/fixed_frame:\ odom2 /scan_matcher/odom_frame:\ odom2 -- cube_scan_matcher tilting_laser.launch \
  matcher_config:="$WORK/matcher.yaml" assembler_config:="$WORK/assembler.yaml" base_frame:=chassis tilt_axis:=z odom_frame:=odom2
# The filter-chain hook is included (with the scan argument), and the nodelets load into a
# manager that is given.
check "scan_filter_launch" /filter_hook/scan:\ /tilt_scan -- cube_scan_matcher tilting_laser.launch \
  scan:=/tilt_scan tilt_reference_frame:=m scan_filter_launch:="$HERE/filter_hook.launch"
check_args "manager" /scan_matcher "load cube_scan_matcher/ScanMatcherNodelet driver_manager" -- \
  cube_scan_matcher tilting_laser.launch manager:=driver_manager
check_args "manager" /sweep_assembler "load cube_scan_matcher/SweepAssemblerNodelet driver_manager" -- \
  cube_scan_matcher tilting_laser.launch manager:=driver_manager
check_args "bag_replay lines" /player "assembled_cloud:=bag/assembled_cloud" -- \
  cube_scan_matcher bag_replay.launch bag:=x.bag input:=lines
# respawn reaches the manager and the loaders (roslaunch --dump cannot show it: the XML is read).
for f in scan_matcher sweep_assembler; do
  if grep -q 'respawn="$(arg respawn)"' "$(rospack find cube_scan_matcher)/launch/$f.launch"; then
    echo "ok   respawn: $f.launch"
  else echo "FAIL respawn: $f.launch has no respawn argument on its nodes"; FAILED=1; fi
done
[ "$FAILED" -eq 0 ] && echo "yaml_respected: OK" || echo "yaml_respected: FAILED"
exit "$FAILED"
