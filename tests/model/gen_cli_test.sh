#!/bin/bash
# cosmicctl gen without building: the files of a skeleton, what they hold from the model, the
# user's logic file kept on regeneration, and clear refusals.
# Usage: gen_cli_test.sh COSMICCTL ROBOT_YAML
set -u
COSMICCTL=$1 ROBOT=$2
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
status=0
fail() { echo "FAIL: $*" >&2; status=1; }

"$COSMICCTL" gen "$ROBOT" --component speed_controller --output "$WORK/sc" 2>"$WORK/gen.err" || fail "gen exited $?"
for f in CMakeLists.txt channels.hpp speed_controller.hpp speed_controller.cpp speed_controller_logic.cpp main.cpp; do
  [ -s "$WORK/sc/$f" ] || fail "no $f"
done
grep -q 'kSegment = "dds:0"' "$WORK/sc/channels.hpp" || fail "segment of lan is not dds:0"
grep -q 'speed{"speed", 0x0000000100000051ull, COSMIC_SRT, 10000000, 8000000, 40000000, 1, 4, COSMIC_PUBLISH}' "$WORK/sc/channels.hpp" ||
  fail "speed's configuration differs from the model"
grep -q 'actual_speed{"actual_speed", 0x0000000100000070ull, COSMIC_NRT, 20000000, 0, 0, 5, 4, COSMIC_SUBSCRIBE}' "$WORK/sc/channels.hpp" ||
  fail "actual_speed's configuration differs from the model"
for h in refresh_actual_speed refresh_command refresh_obstacle speed_period; do
  grep -q "void $h(" "$WORK/sc/speed_controller.hpp" || fail "no handler $h"
done
grep -q "refresh_speed\|actual_speed_period" "$WORK/sc/speed_controller.hpp" && fail "a handler for a channel in the wrong direction"
# No typed channel, no struct headers (gen_typed_test.sh has the typed ones).
[ -e "$WORK/sc/compact.hpp" ] && fail "compact.hpp for a component without typed channels"

# The logic file is the user's: a second run keeps it.
echo "// mine" >>"$WORK/sc/speed_controller_logic.cpp"
"$COSMICCTL" gen "$ROBOT" --component speed_controller --output "$WORK/sc" 2>"$WORK/gen2.err" || fail "second gen exited $?"
grep -q "// mine" "$WORK/sc/speed_controller_logic.cpp" || fail "the user's logic file was overwritten"
grep -q "kept .*speed_controller_logic.cpp" "$WORK/gen2.err" || fail "gen did not say it kept the logic file"

# A CAN component opens its bus with a TxNode of its own.
"$COSMICCTL" gen "$ROBOT" --component drives --output "$WORK/drives" 2>/dev/null || fail "gen drives exited $?"
grep -q 'kSegment = "can:vcan0?node=' "$WORK/drives/channels.hpp" || fail "drives does not open vcan0"

"$COSMICCTL" gen "$ROBOT" --component nobody --output "$WORK/x" 2>"$WORK/unknown.err"
[ $? -eq 64 ] || fail "unknown component: exit code is not 64"
grep -q "no component 'nobody'.*speed_controller" "$WORK/unknown.err" || fail "unknown component: $(cat "$WORK/unknown.err")"
# Channels whose names differ only in '-' or '.' would be one C++ identifier: refused, nothing written.
cat >"$WORK/twins.yaml" <<'YAML'
segments: [{name: lan, type: dds}, {name: viz, type: lcm}]
channels:
  - {name: arm-left, subject: 1, class: nrt, payload: 8B}
  - {name: arm.left, subject: 2, class: nrt, payload: 8B}
components:
  - {name: arm, segment: viz, publishes: [arm-left, arm.left]}
  - {name: plot, segment: lan, subscribes: [arm-left, arm.left]}
YAML
"$COSMICCTL" gen "$WORK/twins.yaml" --component arm --output "$WORK/twins" 2>"$WORK/twins.err"
[ $? -eq 2 ] || fail "twin channel names: exit code is not 2"
grep -q "twins.yaml: channels 'arm-left' and 'arm.left' of component arm both become the C++ identifier arm_left" "$WORK/twins.err" ||
  fail "twin channel names: $(cat "$WORK/twins.err")"
[ -e "$WORK/twins" ] && fail "twin channel names: files were written"

# Components (and segments) whose names differ only so are refused where the second is written.
printf 'segments: [{name: lan, type: dds}]\nchannels: [{name: c, subject: 1, class: nrt, payload: 8B}]\ncomponents:\n  - {name: a-b, segment: lan, publishes: [c]}\n  - {name: a_b, segment: lan, subscribes: [c]}\n' >"$WORK/ctwins.yaml"
"$COSMICCTL" gen "$WORK/ctwins.yaml" --component a-b --output "$WORK/ctwins" 2>"$WORK/ctwins.err"
[ $? -eq 2 ] || fail "twin component names: exit code is not 2"
grep -q "ctwins.yaml:5:.*components\[1\].name: component name 'a_b' and component 'a-b' (line 4) differ only in" "$WORK/ctwins.err" ||
  fail "twin component names: $(cat "$WORK/ctwins.err")"
# The model's path lands in comments: a newline in it cannot start a line of code (issue 22, item 4).
odd_dir="$WORK/dir
static int injected = 1;"
mkdir -p "$odd_dir"
cp "$ROBOT" "$odd_dir/robot.yaml"
"$COSMICCTL" gen "$odd_dir/robot.yaml" --component speed_controller --output "$WORK/odd" 2>/dev/null || fail "odd path: gen exited $?"
grep -q "^static int injected" "$WORK/odd/"* && fail "odd path: the model's path became code"
exit $status
