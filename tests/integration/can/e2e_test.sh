#!/usr/bin/env bash
# End-to-end tests of the CAN segment through the real daemon: can-utils on vcan0 <-> cosmicd <->
# cosmic-lcm-peer (LCM) and cosmic-dds-peer (Fast DDS), all on this machine.
#
# Usage (as root where vcan0 exists and is up, i.e. inside scripts/can-vm; ctest: can.e2e):
#   scripts/can-vm -- bash tests/integration/can/e2e_test.sh COSMICD COSMICCTL DDS_PEER LCM_PEER
#
# One cosmicd (configuration e2e/gateway.yaml) serves every scenario, in this order; each prints
# PASS or FAIL with its duration; the exit status is the number of failed scenarios (0: all passed).
#   etags           cosmicctl channels shows the static and dynamic etags; identifiers as documented
#   get_etag        hand-made GET_ETAG requests (cansend) are answered with the documented frames;
#                   an unknown subject gets no answer; a malformed request is counted
#   can_to_ip       cansend in the COSMIC layout -> cosmicd -> an LCM and a DDS subscriber
#   ip_to_can       an LCM and a DDS event -> cosmicd -> candump: 29-bit identifier and payload
#   fragments_up    a 1 KiB and a 13-byte NRT event as classic fragments (canplayer) -> LCM, DDS
#   fragments_down  a 1 KiB LCM and a 1 KiB DDS event -> 171 fragments each on the bus (candump)
#   garbage         cangen (random, 11-bit, mixed, aimed at bound etags, remote frames) and
#                   hostile fragments: cosmicd survives, every frame is accounted for exactly
#                   (frames of unbound etags never reach it), errors are counted, traffic flows
#   link_down_up    ip link set vcan0 down / up: segment down, channels degraded, sends counted as
#                   failed, then up and bound again and traffic in both directions resumes with
#                   the same cosmicd process
# Every wait has a deadline (DDS discovery: both sides must report the match); no fixed sleeps.
# Keep the work directory for inspection: CAN_E2E_KEEP=1.
# shellcheck disable=SC2317  # scenario_* and helpers are called indirectly (run, wait_until, check)
set -uo pipefail

if [ $# -ne 4 ]; then
  echo "usage: $0 COSMICD COSMICCTL DDS_PEER LCM_PEER   (run inside scripts/can-vm)" >&2
  exit 64
fi
COSMICD=$1 COSMICCTL=$2 DDS_PEER=$3 LCM_PEER=$4
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
E2E=$HERE/e2e
CONFIG=$E2E/gateway.yaml

# --- facts of gateway.yaml (the test's independent knowledge; see the comments there)
IF=vcan0
LCM_URL='udpm://239.255.76.67:7671?ttl=0'
DOMAIN=57
GW_NODE=9                 # gateway.can_node_id
DEV=5                     # TxNode of the device this test plays on the bus
SUBJ_SENSOR=0x00000001000000A1 SUBJ_COMMAND=0x00000001000000B2
SUBJ_BULK_UP=0x00000001000000C3 SUBJ_BULK_DOWN=0x00000001000000C4
ETAG_SENSOR=16383         # dynamic: the first etag handed out (docs/can-wire-format.md section 3)
ETAG_COMMAND=300 ETAG_BULK_UP=201 ETAG_BULK_DOWN=202
PRIO_COMMAND=0x10         # the only SRT channel on the bus: the SRT band's first level (section 2)
PRIO_GET_ETAG=0xFD        # binding protocol priority (sections 2 and 5)
ETAG_GET=2 ETAG_SUPPLY=3

for f in "$COSMICD" "$COSMICCTL" "$DDS_PEER" "$LCM_PEER"; do
  [ -x "$f" ] || { echo "not an executable: $f" >&2; exit 64; }
done
for t in cansend candump cangen canplayer ip python3; do
  command -v "$t" >/dev/null || { echo "missing tool: $t" >&2; exit 64; }
done
if ! ip link show "$IF" >/dev/null 2>&1 || [ "$(id -u)" -ne 0 ]; then
  echo "needs root and $IF: run through scripts/can-vm" >&2
  exit 64
fi

WORK=$(mktemp -d /tmp/cosmic-can-e2e.XXXXXX)
SOCK=$WORK/control.sock
COSMICD_PID=

canlog() { python3 "$E2E/canlog.py" "$@"; }
now_ms() { echo $(($(date +%s%N) / 1000000)); }

# ---------------------------------------------------------------------------------- helpers
ctl() { "$COSMICCTL" --socket "$SOCK" --json "$@"; }
# q CMD EXPR: value of EXPR (e2e/q.py) over `cosmicctl --json CMD`; t CMD EXPR: true/false.
# CMD is split into words on purpose ("channel NAME").
# shellcheck disable=SC2086
q() { local cmd=$1; shift; ctl $cmd | python3 "$E2E/q.py" "$@"; }
# shellcheck disable=SC2086
t() { local cmd=$1; shift; ctl $cmd 2>/dev/null | python3 "$E2E/q.py" -t "$@"; }

# wait_until SECONDS WHAT CMD...: polls CMD until it succeeds, or fails after the deadline.
wait_until() {
  local limit=$1 what=$2
  shift 2
  local end=$(($(now_ms) + limit * 1000))
  until "$@"; do
    if [ "$(now_ms)" -ge "$end" ]; then
      echo "    timeout after ${limit}s waiting for: $what" >&2
      return 1
    fi
    sleep 0.05
  done
}

check() {  # check WHAT CMD...
  local what=$1
  shift
  "$@" && return 0
  echo "    check failed: $what" >&2
  return 1
}

expect_eq() {  # expect_eq WHAT ACTUAL EXPECTED
  [ "$2" = "$3" ] && return 0
  echo "    $1: got '$2', expected '$3'" >&2
  return 1
}

lines() { if [ -f "$1" ]; then wc -l <"$1"; else echo 0; fi; }
has_lines() { [ "$(lines "$1")" -ge "$2" ]; }
file_has() { grep -q -- "$2" "$1" 2>/dev/null; }

# Background processes of the running scenario (killed by their pid when it ends).
BG=()
spawn() {  # spawn NAME CMD...: stdout -> $SDIR/NAME.out, stderr -> $SDIR/NAME.err; pid in LAST
  local name=$1
  shift
  "$@" >"$SDIR/$name.out" 2>"$SDIR/$name.err" &
  LAST=$!
  BG+=("$LAST")
}
stop_bg() {
  local p
  for p in "${BG[@]}"; do kill -TERM "$p" 2>/dev/null; done
  for p in "${BG[@]}"; do wait "$p" 2>/dev/null; done
  BG=()
}

# candump NAME FILTER...: dumps $IF (log format) with these filters into $SDIR/NAME.out and
# returns once it provably receives: a marker frame (11-bit 7FF, never seen by cosmicd, whose
# filters take 29-bit frames only) is sent until it shows up in the dump.
candump_start() {
  local name=$1
  shift
  local filters
  filters=$(IFS=,; echo "$*")
  spawn "$name" candump -L -r 4194304 "$IF,$filters,7FF:C00007FF"
  local out=$SDIR/$name.out end=$(($(now_ms) + 10000))
  until grep -q " 7FF#" "$out" 2>/dev/null; do
    cansend "$IF" 7FF#5A
    [ "$(now_ms)" -lt "$end" ] || { echo "    candump $name never received the marker" >&2; return 1; }
    sleep 0.05
  done
}
# frames_of NAME ID: "ID DATA" lines of identifier ID seen by candump NAME so far.
frames_of() { canlog frames "$SDIR/$1.out" "$2"; }
count_frames() { [ "$(frames_of "$1" "$2" | wc -l)" -ge "$3" ]; }

lcm_sub() {  # lcm_sub NAME CHANNEL COUNT: subscribed (READY) when it returns
  spawn "$1" "$LCM_PEER" sub --url "$LCM_URL" --channel "$2" --count "$3" --timeout 60
  wait_until 15 "LCM subscriber $1 ready" file_has "$SDIR/$1.err" READY
}
# dds_sub NAME CHANNEL: returns when the peer's reader matched cosmicd's writer AND cosmicd's
# writer of CHANNEL on segment lan matched a reader (Fast DDS discovery is one-sided).
dds_sub() {
  spawn "$1" "$DDS_PEER" sub --domain "$DOMAIN" --channel "$2" --count 0 --timeout 90
  wait_until 30 "DDS subscriber $1 matched" file_has "$SDIR/$1.err" '"event":"matched","count":1'
  wait_until 30 "cosmicd's DDS writer of $2 matched" t channels "hop('$2','lan')['matched'] >= 1"
}
# dds_pub NAME CHANNEL SIZE SUBJECT: one envelope (payload byte i = (1 + i) & 0xff), published
# once both sides of the discovery have matched.
dds_pub() {
  local name=$1 channel=$2 size=$3 subject=$4
  mkfifo "$SDIR/$name.go"
  spawn "$name" sh -c 'exec "$0" "$@" <"'"$SDIR/$name.go"'"' "$DDS_PEER" pub --domain "$DOMAIN" \
    --channel "$channel" --count 1 --size "$size" --subject "$subject" --wait-subscribers 1 \
    --match-timeout 60 --start-on-stdin
  local pid=$LAST
  exec 7>"$SDIR/$name.go"
  wait_until 30 "DDS publisher $name matched" file_has "$SDIR/$name.err" waiting_for_start
  wait_until 30 "cosmicd's DDS reader of $channel matched" t channels "hop('$channel','lan')['matched'] >= 1"
  echo go >&7
  exec 7>&-
  LAST=$pid
}

# json_field FILE LINE_NO FIELD: a field of the LINE_NO-th JSON line of FILE (1-based).
json_field() {
  python3 -c 'import json,sys; print(json.loads(open(sys.argv[1]).read().splitlines()[int(sys.argv[2])-1])[sys.argv[3]])' "$@"
}
# has_payload FILE HEX: a JSON line of FILE carries this payload.
has_payload() {
  python3 -c '
import json, sys
for line in open(sys.argv[1]):
    try:
        if json.loads(line).get("payload") == sys.argv[2].lower(): sys.exit(0)
    except ValueError: pass
sys.exit(1)' "$@"
}
# subscriber_saw WHAT FILE HEX SUBJECT: the subscriber got exactly this event from cosmicd (subject,
# hop count 1, cosmicd's origin id).
subscriber_saw() {
  local what=$1 file=$2 hex=$3 subject=$4
  wait_until 20 "$what receives $hex" has_payload "$file" "$hex" || return 1
  python3 - "$file" "$hex" "$subject" "0x$GATEWAY_ID" <<'EOF' || { echo "    $what: wrong envelope" >&2; return 1; }
import json, sys
path, hexdata, subject, origin = sys.argv[1], sys.argv[2].lower(), int(sys.argv[3], 0), int(sys.argv[4], 0)
for line in open(path):
    e = json.loads(line)
    if e.get("payload") != hexdata:
        continue
    ok = e["subject"] == subject and e["hop_count"] == 1 and e["origin"] == origin and e["size"] == len(hexdata) // 2
    if not ok:
        print("    event %s" % line.strip(), file=sys.stderr)
    sys.exit(0 if ok else 1)
EOF
}

# ---------------------------------------------------------------------------------- scenarios
scenario_etags() {
  local ch
  ch=$(ctl channels)
  for spec in "sensor:$ETAG_SENSOR" "command:$ETAG_COMMAND" "bulk_up:$ETAG_BULK_UP" "bulk_down:$ETAG_BULK_DOWN"; do
    expect_eq "etag of ${spec%%:*}" "$(python3 "$E2E/q.py" "ch('${spec%%:*}')['etag']" <<<"$ch")" "${spec#*:}"
    expect_eq "verdict of ${spec%%:*}" "$(python3 "$E2E/q.py" "ch('${spec%%:*}')['verdict']" <<<"$ch")" bound
  done
  # The text table shows them too.
  "$COSMICCTL" --socket "$SOCK" channels >"$SDIR/channels.txt"
  check "cosmicctl channels shows etag 16383 for sensor" grep -Eq "^sensor +nrt +bound +$ETAG_SENSOR " "$SDIR/channels.txt"
  check "cosmicctl channels shows etag 300 for command" grep -Eq "^command +srt +bound +$ETAG_COMMAND " "$SDIR/channels.txt"
  # The identifier cosmicd plans for command is the documented one.
  local want
  want=$(canlog id $PRIO_COMMAND $GW_NODE $ETAG_COMMAND)
  expect_eq "can_id of command" "$(printf %08X "$(q "channel command" "[h for h in d['channel']['admission']['hops'] if h['segment']=='bus'][0]['can']['can_id']")")" "$want"
}

scenario_get_etag() {
  local supply errors0
  supply=$(canlog id $PRIO_GET_ETAG $GW_NODE $ETAG_SUPPLY)
  errors0=$(q segments "seg('bus')['adapter']['receive_errors']")
  candump_start dump "$(printf %08X $ETAG_SUPPLY):C0003FFF"
  # Node 0x22 asks for a subject no channel has (no answer), then sends a 7-byte request (a
  # decode error), node 0x23 asks for sensor (dynamic etag), node 0x24 for command (static etag,
  # subscriber role). cosmicd handles frames in order: once the last answer is there, a wrong
  # answer to 0x22 would be too.
  cansend "$IF" "$(canlog id $PRIO_GET_ETAG 0x22 $ETAG_GET)#00000001000000FF"
  cansend "$IF" "$(canlog id $PRIO_GET_ETAG 0x22 $ETAG_GET)#00000001000000"
  cansend "$IF" "$(canlog id $PRIO_GET_ETAG 0x23 $ETAG_GET)#$(printf %016X $((SUBJ_SENSOR)))"
  cansend "$IF" "$(canlog id 0x12 0x24 $ETAG_GET)#$(printf %016X $((SUBJ_COMMAND)))"  # any priority is accepted
  wait_until 10 "4 SUPPLY_ETAG frames" count_frames dump "$supply" 4
  frames_of dump "$supply" >"$SDIR/answers.txt"
  printf '%s\n' "$supply 23003FFF00000001" "$supply 23013FFF000000A1" \
    "$supply 2400012C00000001" "$supply 2401012C000000B2" >"$SDIR/expected.txt"
  check "SUPPLY_ETAG answers as documented (section 5)" diff -u "$SDIR/expected.txt" "$SDIR/answers.txt"
  check "the malformed request is counted" t segments "seg('bus')['adapter']['receive_errors'] == $errors0 + 1"
}

scenario_can_to_ip() {
  local id rx0
  id=$(canlog id 0xF0 $DEV $ETAG_SENSOR)
  rx0=$(q channels "hop('sensor','bus')['rx']")
  lcm_sub lcm sensor 1
  dds_sub dds sensor
  cansend "$IF" "$id#DEADBEEF"
  subscriber_saw "LCM subscriber" "$SDIR/lcm.out" deadbeef $SUBJ_SENSOR
  subscriber_saw "DDS subscriber" "$SDIR/dds.out" deadbeef $SUBJ_SENSOR
  check "one event received on bus" t channels "hop('sensor','bus')['rx'] == $rx0 + 1"
  check "sent on lan and viz" t channels "hop('sensor','lan')['tx'] >= 1 and hop('sensor','viz')['tx'] >= 1"
}

scenario_ip_to_can() {
  local id
  id=$(canlog id $PRIO_COMMAND $GW_NODE $ETAG_COMMAND)
  candump_start dump "$(printf %08X $ETAG_COMMAND):C0003FFF"
  "$LCM_PEER" pub --url "$LCM_URL" --channel command --count 1 --size 6 --subject $SUBJ_COMMAND
  wait_until 10 "the LCM event on the bus" count_frames dump "$id" 1
  dds_pub ddspub command 6 $SUBJ_COMMAND
  wait_until 20 "the DDS event on the bus" count_frames dump "$id" 2
  wait "$LAST" || { echo "    DDS publisher failed" >&2; return 1; }
  frames_of dump "$id" >"$SDIR/frames.txt"
  printf '%s\n' "$id $(canlog payload lcm 6 1 | tr a-f A-F)" "$id $(canlog payload dds 6 1 | tr a-f A-F)" >"$SDIR/expected.txt"
  check "frames on the bus: identifier $id, payloads as published" diff -u "$SDIR/expected.txt" "$SDIR/frames.txt"
  check "no frame of etag $ETAG_COMMAND with another identifier" \
    test "$(canlog frames "$SDIR/dump.out" | wc -l)" -eq 2
}

scenario_fragments_up() {
  local id big small errors0
  id=$(canlog id 0xF1 $DEV $ETAG_BULK_UP)
  big=$(canlog payload dev 1024 1)
  small=$(canlog payload dev 13 2)
  errors0=$(q segments "seg('bus')['adapter']['receive_errors']")
  { canlog fragment "$id" 0 "$big"; canlog fragment "$id" 1 "$small"; } >"$SDIR/events.log"
  check "the 1 KiB event is 171 fragments + 3 for the small one" test "$(wc -l <"$SDIR/events.log")" -eq 174
  lcm_sub lcm bulk_up 2
  dds_sub dds bulk_up
  canplayer -t -g 1 -I "$SDIR/events.log"
  subscriber_saw "LCM subscriber (1 KiB)" "$SDIR/lcm.out" "$big" $SUBJ_BULK_UP
  subscriber_saw "LCM subscriber (13 B)" "$SDIR/lcm.out" "$small" $SUBJ_BULK_UP
  subscriber_saw "DDS subscriber (1 KiB)" "$SDIR/dds.out" "$big" $SUBJ_BULK_UP
  subscriber_saw "DDS subscriber (13 B)" "$SDIR/dds.out" "$small" $SUBJ_BULK_UP
  check "no receive error" t segments "seg('bus')['adapter']['receive_errors'] == $errors0"
  check "no decode error" t channels "drops('bulk_up','bus','decode_error') == 0"
}

scenario_fragments_down() {
  local prio id
  prio=$(q "channel bulk_down" "[h for h in d['channel']['admission']['hops'] if h['segment']=='bus'][0]['can']['priority']")
  check "bulk_down has an NRT priority (0xF0-0xFF), got $prio" test "$prio" -ge 240 -a "$prio" -le 255
  id=$(canlog id "$prio" $GW_NODE $ETAG_BULK_DOWN)
  candump_start dump "$(printf %08X $ETAG_BULK_DOWN):C0003FFF"
  "$LCM_PEER" pub --url "$LCM_URL" --channel bulk_down --count 1 --size 1024 --subject $SUBJ_BULK_DOWN
  wait_until 20 "171 fragments of the LCM event" count_frames dump "$id" 171
  dds_pub ddspub bulk_down 1024 $SUBJ_BULK_DOWN
  wait_until 20 "171 fragments of the DDS event" count_frames dump "$id" 342
  wait "$LAST" || { echo "    DDS publisher failed" >&2; return 1; }
  check "only identifier $id on etag $ETAG_BULK_DOWN" test "$(canlog frames "$SDIR/dump.out" | wc -l)" -eq 342
  canlog reassemble "$SDIR/dump.out" "$id" 0 >"$SDIR/events.txt"
  printf '%s\n' "$(canlog payload lcm 1024 1)" "$(canlog payload dds 1024 1)" >"$SDIR/expected.txt"
  check "fragments (sequence 0, then 1) reassemble to the published events" \
    cmp -s "$SDIR/expected.txt" "$SDIR/events.txt"
}

scenario_garbage() {
  local sensor_id bulk_id get_id sentinel big
  sensor_id=$(canlog id 0xF0 $DEV $ETAG_SENSOR)
  bulk_id=$(canlog id 0xF1 $DEV $ETAG_BULK_UP)
  get_id=$(canlog id $PRIO_GET_ETAG 0x30 $ETAG_GET)
  ctl segments >"$SDIR/segments0.json"
  ctl channels >"$SDIR/channels0.json"
  candump_start all 0:0
  lcm_sub lcm sensor 100000
  lcm_sub lcmbulk bulk_up 100000
  # Random 29-bit, 11-bit and mixed (FD, remote) frames: almost all of unbound etags.
  cangen "$IF" -e -g 0 -p 20 -n 2000
  cangen "$IF" -g 0 -p 20 -n 300
  if [ "$(cat /sys/class/net/$IF/mtu)" = 72 ]; then cangen "$IF" -m -g 0 -p 20 -n 300; fi
  # Aimed at bound etags: random lengths and data, remote frames, malformed GET_ETAG.
  cangen "$IF" -e -I "$sensor_id" -L r -D r -g 1 -p 20 -n 200
  cangen "$IF" -e -I "$bulk_id" -L r -D r -g 1 -p 20 -n 300
  cangen "$IF" -e -R -I "$sensor_id" -g 1 -n 20
  cangen "$IF" -e -R -I "$bulk_id" -g 1 -n 20
  cangen "$IF" -e -I "$get_id" -L r -D r -g 1 -p 20 -n 100
  # Hostile fragments: an event that grows past the channel's 1 KiB payload, a lone last fragment
  # with index 2047, a fragment starting no event.
  canlog fragment "$(canlog id 0xF1 0x11 $ETAG_BULK_UP)" 3 "$(canlog payload dev 1200 9)" >"$SDIR/hostile.log"
  echo "(0.000000) $IF $(canlog id 0xF1 0x12 $ETAG_BULK_UP)#3FFF0102" >>"$SDIR/hostile.log"
  echo "(0.000000) $IF $(canlog id 0xF1 0x13 $ETAG_BULK_UP)#00050102030405" >>"$SDIR/hostile.log"
  canplayer -t -g 1 -I "$SDIR/hostile.log"
  # Sentinels from other TxNodes (no partial event pending there): once they come out, every
  # frame before them has been handled.
  sentinel=5E47191E
  big=$(canlog payload dev 1024 7)
  canlog fragment "$(canlog id 0xF1 0x14 $ETAG_BULK_UP)" 0 "$big" >"$SDIR/sentinel.log"
  canplayer -t -g 1 -I "$SDIR/sentinel.log"
  cansend "$IF" "$(canlog id 0xF0 0x14 $ETAG_SENSOR)#$sentinel"
  wait_until 30 "the sentinel event on LCM (sensor)" has_payload "$SDIR/lcm.out" "$sentinel"
  wait_until 30 "the 1 KiB sentinel event on LCM (bulk_up)" has_payload "$SDIR/lcmbulk.out" "$big"
  check "cosmicd is alive" kill -0 "$COSMICD_PID"
  check "segment bus is up" t segments "seg('bus')['health'] == 'up'"
  wait_until 5 "the LCM sentinel counted as sent" t channels "hop('sensor','viz')['tx'] >= 1"
  ctl segments >"$SDIR/segments1.json"
  ctl channels >"$SDIR/channels1.json"
  # Account for every frame, from what candump saw on the bus and docs/can-wire-format.md.
  python3 - "$SDIR" "$E2E" "$ETAG_SENSOR,$ETAG_BULK_UP,$ETAG_GET" <<'EOF'
import json, sys
sdir, e2e, etags = sys.argv[1], sys.argv[2], {int(e) for e in sys.argv[3].split(",")}
sys.path.insert(0, e2e)
import canlog
frames = [f for f in canlog.read_frames(sdir + "/all.out")]
def load(n): return json.load(open("%s/%s.json" % (sdir, n)))
s0, s1 = [next(s for s in load(n)["segments"] if s["name"] == "bus")["adapter"] for n in ("segments0", "segments1")]
def hop(doc, c):
    return next(h for h in next(x for x in doc["channels"] if x["name"] == c)["segments"] if h["segment"] == "bus")
c0, c1 = load("channels0"), load("channels1")
# cosmicd's socket is classic CAN and filters 29-bit frames of its publisher etags + GET_ETAG.
passing = [f for f in frames if f[1] and not f[3] and (f[0] & 0x3FFF) in etags]
sensor = [f for f in passing if (f[0] & 0x3FFF) == 16383]
sensor_bad = [f for f in sensor if f[2] or len(f[4]) > 4]   # remote frame or longer than 4 B
get = [f for f in passing if (f[0] & 0x3FFF) == 2]
get_bad = [f for f in get if f[2] or len(f[4]) != 8]
received = s1["received"] - s0["received"]
overflow = s1["overflow_drops"] - s0["overflow_drops"]
errors = s1["receive_errors"] - s0["receive_errors"]
d_sensor = hop(c1, "sensor")["dropped"]["decode_error"] - hop(c0, "sensor")["dropped"]["decode_error"]
rx_sensor = hop(c1, "sensor")["rx"] - hop(c0, "sensor")["rx"]
d_bulk = hop(c1, "bulk_up")["dropped"]["decode_error"] - hop(c0, "bulk_up")["dropped"]["decode_error"]
print("    frames on the bus %d, passing the filters %d; cosmicd received %d, overflow %d, receive errors %d;"
      " sensor: %d events, %d decode errors; bulk_up: %d decode errors; GET_ETAG: %d malformed"
      % (len(frames), len(passing), received, overflow, errors, rx_sensor, d_sensor, d_bulk, len(get_bad)))
fails = []
if overflow != 0:
    fails.append("kernel overflow drops during the test (%d): accounting below is off" % overflow)
if received != len(passing):
    fails.append("cosmicd received %d frames, but %d on the bus pass its filters" % (received, len(passing)))
if d_sensor != len(sensor_bad):
    fails.append("sensor decode errors %d, expected %d" % (d_sensor, len(sensor_bad)))
if rx_sensor != len(sensor) - len(sensor_bad):
    fails.append("sensor events %d, expected %d" % (rx_sensor, len(sensor) - len(sensor_bad)))
if d_bulk < 20 + 2:
    fails.append("bulk_up decode errors %d, expected >= 22 (20 remote frames, hostile fragments)" % d_bulk)
if errors < len(sensor_bad) + len(get_bad) + d_bulk:
    fails.append("receive errors %d < %d" % (errors, len(sensor_bad) + len(get_bad) + d_bulk))
for f in fails:
    print("    " + f, file=sys.stderr)
sys.exit(1 if fails else 0)
EOF
}

scenario_link_down_up() {
  local id sensor_id failed0 gw0
  gw0=$(q status "d['gateway']['id']")
  ip link set "$IF" down
  wait_until 10 "segment bus down" t segments "seg('bus')['health'] == 'down' and 'down' in seg('bus')['detail']"
  wait_until 5 "all four channels degraded" t channels \
    "all(ch(n)['verdict'] == 'degraded' and any('segment bus is down' in r for r in ch(n)['reasons']) for n in ('sensor','command','bulk_up','bulk_down'))"
  check "status: 2 of 3 segments up, 4 channels degraded" t status \
    "d['segments']['up'] == 2 and d['channels']['degraded'] == 4"
  q segments "seg('bus')['detail']" >"$SDIR/detail.txt"
  # An event for the bus while it is down is counted as not sent, and nothing breaks.
  failed0=$(q channels "drops('command','bus','send_failed') + drops('command','bus','queue_full')")
  "$LCM_PEER" pub --url "$LCM_URL" --channel command --count 1 --size 6 --subject $SUBJ_COMMAND
  wait_until 10 "the event counted as not sent" t channels \
    "drops('command','bus','send_failed') + drops('command','bus','queue_full') > $failed0"
  ip link set "$IF" up
  wait_until 10 "segment bus up again" t segments "seg('bus')['health'] == 'up'"
  wait_until 5 "channels bound again" t channels \
    "all(ch(n)['verdict'] == 'bound' and not ch(n)['reasons'] for n in ('sensor','command','bulk_up','bulk_down'))"
  check "status: 3 segments up, none degraded" t status "d['segments']['up'] == 3 and d['channels']['degraded'] == 0"
  # Traffic resumes in both directions.
  sensor_id=$(canlog id 0xF0 $DEV $ETAG_SENSOR)
  lcm_sub lcm sensor 1
  cansend "$IF" "$sensor_id#0B0C0D0E"
  subscriber_saw "LCM subscriber after the link came back" "$SDIR/lcm.out" 0b0c0d0e $SUBJ_SENSOR
  id=$(canlog id $PRIO_COMMAND $GW_NODE $ETAG_COMMAND)
  candump_start dump "$(printf %08X $ETAG_COMMAND):C0003FFF"
  "$LCM_PEER" pub --url "$LCM_URL" --channel command --count 1 --size 6 --subject $SUBJ_COMMAND
  wait_until 10 "the LCM event on the bus after the link came back" count_frames dump "$id" 1
  expect_eq "frame on the bus" "$(frames_of dump "$id")" "$id $(canlog payload lcm 6 1 | tr a-f A-F)"
  check "the same cosmicd process" kill -0 "$COSMICD_PID"
  expect_eq "gateway id (no restart)" "$(q status "d['gateway']['id']")" "$gw0"
}

# ---------------------------------------------------------------------------------- driver
FAILED=0
RESULTS=()
run() {  # run NAME: scenario_NAME in a subshell with errexit; PASS/FAIL with its duration
  local name=$1 start rc
  SDIR=$WORK/$name
  mkdir -p "$SDIR"
  start=$(now_ms)
  (
    set -eE
    trap 'echo "    failed: line $LINENO: $BASH_COMMAND" >&2' ERR
    trap stop_bg EXIT
    "scenario_$name"
  ) >"$SDIR/log" 2>&1
  rc=$?
  local secs
  secs=$(awk -v ms=$(($(now_ms) - start)) 'BEGIN { printf "%.1f", ms / 1000 }')
  if [ $rc -eq 0 ]; then
    echo "PASS $name (${secs} s)"
    sed -n 's/^    frames on the bus/    frames on the bus/p' "$SDIR/log"
  else
    echo "FAIL $name (${secs} s)"
    sed 's/^/  | /' "$SDIR/log" | tail -n 40
    for f in "$SDIR"/*.err; do
      [ -s "$f" ] || continue
      echo "  --- $(basename "$f") (last lines)"
      tail -n 8 "$f" | sed 's/^/  | /'
    done
    echo "  --- cosmicd log (last lines)"
    tail -n 15 "$WORK/cosmicd.log" | sed 's/^/  | /'
    FAILED=$((FAILED + 1))
  fi
  RESULTS+=("$name:$rc")
}

cleanup() {
  if [ -n "$COSMICD_PID" ] && kill -0 "$COSMICD_PID" 2>/dev/null; then
    kill -TERM "$COSMICD_PID" 2>/dev/null
    wait "$COSMICD_PID" 2>/dev/null
  fi
  ip link set "$IF" up 2>/dev/null
  if [ "${CAN_E2E_KEEP:-0}" = 1 ]; then echo "work directory kept: $WORK"; else rm -rf "$WORK"; fi
}
trap cleanup EXIT

t0=$(now_ms)
"$COSMICD" --config "$CONFIG" --socket "$SOCK" --state-file "$WORK/bindings.json" --log-level info \
  >"$WORK/cosmicd.log" 2>&1 &
COSMICD_PID=$!
if ! wait_until 30 "cosmicd answering with all 3 segments up" t status "d['segments']['up'] == 3 and d['channels']['bound'] == 4"; then
  echo "FAIL startup"
  cat "$WORK/cosmicd.log"
  exit 1
fi
GATEWAY_ID=$(q status "d['gateway']['id']")
echo "cosmicd up (pid $COSMICD_PID, gateway id $GATEWAY_ID) after $(($(now_ms) - t0)) ms"

for s in etags get_etag can_to_ip ip_to_can fragments_up fragments_down garbage link_down_up; do
  run "$s"
done

# cosmicd stops cleanly on SIGTERM.
kill -TERM "$COSMICD_PID"
end=$(($(now_ms) + 15000))
while kill -0 "$COSMICD_PID" 2>/dev/null && [ "$(now_ms)" -lt "$end" ]; do sleep 0.05; done
if kill -0 "$COSMICD_PID" 2>/dev/null; then
  echo "FAIL shutdown (cosmicd still running 15 s after SIGTERM)"
  FAILED=$((FAILED + 1))
else
  wait "$COSMICD_PID"
  rc=$?
  if [ $rc -eq 0 ]; then echo "PASS shutdown"; else echo "FAIL shutdown (exit status $rc)"; FAILED=$((FAILED + 1)); fi
fi
COSMICD_PID=
echo "$((${#RESULTS[@]} + 1 - FAILED)) passed, $FAILED failed, $(($(now_ms) - t0)) ms"
exit $((FAILED > 0 ? 1 : 0))
