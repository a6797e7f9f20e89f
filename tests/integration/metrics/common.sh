# Shared by the metrics tests: one cosmicd bridging two LCM groups with the metrics endpoint on,
# and HTTP helpers. Sourced after tests/integration/daemon/lib.sh; expects WORK, LCM_PEER.

LCM_A="udpm://239.255.76.67:7911?ttl=0"
LCM_B="udpm://239.255.76.67:7912?ttl=0"

# write_config FILE METRICS_LINE [EXTRA_CHANNEL_LINES]
write_config() {
  cat >"$1" <<YAML
gateway:
  name: gw-metrics
$2
segments:
  - {name: lcm-a, type: lcm, url: "$LCM_A", latency_bound: 2ms}
  - {name: lcm-b, type: lcm, url: "$LCM_B", latency_bound: 2ms}
channels:
  - {name: pose, subject: 0x100, class: nrt, payload: 64B, encoding: raw, omission_degree: 3, publishers: [lcm-a], subscribers: [lcm-b]}
${3:-}
YAML
}

# scrape URL [OUTPUT]: one GET of a metrics endpoint.
scrape() { curl -sf --max-time 5 -o "${2:-/dev/null}" "$1"; }

# metrics_have URL TEXT: the endpoint answers and its document holds TEXT.
metrics_have() { curl -sf --max-time 5 "$1" | grep -qF -- "$2"; }

# publish N: N raw 64-byte LCM messages on channel pose into lcm-a.
publish() { "$LCM_PEER" pub --url "$LCM_A" --channel pose --count "$1" --size 64 --raw --rate "${2:-2000}"; }
