#!/usr/bin/env bash
# Reload at scale (issue 11, README "Admission at scale"): cosmicd runs the set of
# cosmic_admission_bench (1,000 channels on one 1 Mbit/s CAN bus + 10,000 DDS <-> LCM channels,
# a 2 MB YAML file) and reloads are timed, with the file unchanged and with one channel changed:
# `cosmicctl reload` (which prints all 11,000 verdicts) and the bare request on the control
# socket. Prints figures; never passes or fails on them (the target is < 2 s for the unchanged
# file). Where the kernel has no SocketCAN the CAN segment does not start; its channels are
# admitted all the same, which is what is measured.
#   scripts/netns-run tests/bench/reload_bench.sh COSMICD COSMICCTL COSMIC_ADMISSION_BENCH [RUNS]
set -euo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 BENCH=$3 RUNS=${4:-5}
WORK=$(mktemp -d /tmp/cosmic-reload-bench.XXXXXX)
PID=
cleanup() {
  if [ -n "$PID" ]; then kill "$PID" 2>/dev/null || true; wait "$PID" 2>/dev/null || true; fi
  rm -rf "$WORK"
}
trap cleanup EXIT
ctl() { "$COSMICCTL" --socket "$WORK/control.sock" "$@"; }
now_ns() { date +%s%N; }
# CPU time (user + system) of cosmicd so far, in clock ticks.
cpu_ticks() { awk '{print $14 + $15}' "/proc/$PID/stat"; }
ms() { awk -v ns="$1" 'BEGIN {printf "%.0f", ns / 1e6}'; }
cpu_ms() { awk -v t="$1" -v hz="$(getconf CLK_TCK)" 'BEGIN {printf "%.0f", t * 1000 / hz}'; }

"$BENCH" --write-config "$WORK/big.yaml"
echo "configuration: $(grep -c '^  - name:' "$WORK/big.yaml") segments + channels, $(du -k "$WORK/big.yaml" | cut -f1) KiB"

started=$(now_ns)
"$COSMICD" --config "$WORK/big.yaml" --socket "$WORK/control.sock" --state-file "$WORK/state.json" \
  --log-level warning 2>"$WORK/cosmicd.log" &
PID=$!
until ctl status >/dev/null 2>&1; do
  kill -0 "$PID" 2>/dev/null || { echo "cosmicd exited:" >&2; tail -5 "$WORK/cosmicd.log" >&2; exit 1; }
  sleep 0.1
done
echo "cosmicd start until the control socket answers: $(ms $(($(now_ns) - started))) ms"
ctl status | head -4
# The control thread's periodic work at this scale (runtime states, health, the sd_notify STATUS
# line) with no traffic: CPU of cosmicd over 5 s of idling.
idle0=$(cpu_ticks)
sleep 5
echo "cosmicd idle with $(grep -c '^  - name:' "$WORK/big.yaml") channels and segments: $(cpu_ms $(( ($(cpu_ticks) - idle0) / 5 ))) ms CPU per second"

# The reload request on the control socket itself: milliseconds until cosmicd's answer (every
# channel's verdict with its numbers) has arrived, and the answer's size.
raw_reload() {
  python3 - "$WORK/control.sock" <<'PY'
import socket, sys, time
s = socket.socket(socket.AF_UNIX)
s.connect(sys.argv[1])
started = time.monotonic()
s.sendall(b'{"command":"reload"}\n')
answer = bytearray()
while not answer.endswith(b"\n"):
    chunk = s.recv(1 << 20)
    if not chunk:
        break
    answer += chunk
took = (time.monotonic() - started) * 1000
ok = b'"ok":true' in answer[:200] or b'"ok": true' in answer[:200]
print(f"{took:.0f} {len(answer) // 1024} {'ok' if ok else 'FAILED: ' + answer[:300].decode(errors='replace')}")
PY
}

EDITS=0
# One IP channel in the middle of the file changes its payload: the file is parsed again and
# admitted from scratch (only channels appended at the end leave the rest's admission standing).
edit_one_channel() {
  EDITS=$((EDITS + 1))
  sed -i "/^  - name: ip5000\$/,/payload:/s/payload: [0-9]*B/payload: $((100 + EDITS))B/" "$WORK/big.yaml"
}

# time_reload LABEL [PREPARE]: `cosmicctl reload` (which also prints every verdict) and the bare
# request, wall time and cosmicd's CPU time of each; PREPARE runs before each.
time_reload() {
  local before_cpu before after answered size status
  ${2:-true}
  before_cpu=$(cpu_ticks)
  before=$(now_ns)
  ctl reload >"$WORK/reload.out" || { echo "reload failed: $(head -c 300 "$WORK/reload.out")" >&2; exit 1; }
  after=$(now_ns)
  printf '  %-22s cosmicctl reload %6s ms wall, cosmicd CPU %6s ms' "$1" "$(ms $((after - before)))" \
    "$(cpu_ms $(($(cpu_ticks) - before_cpu)))"
  ${2:-true}
  before_cpu=$(cpu_ticks)
  read -r answered size status < <(raw_reload)
  [ "$status" = ok ] || { echo; echo "reload failed: $status" >&2; exit 1; }
  printf ' | request alone %6s ms, cosmicd CPU %6s ms, answer %s KiB\n' "$answered" \
    "$(cpu_ms $(($(cpu_ticks) - before_cpu)))" "$size"
}

echo "reload, $RUNS runs each: cosmicctl reload, then another reload as a bare control-socket request"
for _ in $(seq "$RUNS"); do time_reload "unchanged file"; done
for _ in $(seq "$RUNS"); do time_reload "one channel changed" edit_one_channel; done
