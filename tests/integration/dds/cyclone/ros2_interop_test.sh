#!/usr/bin/env bash
# ROS 2 nodes, as Eclipse Cyclone DDS programs put them on the wire (topic rt/<name>, type
# geometry_msgs::msg::dds_::Twist_, ROS 2's default QoS RELIABLE/VOLATILE/KEEP_LAST 10, XCDR1),
# against cosmicd's native DDS channels, inside a fresh network namespace (run through
# scripts/netns-run):
#   ros2_interop_test.sh COSMICD COSMICCTL COSMIC_CYCLONE_ROS2_PEER COSMIC_LCM_PEER
# One gateway between two DDS domains and two native channels carrying the serialized Twist
# unchanged: cmd_vel (SRT) from the left domain to the right one, odom_twist (NRT) from the right
# to the left. For each, a Cyclone "node" publishes 50 Twists on one domain and another receives
# them through cosmicd on the other. Both hops are reliable, so nothing may be lost: the reader
# must decode all 50 in order with exactly the values written, each sample byte for byte as the
# writer serialized it (52 bytes, encapsulation CDR_LE 00 01 00 00); cosmicd must count each event
# in and out exactly once; no endpoint may be refused for incompatible QoS.
# Between formats (contents travel as bytes): teleop, a ROS 2 writer's Twists -> cosmicd -> raw on
# LCM channel TELEOP (each message exactly the serialized sample); and from_lcm, an LCM publisher
# sending a serialized Twist raw -> cosmicd -> native topic rt/from_lcm, decoded by a Cyclone
# reader. Ten identical samples must all arrive: a native DDS topic has no fingerprint guard.
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 ROS2_PEER=$3 LCM_PEER=$4
LCM_URL="udpm://239.255.76.67:7693?ttl=0"
WORK=$(mktemp -d /tmp/cosmic-ros2.XXXXXX)
# shellcheck source=../../daemon/lib.sh
source "$(dirname "$0")/../../daemon/lib.sh"
trap 'cleanup; rm -rf "$WORK"' EXIT

# The namespace's only interface is a multicast-capable loopback; Cyclone DDS does not use
# multicast on loopback unless told so (Fast DDS does).
export CYCLONEDDS_URI='<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces></General></Domain></CycloneDDS>'

TWIST=geometry_msgs::msg::dds_::Twist_
HERE=$(cd "$(dirname "$0")" && pwd)
COUNT=50

cat >"$WORK/gw.yaml" <<YAML
gateway: {name: gw-ros2}
segments:
  - {name: left, type: dds, domain: 35, latency_bound: 1ms, realtime: true}
  - {name: right, type: dds, domain: 36, latency_bound: 1ms, realtime: true}
  - {name: viz, type: lcm, url: "$LCM_URL", latency_bound: 2ms}
channels:
  - name: cmd_vel
    subject: 0x301
    class: srt
    period: 10ms
    reaction_time: 50ms
    omission_degree: 0
    payload: 52B
    publishers: [left]
    subscribers: [right]
    native:
      left: {topic: rt/cmd_vel, type: "$TWIST"}
      right: {topic: rt/cmd_vel, type: "$TWIST"}
  - name: odom_twist
    subject: 0x302
    class: nrt
    payload: 52B
    publishers: [right]
    subscribers: [left]
    native:
      left: {topic: rt/odom_twist, type: "$TWIST"}
      right: {topic: rt/odom_twist, type: "$TWIST"}
  - name: teleop
    subject: 0x303
    class: nrt
    payload: 52B
    publishers: [left]
    subscribers: [viz]
    native:
      left: {topic: rt/teleop, type: "$TWIST"}
      viz: {channel: TELEOP}
  # Typed (issue 35): the Twist read from the IDL file the Cyclone peers are generated from, so
  # cosmicd converts rather than carries bytes: the Cyclone writer's XCDR1 samples leave as XCDR2,
  # and as JSON on LCM.
  - name: twist_typed
    subject: 0x305
    class: nrt
    type: {idl: "$HERE/ros2_twist.idl", name: "geometry_msgs::msg::dds_::Twist_"}  # what idlc compiled for the peer
    publishers: [left]
    subscribers: [right, viz]
    native:
      left: {topic: rt/twist_typed, type: "$TWIST"}
      right: {topic: rt/twist_typed, type: "$TWIST", representation: xcdr2}
      viz: {channel: TWIST_JSON, representation: json}
  - name: from_lcm
    subject: 0x304
    class: nrt
    payload: 52B
    publishers: [viz]
    subscribers: [right]
    native:
      viz: {channel: FROM_LCM}
      right: {topic: rt/from_lcm, type: "$TWIST"}
YAML

domain_of() { [ "$1" = left ] && echo 35 || echo 36; }

# check_samples FILE COUNT POLICED: what the Cyclone reader decoded, one JSON line per sample.
# Sample i = 1..COUNT must be linear (i, i+0.5, -i), angular (0.25i, -0.125, 1000+i), in order, no
# duplicates, and its serialized form exactly the XCDR1 one: 00 01 00 00 (CDR_LE, options 0)
# followed by the six doubles little-endian, 52 bytes. Every sample must arrive except the POLICED
# ones cosmicd counted as over the channel's rate: the writer paces at 15 ms against the declared
# 10 ms, but on a loaded machine samples can reach cosmicd bunched by more than the segment's 1 ms
# latency bound, and the rate police then drops them, correctly and counted. Nothing else may go.
check_samples() {
  python3 - "$@" <<'PY'
import json, struct, sys
path, count, policed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
samples = [json.loads(l) for l in open(path) if l.strip()]
order = [s["linear"][0] for s in samples]
assert len(order) == count - policed, \
    f"{len(samples)} samples, expected {count} less the {policed} rate-policed (no other loss on reliable hops); linear.x: {order}"
assert all(a < b for a, b in zip(order, order[1:])) and all(x in range(1, count + 1) for x in order), \
    f"samples out of order, duplicated or unknown; linear.x: {order}"
if policed:
    print(f"note: cosmicd's rate police dropped {policed} bunched arrivals (counted as dropped.rate)")
for s in samples:
    i = int(s["linear"][0])
    linear, angular = [float(i), i + 0.5, -float(i)], [0.25 * i, -0.125, 1000.0 + i]
    assert s["linear"] == linear and s["angular"] == angular, \
        f"sample {i}: linear {s['linear']} angular {s['angular']}, expected {linear} {angular}"
    cdr = bytes.fromhex(s["cdr"])
    expected = bytes([0x00, 0x01, 0x00, 0x00]) + struct.pack("<6d", *linear, *angular)
    assert len(cdr) == 52, f"sample {i}: {len(cdr)} serialized bytes, expected 52"
    assert cdr[:4] == expected[:4], f"sample {i}: encapsulation {cdr[:4].hex()}, expected 00010000 (CDR_LE, XCDR1)"
    assert cdr == expected, f"sample {i}: serialized {cdr.hex()}, expected {expected.hex()}"
print(f"checked: {len(samples)} samples decoded in order, values exact, each 52 bytes 00010000 + 6 LE doubles")
PY
}

# check_pub_summary FILE COUNT: the publisher's JSON summary: every sample written and
# acknowledged by the reliable reader (cosmicd's), XCDR1, the ROS 2 type name.
check_pub_summary() {
  python3 - "$@" <<'PY'
import json, sys
path, count = sys.argv[1], int(sys.argv[2])
s = json.loads(open(path).read().strip().splitlines()[-1])
assert s["type"] == "geometry_msgs::msg::dds_::Twist_", f"type {s['type']}"
assert s["representation"] == "XCDR1", f"representation {s['representation']}"
assert s["written"] == count and s["acked"] is True, f"written {s['written']} of {count}, acked {s['acked']}"
print(f"checked: publisher wrote {count} {s['type']} ({s['representation']}), all acknowledged by cosmicd")
PY
}

# No remote endpoint of CHANNEL refused on either segment (the counter is null when the
# transport does not count: that is 0 here), and no mismatch reported for the channel.
no_incompatible_peers() {
  local channel=$1 segment n ok=1
  for segment in left right; do
    n=$(channel_field gw "$channel" "$segment" incompatible)
    [ "$n" = 0 ] || { fail "$channel: cosmicctl reports $n incompatible peers on $segment"; ok=0; }
  done
  n=$(ctl gw --json channels | python3 -c '
import json, sys
for c in json.load(sys.stdin)["channels"]:
    if c["name"] == sys.argv[1]:
        print(len(c.get("mismatches", [])))' "$channel")
  [ "$n" = 0 ] || { fail "$channel: cosmicctl reports mismatches: $(ctl gw channel "$channel" 2>&1 | head -5)"; ok=0; }
  [ "$ok" = 0 ] || log "checked: $channel: no incompatible peers on left and right, no mismatches"
}

# One channel: Cyclone ROS 2 writer (segment FROM) -> cosmicd -> Cyclone ROS 2 reader (TO).
run_channel() {
  local channel=$1 topic=$2 from=$3 to=$4 count=$5
  scenario "$channel: ROS 2 writer $topic (domain $(domain_of "$from")) -> cosmicd -> ROS 2 reader $topic (domain $(domain_of "$to"))"
  "$ROS2_PEER" sub --domain "$(domain_of "$to")" --topic "$topic" --count "$count" --timeout-s 60 \
    >"$WORK/$channel.out" 2>"$WORK/$channel.sub.err" &
  local sub=$!
  PIDS+=("$sub")
  wait_until 30 "$channel: Cyclone reader created" stderr_has "$WORK/$channel.sub.err" ready || return
  wait_until 30 "$channel: cosmicd's writer matched the Cyclone reader" field_at_least gw "$channel" "$to" matched 1 || return
  wait_until 30 "$channel: Cyclone reader matched cosmicd's writer" stderr_has "$WORK/$channel.sub.err" MATCHED || return

  # The writer is VOLATILE: it writes only once both sides know each other (the start gate).
  mkfifo "$WORK/$channel.go"
  "$ROS2_PEER" pub --domain "$(domain_of "$from")" --topic "$topic" --count "$count" --period-ms 15 \
    --wait-readers 1 --timeout-s 60 --gate stdin \
    <"$WORK/$channel.go" >"$WORK/$channel.pub.out" 2>"$WORK/$channel.pub.err" &
  local pub=$!
  PIDS+=("$pub")
  local go
  exec {go}>"$WORK/$channel.go"
  wait_until 30 "$channel: Cyclone writer matched cosmicd's reader" stderr_has "$WORK/$channel.pub.err" MATCHED || { exec {go}>&-; return; }
  wait_until 30 "$channel: cosmicd's reader matched the Cyclone writer" field_at_least gw "$channel" "$from" matched 1 || { exec {go}>&-; return; }
  echo go >&"$go"
  exec {go}>&-

  wait "$pub" || fail "$channel: Cyclone publisher failed: $(cat "$WORK/$channel.pub.out" "$WORK/$channel.pub.err")"
  check_pub_summary "$WORK/$channel.pub.out" "$count" >&2 || fail "$channel: publisher summary: $(cat "$WORK/$channel.pub.out")"
  wait "$sub"
  local sub_rc=$?
  # The subscriber waits for COUNT samples; when cosmicd policed some it ends at its timeout, so the
  # rate drops are read once it has ended (every event was judged before the last one left).
  local policed
  policed=$(channel_field gw "$channel" "$from" dropped.rate)
  if ! check_samples "$WORK/$channel.out" "$count" "$policed" >&2; then
    fail "$channel: wrong samples (subscriber exit $sub_rc: $(cat "$WORK/$channel.sub.err"))"
    log "--- where the events went (cosmicd's counters of $channel)"
    ctl gw channel "$channel" >&2
    return
  fi
  [ "$sub_rc" = 0 ] || [ "$policed" -gt 0 ] || fail "$channel: subscriber exit $sub_rc: $(cat "$WORK/$channel.sub.err")"
  expect_field gw "$channel" "$from" rx "$count" && expect_field gw "$channel" "$to" tx "$((count - policed))" &&
    log "checked: $channel: cosmicd counted $count in on $from and $((count - policed)) out on $to"
  no_incompatible_peers "$channel"
  passed
}

# teleop: Cyclone ROS 2 writer (left) -> cosmicd -> LCM channel TELEOP, raw. Every message must be
# the writer's serialized sample, byte for byte.
run_to_lcm() {
  local count=10
  scenario "teleop: ROS 2 writer rt/teleop (domain 35) -> cosmicd -> raw LCM channel TELEOP"
  "$LCM_PEER" sub --url "$LCM_URL" --channel TELEOP --count "$count" --timeout 60 --raw \
    >"$WORK/teleop.out" 2>"$WORK/teleop.sub.err" &
  local sub=$!
  PIDS+=("$sub")
  wait_until 30 "teleop: LCM subscriber ready" stderr_has "$WORK/teleop.sub.err" READY || return
  mkfifo "$WORK/teleop.go"
  "$ROS2_PEER" pub --domain 35 --topic rt/teleop --count "$count" --period-ms 10 --wait-readers 1 --timeout-s 60 \
    --gate stdin <"$WORK/teleop.go" >"$WORK/teleop.pub.out" 2>"$WORK/teleop.pub.err" &
  local pub=$! go
  PIDS+=("$pub")
  exec {go}>"$WORK/teleop.go"
  wait_until 30 "teleop: cosmicd's reader matched the Cyclone writer" field_at_least gw teleop left matched 1 || { exec {go}>&-; return; }
  wait_until 30 "teleop: Cyclone writer matched" stderr_has "$WORK/teleop.pub.err" MATCHED || { exec {go}>&-; return; }
  echo go >&"$go"
  exec {go}>&-
  wait "$pub" || fail "teleop: Cyclone publisher failed: $(cat "$WORK/teleop.pub.err")"
  wait "$sub" || fail "teleop: LCM subscriber: $(cat "$WORK/teleop.sub.err")"
  python3 - "$WORK/teleop.out" "$count" >&2 <<'PY' || fail "teleop: LCM messages are not the serialized samples"
import json, struct, sys
lines = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
count = int(sys.argv[2])
assert len(lines) == count, f"{len(lines)} LCM messages, expected {count}"
for i, line in enumerate(lines, 1):
    linear, angular = [float(i), i + 0.5, -float(i)], [0.25 * i, -0.125, 1000.0 + i]
    expected = bytes([0, 1, 0, 0]) + struct.pack("<6d", *linear, *angular)
    assert bytes.fromhex(line["payload"]) == expected, f"message {i}: {line['payload']}, expected {expected.hex()}"
print(f"checked: {count} LCM messages on TELEOP, each exactly the ROS 2 writer's serialized Twist")
PY
  passed
}

# from_lcm: an LCM publisher sends one serialized Twist (linear 7, 7.5, -7; angular 1.75, -0.125,
# 1007) raw ten times -> cosmicd -> rt/from_lcm on the right domain -> Cyclone ROS 2 reader.
run_from_lcm() {
  local count=10
  scenario "from_lcm: raw LCM FROM_LCM (serialized Twist) -> cosmicd -> ROS 2 reader rt/from_lcm (domain 36)"
  local hex
  hex=$(python3 -c 'import struct; print((bytes([0, 1, 0, 0]) + struct.pack("<6d", 7, 7.5, -7, 1.75, -0.125, 1007)).hex())')
  "$ROS2_PEER" sub --domain 36 --topic rt/from_lcm --count "$count" --timeout-s 60 \
    >"$WORK/from_lcm.out" 2>"$WORK/from_lcm.sub.err" &
  local sub=$!
  PIDS+=("$sub")
  wait_until 30 "from_lcm: Cyclone reader matched cosmicd's writer" stderr_has "$WORK/from_lcm.sub.err" MATCHED || return
  wait_until 30 "from_lcm: cosmicd's writer matched the Cyclone reader" field_at_least gw from_lcm right matched 1 || return
  "$LCM_PEER" pub --url "$LCM_URL" --channel FROM_LCM --count "$count" --rate 20 --raw --payload-hex "$hex" \
    || fail "from_lcm: LCM publisher failed"
  wait "$sub" || fail "from_lcm: Cyclone reader: $(cat "$WORK/from_lcm.sub.err")"
  python3 - "$WORK/from_lcm.out" "$count" >&2 <<'PY' || fail "from_lcm: the Cyclone reader did not decode the LCM bytes"
import json, sys
samples = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
count = int(sys.argv[2])
assert len(samples) == count, f"{len(samples)} samples, expected {count} (identical samples must all pass)"
for s in samples:
    assert s["linear"] == [7.0, 7.5, -7.0] and s["angular"] == [1.75, -0.125, 1007.0], f"decoded {s}"
print(f"checked: a Cyclone ROS 2 reader decoded all {count} identical Twists sent raw on LCM")
PY
  passed
}

# twist_typed: Cyclone ROS 2 writer (left, XCDR1) -> cosmicd (writing XCDR2 on right) -> a Cyclone
# reader that takes XCDR1 and XCDR2 (right) and LCM channel TWIST_JSON. The reader must decode every
# sample to the values written, each serialized as XCDR2 (CDR2_LE 00 07 00 00, the six doubles: no
# padding at 4-byte alignment): cosmicd transcodes. The LCM tool must get each as JSON with the
# exact values. (A reader that asks for XCDR2 alone does not match: Fast DDS 2.9 does not announce
# its writer's representation, eProsima/Fast-DDS#3935; cosmicd reports that peer as a conflict.)
run_typed() {
  local count=10
  scenario "twist_typed: ROS 2 writer (XCDR1, domain 35) -> cosmicd -> XCDR2 to a ROS 2 reader (domain 36) and JSON on LCM"
  "$ROS2_PEER" sub --domain 36 --topic rt/twist_typed --count "$count" --timeout-s 60 --representation both \
    >"$WORK/typed.out" 2>"$WORK/typed.sub.err" &
  local sub=$!
  PIDS+=("$sub")
  "$LCM_PEER" sub --url "$LCM_URL" --channel TWIST_JSON --count "$count" --timeout 60 --raw \
    >"$WORK/typed_json.out" 2>"$WORK/typed_json.err" &
  local lcm=$!
  PIDS+=("$lcm")
  wait_until 30 "twist_typed: LCM subscriber ready" stderr_has "$WORK/typed_json.err" READY || return
  wait_until 30 "twist_typed: the reader matched cosmicd's writer" stderr_has "$WORK/typed.sub.err" MATCHED || return
  wait_until 30 "twist_typed: cosmicd's writer matched the reader" field_at_least gw twist_typed right matched 1 || return
  mkfifo "$WORK/typed.go"
  "$ROS2_PEER" pub --domain 35 --topic rt/twist_typed --count "$count" --period-ms 10 --wait-readers 1 --timeout-s 60 \
    --gate stdin <"$WORK/typed.go" >"$WORK/typed.pub.out" 2>"$WORK/typed.pub.err" &
  local pub=$! go
  PIDS+=("$pub")
  exec {go}>"$WORK/typed.go"
  wait_until 30 "twist_typed: cosmicd's reader matched the Cyclone writer" field_at_least gw twist_typed left matched 1 || { exec {go}>&-; return; }
  wait_until 30 "twist_typed: Cyclone writer matched" stderr_has "$WORK/typed.pub.err" MATCHED || { exec {go}>&-; return; }
  echo go >&"$go"
  exec {go}>&-
  wait "$pub" || fail "twist_typed: Cyclone publisher failed: $(cat "$WORK/typed.pub.err")"
  wait "$sub" || fail "twist_typed: XCDR2 reader: $(cat "$WORK/typed.sub.err")"
  wait "$lcm" || fail "twist_typed: LCM subscriber: $(cat "$WORK/typed_json.err")"
  python3 - "$WORK/typed.out" "$WORK/typed_json.out" "$count" >&2 <<'PY' || fail "twist_typed: wrong samples or JSON"
import json, struct, sys
samples = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
texts = [json.loads(l) for l in open(sys.argv[2]) if l.strip()]
count = int(sys.argv[3])
assert len(samples) == count, f"{len(samples)} XCDR2 samples, expected {count}"
assert len(texts) == count, f"{len(texts)} JSON messages, expected {count}"
for i, (s, t) in enumerate(zip(samples, texts), 1):
    linear, angular = [float(i), i + 0.5, -float(i)], [0.25 * i, -0.125, 1000.0 + i]
    assert s["linear"] == linear and s["angular"] == angular, f"sample {i}: {s}"
    expected = bytes([0x00, 0x07, 0x00, 0x00]) + struct.pack("<6d", *linear, *angular)
    assert bytes.fromhex(s["cdr"]) == expected, f"sample {i}: serialized {s['cdr']}, expected {expected.hex()}"
    got = json.loads(bytes.fromhex(t["payload"]).decode())
    want = {"linear": dict(zip("xyz", linear)), "angular": dict(zip("xyz", angular))}
    assert got == want and list(got) == ["linear", "angular"], f"JSON {i}: {got}, expected {want}"
print(f"checked: {count} Twists written in XCDR1 reached the reader as XCDR2 and the LCM tool as JSON, values exact")
PY
  expect_field gw twist_typed right tx "$count"
  passed
}

# A reader of twist_typed that asks for XCDR2 alone: Cyclone does not match it with cosmicd's
# writer, which Fast DDS 2.9 announces as XCDR1 (eProsima/Fast-DDS#3935) although it writes XCDR2,
# and cosmicd must say so: a data_representation conflict on right naming the library's limit.
xcdr2_only_conflict() {
  python3 -c '
import json, sys
hop = next(s for s in json.load(sys.stdin)["channel"]["segments"] if s["segment"] == "right")
found = [c for c in hop["peer_conflicts"] if c["peer"] == "reader" and c["policy"] == "data_representation"]
sys.exit(0 if found and "Fast-DDS#3935" in found[0]["reason"] else 1)' < <(ctl gw --json channel twist_typed)
}
run_typed_xcdr2_only() {
  scenario "twist_typed: a reader asking for XCDR2 alone -> cosmicd reports why it does not match"
  "$ROS2_PEER" sub --domain 36 --topic rt/twist_typed --count 1 --timeout-s 30 --representation xcdr2 \
    >"$WORK/typed_x2.out" 2>"$WORK/typed_x2.err" &
  local sub=$!
  PIDS+=("$sub")
  wait_until 30 "twist_typed: cosmicd reports the XCDR2-only reader's conflict" xcdr2_only_conflict || return
  kill "$sub" 2>/dev/null
  passed
}

start_daemon gw "$WORK/gw.yaml" || { tail -20 "$WORK/gw.log" >&2; exit 1; }
# Every channel admitted and bound (a rejection would leave the test meaningless).
[ "$(channel_count gw)" -eq 5 ] || fail "expected 5 bound channels, got $(channel_count gw)"

run_channel cmd_vel rt/cmd_vel left right "$COUNT"
run_channel odom_twist rt/odom_twist right left "$COUNT"
run_to_lcm
run_from_lcm
run_typed
run_typed_xcdr2_only

if grep -q "incompatible QoS" "$WORK/gw.log"; then
  fail "cosmicd refused a Cyclone endpoint: $(grep "incompatible QoS" "$WORK/gw.log" | head -3)"
fi
[ "$FAILED" = 0 ] || { log "--- cosmicd log"; tail -40 "$WORK/gw.log" >&2; exit 1; }
log "all ROS 2 (Cyclone DDS) native-channel scenarios passed"
