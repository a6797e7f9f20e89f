#!/usr/bin/env bash
# Two gateways on one CAN bus (issue 21): cosmicd gw1 and gw2 both attach vcan0 as the network
# `body` and federate over a DDS segment, inside scripts/can-vm (ctest: can.federation).
#   - gw2's admission counts gw1's frames on the bus: an HRT channel that fits gw2 alone is
#     rejected once gw1's channel is bound, and the reason names gw1's frame;
#   - a bind on gw2 whose frame would push gw1's HRT frame past what gw1's channel allows is
#     rejected, naming gw1's channel; a smaller one that keeps it within is bound;
#   - gw2 never hands out an etag gw1's frames carry;
#   - once gw1 stops (cleanly), the same bind is bound.
#   scripts/can-vm -- bash tests/integration/can/federation_can_test.sh COSMICD COSMICCTL
set -uo pipefail
COSMICD=$1 COSMICCTL=$2
. "$(dirname "${BASH_SOURCE[0]}")/vm_test_lib.sh"
vm_test_begin fedcan vcan0
ctl() { local name=$1; shift; "$COSMICCTL" --socket "$WORK/$name.sock" "$@"; }

# 500 kbit/s: an 8-byte extended frame takes at most 320 us, a 1-byte one 180 us. gw1 sends `steer`
# every 1 ms, released 0.2 ms after it arrived (0.1 ms backbone + 0.1 ms residence): R = 0.52 ms,
# end to end 0.52 ms of the 0.8 ms its reaction_time allows, so R may grow to 0.8 ms.
steer='  - {name: steer, subject: 0x500, class: hrt, period: 1ms, reaction_time: 800us, omission_degree: 1, payload: 8B,
     publishers: [backbone], subscribers: [body]}'
for i in 1 2; do
  cat >"$WORK/gw$i.yaml" <<YAML
gateway:
  name: gw$i
  can_node_id: $i
  residence_bound: 100us
  federation: {segment: backbone, lease: 1s}
segments:
  - {name: backbone, type: dds, domain: 44, latency_bound: 100us, realtime: true}
  - {name: body, type: can, interface: vcan0, bitrate: 500kbit/s, network: body}
channels:$([ "$i" = 1 ] && printf '\n%s' "$steer" || printf ' []')
YAML
done
# On gw2 alone: 0.1 + 0.1 + 0.32 = 0.52 ms <= 0.6 ms. With gw1's frame winning arbitration (TxNode
# 1 < 2 in the same priority): R = 0.64 ms, over 0.6 ms.
cat >"$WORK/brake.yaml" <<'YAML'
- {name: brake, subject: 0x501, class: hrt, period: 10ms, reaction_time: 600us, omission_degree: 1, payload: 8B,
   publishers: [backbone], subscribers: [body]}
YAML

for i in 1 2; do
  "$COSMICD" --config "$WORK/gw$i.yaml" --socket "$WORK/gw$i.sock" --state-file "$WORK/gw$i.state" 2>"$WORK/gw$i.log" &
  PIDS+=($!)
  eval "PID_gw$i=$!"
  wait_until 60 "gw$i answering" ctl "gw$i" status || { cat "$WORK/gw$i.log" >&2; exit 1; }
done

peer_alive() {
  ctl gw2 --json peers | "$python" -c '
import json, sys
sys.exit(0 if any(p["name"] == "gw1" and p["state"] == "alive" and p["channels"] == 1 for p in json.load(sys.stdin)["peers"]) else 1)'
}
wait_until 60 "gw2 hears gw1 and its channel" peer_alive || { tail -5 "$WORK"/gw*.log >&2; exit 1; }

log "--- gw2's admission counts gw1's frames on the shared bus"
peers_share=$(ctl gw2 --json segments | "$python" -c '
import json, sys
print(next(s["peers"] for s in json.load(sys.stdin)["segments"] if s["name"] == "body"))')
"$python" -c 'import sys; sys.exit(0 if abs(float(sys.argv[1]) - 0.32) < 0.01 else 1)' "$peers_share" ||
  fail "gw2 counts ${peers_share} of the bus for gw1, want 0.32"
ctl gw2 bind "$WORK/brake.yaml" >"$WORK/bind1.txt" 2>&1 && fail "brake was bound despite gw1's frame: $(cat "$WORK/bind1.txt")"
grep -q 'gw1:steer' "$WORK/bind1.txt" || fail "the rejection does not name gw1's frame: $(cat "$WORK/bind1.txt")"

log "--- a bind that would push gw1's HRT frame past its deadline is rejected, naming it"
# An 8-byte NRT frame loses to steer but may hold the bus when steer is queued: R = 0.84 ms > 0.8 ms.
cat >"$WORK/logbook.yaml" <<'YAML'
- {name: logbook, subject: 0x503, class: nrt, period: 10ms, omission_degree: 1, payload: 8B, publishers: [backbone], subscribers: [body]}
YAML
ctl gw2 bind "$WORK/logbook.yaml" >"$WORK/bind-logbook.txt" 2>&1 && fail "logbook was bound: $(cat "$WORK/bind-logbook.txt")"
grep -q 'would break the hrt frame gw1:steer of gateway gw1' "$WORK/bind-logbook.txt" ||
  fail "the rejection does not name gw1's steer: $(cat "$WORK/bind-logbook.txt")"

log "--- gw2 never hands out an etag gw1's frames carry (a 1-byte frame keeps steer within: R = 0.70 ms)"
steer_etag=$(ctl gw1 --json channels | "$python" -c '
import json, sys
c = next(c for c in json.load(sys.stdin)["channels"] if c["name"] == "steer")
print(c["etag"])')
cat >"$WORK/slow.yaml" <<'YAML'
- {name: slow, subject: 0x502, class: nrt, period: 100ms, omission_degree: 1, payload: 1B, publishers: [backbone], subscribers: [body]}
YAML
ctl gw2 bind "$WORK/slow.yaml" >/dev/null 2>&1 || fail "bind of slow on gw2"
slow_etag=$(ctl gw2 --json channels | "$python" -c '
import json, sys
c = next(c for c in json.load(sys.stdin)["channels"] if c["name"] == "slow")
print(c["etag"])')
[ -n "$steer_etag" ] && [ "$steer_etag" != "$slow_etag" ] || fail "gw2 handed out etag $slow_etag, which gw1's steer carries ($steer_etag)"
ctl gw2 unbind slow >/dev/null || fail "unbind slow"

log "--- once gw1 leaves, the same bind is bound"
kill -TERM "$PID_gw1"
wait "$PID_gw1"
gw1_left() { ctl gw2 --json peers | "$python" -c '
import json, sys
sys.exit(0 if any(p["name"] == "gw1" and p["state"] == "left" for p in json.load(sys.stdin)["peers"]) else 1)'; }
wait_until 10 "gw2 sees gw1 left" gw1_left
ctl gw2 bind "$WORK/brake.yaml" >"$WORK/bind2.txt" 2>&1 || fail "brake after gw1 left: $(cat "$WORK/bind2.txt")"

if [ "$FAILED" != 0 ]; then
  tail -n 20 "$WORK"/gw*.log >&2
  exit 1
fi
log "all federation CAN scenarios passed"
