#!/usr/bin/env bash
# DDS Security against an implementation we did not write (issue 36, item 6): Eclipse Cyclone DDS
# 0.10 participants with its own security plugins against cosmicd (Fast DDS 2.9's builtin plugins),
# inside a fresh network namespace (run through scripts/netns-run):
#   cyclone_security_test.sh COSMICD COSMICCTL COSMIC_CYCLONE_PEER SOURCE_DIR
# One gateway between a secure DDS domain (identity gateway-b) and a plain one, the test PKI made
# here by tests/support/make_test_pki.sh. Scenarios:
#   1. a Cyclone participant authenticated as gateway-a exchanges a channel with cosmicd both ways:
#      its samples reach the plain domain through cosmicd, the plain domain's reach it, exactly;
#   2. a Cyclone participant without security publishing the same topic on the secure domain reaches
#      nothing: cosmicd takes none of its samples while it takes the authenticated peer's, and counts
#      it as unauthenticated (cosmicctl segments --json: the segment's adapter.unauthenticated);
#   3. monitor, authenticated but granted no topic to publish, cannot publish: Cyclone's own access
#      control refuses its writer (DDS_RETCODE_NOT_ALLOWED_BY_SECURITY), and it still receives.
# Fast DDS 2.9 and Cyclone 0.10 complete a PKI-DH handshake only when Cyclone starts it, that is when
# the Cyclone participant's GUID is the lower (docs/security.md, "Interoperability"); under PKI-DH
# the GUID prefix follows from the certificate's subject, so the identities are chosen for it and
# the test checks that first.
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 CYCLONE_PEER=$3 SOURCE_DIR=$4
WORK=$(mktemp -d /tmp/cosmic-cyclone-security.XXXXXX)
# shellcheck source=../../daemon/lib.sh
source "$(dirname "$0")/../../daemon/lib.sh"
trap 'cleanup; rm -rf "$WORK"' EXIT
# A peer that died leaves its start gate without a reader: writing to it then fails, not kills.
trap "" PIPE

# The namespace's only interface is a multicast-capable loopback; Cyclone DDS does not use
# multicast on loopback unless told so (Fast DDS does).
export CYCLONEDDS_URI='<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces></General></Domain></CycloneDDS>'

SECURE=71 PLAIN=72
PKI=$WORK/pki
"$SOURCE_DIR/tests/support/make_test_pki.sh" "$PKI" || exit 1

cat >"$WORK/gw.yaml" <<YAML
gateway: {name: gw-secure}
segments:
  - name: secure
    type: dds
    domain: $SECURE
    security: {identity_ca: pki/identity_ca.pem, certificate: pki/gateway-b_cert.pem,
               private_key: pki/gateway-b_key.pem, permissions_ca: pki/permissions_ca.pem,
               governance: pki/governance.p7s, permissions: pki/permissions.p7s}
  - {name: plain, type: dds, domain: $PLAIN}
# Both segments' readers are reliable (the default) and every writer keeps 31 samples: with reliable
# Cyclone peers, nothing is lost on the wire and every count below is exact.
channels:
  - {name: obstacle, subject: 0x301, class: nrt, payload: 16B, omission_degree: 30, publishers: [secure], subscribers: [plain]}
  - {name: drive, subject: 0x302, class: nrt, payload: 8B, omission_degree: 30, publishers: [plain], subscribers: [secure]}
  - {name: status, subject: 0x303, class: nrt, payload: 8B, omission_degree: 30, publishers: [plain], subscribers: [secure]}
YAML

# guid_prefix CERT: the first 6 bytes of the GUID prefix PKI-DH gives the holder of CERT (DDS
# Security 1.1, 9.3.3): bit 0 set, then the first 47 bits of SHA-256 over the DER encoding of the
# certificate's subject, as "b3.18.4a.80.e9.71". Fast DDS 2.9 and Cyclone 0.10 both derive it so
# (checked below against the prefixes they use).
guid_prefix() {
  python3 - "$1" <<'PY'
import hashlib, ssl, sys
der = ssl.PEM_cert_to_DER_cert(open(sys.argv[1]).read())
def element(at):  # (start of the value, end) of the DER element at `at`
    length, at = der[at + 1], at + 2
    if length & 0x80:
        count = length & 0x7F
        length, at = int.from_bytes(der[at:at + count], "big"), at + count
    return at, at + length
at = element(0)[0]  # Certificate: tbsCertificate comes first
at = element(at)[0]  # tbsCertificate's fields
if der[at] == 0xA0:  # [0] version
    at = element(at)[1]
for _ in ("serialNumber", "signature", "issuer", "validity"):
    at = element(at)[1]
subject = der[at:element(at)[1]]
bits = (1 << 47) | (int.from_bytes(hashlib.sha256(subject).digest()[:6], "big") >> 1)
print(".".join(f"{b:02x}" for b in bits.to_bytes(6, "big")))
PY
}

# check_exact FILE COUNT SIZE: the envelopes a reliable Cyclone reader got are exactly events
# 1..COUNT of the peers' pattern (byte i of event q is (q * 7 + i) mod 256), in order, each stamped
# by the gateway (origin non-zero).
check_exact() {
  python3 - "$@" <<'PY'
import json, sys
path, count, size = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
got = [json.loads(line) for line in open(path)]
want = [bytes(((q * 7 + i) & 0xFF) for i in range(size)).hex() for q in range(1, count + 1)]
assert [e["payload"] for e in got] == want, f"got {[e['payload'] for e in got]}, expected {want}"
assert all(e["origin"] != 0 for e in got), "an envelope not stamped by the gateway"
PY
}

# start_peer NAME pub|sub ARGS...: a Cyclone peer, stderr in NAME.err (a reader's envelopes in
# NAME.out), process PEER_PID. A writer is held at its start gate, a fifo this shell keeps open as
# file descriptor PEER_GATE, until `go PEER_GATE`.
start_peer() {
  local name=$1 mode=$2
  shift 2
  if [ "$mode" = pub ]; then
    rm -f "$WORK/$name.go" && mkfifo "$WORK/$name.go"
    "$CYCLONE_PEER" pub "$@" <"$WORK/$name.go" 2>"$WORK/$name.err" &
    PEER_PID=$!
    exec {PEER_GATE}>"$WORK/$name.go"
  else
    "$CYCLONE_PEER" sub "$@" >"$WORK/$name.out" 2>"$WORK/$name.err" &
    PEER_PID=$!
  fi
  PIDS+=("$PEER_PID")
}
go() {
  local gate=$1
  echo go >&"$gate"
  exec {gate}>&-
}

# start_secure_peer NAME pub|sub ARGS...: start_peer for a participant with security, restarted
# (at most twice) when its handshake with cosmicd stalls: in about one handshake in 25 on this
# machine, Cyclone 0.10 completes it and sends its crypto tokens while Fast DDS 2.9 never sends its
# own, and the pair stays unmatched until the Cyclone participant is replaced (docs/security.md,
# "Interoperability"). A handshake that works takes well under a second; STALLS counts the restarts.
STALLS=0
start_secure_peer() {
  local name=$1 attempt deadline
  for attempt in 1 2 3; do
    start_peer "$@"
    deadline=$((SECONDS + 10))
    until grep -q MATCHED "$WORK/$name.err" 2>/dev/null || [ "$SECONDS" -ge "$deadline" ]; do sleep 0.05; done
    grep -q MATCHED "$WORK/$name.err" && return 0
    STALLS=$((STALLS + 1))
    log "note: $name: no match with cosmicd 10 s after start (attempt $attempt): a stalled handshake, restarting the peer"
    [ "$2" = pub ] && exec {PEER_GATE}>&-
    kill "$PEER_PID" 2>/dev/null
    wait "$PEER_PID" 2>/dev/null
  done
  fail "$name never matched cosmicd (3 participants, 10 s each): $(cat "$WORK/$name.err")"
}

# plain_to_secure CHANNEL IDENTITY PREFIX COUNT: a plain Cyclone writer (domain PLAIN) -> cosmicd ->
# a Cyclone reader authenticated as IDENTITY (domain SECURE, GUID prefix PREFIX): the reader gets
# exactly the COUNT events, which cosmicd took and forwarded once each. CHANNEL has no other reader
# on the secure segment, so cosmicd's match count says when this one matched.
plain_to_secure() {
  local channel=$1 identity=$2 prefix=$3 count=$4 reader writer gate
  start_secure_peer "$identity-reader" sub "${SECURE_ARGS[@]}" --identity "$identity" --topic "cosmic/$channel" \
    --count "$count" --reliability reliable --timeout 30
  reader=$PEER_PID
  grep -q "^GUID $prefix" "$WORK/$identity-reader.err" ||
    fail "$identity's GUID is not the one derived from its subject ($prefix): $(grep GUID "$WORK/$identity-reader.err")"
  wait_until 20 "cosmicd's writer matched $identity's reader" field_at_least gw "$channel" secure matched 1
  start_peer "$channel-writer" pub --domain "$PLAIN" --topic "cosmic/$channel" --count "$count" --size 8 --timeout 30
  writer=$PEER_PID gate=$PEER_GATE
  wait_until 20 "the plain writer matched cosmicd's reader" stderr_has "$WORK/$channel-writer.err" MATCHED
  wait_until 20 "cosmicd's reader matched the plain writer" field_at_least gw "$channel" plain matched 1
  go "$gate"
  wait "$writer" || fail "the plain writer failed: $(cat "$WORK/$channel-writer.err")"
  wait "$reader" || fail "$identity's reader failed: $(cat "$WORK/$identity-reader.err")"
  check_exact "$WORK/$identity-reader.out" "$count" 8 || fail "$identity's reader did not get exactly the plain writer's $count events"
  expect_field gw "$channel" plain rx "$count"
  expect_field gw "$channel" secure tx "$count"
}

COSMICD_PREFIX=$(guid_prefix "$PKI/gateway-b_cert.pem")
PEER_PREFIX=$(guid_prefix "$PKI/gateway-a_cert.pem")
MONITOR_PREFIX=$(guid_prefix "$PKI/monitor_cert.pem")
scenario "the identities make every Cyclone participant the handshake's initiator (the lower GUID)"
[[ "$PEER_PREFIX" < "$COSMICD_PREFIX" ]] || fail "gateway-a's GUID $PEER_PREFIX is not below cosmicd's $COSMICD_PREFIX"
[[ "$MONITOR_PREFIX" < "$COSMICD_PREFIX" ]] || fail "monitor's GUID $MONITOR_PREFIX is not below cosmicd's $COSMICD_PREFIX"
passed

start_daemon gw "$WORK/gw.yaml" || exit 1
[ "$(channel_count gw)" -eq 3 ] || fail "expected 3 bound channels, got $(channel_count gw)"
SECURE_ARGS=(--domain "$SECURE" --pki "$PKI")

# --- 1. secure -> plain, with an outsider on the secure domain all along (2.)
scenario "authenticated Cyclone writer (gateway-a) -> cosmicd's secure segment -> plain domain, exactly"
start_peer plain-reader sub --domain "$PLAIN" --topic cosmic/obstacle --count 20 --reliability reliable --timeout 30
plain_reader=$PEER_PID
wait_until 20 "cosmicd's writer on the plain domain matched the reader" field_at_least gw obstacle plain matched 1
wait_until 20 "the plain reader matched cosmicd's writer" stderr_has "$WORK/plain-reader.err" MATCHED
# Matching an encrypted endpoint needs the handshake done and the crypto tokens exchanged.
start_secure_peer secure-writer pub "${SECURE_ARGS[@]}" --identity gateway-a --topic cosmic/obstacle --count 20 --size 16 --timeout 30
secure_writer=$PEER_PID secure_writer_gate=$PEER_GATE
wait_until 20 "cosmicd's reader matched gateway-a's writer" field_at_least gw obstacle secure matched 1
grep -q "^GUID $PEER_PREFIX" "$WORK/secure-writer.err" ||
  fail "Cyclone's GUID is not the one derived from gateway-a's subject ($PEER_PREFIX): $(grep GUID "$WORK/secure-writer.err")"
grep -q "^PEER $COSMICD_PREFIX" "$WORK/secure-writer.err" ||
  fail "cosmicd's GUID is not the one derived from gateway-b's subject ($COSMICD_PREFIX): $(grep PEER "$WORK/secure-writer.err")"
# The outsider: Cyclone without security, the same topic on the secure domain, 12-byte payloads
# (the authenticated writer's are 16), writing before, during and after the authenticated writer.
# cosmicd counts each participant it refused once (a restarted stalled peer may have been one).
refused_before=$(segment_adapter_field gw secure unauthenticated)
"$CYCLONE_PEER" pub --domain "$SECURE" --topic cosmic/obstacle --count 150 --size 12 --period-ms 20 --await-match no \
  </dev/null 2>"$WORK/outsider.err" &
outsider=$!
PIDS+=("$outsider")
wait_until 10 "the outsider's participant is up" stderr_has "$WORK/outsider.err" "^GUID"
go "$secure_writer_gate"
wait "$secure_writer" || fail "gateway-a's writer failed: $(cat "$WORK/secure-writer.err")"
wait "$plain_reader" || fail "the plain reader failed: $(cat "$WORK/plain-reader.err")"
check_exact "$WORK/plain-reader.out" 20 16 || fail "the plain reader did not get exactly gateway-a's 20 events"
passed

scenario "an outsider without security on the secure domain: none of its samples is taken or forwarded, it is counted"
wait "$outsider" || fail "the outsider failed: $(cat "$WORK/outsider.err")"
# It heard cosmicd's participant (announced in the clear): it was on the same wire all along.
grep -q "^PEER $COSMICD_PREFIX" "$WORK/outsider.err" || fail "the outsider never discovered cosmicd: $(cat "$WORK/outsider.err")"
wait_until 10 "cosmicd's counters settle" settled gw
expect_field gw obstacle secure rx 20
expect_field gw obstacle plain tx 20
wait_until 10 "cosmicd counted the outsider as unauthenticated" segment_field_at_least gw secure unauthenticated $((refused_before + 1))
refused=$(segment_adapter_field gw secure unauthenticated)
[ "$refused" -eq $((refused_before + 1)) ] ||
  fail "cosmicd counted $((refused - refused_before)) unauthenticated participants for the one outsider"
passed

# --- 1. plain -> secure
scenario "plain domain -> cosmicd's secure segment -> authenticated Cyclone reader (gateway-a), exactly"
plain_to_secure drive gateway-a "$PEER_PREFIX" 20
passed

# --- 3. authenticated, not granted
# (on a channel of its own: cosmicd may count a reader that left as matched until its lease ends,
# since Fast DDS 2.9 cannot read Cyclone's notice of leaving; docs/operations.md)
scenario "monitor (authenticated, granted subscribe only) receives, but Cyclone refuses it a writer"
plain_to_secure status monitor "$MONITOR_PREFIX" 5
# Its writer: Cyclone's access control checks the local permissions when a writer is created
# (DDS_RETCODE_NOT_ALLOWED_BY_SECURITY), so nothing of it is announced or sent, and cosmicd takes nothing.
"$CYCLONE_PEER" pub "${SECURE_ARGS[@]}" --identity monitor --topic cosmic/obstacle --count 5 --size 16 --timeout 10 \
  </dev/null 2>"$WORK/monitor-writer.err"
rc=$?
[ "$rc" -eq 3 ] || fail "monitor's publisher exited $rc, expected 3 (writer refused): $(cat "$WORK/monitor-writer.err")"
grep -q "cannot create a writer on cosmic/obstacle: Not Allowed By Security" "$WORK/monitor-writer.err" ||
  fail "monitor's writer was not refused by security: $(cat "$WORK/monitor-writer.err")"
expect_field gw obstacle secure rx 20
passed

[ "$STALLS" -eq 0 ] || log "note: $STALLS stalled handshake(s) restarted"
[ "$FAILED" = 0 ] || { log "--- cosmicd log"; grep -v "key-only\|no Key\|getting the key" "$WORK/gw.log" | tail -40 >&2; exit 1; }
log "all Cyclone DDS Security scenarios passed"
