#!/usr/bin/env bash
# Recording (issue 37, docs/recording.md) end to end over real LCM, each file read by the MCAP
# implementation we did not write (npm's @mcap/core with @mcap/nodejs and @mcap/support):
#   - cosmicd records from start (recording.start defaults to true) the channels recording.channels
#     selects, and only those: an untyped channel as its bytes, a typed one as CDR with its ROS 2
#     message definition (typed_encoding defaults to cdr); McapIndexedReader finds the summary,
#     chunk indexes and statistics, every message time-ordered with its source segment, origin,
#     sequence and contents, and @foxglove/rosmsg2-serialization decodes the CDR to the values sent;
#   - `cosmicctl record stop` finishes the file (status counts what it holds); `record start`
#     opens a new one; SIGTERM finishes the last;
#   - a crash (SIGKILL) leaves a file McapStreamReader reads up to its last complete chunk: the
#     chunks written within the flush interval (1 s) hold every event recorded before;
#   - a reload that widens recording.channels records the newly selected channel at once; with
#     typed_encoding: json the typed channel is recorded as JSON with its JSON Schema;
#   - a typed channel's recorded CDR, and its recorded JSON, replay (a `type: replay` segment) as
#     its compact events;
#   - a typed channel whose type has no ROS 2 form (a CamelCase field) is recorded as JSON, and
#     cosmicd says why, once (across a reload of the recording section);
#   - `cosmicctl record info` counts each file's channels, messages, gaps and drops (a crashed file's
#     up to its cut), and refuses a file that is not MCAP;
#   - a directory that cannot be written: `record start` fails with the reason, exit 1, and
#     forwarding goes on; a cosmicd without a recording section says so.
#   recording_test.sh COSMICD COSMICCTL COSMIC_LCM_PEER NODE_MODULES SOURCE_DIR
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 LCM_PEER=$3 NODE_MODULES=$4 SRC=$5
WORK=$(mktemp -d /tmp/cosmic-recording.XXXXXX)
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
trap 'cleanup; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT

IN="udpm://239.255.76.67:7841?ttl=0"
OUT="udpm://239.255.76.67:7842?ttl=0"

write_config() {  # write_config FILE DIRECTORY [TYPED_ENCODING]
  cat >"$1" <<YAML
gateway: {name: gw-rec}
segments:
  - {name: field, type: lcm, url: "$IN", latency_bound: 2ms}
  - {name: viz, type: lcm, url: "$OUT", latency_bound: 2ms}
channels:
  - {name: obstacle, subject: 0x500, class: nrt, payload: 4B, publishers: [field], subscribers: [viz]}
  - name: range
    subject: 0x501
    class: nrt
    publishers: [field]
    subscribers: [viz]
    type: {fields: [{name: distance, type: float32, unit: m}, {name: valid, type: bool}]}
  - {name: chatter, subject: 0x502, class: nrt, payload: 4B, publishers: [field], subscribers: [viz]}
recording: {directory: $2, channels: [obstacle, 'ran*'], chunk_size: 4KiB${3:+, typed_encoding: $3}}
YAML
}

# read_mcap MODE FILE: what npm's reader finds, as JSON.
read_mcap() { NODE_PATH="$NODE_MODULES" node "$SRC/tests/mcap/read_recording.cjs" "$1" "$2"; }
# record_field NAME FIELD: a field of `cosmicctl --json record status`.
record_field() {
  ctl "$1" --json record status | python3 -c 'import json,sys; print(json.load(sys.stdin)["recording"][sys.argv[1]])' "$2"
}
recorded_at_least() { [ "$(record_field "$1" messages)" -ge "$2" ]; }
files_in() { find "$1" -name '*.mcap' | sort; }
# on_disk N: the newest file holds N messages in complete chunks, as the stream reader finds them.
on_disk() {
  [ "$(read_mcap stream "$(crash_file)" |
    python3 -c 'import json,sys; print(len(json.load(sys.stdin)["messages"]))')" -eq "$1" ]
}

# range's compact event: float32 distance, bool valid (1.5 m, true: 0x3fc00000 LE, then 01).
RANGE_HEX=0000c03f01

write_config "$WORK/g.yaml" "$WORK/rec"
start_daemon g "$WORK/g.yaml" || exit 1

scenario "the selected channels are recorded from start, read back by @mcap/core with their schema"
[ "$(record_field g active)" = True ] || fail "recording is not active after start: $(ctl g record status)"
"$LCM_PEER" pub --url "$IN" --channel obstacle --count 20 --rate 200 --subject 0x500 --origin 0xA1 --payload-hex 0a0b0c0d
"$LCM_PEER" pub --url "$IN" --channel range --count 10 --rate 200 --subject 0x501 --origin 0xB2 --payload-hex "$RANGE_HEX"
"$LCM_PEER" pub --url "$IN" --channel chatter --count 10 --rate 200 --subject 0x502 --origin 0xA1 --payload-hex 01020304
expect_field g chatter viz tx 10
wait_until 10 "30 events recorded" recorded_at_least g 30
ctl g record stop >"$WORK/stop.out" || fail "record stop failed: $(cat "$WORK/stop.out")"
grep -q "recording: off" "$WORK/stop.out" || fail "record stop: $(cat "$WORK/stop.out")"
[ "$(record_field g messages)" -eq 30 ] || fail "status counts $(record_field g messages) messages, expected 30"
mapfile -t files < <(files_in "$WORK/rec")
[ "${#files[@]}" -eq 1 ] || fail "expected one file, found: ${files[*]}"
read_mcap indexed "${files[0]}" >"$WORK/first.json" || fail "@mcap/core could not read ${files[0]}"
python3 - "$WORK/first.json" <<'PY' || fail "the first recording as @mcap/core reads it"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["profile"] == "x-cosmic", d["profile"]
assert d["ordered"], "messages not in time order"
assert d["statistics"]["messageCount"] == 30, d["statistics"]
assert d["chunkIndexes"] >= 1 and d["metadataIndexes"] == 2, d  # "cosmic" and "cosmic.closing"
topics = {c["topic"]: c for c in d["channels"]}
assert set(topics) == {"obstacle", "range"}, topics  # chatter is not selected
assert topics["obstacle"]["messageEncoding"] == "x-cosmic-bytes" and topics["obstacle"]["schemaId"] == 0
assert topics["range"]["messageEncoding"] == "cdr", topics["range"]
for name, c in topics.items():
    assert c["metadata"]["segment"] == "field", c
    assert c["metadata"]["publishers"] == "field" and c["metadata"]["subscribers"] == "viz", c
assert topics["obstacle"]["metadata"]["origin"] == "a1" and topics["obstacle"]["metadata"]["subject"] == "0x500"
assert topics["range"]["metadata"]["origin"] == "b2"
[schema] = d["schemas"]
assert schema["name"] == "cosmic/msg/Range" and schema["encoding"] == "ros2msg", schema
assert schema["data"] == "float32 distance # [m]\nbool valid\n", schema["data"]
obstacle = [m for m in d["messages"] if m["topic"] == "obstacle"]
ranges = [m for m in d["messages"] if m["topic"] == "range"]
assert len(obstacle) == 20 and len(ranges) == 10
assert all(m["data"] == "0a0b0c0d" for m in obstacle), obstacle[0]
assert all(m["data"] == {"distance": 1.5, "valid": True} for m in ranges), ranges[0]
assert [m["sequence"] for m in obstacle] == list(range(1, 21)), [m["sequence"] for m in obstacle]
assert all(int(m["publishTime"]) > 0 and int(m["logTime"]) >= int(m["publishTime"]) - 10**9 for m in d["messages"])
PY
ctl g --json record info "${files[0]}" >"$WORK/info.json" || fail "record info failed"
python3 - "$WORK/info.json" <<'PY' || fail "record info of the first file: $(head -c 800 "$WORK/info.json")"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["whole"] and d["messages"] == 30 and d["gateway"] == "gw-rec", d
assert d["closing"] == {"dropped_queue_full": "0", "dropped_not_written": "0", "dropped_invalid": "0"}, d["closing"]
streams = {s["channel"]: s for s in d["streams"]}
assert streams["obstacle"]["messages"] == 20 and streams["obstacle"]["missing"] == 0, streams
assert streams["obstacle"]["segment"] == "field" and streams["obstacle"]["origin"] == "a1", streams
assert streams["range"]["messages"] == 10 and streams["range"]["encoding"] == "cdr", streams
assert 0 < streams["obstacle"]["rate_hz"] < 1000, streams["obstacle"]
PY
ctl g record info "${files[0]}" >"$WORK/info.txt" || fail "record info (text) failed"
grep -q "30 messages in" "$WORK/info.txt" || fail "record info text: $(cat "$WORK/info.txt")"
passed

scenario "record start opens a new file; SIGTERM finishes it"
ctl g record start >"$WORK/start.out" || fail "record start failed: $(cat "$WORK/start.out")"
# A new origin: the duplicate filter remembers 0xA1's numbers from the first batch.
"$LCM_PEER" pub --url "$IN" --channel obstacle --count 5 --rate 200 --subject 0x500 --origin 0xA3 --payload-hex 01010101
wait_until 10 "35 events recorded" recorded_at_least g 35
kill -TERM "$PID_g"
wait "$PID_g" 2>/dev/null
mapfile -t files < <(files_in "$WORK/rec")
[ "${#files[@]}" -eq 2 ] || fail "expected two files, found: ${files[*]}"
read_mcap indexed "${files[1]}" >"$WORK/second.json" || fail "@mcap/core could not read ${files[1]}"
python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
assert d["statistics"]["messageCount"] == 5 and [m["data"] for m in d["messages"]] == ["01010101"] * 5, d
' "$WORK/second.json" || fail "the second file: $(head -c 600 "$WORK/second.json")"
passed

scenario "a crash keeps every complete chunk"
PIDS=()
files_in "$WORK/rec" >"$WORK/before-crash"
start_daemon g "$WORK/g.yaml" || exit 1
# The file this cosmicd writes: the one that was not there before (names may share their second).
crash_file() { files_in "$WORK/rec" | grep -vxFf "$WORK/before-crash" | head -n 1; }
"$LCM_PEER" pub --url "$IN" --channel obstacle --count 40 --rate 400 --subject 0x500 --origin 0xA1 --payload-hex 02020202
wait_until 10 "40 events recorded" recorded_at_least g 40
# Within the writer's flush interval (1 s) the events are in a complete chunk on disk.
wait_until 10 "the 40 events in complete chunks on disk" on_disk 40
kill -KILL "$PID_g"
wait "$PID_g" 2>/dev/null
crashed=$(crash_file)
read_mcap stream "$crashed" >"$WORK/crash.json" || fail "@mcap/core's stream reader failed on the crashed file"
python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
assert not d["done"], "a crashed file cannot be whole"
assert [m["data"] for m in d["messages"]] == ["02020202"] * 40, len(d["messages"])
' "$WORK/crash.json" || fail "the crashed file: $(head -c 600 "$WORK/crash.json")"
ctl g --json record info "$crashed" >"$WORK/crash_info.json" || fail "record info of the crashed file failed"
python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
assert not d["whole"] and d["messages"] == 40 and d["truncation"], d
' "$WORK/crash_info.json" || fail "record info of the crashed file: $(head -c 600 "$WORK/crash_info.json")"
printf 'not mcap' >"$WORK/garbage.mcap"
ctl g record info "$WORK/garbage.mcap" >"$WORK/garbage.out" 2>&1
[ $? -eq 1 ] || fail "record info of a file that is not MCAP did not exit 1"
grep -q "is not a readable MCAP recording" "$WORK/garbage.out" || fail "record info garbage: $(cat "$WORK/garbage.out")"
passed

# replay_typed NAME FILE: a replay segment plays FILE's range events, which reach an LCM subscriber
# as the compact events that were published.
replay_typed() {
  cat >"$WORK/typed-$1.yaml" <<YAML
gateway: {name: gw-replay}
segments:
  - {name: viz, type: lcm, url: "$OUT", latency_bound: 2ms}
  - {name: again, type: replay, file: $2, channels: [range]}
channels:
  - name: range
    subject: 0x501
    class: nrt
    publishers: [again]
    subscribers: [viz]
    type: {fields: [{name: distance, type: float32, unit: m}, {name: valid, type: bool}]}
YAML
  "$LCM_PEER" sub --url "$OUT" --channel range --count 10 --timeout 30 >"$WORK/typed-$1.jsonl" 2>"$WORK/typed-$1.err" &
  local sub=$!
  PIDS=()
  start_daemon t "$WORK/typed-$1.yaml" || exit 1
  wait "$sub" || fail "the typed replay ($1) did not deliver 10 events: $(cat "$WORK/typed-$1.err")"
  python3 -c '
import json, sys
p = [json.loads(l)["payload"] for l in open(sys.argv[1]) if l.strip()]
assert p == [sys.argv[2]] * 10, p
' "$WORK/typed-$1.jsonl" "$RANGE_HEX" || fail "typed replay ($1) payloads: $(head -n 2 "$WORK/typed-$1.jsonl")"
  kill -TERM "$PID_t"
  wait "$PID_t" 2>/dev/null
  PIDS=()
}

scenario "a typed channel replays from its recorded CDR into the compact layout"
replay_typed cdr "${files[0]}"
passed

scenario "a reload that widens recording.channels records the newly selected channel"
write_config "$WORK/reload.yaml" "$WORK/rec-reload" json
PIDS=()
start_daemon r "$WORK/reload.yaml" || exit 1
sed -i "s/channels: \[obstacle, 'ran\*'\]/channels: [obstacle, 'ran*', chatter]/" "$WORK/reload.yaml"
grep -q "chatter\]" "$WORK/reload.yaml" || fail "could not widen the selection in reload.yaml"
ctl r reload >"$WORK/reload.out" 2>&1 || fail "reload failed: $(cat "$WORK/reload.out")"
"$LCM_PEER" pub --url "$IN" --channel chatter --count 6 --rate 200 --subject 0x502 --origin 0xC1 --payload-hex 06060606
"$LCM_PEER" pub --url "$IN" --channel range --count 10 --rate 200 --subject 0x501 --origin 0xC2 --payload-hex "$RANGE_HEX"
wait_until 10 "16 events recorded" recorded_at_least r 16
ctl r record stop >/dev/null || fail "record stop after the reload failed"
[ "$(ctl r --json record status | python3 -c 'import json,sys; d=json.load(sys.stdin)["recording"]; print(d["record_dropped"]["invalid"])')" -eq 0 ] ||
  fail "events counted invalid after the reload: $(ctl r record status)"
reloaded=$(files_in "$WORK/rec-reload" | tail -n 1)
read_mcap indexed "$reloaded" | python3 -c '
import json, sys
d = json.load(sys.stdin)
assert [m["data"] for m in d["messages"] if m["topic"] == "chatter"] == ["06060606"] * 6, d["messages"]
# typed_encoding: json: the typed channel as JSON with its JSON Schema.
[schema] = d["schemas"]
assert schema["name"] == "range" and schema["encoding"] == "jsonschema", schema
props = json.loads(schema["data"])["properties"]
assert list(props) == ["distance", "valid"] and props["valid"]["type"] == "boolean", props
assert {c["messageEncoding"] for c in d["channels"] if c["topic"] == "range"} == {"json"}, d["channels"]
assert [m["data"] for m in d["messages"] if m["topic"] == "range"] == [{"distance": 1.5, "valid": True}] * 10
' || fail "the reloaded file (chatter, range as JSON): $(read_mcap indexed "$reloaded" | head -c 600)"
kill -TERM "$PID_r"
wait "$PID_r" 2>/dev/null
PIDS=()
passed

scenario "a typed channel replays from its recorded JSON into the compact layout"
replay_typed json "$reloaded"
passed

scenario "a typed channel without a ROS 2 form falls back to JSON, said once"
cat >"$WORK/fallback.yaml" <<YAML
gateway: {name: gw-fallback}
segments:
  - {name: field, type: lcm, url: "$IN", latency_bound: 2ms}
  - {name: viz, type: lcm, url: "$OUT", latency_bound: 2ms}
channels:
  - {name: status, subject: 0x503, class: nrt, publishers: [field], subscribers: [viz],
     type: {fields: [{name: Mode, type: uint8}]}}
recording: {directory: $WORK/rec-fallback, chunk_size: 4KiB}
YAML
PIDS=()
start_daemon f "$WORK/fallback.yaml" || exit 1
# A reload that changes the section starts a new file; the warning is not repeated.
sed -i 's/chunk_size: 4KiB/chunk_size: 8KiB/' "$WORK/fallback.yaml"
ctl f reload >"$WORK/fallback-reload.out" 2>&1 || fail "reload failed: $(cat "$WORK/fallback-reload.out")"
"$LCM_PEER" pub --url "$IN" --channel status --count 3 --rate 200 --subject 0x503 --origin 0xD1 --payload-hex 05
wait_until 10 "3 status events recorded" recorded_at_least f 3
ctl f record stop >/dev/null || fail "record stop failed"
warnings=$(grep -c "recording: channel status is recorded as JSON, not CDR (typed_encoding: cdr): field Mode is not a ROS 2 field name" "$WORK/f.log")
[ "$warnings" -eq 1 ] || fail "expected one fallback warning, found $warnings: $(grep -i 'recorded as JSON' "$WORK/f.log")"
fallback=$(files_in "$WORK/rec-fallback" | tail -n 1)
read_mcap indexed "$fallback" | python3 -c '
import json, sys
d = json.load(sys.stdin)
assert [s["encoding"] for s in d["schemas"]] == ["jsonschema"], d["schemas"]
assert {c["messageEncoding"] for c in d["channels"]} == {"json"}, d["channels"]
assert [m["data"] for m in d["messages"]] == [{"Mode": 5}] * 3, d["messages"]
' || fail "the fallback file: $(read_mcap indexed "$fallback" | head -c 600)"
kill -TERM "$PID_f"
wait "$PID_f" 2>/dev/null
PIDS=()
passed

scenario "a directory that cannot be written: start fails with the reason, forwarding goes on"
: >"$WORK/not-a-directory"
write_config "$WORK/bad.yaml" "$WORK/not-a-directory/rec"
PIDS=()
start_daemon g "$WORK/bad.yaml" || exit 1
grep -q "recording did not start: cannot make the recording directory $WORK/not-a-directory/rec" "$WORK/g.log" ||
  fail "no log line for the failed start: $(grep -i record "$WORK/g.log")"
ctl g record start >"$WORK/bad.out" 2>&1
[ $? -eq 1 ] || fail "record start into a plain file did not exit 1"
grep -q "cannot make the recording directory" "$WORK/bad.out" || fail "record start: $(cat "$WORK/bad.out")"
"$LCM_PEER" pub --url "$IN" --channel chatter --count 3 --rate 200 --subject 0x502 --origin 0xA1 --payload-hex 01020304
expect_field g chatter viz tx 3
passed

scenario "without a recording section, record status and start say so"
sed '/^recording:/d' "$WORK/g.yaml" >"$WORK/plain.yaml"
PIDS=()
kill "$PID_g" 2>/dev/null
wait "$PID_g" 2>/dev/null
start_daemon g "$WORK/plain.yaml" || exit 1
ctl g record status | grep -q "recording: not configured" || fail "record status: $(ctl g record status)"
ctl g record start >"$WORK/none.out" 2>&1
[ $? -eq 1 ] || fail "record start without a section did not exit 1"
grep -q "the configuration has no recording section" "$WORK/none.out" || fail "record start: $(cat "$WORK/none.out")"
passed

exit "$FAILED"
