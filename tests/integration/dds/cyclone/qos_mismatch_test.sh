#!/usr/bin/env bash
# QoS mismatches that only the far side sees (issue 22, item 11), against Eclipse Cyclone DDS,
# inside a fresh network namespace (run through scripts/netns-run):
#   qos_mismatch_test.sh COSMICD COSMICCTL COSMIC_CYCLONE_QOS_PEER COSMIC_CYCLONE_APPENDABLE_PEER
# One gateway between two DDS domains; channel wheel (SRT, reaction_time 50 ms) is read from
# `left` and written to `right`. Each scenario starts one Cyclone endpoint on cosmic/wheel that
# Cyclone itself refuses to match with cosmicd's (the peer must say so: its incompatible-QoS
# status), while Fast DDS 2.9 does not check that rule. cosmicd must then report the refusal for
# channel wheel on the right hop: `cosmicctl --json channel wheel` has a `peer_conflicts` entry on
# that segment with the peer kind and policy, the channel's `mismatches` a line naming the remote
# endpoint and segment, and `cosmicctl channel wheel` prints it as `! QoS mismatch:`. When the peer
# leaves, the conflict goes. A writer whose latency budget is within the reaction time is matched
# by Cyclone, delivers, and is reported as nothing.
#   1. a reader requesting XCDR2 only           -> right (cosmicd's writer), data_representation
#   2. a reader of an @appendable cosmic::Envelope with Cyclone's default QoS -> right, same
#   3. a writer offering XCDR2                  -> left (cosmicd's reader), data_representation
#   4. a writer offering latency budget 200 ms  -> left, latency_budget (reaction_time 50 ms)
#   5. a writer offering latency budget 10 ms   -> no conflict, events arrive
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 QOS_PEER=$3 APPENDABLE_PEER=$4
WORK=$(mktemp -d /tmp/cosmic-qos.XXXXXX)
# shellcheck source=../../daemon/lib.sh
source "$(dirname "$0")/../../daemon/lib.sh"
trap 'cleanup; rm -rf "$WORK"' EXIT

# The namespace's only interface is a multicast-capable loopback; Cyclone DDS does not use
# multicast on loopback unless told so (Fast DDS does).
export CYCLONEDDS_URI='<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces></General></Domain></CycloneDDS>'

cat >"$WORK/gw.yaml" <<YAML
gateway: {name: gw-qos}
segments:
  - {name: left, type: dds, domain: 41, latency_bound: 1ms, realtime: true}
  - {name: right, type: dds, domain: 42, latency_bound: 1ms, realtime: true}
channels:
  - {name: wheel, subject: 0x501, class: srt, period: 10ms, reaction_time: 50ms, payload: 4B,
     publishers: [left], subscribers: [right]}
YAML

domain_of() { [ "$1" = left ] && echo 41 || echo 42; }

# conflicts_on SEGMENT PEER POLICY: how many peer_conflicts of channel wheel on SEGMENT name a
# remote PEER (reader/writer) and POLICY, and that each is also a mismatch line of the channel.
conflicts_on() {
  ctl gw --json channel wheel | python3 -c '
import json, sys
segment, peer, policy = sys.argv[1:4]
c = json.load(sys.stdin)["channel"]
hop = next(s for s in c["segments"] if s["segment"] == segment)
found = [x for x in hop["peer_conflicts"] if x["peer"] == peer and x["policy"] == policy]
lines = [m for m in c["mismatches"] if m.startswith("remote " + peer + " ") and " on " + segment + ": " + policy + ": " in m]
print(min(len(found), len(lines)))' "$@"
}
has_conflict() { [ "$(conflicts_on "$@")" -ge 1 ]; }
# No peer conflict on any hop of wheel and no mismatch line.
no_conflicts() {
  ctl gw --json channel wheel | python3 -c '
import json, sys
c = json.load(sys.stdin)["channel"]
sys.exit(0 if c["mismatches"] == [] and all(s["peer_conflicts"] == [] for s in c["segments"]) else 1)'
}

# scenario_conflict NAME PEER_BIN ROLE SEGMENT POLICY [PEER OPTIONS...]
scenario_conflict() {
  local name=$1 bin=$2 role=$3 segment=$4 policy=$5
  shift 5
  local remote_kind=$role
  scenario "$name: Cyclone $role on $segment ($*) -> cosmicd reports $policy for wheel on $segment"
  mkfifo "$WORK/$name.stdin"
  "$bin" "$role" --domain "$(domain_of "$segment")" --topic cosmic/wheel --timeout-s 90 "$@" \
    <"$WORK/$name.stdin" >"$WORK/$name.out" 2>"$WORK/$name.err" &
  local pid=$! hold
  PIDS+=("$pid")
  exec {hold}>"$WORK/$name.stdin"
  # The premise: Cyclone refuses cosmicd's endpoint, and Fast DDS counts the peer as matched.
  wait_until 30 "$name: Cyclone refuses cosmicd's endpoint for its QoS" stderr_has "$WORK/$name.err" INCOMPATIBLE ||
    log "peer: $(cat "$WORK/$name.err")"
  wait_until 30 "$name: cosmicd's Fast DDS counts the Cyclone $role matched on $segment" \
    field_at_least gw wheel "$segment" matched 1
  wait_until 30 "$name: cosmicd reports a $policy conflict with a remote $remote_kind on $segment" \
    has_conflict "$segment" "$remote_kind" "$policy" || ctl gw --json channel wheel >&2
  ctl gw channel wheel >"$WORK/$name.text" 2>&1
  grep -Eq "! QoS mismatch: remote $remote_kind [0-9a-f.|]+ of cosmic/wheel on $segment: $policy: " "$WORK/$name.text" ||
    fail "$name: cosmicctl channel wheel prints no mismatch line: $(grep -i mismatch "$WORK/$name.text")"
  log "cosmicctl: $(grep '! QoS mismatch' "$WORK/$name.text" | head -2)"
  # The peer leaves: its conflict goes with it.
  exec {hold}>&-
  wait "$pid" || fail "$name: peer exit $?: $(cat "$WORK/$name.err")"
  wait_until 30 "$name: the conflict is cleared once the Cyclone $role left" no_conflicts
  passed
}

# A writer within the reaction time: Cyclone matches cosmicd's reader and delivers; no conflict.
scenario_within_budget() {
  scenario "within_budget: Cyclone writer on left, latency budget 10 ms <= reaction_time 50 ms -> no conflict, events arrive"
  mkfifo "$WORK/within.stdin"
  "$QOS_PEER" writer --domain 41 --topic cosmic/wheel --latency-budget-ms 10 --timeout-s 90 \
    <"$WORK/within.stdin" >"$WORK/within.out" 2>"$WORK/within.err" &
  local pid=$! hold rx
  PIDS+=("$pid")
  exec {hold}>"$WORK/within.stdin"
  wait_until 30 "within_budget: Cyclone writer matched cosmicd's reader" stderr_has "$WORK/within.err" MATCHED
  rx=$(channel_field gw wheel left rx)
  wait_until 30 "within_budget: events of the Cyclone writer arrive at cosmicd" field_at_least gw wheel left rx $((rx + 5))
  no_conflicts || fail "within_budget: a conflict is reported: $(ctl gw channel wheel 2>&1 | grep mismatch)"
  exec {hold}>&-
  wait "$pid"
  ! grep -q INCOMPATIBLE "$WORK/within.err" || fail "within_budget: Cyclone refused cosmicd's reader: $(cat "$WORK/within.err")"
  passed
}

start_daemon gw "$WORK/gw.yaml" || { tail -20 "$WORK/gw.log" >&2; exit 1; }
[ "$(channel_count gw)" -eq 1 ] || fail "expected 1 bound channel, got $(channel_count gw)"
no_conflicts || fail "a conflict before any peer exists"

scenario_conflict xcdr2_reader "$QOS_PEER" reader right data_representation --representation xcdr2
scenario_conflict appendable_reader "$APPENDABLE_PEER" reader right data_representation
scenario_conflict xcdr2_writer "$QOS_PEER" writer left data_representation --representation xcdr2
scenario_conflict slow_writer "$QOS_PEER" writer left latency_budget --latency-budget-ms 200
scenario_within_budget

[ "$FAILED" = 0 ] || { log "--- cosmicd log"; tail -40 "$WORK/gw.log" >&2; exit 1; }
log "all QoS-mismatch scenarios against Cyclone DDS passed"
