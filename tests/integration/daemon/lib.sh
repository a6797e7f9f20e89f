# Shared helpers of the cosmicd end-to-end tests: start daemons, read their counters, wait on
# conditions with deadlines. Sourced by the test scripts; expects COSMICD, COSMICCTL, WORK.

PIDS=()
FAILED=0

cleanup() {
  for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do wait "$pid" 2>/dev/null || true; done
  [ "$FAILED" = 0 ] || show_daemon_logs
}

# After a failure: what each daemon logged above debug, the last lines (a CI run keeps no files).
show_daemon_logs() {
  local f
  for f in "$WORK"/*.log; do
    [ -f "$f" ] || continue
    log "--- $(basename "$f"), without debug lines, last 40:"
    grep -v '^[0-9-]* [0-9:.]* debug ' "$f" | tail -n 40 >&2
  done
}

log() { printf '%s\n' "$*" >&2; }

fail() {
  log "FAIL: $*"
  FAILED=1
  SCENARIO_FAILED=1
  return 1
}

# wait_until TIMEOUT_S DESCRIPTION CMD...: polls CMD until it succeeds or the deadline passes.
wait_until() {
  local timeout=$1 what=$2
  shift 2
  local deadline=$((SECONDS + timeout))
  until "$@" >/dev/null 2>&1; do
    if [ "$SECONDS" -ge "$deadline" ]; then
      fail "timed out after ${timeout}s waiting for: $what"
      return 1
    fi
    sleep 0.05
  done
}

ctl() {
  local name=$1
  shift
  "$COSMICCTL" --socket "$WORK/$name.sock" "$@"
}

# start_daemon NAME CONFIG: runs cosmicd in the background and waits until it answers.
start_daemon() {
  local name=$1 config=$2
  "$COSMICD" --config "$config" --socket "$WORK/$name.sock" --state-file "$WORK/$name.state" \
    --log-level debug 2>"$WORK/$name.log" &
  PIDS+=($!)
  eval "PID_${name//-/_}=$!"
  wait_until 30 "cosmicd $name answering" ctl "$name" status
}

# channel_field NAME CHANNEL SEGMENT FIELD: a per-segment counter from `channels --json`
# (FIELD is rx, tx, matched, or dropped.REASON).
channel_field() {
  ctl "$1" --json channels | python3 -c '
import json, sys
channel, segment, field = sys.argv[1:4]
for c in json.load(sys.stdin)["channels"]:
    if c["name"] != channel:
        continue
    for s in c["segments"]:
        if s["segment"] == segment:
            value = s["dropped"][field.split(".")[1]] if field.startswith("dropped.") else s[field]
            print(0 if value is None else value)
            sys.exit(0)
print(-1)' "$2" "$3" "$4"
}

# field_at_least NAME CHANNEL SEGMENT FIELD MIN
# segment_adapter_field GW SEGMENT FIELD: an adapter counter of a segment (cosmicctl segments --json).
segment_adapter_field() {
  ctl "$1" --json segments | python3 -c '
import json, sys
for s in json.load(sys.stdin)["segments"]:
    if s["name"] == sys.argv[1]:
        print(s["adapter"][sys.argv[2]])' "$2" "$3"
}
segment_field_at_least() { [ "$(segment_adapter_field "$1" "$2" "$3")" -ge "$4" ]; }

field_at_least() { [ "$(channel_field "$1" "$2" "$3" "$4")" -ge "$5" ]; }
# field_equals NAME CHANNEL SEGMENT FIELD VALUE
field_equals() { [ "$(channel_field "$1" "$2" "$3" "$4")" -eq "$5" ]; }

# expect_field NAME CHANNEL SEGMENT FIELD VALUE: the counter reaches VALUE within 10 s and is VALUE
# then. A counter counts after its event's write returns, so a peer that already received the
# event may be answered before the count (seen: tx 39 of 40 read the moment the reader had 40).
expect_field() {
  local actual deadline=$((SECONDS + 10))
  while actual=$(channel_field "$1" "$2" "$3" "$4"); [ "$actual" -lt "$5" ] && [ "$SECONDS" -lt "$deadline" ]; do
    sleep 0.05
  done
  [ "$actual" -eq "$5" ] || fail "$1 $2 $3 $4 = $actual, expected $5"
}

channel_count() { ctl "$1" --json channels | python3 -c 'import json,sys; print(len(json.load(sys.stdin)["channels"]))'; }

# The counters of a gateway stop moving (every event in flight has been handled).
settled() {
  local name=$1 before after
  before=$(ctl "$name" --json channels | python3 -c 'import json,sys; print(json.dumps([c["segments"] for c in json.load(sys.stdin)["channels"]]))')
  sleep 0.3
  after=$(ctl "$name" --json channels | python3 -c 'import json,sys; print(json.dumps([c["segments"] for c in json.load(sys.stdin)["channels"]]))')
  [ "$before" = "$after" ]
}

# peer_field GW PEER FIELD: a field of gateway GW's entry for gateway PEER in `peers --json` ("" when not listed).
peer_field() {
  ctl "$1" --json peers | python3 -c '
import json, sys
p = next((p for p in json.load(sys.stdin)["peers"] if p["name"] == sys.argv[1]), None)
print("" if p is None else ("null" if p[sys.argv[2]] is None else p[sys.argv[2]]))' "$2" "$3"
}
# state_is GW PEER STATE: gateway GW shows gateway PEER in STATE.
state_is() { [ "$(peer_field "$1" "$2" state)" = "$3" ]; }

# backbone_field NAME FIELD: a field of the segment named backbone in `segments --json` (the
# federation tests' shared network).
backbone_field() {
  ctl "$1" --json segments | python3 -c '
import json, sys
print(next(s[sys.argv[1]] for s in json.load(sys.stdin)["segments"] if s["name"] == "backbone"))' "$2"
}
# near A B: two numbers within 0.005 of each other.
near() { python3 -c 'import sys; sys.exit(0 if abs(float(sys.argv[1]) - float(sys.argv[2])) < 0.005 else 1)' "$1" "$2"; }

# stderr_has FILE TEXT
stderr_has() { grep -q -- "$2" "$1"; }

scenario() {
  SCENARIO=$1
  SCENARIO_FAILED=0
  log "--- $SCENARIO"
}

# Ends a scenario: PASS unless one of its checks failed.
passed() { [ "$SCENARIO_FAILED" = 0 ] && log "PASS: $SCENARIO"; }
