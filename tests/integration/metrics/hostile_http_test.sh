#!/usr/bin/env bash
# The metrics endpoint stays answering under the attacks of issue 22, item 3: slow-loris
# connections, hundreds of idle connections, a Range of thousands of ranges, oversized heads.
#   hostile_http_test.sh COSMICD COSMICCTL COSMIC_LCM_PEER   (through netns-run)
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 LCM_PEER=$3
WORK=$(mktemp -d /tmp/cosmic-metrics-hostile.XXXXXX)
HERE=$(dirname "$0")
# shellcheck source=../daemon/lib.sh
source "$HERE/../daemon/lib.sh"
# shellcheck source=common.sh
source "$HERE/common.sh"
trap 'cleanup; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT

HOST=127.0.0.1 PORT=9877
METRICS=http://$HOST:$PORT/metrics
CAP=8  # HttpLimits::max_connections
attack() { python3 "$HERE/http_attacks.py" "$1" "$HOST" "$PORT" "${@:2}"; }
fds() { ls /proc/"$PID_gw"/fd | wc -l; }

# scrapes_answered N SECONDS: N scrapes at once, each answered (200, a whole document) in SECONDS.
scrapes_answered() {
  local n=$1 seconds=$2 pids=() i bad=0 start=$EPOCHREALTIME
  for i in $(seq "$n"); do
    curl -sf --max-time "$seconds" -o "$WORK/scrape.$i" "$METRICS" &
    pids+=($!)
  done
  for i in "${!pids[@]}"; do wait "${pids[$i]}" || bad=$((bad + 1)); done
  [ "$bad" = 0 ] || { log "$bad of $n scrapes not answered within ${seconds}s"; return 1; }
  log "   $n scrapes answered in $(python3 -c "print(f'{$EPOCHREALTIME - $start:.2f}')") s"
  grep -q '^cosmic_channel_sent_events_total' "$WORK/scrape.1" || { log "scrape without the counters"; return 1; }
}

# (a) More slow-loris connections than the cap, each sending one head byte every 2 s.
test_slowloris() {
  scenario "slow-loris connections neither hold off scrapes nor stay open past the head deadline"
  local count=$((CAP + 2))
  attack slowloris "$count" 40 "$WORK/loris" &
  PIDS+=($!)
  wait_until 15 "$count slow-loris connections open" grep -q "^open $count " "$WORK/loris" || return
  scrapes_answered 4 10 || fail "scrapes not answered while $count slow-loris connections dribble"
  # The head deadline (3 s from a head's first byte) closes every one of them, long before the
  # 40 s they would keep dribbling.
  wait_until 30 "the endpoint closes every slow-loris connection" grep -q " closed $count\$" "$WORK/loris" || return
  passed
}

# (b) Hundreds of idle connections, far above the cap: the newest scrape gets in by closing the
# connection idle longest; the endpoint's descriptors stay bounded.
test_idle_flood() {
  scenario "300 idle connections neither block a scrape nor take the process's descriptors"
  local sampler max
  # The most descriptors cosmicd holds, sampled all through the flood.
  (max=0; while :; do n=$(fds); [ "$n" -gt "$max" ] && max=$n && echo "$max" >"$WORK/fds.max"; sleep 0.05; done) &
  sampler=$!
  attack idle 300 60 "$WORK/idle" &
  PIDS+=($!)
  wait_until 20 "300 idle connections started" grep -q '^open' "$WORK/idle" || { kill "$sampler"; return; }
  scrapes_answered 2 10 || fail "scrapes not answered while 300 idle connections are open"
  scrapes_answered 1 10 || fail "second scrape not answered while 300 idle connections are open"
  kill "$sampler"
  wait "$sampler" 2>/dev/null
  max=$(cat "$WORK/fds.max")
  log "   descriptors: $BASE_FDS before, at most $max while 300 idle connections were open ($(cat "$WORK/idle"))"
  # The cap, the listening socket and a few for the scrapes themselves; far below 300.
  [ "$max" -le $((BASE_FDS + CAP + 8)) ] || fail "cosmicd held $max descriptors with 300 idle connections (before: $BASE_FDS, cap $CAP)"
  wait_until 10 "eviction reported" stderr_has "$WORK/gw.log" "closed at the cap of $CAP connections" || return
  [ "$(grep -c "closed at the cap of" "$WORK/gw.log")" -le 2 ] || fail "evictions logged one by one"
  passed
}

# (c) Range is never honoured: the whole document, once, 200.
test_range() {
  scenario "a request with a Range gets the whole document once, 200"
  local answer status body length help type
  answer=$(attack range 1000) || { fail "range request failed"; return; }
  read -r status body length help type <<<"$answer"
  [ "$status" = 200 ] || fail "Range of 1000 x '0-' answered $status (want 200): $answer"
  [ "$body" = "$length" ] || fail "body $body bytes but Content-Length $length"
  [ "$help" = 1 ] || fail "the document's first line occurs $help times"
  [[ "$type" == text/plain* ]] || fail "content type $type"
  [ "$body" -lt 200000 ] || fail "$body bytes for one scrape"
  [ "$(curl -s -o /dev/null -w '%{http_code}' -H 'Range: bytes=0-10' "$METRICS")" = 200 ] || fail "Range 0-10 not 200"
  [ "$(curl -s -o /dev/null -w '%{http_code}' -H 'Range: bytes=abc' "$METRICS")" = 200 ] || fail "bad Range not 200"
  passed
}

# (d) Heads are limited to 4 KiB (docs/metrics.md).
test_head_limit() {
  scenario "a request head over 4 KiB is refused, one under it answered"
  local status
  status=$(attack head 4000) || true
  [ "$status" = 200 ] || fail "a 4,000-byte head answered '$status' (want 200)"
  for size in 8192 1048576; do
    status=$(attack head "$size") || true
    case "$status" in
      431|closed) ;;
      *) fail "a $size-byte head answered '$status' (want 431 or the connection closed)" ;;
    esac
  done
  scrape "$METRICS" || fail "endpoint gone after the oversized heads"
  passed
}

write_config "$WORK/gw.yaml" "  metrics: {listen: $HOST:$PORT}"
start_daemon gw "$WORK/gw.yaml" || exit 1
wait_until 10 "metrics endpoint answers" scrape "$METRICS" || exit 1
BASE_FDS=$(fds)
test_range
test_head_limit
test_slowloris
test_idle_flood
ctl gw status >/dev/null || fail "control socket stopped answering"
[ "$FAILED" = 0 ] || { log "--- cosmicd log"; tail -30 "$WORK/gw.log" >&2; }
exit "$FAILED"
