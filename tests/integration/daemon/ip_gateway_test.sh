#!/usr/bin/env bash
# End-to-end tests of cosmicd over real Fast DDS and real LCM, every program in its own process,
# inside a fresh network namespace (run through scripts/netns-run).
#   ip_gateway_test.sh COSMICD COSMICCTL COSMIC_LCM_PEER COSMIC_DDS_PEER [SCENARIO...]
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 LCM_PEER=$3 DDS_PEER=$4
shift 4
WORK=$(mktemp -d /tmp/cosmic-e2e.XXXXXX)
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
trap 'cleanup; rm -rf "$WORK"' EXIT

LCM_A="udpm://239.255.76.67:7811?ttl=0"
LCM_B="udpm://239.255.76.67:7812?ttl=0"
LCM_X="udpm://239.255.76.67:7821?ttl=0"
LCM_R="udpm://239.255.76.67:7822?ttl=0"

write_gateway_a() {
  cat >"$WORK/a.yaml" <<YAML
gateway: {name: gw-a}
segments:
  - {name: lcm-a, type: lcm, url: "$LCM_A", latency_bound: 2ms}
  - {name: lan, type: dds, domain: 21, latency_bound: 2ms}
channels:
  - {name: pose, subject: 0x100, class: nrt, payload: 64B, encoding: raw, omission_degree: 3, publishers: [lcm-a], subscribers: [lan]}
  - {name: old, subject: 0x101, class: nrt, payload: 16B, temp_validity: 5ms, omission_degree: 3, publishers: [lan], subscribers: [lcm-a]}
  - {name: fast, subject: 0x102, class: srt, period: 10ms, reaction_time: 50ms, omission_degree: 1, payload: 16B, publishers: [lan], subscribers: [lcm-a]}
  - {name: steady, subject: 0x103, class: nrt, payload: 32B, omission_degree: 3, publishers: [lan], subscribers: [lcm-a]}
$1
YAML
}

write_gateway_b() {
  cat >"$WORK/b.yaml" <<YAML
gateway: {name: gw-b}
segments:
  - {name: lan, type: dds, domain: 21, latency_bound: 2ms}
  - {name: lcm-b, type: lcm, url: "$LCM_B", latency_bound: 2ms}
channels:
  - {name: pose, subject: 0x100, class: nrt, payload: 64B, encoding: raw, omission_degree: 3, publishers: [lan], subscribers: [lcm-b]}
YAML
}

# LCM raw events into gateway A cross the DDS domain into gateway B and come out on another LCM
# group, each exactly once, with the counters of both gateways agreeing.
test_raw_lcm_across_dds() {
  scenario "raw LCM -> gw-a -> DDS -> gw-b -> LCM, exactly once"
  local n=500
  wait_until 20 "gw-a pose writer matched" field_at_least a pose lan matched 1 || return
  wait_until 20 "gw-b pose reader matched" field_at_least b pose lan matched 1 || return
  "$LCM_PEER" sub --url "$LCM_B" --channel pose --count "$n" --raw --timeout 30 >"$WORK/pose.out" 2>"$WORK/pose.err" &
  local sub=$!
  PIDS+=("$sub")
  wait_until 10 "LCM subscriber ready" stderr_has "$WORK/pose.err" READY || return
  "$LCM_PEER" pub --url "$LCM_A" --channel pose --count "$n" --size 64 --raw --rate 2000 || fail "publisher failed"
  wait "$sub" || { fail "subscriber got $(wc -l <"$WORK/pose.out") of $n"; return; }
  # Every message once, bytes unchanged: message k byte i is (k*31+i)&0xff.
  python3 -c '
import json, sys
seen = sorted(bytes.fromhex(json.loads(l)["payload"]) for l in open(sys.argv[1]))
expected = sorted(bytes(((k * 31 + i) & 0xff) for i in range(64)) for k in range(1, int(sys.argv[2]) + 1))
sys.exit(0 if seen == expected else 1)' "$WORK/pose.out" "$n" || fail "payload bytes changed on the way"
  wait_until 10 "gw-b forwarded all" field_equals b pose lcm-b tx "$n" || return
  wait_until 10 "counters settled" settled a
  wait_until 10 "counters settled" settled b
  expect_field a pose lcm-a rx "$n"
  expect_field a pose lan tx "$n"
  expect_field b pose lan rx "$n"
  expect_field b pose lcm-b tx "$n"
  expect_field b pose lan dropped.duplicate 0
  passed
}

# Two gateways bridging the same LCM group and DDS domain in opposite directions: every event
# reaches DDS exactly once and the loop is cut.
test_cross_connected_gateways() {
  scenario "two cross-connected gateways deliver each event exactly once"
  local n=200
  cat >"$WORK/c.yaml" <<YAML
gateway: {name: gw-c}
segments:
  - {name: lcm, type: lcm, url: "$LCM_X", latency_bound: 2ms}
  - {name: lan, type: dds, domain: 22, latency_bound: 2ms}
channels:
  - {name: x, subject: 0x200, class: nrt, payload: 16B, omission_degree: 3, publishers: [lcm], subscribers: [lan]}
YAML
  sed -e 's/gw-c/gw-d/' -e 's/publishers: \[lcm\], subscribers: \[lan\]/publishers: [lan], subscribers: [lcm]/' "$WORK/c.yaml" >"$WORK/d.yaml"
  start_daemon c "$WORK/c.yaml" || return
  start_daemon d "$WORK/d.yaml" || return
  "$DDS_PEER" sub --domain 22 --channel x --count "$n" --timeout 30 >"$WORK/x.out" 2>"$WORK/x.err" &
  local sub=$!
  PIDS+=("$sub")
  wait_until 20 "gw-c writer matched by gw-d and the subscriber" field_at_least c x lan matched 2 || return
  wait_until 20 "gw-d reader matched" field_at_least d x lan matched 1 || return
  wait_until 20 "DDS subscriber matched" stderr_has "$WORK/x.err" '"matched"' || return
  "$LCM_PEER" pub --url "$LCM_X" --channel x --count "$n" --size 16 --rate 1000 || fail "publisher failed"
  wait "$sub" || { fail "DDS subscriber got $(wc -l <"$WORK/x.out") of $n"; return; }
  wait_until 10 "gw-d forwarded all back to LCM" field_equals d x lcm tx "$n" || return
  wait_until 10 "counters settled" settled c
  local sequences
  sequences=$(python3 -c 'import json,sys; print(len({json.loads(l)["sequence"] for l in open(sys.argv[1])}))' "$WORK/x.out")
  [ "$sequences" -eq "$n" ] || fail "$sequences distinct sequences of $n on DDS"
  # gw-c took the native events and gw-d's copies (its own origin), and dropped every copy as a
  # loop copy, counted: no second lap.
  wait_until 10 "gw-c counted gw-d's copies" field_equals c x lcm dropped.duplicate "$n" || return
  expect_field c x lcm rx $((2 * n))
  expect_field c x lan tx "$n"
  expect_field d x lan rx "$n"
  passed
}

# Three gateways in a ring (LCM X -> gw-e -> DDS 24 -> gw-f -> DDS 25 -> gw-g -> LCM X): every event
# crosses each network once and the loop is cut where it started: gw-e drops every copy coming
# back with its own origin (issue 21, item 4).
test_three_gateways_in_a_ring() {
  scenario "three gateways in a ring forward each event once around and cut the loop"
  local n=200
  ring_gateway() { # ring_gateway NAME FROM_SEGMENT_YAML TO_SEGMENT_YAML FROM TO
    cat >"$WORK/$1.yaml" <<YAML
gateway: {name: gw-$1}
segments:
  - $2
  - $3
channels:
  - {name: ring, subject: 0x210, class: nrt, payload: 16B, omission_degree: 3, publishers: [$4], subscribers: [$5]}
YAML
  }
  ring_gateway e "{name: lcm, type: lcm, url: \"$LCM_R\", latency_bound: 2ms}" "{name: a, type: dds, domain: 24, latency_bound: 2ms}" lcm a
  ring_gateway f "{name: a, type: dds, domain: 24, latency_bound: 2ms}" "{name: b, type: dds, domain: 25, latency_bound: 2ms}" a b
  ring_gateway g "{name: b, type: dds, domain: 25, latency_bound: 2ms}" "{name: lcm, type: lcm, url: \"$LCM_R\", latency_bound: 2ms}" b lcm
  start_daemon e "$WORK/e.yaml" || return
  start_daemon f "$WORK/f.yaml" || return
  start_daemon g "$WORK/g.yaml" || return
  wait_until 20 "gw-f reader matched gw-e's writer" field_at_least f ring a matched 1 || return
  wait_until 20 "gw-g reader matched gw-f's writer" field_at_least g ring b matched 1 || return
  "$LCM_PEER" pub --url "$LCM_R" --channel ring --count "$n" --size 16 --rate 1000 || fail "publisher failed"
  wait_until 20 "gw-g sent every event back onto LCM" field_equals g ring lcm tx "$n" || return
  wait_until 10 "gw-e counted the copies that came around" field_equals e ring lcm dropped.duplicate "$n" || return
  wait_until 10 "counters settled" settled e
  expect_field e ring lcm rx $((2 * n))
  expect_field e ring a tx "$n"
  expect_field f ring a rx "$n"
  expect_field f ring b tx "$n"
  expect_field g ring b rx "$n"
  passed
}

# Starts a DDS publisher that waits for stdin, until gateway A's reader has matched it.
publish_dds_to_a() {
  local channel=$1
  shift
  local fifo="$WORK/$channel.start"
  mkfifo "$fifo"
  "$DDS_PEER" pub --domain 21 --channel "$channel" --start-on-stdin "$@" <"$fifo" 2>"$WORK/$channel.pub.err" &
  local pub=$!
  PIDS+=("$pub")
  exec 7>"$fifo"
  wait_until 20 "gw-a $channel reader matched" field_at_least a "$channel" lan matched 1 || { exec 7>&-; return 1; }
  echo go >&7
  exec 7>&-
  wait "$pub" || fail "DDS publisher on $channel failed: $(tail -2 "$WORK/$channel.pub.err")"
}

test_expired_events_are_dropped() {
  scenario "events older than temp_validity are dropped and counted"
  publish_dds_to_a old --count 20 --size 16 --age-ns 10000000 || return
  wait_until 10 "20 expired" field_equals a old lan dropped.expired 20 || return
  expect_field a old lan rx 20
  expect_field a old lcm-a tx 0
  passed
}

test_rate_limit_holds() {
  scenario "a babbling source is held to the channel's rate"
  publish_dds_to_a fast --count 100 --size 16 || return
  wait_until 10 "100 received" field_equals a fast lan rx 100 || return
  local tx rate
  tx=$(channel_field a fast lcm-a tx)
  rate=$(channel_field a fast lan dropped.rate)
  [ $((tx + rate)) -eq 100 ] || fail "tx $tx + rate drops $rate != 100"
  [ "$rate" -ge 50 ] || fail "only $rate events dropped for rate"
  passed
}

test_bind_unbind_while_traffic_flows() {
  scenario "bind and unbind at run time lose nothing on other channels"
  local n=1000
  cat >"$WORK/extra.yaml" <<YAML
channels:
  - {name: extra, subject: 0x1ff, class: nrt, payload: 8B, omission_degree: 3, publishers: [lcm-a], subscribers: [lan]}
YAML
  "$LCM_PEER" sub --url "$LCM_A" --channel steady --count "$n" --timeout 30 >"$WORK/steady.out" 2>"$WORK/steady.err" &
  local sub=$!
  PIDS+=("$sub")
  wait_until 10 "LCM subscriber ready" stderr_has "$WORK/steady.err" READY || return
  publish_dds_to_a steady --count "$n" --size 32 --rate 500 &
  local pub=$!
  wait_until 10 "traffic flowing" field_at_least a steady lcm-a tx 50 || return
  for _ in 1 2 3; do
    ctl a bind "$WORK/extra.yaml" >/dev/null || fail "runtime bind failed"
    [ "$(channel_count a)" -eq 5 ] || fail "extra not listed after bind"
    ctl a unbind extra >/dev/null || fail "runtime unbind failed"
  done
  wait "$pub" || fail "publisher failed"
  wait "$sub" || fail "subscriber got $(wc -l <"$WORK/steady.out") of $n"
  ctl a unbind extra >/dev/null 2>&1 && fail "unbinding an unbound channel succeeded"
  passed
}

# own_datagrams: drop (the default): gw-a's lcm-a receives a channel, so it is a member of the
# group and its filter drops what it sends looped back, one per message, which cosmicctl reports;
# gw-b's lcm-b only sends, so it left the group and gets none of its own back.
test_own_datagrams_are_counted() {
  scenario "own LCM datagrams dropped by the filter are counted, none on a segment that only sends"
  local before
  before=$(segment_adapter_field a lcm-a sent)
  publish_dds_to_a steady --count 200 --size 32 --rate 1000 || return
  wait_until 10 "200 more sent on lcm-a" segment_field_at_least a lcm-a sent $((before + 200)) || return
  local sent own
  sent=$(segment_adapter_field a lcm-a sent)
  own=$(segment_adapter_field a lcm-a own_datagrams_dropped)
  [ "$own" = "$sent" ] || fail "gw-a lcm-a: own_datagrams_dropped $own, sent $sent"
  ctl a segments | grep -q "^lcm-a: $own own datagrams dropped by its receive filter" ||
    fail "cosmicctl segments (text) does not name them: $(ctl a segments)"
  [ "$(segment_adapter_field b lcm-b sent)" -gt 0 ] || fail "gw-b sent nothing on lcm-b"
  own=$(segment_adapter_field b lcm-b own_datagrams_dropped)
  [ "$own" = 0 ] || fail "gw-b lcm-b, which only sends, had $own of its own back"
  ctl b segments | grep -q "own datagrams dropped" && fail "gw-b's text names own drops it does not have"
  passed
}

test_reload_of_broken_file_keeps_running_configuration() {
  scenario "reload of a broken file keeps the running configuration"
  cp "$WORK/a.yaml" "$WORK/a.good"
  printf 'segments: [\n' >"$WORK/a.yaml"
  ctl a reload >"$WORK/reload.out" 2>&1
  local code=$?
  [ "$code" -eq 2 ] || fail "reload of a broken file exited $code, expected 2"
  grep -q "a.yaml:" "$WORK/reload.out" || fail "reload did not name FILE:LINE:COL: $(cat "$WORK/reload.out")"
  kill -HUP "$PID_a"
  wait_until 5 "SIGHUP refusal logged" stderr_has "$WORK/a.log" "reload refused" || return
  ctl a status >/dev/null || fail "gateway died on a broken reload"
  [ "$(channel_count a)" -eq 4 ] || fail "channels changed by a broken reload"
  write_gateway_a "  - {name: added, subject: 0x1a0, class: nrt, publishers: [lan], subscribers: [lcm-a]}"
  ctl a reload >/dev/null || fail "reload of a good file failed"
  [ "$(channel_count a)" -eq 5 ] || fail "reload did not add the channel"
  passed
}

test_hrt_bind_over_lcm_is_rejected() {
  scenario "an HRT bind over LCM is rejected with its reason and changes nothing"
  cat >"$WORK/hrt.yaml" <<YAML
- {name: brake, subject: 0x1b0, class: hrt, period: 10ms, reaction_time: 5ms, payload: 8B, publishers: [lan], subscribers: [lcm-a]}
YAML
  local before
  before=$(channel_count a)
  ctl a bind "$WORK/hrt.yaml" >"$WORK/hrt.out" 2>&1
  local code=$?
  [ "$code" -eq 1 ] || fail "HRT bind over LCM exited $code, expected 1"
  grep -q "real-time guarantee" "$WORK/hrt.out" || fail "no real-time reason: $(cat "$WORK/hrt.out")"
  grep -q "does not retransmit" "$WORK/hrt.out" || fail "no omission reason: $(cat "$WORK/hrt.out")"
  [ "$(channel_count a)" -eq "$before" ] || fail "a rejected bind changed the channels"
  passed
}

# A remote DDS writer whose QoS cosmicd must refuse (best effort on a reliable segment) is a
# visible per-channel mismatch: counted in the control answer, named by cosmicctl.
test_incompatible_peer_is_a_visible_mismatch() {
  scenario "a DDS writer refused for its QoS shows in cosmicctl channels and channel"
  cat >"$WORK/wheel.yaml" <<YAML
channels:
  - {name: wheel, subject: 0x1c0, class: nrt, payload: 8B, omission_degree: 3, publishers: [lan], subscribers: [lcm-a]}
YAML
  ctl a bind "$WORK/wheel.yaml" >/dev/null || { fail "bind of wheel failed"; return; }
  expect_field a wheel lan incompatible 0
  "$DDS_PEER" pub --domain 21 --channel wheel --count 1 --size 8 --best-effort --match-timeout 60 \
    >/dev/null 2>"$WORK/wheel.pub.err" &
  local pub=$!
  PIDS+=("$pub")
  wait_until 30 "gw-a counts the best-effort writer of wheel as incompatible" field_at_least a wheel lan incompatible 1 || return
  expect_field a wheel lan matched 0
  ctl a channels >"$WORK/wheel.channels" || fail "cosmicctl channels failed"
  grep -Eq '! QoS mismatch: [0-9]+ remote writers? on lan refused for incompatible QoS' "$WORK/wheel.channels" ||
    fail "cosmicctl channels shows no QoS mismatch: $(cat "$WORK/wheel.channels")"
  ctl a channel wheel >"$WORK/wheel.channel" || fail "cosmicctl channel failed"
  grep -Eq '! QoS mismatch: [0-9]+ remote writers? on lan refused for incompatible QoS' "$WORK/wheel.channel" ||
    fail "cosmicctl channel wheel shows no QoS mismatch: $(cat "$WORK/wheel.channel")"
  ctl a --json channel wheel | python3 -c '
import json, sys
c = json.load(sys.stdin)["channel"]
lan = next(s for s in c["segments"] if s["segment"] == "lan")
lcm = next(s for s in c["segments"] if s["segment"] == "lcm-a")
assert lan["incompatible"] >= 1, lan
assert lcm["incompatible"] is None, lcm
assert len(c["mismatches"]) == 1 and "on lan refused for incompatible QoS" in c["mismatches"][0], c["mismatches"]
' || fail "cosmicctl --json channel wheel: no incompatible count or mismatch"
  # A channel nobody refused shows none.
  ctl a --json channel steady | python3 -c '
import json, sys
c = json.load(sys.stdin)["channel"]
assert c["mismatches"] == [], c["mismatches"]
assert all(s["incompatible"] in (0, None) for s in c["segments"]), c["segments"]
' || fail "a channel without refused peers shows a mismatch"
  kill "$pub" 2>/dev/null
  wait "$pub" 2>/dev/null
  ctl a unbind wheel >/dev/null || fail "unbind of wheel failed"
  passed
}

write_gateway_a ""
write_gateway_b
start_daemon a "$WORK/a.yaml" || exit 1
start_daemon b "$WORK/b.yaml" || exit 1

scenarios=("$@")
[ ${#scenarios[@]} -gt 0 ] || scenarios=(raw_lcm_across_dds cross_connected_gateways three_gateways_in_a_ring expired_events_are_dropped
  rate_limit_holds bind_unbind_while_traffic_flows own_datagrams_are_counted hrt_bind_over_lcm_is_rejected
  incompatible_peer_is_a_visible_mismatch reload_of_broken_file_keeps_running_configuration)
for s in "${scenarios[@]}"; do
  "test_$s"
done
if [ "$FAILED" != 0 ]; then
  log "--- cosmicd logs"
  tail -n 30 "$WORK"/*.log >&2
  exit 1
fi
log "all scenarios passed"
