#!/usr/bin/env bash
# SecOC on CAN (issue 36, items 4 and 6) against implementations we did not write, inside
# scripts/can-vm (ctest: can.secoc): an "ECU" whose secured frames the openssl command line
# computes (AES-128-CMAC, `openssl mac ... CMAC`) and can-utils send (cansend) and capture (candump).
#   - cosmicd forwards the ECU's authentic frames (native 0x123 on vcan0) to vcan1 (native 0x456),
#     protected with its own counter, and openssl verifies every MAC cosmicd wrote;
#   - a forged MAC and an altered data byte are dropped as unauthenticated, the same frame sent
#     again as replayed, each counted per segment (`cosmicctl segments`), none forwarded;
#   - a frame in this project's layout (channel brake, from a plain native frame on vcan1) carries
#     the data ID of its TxNode and etag, and openssl verifies it;
#   - across clean restarts: the receiver still refuses the last frame it accepted (replayed), and
#     the sender continues right after the last value it used, which its state file recorded.
#   scripts/can-vm -- bash tests/integration/can/secoc_test.sh COSMICD COSMICCTL
set -uo pipefail
COSMICD=$1 COSMICCTL=$2
. "$(dirname "${BASH_SOURCE[0]}")/vm_test_lib.sh"
vm_test_begin secoc vcan1
ctl() { "$COSMICCTL" --socket "$WORK/gw.sock" "$@"; }

KEY=2b7e151628aed2a6abf7158809cf4f3c  # RFC 4493's example key
(umask 077 && echo "$KEY" >"$WORK/ecu.key")
mkdir -p "$WORK/state"
cat >"$WORK/gw.yaml" <<YAML
gateway: {name: gw, can_node_id: 3}
segments:
  - {name: bus0, type: can, interface: vcan0, bitrate: 500kbit/s}
  - {name: bus1, type: can, interface: vcan1, bitrate: 500kbit/s}
channels:
  - {name: wheel, subject: 0x601, class: srt, period: 1ms, reaction_time: 20ms, payload: 4B,
     publishers: [bus0], subscribers: [bus1],
     native: {bus0: {can_id: 0x123}, bus1: {can_id: 0x456}},
     secoc: {bus0: {key_file: ecu.key}, bus1: {key_file: ecu.key, data_id: 0x77}}}
  - {name: brake, subject: 0x602, class: srt, period: 1ms, reaction_time: 20ms, payload: 4B,
     publishers: [bus1], subscribers: [bus0], native: {bus1: {can_id: 0x124}},
     secoc: {bus0: {key_file: ecu.key}}}
YAML

# secured DATA_ID DATA_HEX FRESHNESS: the secured PDU (data || low freshness byte || first 3 MAC
# bytes), the MAC from openssl over data ID (4 bytes) || data || freshness (8 bytes), big-endian.
secured() {
  local input mac
  input=$(printf '%08x%s%016x' "$1" "$2" "$3")
  mac=$(printf '%s' "$input" | xxd -r -p | openssl mac -cipher AES-128-CBC -macopt "hexkey:$KEY" CMAC) || return 1
  printf '%s%02x%s\n' "$2" $(($3 & 0xff)) "$(printf '%s' "${mac:0:6}" | tr 'A-F' 'a-f')"
}
# frames FILE ID: the data of every frame of identifier ID in a candump -L log, in order.
frames() { awk -v id="$2" '{ split($3, f, "#"); if (f[1] == id) print tolower(f[2]) }' "$1"; }
count() { frames "$1" "$2" | wc -l; }
counter() { # counter SEGMENT NAME: the segment's transport counter
  ctl --json segments | "$python" -c '
import json, sys
for s in json.load(sys.stdin)["segments"]:
    if s["name"] == sys.argv[1]: print(s["adapter"].get(sys.argv[2], "absent"))' "$1" "$2"
}
expect_counter() { # expect_counter SEGMENT NAME VALUE
  local got
  got=$(counter "$1" "$2")
  [ "$got" = "$3" ] || fail "$1 $2: $got, expected $3"
}
start_gateway() {
  "$COSMICD" --config "$WORK/gw.yaml" --socket "$WORK/gw.sock" --state-file "$WORK/state/bindings.json" \
    2>>"$WORK/gw.log" &
  GW=$!
  PIDS+=("$GW")
  wait_until 60 "cosmicd answering" ctl status || { cat "$WORK/gw.log" >&2; exit 1; }
}
stop_gateway() {
  kill -TERM "$GW"
  wait "$GW"
}
# The ECU sends frame FRESHNESS of wheel; the gateway's copy on vcan1 is awaited as the Nth.
ecu_send() { cansend vcan0 "123#$(secured 0x123 "$2" "$1")"; }
forwarded() { [ "$(count "$WORK/bus1.log" 456)" -ge "$1" ]; }

candump -L vcan1 >"$WORK/bus1.log" &
PIDS+=($!)
candump -L vcan0 >"$WORK/bus0.log" &
PIDS+=($!)
start_gateway

log "--- authentic frames cross, and cosmicd's own MACs verify with openssl"
for fv in 1 2 3; do
  ecu_send "$fv" "0a0b0c0$fv"
  wait_until 30 "frame $fv forwarded to vcan1" forwarded "$fv"
done
fv_out=0
while read -r pdu; do
  fv_out=$((fv_out + 1))
  want=$(secured 0x77 "${pdu:0:8}" "$fv_out")
  [ "$pdu" = "$want" ] || fail "cosmicd's frame $fv_out on vcan1 is $pdu, openssl computes $want"
  [ "${pdu:0:8}" = "0a0b0c0$fv_out" ] || fail "frame $fv_out carries ${pdu:0:8}"
done <<<"$(frames "$WORK/bus1.log" 456)"
[ "$fv_out" = 3 ] || fail "$fv_out frames on vcan1, expected 3"

log "--- forged and altered frames are unauthenticated, a frame sent again is replayed"
cansend vcan0 "123#0a0b0c0d04000000"  # freshness 4, no valid MAC
altered=$(secured 0x123 0a0b0c04 4)
cansend vcan0 "123#ff${altered:2}"  # authentic for 0a0b0c04, its first data byte changed
ecu_send 5 0a0b0c05
wait_until 30 "frame 5 forwarded" forwarded 4
replay=$(secured 0x123 0a0b0c02 2)
cansend vcan0 "123#$replay"
ecu_send 6 0a0b0c06
wait_until 30 "frame 6 forwarded" forwarded 5
[ "$(count "$WORK/bus1.log" 456)" = 5 ] || fail "$(count "$WORK/bus1.log" 456) frames forwarded, expected 5"
[ "$(frames "$WORK/bus1.log" 456 | cut -c1-8 | tr '\n' ' ')" = "0a0b0c01 0a0b0c02 0a0b0c03 0a0b0c05 0a0b0c06 " ] ||
  fail "forwarded: $(frames "$WORK/bus1.log" 456 | tr '\n' ' ')"
expect_counter bus0 unauthenticated 2
expect_counter bus0 replayed 1
ctl segments | grep -q "bus0: authenticated; dropped 2 unauthenticated, 1 replayed" ||
  fail "cosmicctl segments does not show bus0's refusals: $(ctl segments)"
ctl --json channels | "$python" -c '
import json, sys
channel = next(c for c in json.load(sys.stdin)["channels"] if c["name"] == "wheel")
d = next(h for h in channel["segments"] if h["segment"] == "bus0")["dropped"]
sys.exit(0 if d.get("unauthenticated") == 2 and d.get("replayed") == 1 else 1)' ||
  fail "channel wheel's drops on bus0: $(ctl --json channels)"

log "--- a frame in this project's layout carries its TxNode and etag as data ID"
cansend vcan1 "124#11223344"
layout_frame() { awk '{ split($3, f, "#"); if (length(f[1]) == 8) { print; exit } }' "$WORK/bus0.log" | grep -q .; }
wait_until 30 "brake on vcan0" layout_frame
read -r id pdu <<<"$(awk '{ split($3, f, "#"); if (length(f[1]) == 8) { print f[1], tolower(f[2]); exit } }' "$WORK/bus0.log")"
data_id=$((0x$id & 0x1FFFFF))
[ $(((0x$id >> 14) & 0x7F)) = 3 ] || fail "brake went out with TxNode $(((0x$id >> 14) & 0x7F)), expected 3"
want=$(secured "$data_id" 11223344 1)
[ "$pdu" = "$want" ] || fail "brake's frame $id#$pdu, openssl computes $want (data ID $data_id)"

log "--- across a restart: the receiver remembers, the sender continues past its lease"
stop_gateway
state="$WORK/state/secoc-bus1.json"
[ -f "$state" ] || fail "no SecOC state file $state"
lease=$("$python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["senders"]["wheel/119"])' "$state")
last=$("$python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["receivers"]["wheel/291"])' \
  "$WORK/state/secoc-bus0.json")
[ "$last" = 6 ] || fail "bus0's receiver persisted $last, expected 6"
[ "$lease" = 5 ] || fail "bus1's sender persisted $lease at a clean stop, expected 5 (the last value used)"
start_gateway
cansend vcan0 "123#$(secured 0x123 0a0b0c06 6)"
ecu_send 7 0a0b0c07
wait_until 30 "frame 7 forwarded after the restart" forwarded 6
expect_counter bus0 replayed 1
expect_counter bus0 unauthenticated 0
pdu=$(frames "$WORK/bus1.log" 456 | tail -1)
want=$(secured 0x77 0a0b0c07 $((lease + 1)))
[ "$pdu" = "$want" ] || fail "after the restart cosmicd sent $pdu, expected freshness $((lease + 1)): $want"
# Once more: a clean restart skips nothing, however often.
stop_gateway
start_gateway
ecu_send 8 0a0b0c08
wait_until 30 "frame 8 forwarded after the second restart" forwarded 7
pdu=$(frames "$WORK/bus1.log" 456 | tail -1)
want=$(secured 0x77 0a0b0c08 $((lease + 2)))
[ "$pdu" = "$want" ] || fail "after the second restart cosmicd sent $pdu, expected freshness $((lease + 2)): $want"

if [ "$FAILED" -ne 0 ]; then
  tail -20 "$WORK/gw.log" >&2
  exit 1
fi
log "secoc: all checks passed"
