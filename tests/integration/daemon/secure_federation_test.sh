#!/usr/bin/env bash
# Authenticated federation (issue 36, item 2) and refused participants on a secure DDS segment, end
# to end over real Fast DDS, with a test PKI the openssl command line makes here
# (tests/support/make_test_pki.sh). Three gateways share a secure backbone (1 Mbit/s, 50% for
# reservations), each with an LCM edge of its own (loads chosen so that the checks hold even if a
# secure hop's samples grow by half):
#   - gw-a and gw-b list each other in gateway.federation.peers: they federate, and `cosmicctl
#     peers` shows each one's authenticated subject (text and --json);
#   - gw-c authenticates too (its permissions let it publish cosmic/federation) but neither lists
#     it: its reservations (30% of the backbone, then more after a bind) change no admission on gw-a,
#     `peers` does not list it, every announcement of it is counted as refused, and the refusal is
#     logged once, with the subject its GUID proves;
#   - gw-c lists no peers: every authenticated gateway counts there, with the subject it proves;
#   - a plain Fast DDS participant (no security) on the backbone is counted once as unauthenticated
#     (`segments --json`: adapter.unauthenticated, adapter.last_unauthenticated; text "secure;
#     refused 1 unauthenticated participants").
#   secure_federation_test.sh COSMICD COSMICCTL COSMIC_DDS_PEER SOURCE_DIR
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 DDS_PEER=$3 SOURCE_DIR=$4
WORK=$(mktemp -d /tmp/cosmic-secure-federation.XXXXXX)
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
trap 'cleanup; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT

"$SOURCE_DIR/tests/support/make_test_pki.sh" "$WORK/pki" || { echo "FAIL: cannot make the test PKI" >&2; exit 1; }
DOMAIN=44
# gateway NAME IDENTITY EDGE_PORT PEERS LOAD_PERIOD CHANNEL: a gateway whose channel sends 29 B
# (125 B on the backbone) every LOAD_PERIOD from its edge onto the backbone.
gateway() {
  cat >"$WORK/$1.yaml" <<YAML
gateway:
  name: $1
  federation: {segment: backbone, lease: 1s$4}
segments:
  - name: backbone
    type: dds
    domain: $DOMAIN
    bandwidth: 1Mbit/s
    max_utilization: 50%
    latency_bound: 2ms
    security: {identity_ca: pki/identity_ca.pem, certificate: pki/$2_cert.pem, private_key: pki/$2_key.pem,
               permissions_ca: pki/permissions_ca.pem, governance: pki/governance.p7s, permissions: pki/permissions.p7s}
  - {name: edge, type: lcm, url: "udpm://239.255.76.67:$3?ttl=0", latency_bound: 2ms}
channels:
  - {name: $6, subject: 0x$3, class: srt, period: $5, reaction_time: 50ms, omission_degree: 1, payload: 29B,
     publishers: [edge], subscribers: [backbone]}
YAML
}
# 5% each for gw-a and gw-b; 20% for gw-c.
# gateway-c's permissions let it publish cosmic/telemetry (and cosmic/federation) only.
gateway gw-a gateway-a 7951 ", peers: ['CN=gateway-b,O=cosmic']" 20ms status-a
gateway gw-b gateway-b 7952 ", peers: [/O=cosmic/CN=gateway-a]" 20ms status-b
gateway gw-c gateway-c 7953 "" 5ms telemetry
# A channel gw-c receives from the backbone, later: a new announcement of it.
cat >"$WORK/more.yaml" <<'YAML'
- {name: more, subject: 0x7954, class: srt, period: 40ms, reaction_time: 50ms, omission_degree: 1, payload: 29B,
   publishers: [backbone], subscribers: [edge]}
YAML
# 20% for gw-a: fits beside gw-b's 5% (30%), not were gw-c's 22.5% counted (52.5%).
cat >"$WORK/big.yaml" <<'YAML'
- {name: big, subject: 0x7955, class: srt, period: 5ms, reaction_time: 50ms, omission_degree: 1, payload: 29B,
   publishers: [edge], subscribers: [backbone]}
YAML

counter() { ctl "$1" --json peers | python3 -c 'import json,sys; print(json.load(sys.stdin)["counters"][sys.argv[1]])' "$2"; }
refused_at_least() { [ "$(counter "$1" refused)" -ge "$2" ]; }
# The share of the backbone gateway GW counts for its peers is what gateway PEER announces there alone.
peers_load_is_only() {
  local theirs
  theirs=$(ctl "$1" --json peers | python3 -c '
import json, sys
p = next(p for p in json.load(sys.stdin)["peers"] if p["name"] == sys.argv[1])
print(next(s["load"] for s in p["segments"] if s["name"] == "backbone"))' "$2") || return 1
  near "$(backbone_field "$1" peers)" "$theirs" && python3 -c 'import sys; sys.exit(float(sys.argv[1]) <= 0)' "$theirs"
}

for g in gw-a gw-b gw-c; do start_daemon "$g" "$WORK/$g.yaml" || exit 1; done

scenario "two secure gateways that list each other federate, each shown with its authenticated subject"
wait_until 30 "gw-a sees gw-b alive" state_is gw-a gw-b alive
wait_until 30 "gw-b sees gw-a alive" state_is gw-b gw-a alive
[ "$(peer_field gw-a gw-b subject)" = "/O=cosmic/CN=gateway-b" ] || fail "gw-a shows gw-b's subject as '$(peer_field gw-a gw-b subject)'"
[ "$(peer_field gw-b gw-a subject)" = "/O=cosmic/CN=gateway-a" ] || fail "gw-b shows gw-a's subject as '$(peer_field gw-b gw-a subject)'"
ctl gw-a peers >"$WORK/peers-a.txt" || fail "cosmicctl peers failed"
grep -Eq '^gw-b +[0-9a-f]{16} +alive +/O=cosmic/CN=gateway-b +' "$WORK/peers-a.txt" ||
  fail "cosmicctl peers does not show gw-b's subject: $(cat "$WORK/peers-a.txt")"
wait_until 10 "gw-a counts gw-b's share of the backbone" peers_load_is_only gw-a gw-b
passed

scenario "an authenticated gateway nobody lists changes no admission; its refusals are counted and logged once"
# gw-c hears gw-a and gw-b (it lists nobody: every authenticated gateway counts, with its proven subject).
# 90 s: a fresh-clone scripts/test run (sanitizer trees compiling beside the tests) waited more than
# 30 s for this third participant's handshakes, which Fast DDS retries with a growing interval.
wait_until 90 "gw-c sees gw-a alive" state_is gw-c gw-a alive
[ "$(peer_field gw-c gw-a subject)" = "/O=cosmic/CN=gateway-a" ] || fail "gw-c shows gw-a's subject as '$(peer_field gw-c gw-a subject)'"
wait_until 90 "gw-a refused gw-c's announcement" refused_at_least gw-a 1
wait_until 90 "gw-b refused gw-c's announcement" refused_at_least gw-b 1
counter gw-a last_refusal | grep -q 'authenticated as /O=cosmic/CN=gateway-c, which gateway.federation.peers does not list' ||
  fail "gw-a's last refusal: $(counter gw-a last_refusal)"
[ -z "$(peer_field gw-a gw-c state)" ] || fail "gw-a lists gw-c as a peer"
peers_load_is_only gw-a gw-b || fail "gw-a counts $(backbone_field gw-a peers) of the backbone for its peers (gw-c's counted?)"
# gw-c announces again (a bind): refused again, not logged again.
refused_before=$(counter gw-a refused)
ctl gw-c bind "$WORK/more.yaml" >"$WORK/more.txt" 2>&1 || fail "bind on gw-c: $(cat "$WORK/more.txt")"
wait_until 20 "gw-a refused gw-c's new announcement" refused_at_least gw-a $((refused_before + 1))
# A bind that only fits without gw-c's reservations is bound on gw-a.
ctl gw-a bind "$WORK/big.yaml" >"$WORK/big.txt" 2>&1 || fail "a bind on gw-a was refused for gw-c's reservations: $(cat "$WORK/big.txt")"
peers_load_is_only gw-a gw-b || fail "gw-a counts $(backbone_field gw-a peers) of the backbone for its peers"
[ -z "$(peer_field gw-a gw-c state)" ] || fail "gw-a lists gw-c as a peer after its new announcement"
logged=$(grep -c 'federation: ignoring gateway [0-9a-f]*: participant .* authenticated as /O=cosmic/CN=gateway-c, which gateway.federation.peers does not list' "$WORK/gw-a.log")
[ "$logged" = 1 ] || fail "gw-a logged gw-c's refusal $logged times, want once: $(grep 'ignoring gateway' "$WORK/gw-a.log")"
passed

scenario "a participant without security on the secure backbone is counted once as unauthenticated"
[ "$(ctl gw-a --json segments | python3 -c '
import json, sys
print(next(s["adapter"]["unauthenticated"] for s in json.load(sys.stdin)["segments"] if s["name"] == "backbone"))')" = 0 ] ||
  fail "gw-a counted an unauthenticated participant before there was one"
"$DDS_PEER" sub --domain "$DOMAIN" --channel status-a --count 0 --timeout 4 >/dev/null 2>"$WORK/plain.err" &
plain=$!
unauthenticated_is() {
  ctl "$1" --json segments | python3 -c '
import json, sys
a = next(s["adapter"] for s in json.load(sys.stdin)["segments"] if s["name"] == "backbone")
sys.exit(0 if a["unauthenticated"] == int(sys.argv[1]) and a["last_unauthenticated"].startswith("01.0f.") else 1)' "$2"
}
wait_until 20 "gw-a counts the plain participant" unauthenticated_is gw-a 1
wait "$plain"
unauthenticated_is gw-a 1 || fail "gw-a counted the plain participant more than once: $(ctl gw-a --json segments)"
ctl gw-a segments >"$WORK/segments-a.txt" || fail "cosmicctl segments failed"
grep -Eq '^backbone: secure; refused 1 unauthenticated participants \(last 01\.0f\.' "$WORK/segments-a.txt" ||
  fail "cosmicctl segments does not say what the backbone refused: $(cat "$WORK/segments-a.txt")"
grep -q 'DDS segment backbone: refused participant 01.0f.* it did not authenticate (counted as unauthenticated' "$WORK/gw-a.log" ||
  fail "gw-a did not log the refused participant"
passed

[ "$FAILED" = 0 ] && log "secure_federation_test: all passed"
exit "$FAILED"
