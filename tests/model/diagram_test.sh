#!/bin/bash
# The Event-Channel Diagram of config/robot.yaml, offline: DOT text, SVG from Graphviz, and the
# SVG drawn by a real browser (headless Chromium) into a PNG that must show the diagram's colours.
# Usage: diagram_test.sh COSMICCTL ROBOT_YAML
set -u
COSMICCTL=$1
ROBOT=$2
HERE=$(cd "$(dirname "$0")" && pwd)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
status=0
fail() { echo "FAIL: $*" >&2; status=1; }

"$COSMICCTL" diagram --format dot "$ROBOT" >"$WORK/robot.dot" || fail "diagram --format dot exited $?"
grep -q '^digraph event_channels' "$WORK/robot.dot" || fail "DOT has no digraph"
for channel in distance acceleration odometry obstacle speed command actual_speed diagnostics; do
  grep -q "\"channel_$channel\" \[" "$WORK/robot.dot" || fail "DOT lacks channel $channel"
done
# Left to right as the paper's Fig. 6: publishers (P_ nodes) -> channels -> subscribers (S_ nodes);
# a component that does both is drawn on both sides, each side in clusters of its segments.
grep -q 'rankdir=LR' "$WORK/robot.dot" || fail "not drawn left to right"
grep -q '"P_component_speed_controller" -> "channel_speed" \[headlabel="P"' "$WORK/robot.dot" || fail "no P tag speed_controller -> speed"
grep -q '"channel_actual_speed" -> "S_component_speed_controller" \[taillabel="S"' "$WORK/robot.dot" || fail "no S tag actual_speed -> speed_controller"
grep -qE -- '-> "P_component_|"S_component_[a-z_]*" ->' "$WORK/robot.dot" && fail "an edge runs back across the page"
grep -q 'subgraph "cluster_P_body-can"' "$WORK/robot.dot" || fail "no cluster of the publishers on body-can"
grep -q 'subgraph "cluster_S_viz"' "$WORK/robot.dot" || fail "no cluster of the subscribers on viz"
# Compact by default: one row a channel (name, class, verdict, end-to-end bound), the rest as tooltip.
grep -q '"channel_distance" \[[^]]*tooltip="distance: HRT, subject 0x0000000100000042' "$WORK/robot.dot" || fail "distance's subject is not in its tooltip"
grep -q '"channel_distance" \[[^]]*reaction_time 5 ms' "$WORK/robot.dot" || fail "distance's QoS list is not in its tooltip"
rows() { grep '^  "channel_' "$1" | grep -o '<TR>' | wc -l; }
[ "$(rows "$WORK/robot.dot")" -eq 8 ] || fail "compact: not one row per channel ($(rows "$WORK/robot.dot") rows for 8 channels)"
"$COSMICCTL" diagram --format dot --detail "$ROBOT" >"$WORK/detail.dot" || fail "diagram --detail exited $?"
[ "$(rows "$WORK/detail.dot")" -gt 16 ] || fail "--detail: channels are not drawn as tables"

"$COSMICCTL" diagram "$ROBOT" >"$WORK/robot.svg" || fail "diagram (svg) exited $?"
grep -q '<svg' "$WORK/robot.svg" || fail "no SVG on stdout"
grep -q '#a5d6a7' "$WORK/robot.svg" || fail "SVG has no 'bound' colour"

# Names that differ only in '-' and '.' stay two nodes (issue 22, item 5).
cat >"$WORK/twins.yaml" <<'YAML'
segments: [{name: lan, type: dds}, {name: viz, type: lcm}]
channels:
  - {name: arm-left, subject: 1, class: nrt, payload: 8B, publishers: [lan], subscribers: [viz]}
  - {name: arm.left, subject: 2, class: nrt, payload: 8B, publishers: [viz], subscribers: [lan]}
YAML
"$COSMICCTL" diagram --format dot "$WORK/twins.yaml" >"$WORK/twins.dot" || fail "twins: diagram exited $?"
for channel in arm-left arm.left; do
  grep -q "\"channel_$channel\" \[" "$WORK/twins.dot" || fail "twins: DOT lacks its own node for $channel"
done

# Any file name, even one with markup, control characters or bytes that are not UTF-8, gives
# well-formed DOT that Graphviz draws (issue 22, item 6).
odd="$WORK/a&b<c>\"d\"&#1;$(printf '\x01\xff\xc3')e.yaml"
cp "$WORK/twins.yaml" "$odd"
"$COSMICCTL" diagram "$odd" >"$WORK/odd.svg" 2>"$WORK/odd.err" || fail "odd file name: diagram exited $?: $(cat "$WORK/odd.err")"
grep -q '<svg' "$WORK/odd.svg" || fail "odd file name: no SVG"

# A configuration error is reported with its location, nothing on stdout.
printf 'segments: []\nchannels: []\ncomponents: [{name: x, segment: nowhere, publishes: [a]}]\n' >"$WORK/bad.yaml"
"$COSMICCTL" diagram "$WORK/bad.yaml" >"$WORK/bad.out" 2>"$WORK/bad.err"
[ $? -eq 2 ] || fail "bad file: exit code is not 2"
grep -q "bad.yaml:3:.*components\[0\].segment: unknown segment 'nowhere'" "$WORK/bad.err" || fail "bad file: no located error: $(cat "$WORK/bad.err")"
[ -s "$WORK/bad.out" ] && fail "bad file: something on stdout"

# Compact enough to read: the robot's 8 channels fit a screen (before: 1,601 pt tall), and a
# model of 50 channels stays one readable column of channels.
svg_height() { sed -n 's/^<svg width="[0-9.]*pt" height="\([0-9.]*\)pt".*/\1/p' "$1" | head -1 | cut -d. -f1; }
height=$(svg_height "$WORK/robot.svg")
[ -n "$height" ] && [ "$height" -lt 900 ] || fail "the robot's diagram is ${height:-?} pt tall (at most 900)"
python3 "$HERE/generate_model.py" 50 >"$WORK/wide.yaml" || fail "generate_model.py failed"
"$COSMICCTL" diagram "$WORK/wide.yaml" >"$WORK/wide.svg" 2>"$WORK/wide.err" || fail "50 channels: diagram exited $?: $(cat "$WORK/wide.err")"
[ "$(grep -c 'class="node channel' "$WORK/wide.svg")" -eq 50 ] || fail "50 channels: $(grep -c 'class="node channel' "$WORK/wide.svg") channel nodes"
echo "robot: ${height} pt tall; 50 channels: $(svg_height "$WORK/wide.svg") pt tall"

# A real browser draws it.
timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-background-networking --disable-component-update \
  --disable-sync --no-first-run --user-data-dir="$WORK/chromium" --window-size=1800,1600 \
  --screenshot="$WORK/robot.png" "file://$WORK/robot.svg" >"$WORK/chromium.log" 2>&1
[ -s "$WORK/robot.png" ] || fail "chromium made no screenshot: $(tail -5 "$WORK/chromium.log")"
# bound (green), the channel header (slate), the segment clusters (light blue), components (cream)
python3 "$HERE/png_colours.py" "$WORK/robot.png" a5d6a7 37474f e3f2fd fff8e1 || fail "the screenshot lacks the diagram's colours"
exit $status
