#!/usr/bin/env bash
# CAN logs (issue 37, item 2) against can-utils, inside scripts/can-vm (ctest: can.candump):
#   - cosmicd records both CAN FD segments (recording.candump: [bus0, bus1]); frames from cangen
#     (classic, 0x123) and cansend (CAN FD with BRS, 0x124) on vcan0 are forwarded to vcan1 (native
#     0x456, and speed_fd in this project's 29-bit layout);
#   - cosmicd's log of bus0 (what its adapter received) and of bus1 (what it sent) hold the same
#     frames in the same order as `candump -l` logged on vcan0 and vcan1 at the same time;
#   - `canplayer -I LOG vcan0=vcan0` replays cosmicd's bus0 log into the running cosmicd, which
#     forwards every replayed frame again (bus1's sent counter), and the new logs of both segments
#     hold the same frames as the first ones.
#   scripts/can-vm -- bash tests/integration/can/candump_test.sh COSMICD COSMICCTL
set -uo pipefail
COSMICD=$1 COSMICCTL=$2
. "$(dirname "${BASH_SOURCE[0]}")/vm_test_lib.sh"
vm_test_begin candump vcan1
ctl() { "$COSMICCTL" --socket "$WORK/gw.sock" "$@"; }

CLASSIC_FRAMES=20
FD_FRAMES=3
FRAMES=$((CLASSIC_FRAMES + FD_FRAMES))
mkdir -p "$WORK/rec" "$WORK/ref0" "$WORK/ref1"
cat >"$WORK/gw.yaml" <<YAML
gateway: {name: gw, can_node_id: 3}
recording: {directory: $WORK/rec, candump: [bus0, bus1]}
segments:
  - {name: bus0, type: can, interface: vcan0, bitrate: 500kbit/s, fd: true, data_bitrate: 2Mbit/s}
  - {name: bus1, type: can, interface: vcan1, bitrate: 500kbit/s, fd: true, data_bitrate: 2Mbit/s}
channels:
  - {name: speed, subject: 0x701, class: srt, period: 1ms, reaction_time: 50ms, payload: 4B,
     publishers: [bus0], subscribers: [bus1], native: {bus0: {can_id: 0x123}, bus1: {can_id: 0x456}}}
  - {name: speed_fd, subject: 0x702, class: srt, period: 1ms, reaction_time: 50ms, payload: 12B,
     publishers: [bus0], subscribers: [bus1], native: {bus0: {can_id: 0x124}}}
YAML

# status KEY: a number of record status' candump section.
status() {
  ctl --json record status | "$python" -c 'import json, sys; print(json.load(sys.stdin)["recording"]["candump"][sys.argv[1]])' "$1"
}
lines_at_least() { [ "$(status lines)" -ge "$1" ]; }
sent_on_bus1() {
  ctl --json segments | "$python" -c '
import json, sys
print(next(s for s in json.load(sys.stdin)["segments"] if s["name"] == "bus1")["adapter"]["sent"])'
}
sent_at_least() { [ "$(sent_on_bus1)" -ge "$1" ]; }
# frames FILE: interface and frame of every line of a candump -l log, the time left out.
frames() { grep '^(' "$1" | cut -d' ' -f2-; }
# the_log SEGMENT N: cosmicd's Nth log file of SEGMENT (numbered in the order opened).
the_log() { ls "$WORK"/rec/gw-"$1"-*.log | awk -F- -v n="$2" '{ if ($NF == n ".log") print }'; }
same_frames() { # same_frames WHAT EXPECTED_FILE GOT_FILE (no <(...): the VM has no /dev/fd)
  frames "$2" >"$WORK/expected"
  frames "$3" >"$WORK/got"
  if ! diff "$WORK/expected" "$WORK/got" >"$WORK/diff" 2>&1; then
    fail "$1: the frames differ ($(wc -l <"$WORK/diff") diff lines)"
    head -20 "$WORK/diff" >&2
    return 1
  fi
}
# candump -l writes its log file (in its working directory) when it stops.
(cd "$WORK/ref0" && exec candump -l vcan0) >/dev/null 2>&1 &
DUMP0=$!
PIDS+=("$DUMP0")
(cd "$WORK/ref1" && exec candump -l vcan1) >/dev/null 2>&1 &
DUMP1=$!
PIDS+=("$DUMP1")

"$COSMICD" --config "$WORK/gw.yaml" --socket "$WORK/gw.sock" --state-file "$WORK/bindings.json" 2>>"$WORK/gw.log" &
PIDS+=($!)
wait_until 60 "cosmicd answering" ctl status || { cat "$WORK/gw.log" >&2; exit 1; }
logging() { [ "$(status active)" = True ]; }
wait_until 30 "candump logging on" logging

log "--- classic and FD frames on vcan0: logged as received on bus0, forwarded and logged as sent on bus1"
cangen vcan0 -I 123 -L 4 -D i -n "$CLASSIC_FRAMES" -g 2
for i in $(seq 1 "$FD_FRAMES"); do
  cansend vcan0 "124##1$(printf '%02x' "$i")112233445566778899aabb"
done
wait_until 60 "$FRAMES frames forwarded to vcan1" sent_at_least "$FRAMES"
wait_until 30 "$((2 * FRAMES)) lines logged" lines_at_least $((2 * FRAMES))
ctl record status >&2
ctl record stop >/dev/null || fail "record stop"
kill -INT "$DUMP0" "$DUMP1"
wait "$DUMP0" "$DUMP1" 2>/dev/null
ref0=$(ls "$WORK"/ref0/candump-*.log)
ref1=$(ls "$WORK"/ref1/candump-*.log)
bus0=$(the_log bus0 1)
bus1=$(the_log bus1 2)
[ -f "$bus0" ] && [ -f "$bus1" ] || fail "cosmicd's logs: $(ls "$WORK/rec")"
[ "$(frames "$bus0" | wc -l)" = "$FRAMES" ] || fail "bus0's log has $(frames "$bus0" | wc -l) frames, expected $FRAMES"
same_frames "bus0 (received) against candump -l vcan0" "$ref0" "$bus0"
same_frames "bus1 (sent) against candump -l vcan1" "$ref1" "$bus1"
frames "$bus0" | grep -Eq '^vcan0 124##[13579BDF]' || fail "no CAN FD frame with BRS in bus0's log"
frames "$bus1" | grep -Eq '^vcan1 [0-9A-F]{8}##' || fail "no extended (29-bit) FD frame in bus1's log"
# Times as candump writes them, close to candump's own (same kernel stamp on receive).
! grep -Ev '^\([0-9]{10}\.[0-9]{6}\) ' "$bus0" >&2 || fail "a time in bus0's log is not (SSSSSSSSSS.UUUUUU)"
grep '^(' "$ref0" | cut -d' ' -f1 | tr -d '()' >"$WORK/ref0.times"
cut -d' ' -f1 "$bus0" | tr -d '()' >"$WORK/bus0.times"
paste -d' ' "$WORK/ref0.times" "$WORK/bus0.times" |
  awk '{ d = $1 - $2; if (d < 0) d = -d; if (d > 1) bad = 1 } END { exit bad }' ||
  fail "bus0's times are more than 1 s from candump's"
[ "$(status dropped)" = 0 ] || fail "$(status dropped) frames dropped"

log "--- canplayer replays bus0's log into the running cosmicd, which forwards it again"
ctl record start >/dev/null || fail "record start"
sent_before=$(sent_on_bus1)
canplayer -I "$bus0" vcan0=vcan0 || fail "canplayer exited with $?"
wait_until 60 "the replayed frames forwarded" sent_at_least $((sent_before + FRAMES))
wait_until 30 "the replay logged" lines_at_least $((4 * FRAMES))
ctl record stop >/dev/null || fail "record stop"
[ "$(sent_on_bus1)" = $((sent_before + FRAMES)) ] || fail "bus1 sent $(($(sent_on_bus1) - sent_before)) frames for the replay, expected $FRAMES"
same_frames "the replay on bus0" "$bus0" "$(the_log bus0 3)"
same_frames "the replay forwarded on bus1" "$bus1" "$(the_log bus1 4)"
ctl record status >&2

if [ "$FAILED" -ne 0 ]; then
  log "cosmicd's log:"
  tail -30 "$WORK/gw.log" >&2
  for f in "$WORK"/rec/*.log "$WORK"/ref*/*.log; do log "== $f"; head -30 "$f" >&2; done
fi
[ "$FAILED" -eq 0 ] && log "candump: all checks passed"
exit "$FAILED"
