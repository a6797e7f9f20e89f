#!/usr/bin/env bash
# A real Prometheus server scrapes a running cosmicd; the test asks Prometheus's HTTP API for a
# counter that moved. Also: the endpoint's thread, its lint, reloads, a port already taken.
#   prometheus_test.sh COSMICD COSMICCTL COSMIC_LCM_PEER PROMETHEUS PROMTOOL   (through netns-run)
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 LCM_PEER=$3 PROMETHEUS=$4 PROMTOOL=$5
for tool in "$PROMETHEUS" "$PROMTOOL"; do
  [ -x "$tool" ] || { echo "FAIL: $tool: Prometheus is not installed (scripts/setup installs the prometheus package)" >&2; exit 1; }
done
WORK=$(mktemp -d /tmp/cosmic-metrics.XXXXXX)
HERE=$(dirname "$0")
# shellcheck source=../daemon/lib.sh
source "$HERE/../daemon/lib.sh"
# shellcheck source=common.sh
source "$HERE/common.sh"
trap 'cleanup; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT

METRICS=http://127.0.0.1:9877/metrics
PROM=http://127.0.0.1:9090

# prom_value QUERY: the first sample's value of an instant query, or "none".
prom_value() {
  curl -sf --max-time 5 --data-urlencode "query=$1" "$PROM/api/v1/query" | python3 -c '
import json, sys
result = json.load(sys.stdin)["data"]["result"]
print(result[0]["value"][1] if result else "none")'
}

# prom_at_least QUERY MIN
prom_at_least() {
  local value
  value=$(prom_value "$1") || return 1
  [ "$value" != none ] && python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) >= float(sys.argv[2]) else 1)' "$value" "$2"
}

# Every query of the example Grafana dashboard, its variables filled in, runs on this Prometheus.
dashboard_queries_run() {
  python3 - "$HERE/../../../dashboards/grafana-cosmicd.json" "$PROM" <<'PY'
import json, sys, urllib.parse, urllib.request
dashboard, prom = sys.argv[1], sys.argv[2]
panels = json.load(open(dashboard))["panels"]
bad = 0
for expr in (t["expr"] for p in panels for t in p.get("targets", [])):
    query = expr.replace("$__rate_interval", "1m").replace("$instance", ".*").replace("$channel", ".*")
    data = urllib.parse.urlencode({"query": query}).encode()
    try:
        answer = json.load(urllib.request.urlopen(prom + "/api/v1/query", data, timeout=5))
        ok = answer.get("status") == "success"
    except Exception as e:  # a 400 answer is an invalid query
        ok, answer = False, e
    if not ok:
        print(f"dashboard query failed: {query}: {answer}", file=sys.stderr)
        bad += 1
sys.exit(1 if bad else 0)
PY
}

# The endpoint serves a lint-clean document from threads named cosmic-metrics.
test_endpoint() {
  scenario "cosmicd serves /metrics from its own thread, lint-clean in both formats"
  wait_until 10 "metrics endpoint answers" scrape "$METRICS" "$WORK/first.txt" || return
  "$PROMTOOL" check metrics <"$WORK/first.txt" >"$WORK/lint.txt" 2>&1 || fail "promtool check metrics: $(cat "$WORK/lint.txt")"
  grep -q '^cosmic_channel_sent_events_total{channel="pose",class="nrt",segment="lcm-b",role="subscriber"} ' "$WORK/first.txt" ||
    fail "no sent counter for pose on lcm-b"
  curl -sf -H 'Accept: application/openmetrics-text;version=1.0.0' "$METRICS" -o "$WORK/om.txt" -D "$WORK/om.headers" || fail "OpenMetrics scrape"
  grep -qi '^content-type: application/openmetrics-text' "$WORK/om.headers" || fail "OpenMetrics content type"
  [ "$(tail -n 1 "$WORK/om.txt")" = "# EOF" ] || fail "OpenMetrics document does not end in # EOF"
  grep -qx cosmic-metrics /proc/"$PID_gw"/task/*/comm || fail "no thread named cosmic-metrics"
  [ "$(curl -s -o /dev/null -w '%{http_code}' http://127.0.0.1:9877/nothing)" = 404 ] || fail "unknown path not 404"
  passed
}

test_prometheus_scrape() {
  scenario "Prometheus scrapes cosmicd and its API shows the sent counter moving"
  cat >"$WORK/prometheus.yml" <<YAML
global: {scrape_interval: 1s, scrape_timeout: 1s}
scrape_configs:
  - job_name: cosmicd
    static_configs: [{targets: ["127.0.0.1:9877"]}]
YAML
  "$PROMETHEUS" --config.file="$WORK/prometheus.yml" --storage.tsdb.path="$WORK/tsdb" \
    --web.listen-address=127.0.0.1:9090 --log.level=warn 2>"$WORK/prometheus.log" &
  PIDS+=($!)
  wait_until 60 "Prometheus ready" curl -sf "$PROM/-/ready" || { log "$(tail -5 "$WORK/prometheus.log")"; return; }
  wait_until 30 "Prometheus scraped cosmicd" prom_at_least 'up{job="cosmicd"}' 1 || return
  local series='cosmic_channel_sent_events_total{job="cosmicd",channel="pose",segment="lcm-b"}'
  wait_until 30 "Prometheus has the counter" prom_at_least "$series" 0 || return
  [ "$(prom_value "$series")" = 0 ] || fail "counter not 0 before any event"
  publish 300 || fail "LCM publisher failed"
  wait_until 30 "Prometheus sees 300 events sent" prom_at_least "$series" 300 || return
  prom_at_least 'cosmic_channel_residence_seconds_count{channel="pose",segment="lcm-b"}' 300 || fail "residence histogram count"
  prom_at_least 'histogram_quantile(0.99, rate(cosmic_channel_residence_seconds_bucket{channel="pose"}[1m]))' 0 ||
    fail "histogram_quantile over the residence buckets"
  prom_at_least 'cosmic_segment_up{segment="lcm-a"}' 1 || fail "segment lcm-a not up in Prometheus"
  dashboard_queries_run || fail "a Grafana dashboard query is not valid PromQL"
  passed
}

# Reloads keep the endpoint; a changed address moves it; a broken file changes nothing.
test_reload() {
  scenario "reload keeps the endpoint, moves it when the address changes"
  write_config "$WORK/gw.yaml" "  metrics: {listen: 127.0.0.1:9877}" \
    "  - {name: extra, subject: 0x101, class: nrt, payload: 8B, omission_degree: 3, publishers: [lcm-b], subscribers: [lcm-a]}"
  ctl gw reload >/dev/null || fail "reload"
  wait_until 10 "new channel in /metrics" metrics_have "$METRICS" 'channel="extra"' || return
  prom_at_least 'up{job="cosmicd"}' 1 || fail "Prometheus lost the target"
  write_config "$WORK/gw.yaml" "  metrics: {listen: 127.0.0.1:9877, port: 1}"
  ctl gw reload >/dev/null 2>&1 && fail "a broken file was accepted"
  scrape "$METRICS" || fail "endpoint gone after a refused reload"
  write_config "$WORK/gw.yaml" "  metrics: {listen: 127.0.0.1:9878}"
  ctl gw reload >/dev/null || fail "reload to port 9878"
  wait_until 10 "endpoint on 9878" scrape http://127.0.0.1:9878/metrics || return
  wait_until 10 "9877 closed" bash -c '! curl -sf --max-time 2 -o /dev/null http://127.0.0.1:9877/metrics'
  # Prometheus holds 9090: the endpoint stays where it was.
  write_config "$WORK/gw.yaml" "  metrics: {listen: 127.0.0.1:9090}"
  ctl gw reload >/dev/null || fail "reload to a taken port"
  wait_until 10 "move refused and logged" stderr_has "$WORK/gw.log" "metrics endpoint stays on http://127.0.0.1:9878/metrics" || return
  scrape http://127.0.0.1:9878/metrics || fail "endpoint lost after a refused move"
  write_config "$WORK/gw.yaml" ""
  ctl gw reload >/dev/null || fail "reload without metrics"
  wait_until 10 "endpoint closed" bash -c '! curl -sf --max-time 2 -o /dev/null http://127.0.0.1:9878/metrics'
  # The line follows the close (the listening thread is joined first): on a loaded host the curl above
  # can fail before it is written.
  wait_until 10 "close logged" stderr_has "$WORK/gw.log" "metrics endpoint http://127.0.0.1:9878/metrics closed" ||
    fail "close not logged"
  passed
}

# A second gateway configured for a port in use logs the error and forwards anyway.
test_port_taken() {
  scenario "a metrics port already taken is reported; the gateway runs on"
  cat >"$WORK/other.yaml" <<YAML
gateway: {name: gw-other, metrics: {listen: 127.0.0.1:9090}}
segments:
  - {name: lcm-c, type: lcm, url: "udpm://239.255.76.67:7913?ttl=0", latency_bound: 2ms}
channels: []
YAML
  start_daemon other "$WORK/other.yaml" || return
  wait_until 10 "bind error logged" stderr_has "$WORK/other.log" "metrics endpoint: cannot listen on http://127.0.0.1:9090/metrics: Address already in use" || return
  ctl other status >/dev/null || fail "gateway stopped answering"
  passed
}

write_config "$WORK/gw.yaml" "  metrics: {listen: 127.0.0.1:9877}"
start_daemon gw "$WORK/gw.yaml" || exit 1
test_endpoint
test_prometheus_scrape
test_reload
test_port_taken
[ "$FAILED" = 0 ] || { log "--- cosmicd log"; tail -30 "$WORK/gw.log" >&2; }
exit "$FAILED"
