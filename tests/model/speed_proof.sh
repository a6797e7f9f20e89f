#!/bin/bash
# The proof of issue 13 (docs/components.md): the paper's speed controller generated from
# config/robot.yaml by `cosmicctl gen`, filled in with Fig. 8 (speed_controller_logic.cpp), built
# as its own CMake project and run against cosmicd:
#   sensors (body segment) -> cosmicd -> speed_controller on DDS -> cosmicd -> drive (body segment)
# with the end-to-end reaction measured (cosmic-speed-probe) next to what admission promised.
# Here the body segment is LCM in a private network namespace (the DDS/LCM-only version of the
# proof: the CAN kernel modules exist only in scripts/can-vm); every channel keeps robot.yaml's
# definition.
#   speed_proof.sh COSMICD COSMICCTL SPEED_PROBE ROBOT_YAML [COUNT]
set -u
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 PROBE=$3 ROBOT=$4 COUNT=${5:-20}
HERE=$(cd "$(dirname "$0")" && pwd)
WORK=$(mktemp -d /tmp/cosmic-proof.XXXXXX)
PIDS=()
trap 'for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; rm -rf "$WORK"' EXIT
fail() {
  echo "FAIL: $*" >&2
  [ -s "$WORK/cosmicd.log" ] && tail -n 20 "$WORK/cosmicd.log" | sed 's/^/cosmicd: /' >&2
  exit 1
}
wait_until() {  # wait_until SECONDS WHAT CMD...: polls CMD until it succeeds
  local deadline=$((SECONDS + $1)) what=$2
  shift 2
  until "$@" >/dev/null 2>&1; do
    [ "$SECONDS" -lt "$deadline" ] || fail "timed out waiting for $what"
    sleep 0.05
  done
}

# 1. robot.yaml with the body bus as an LCM group (real-time declared, as the CAN bus would be).
python3 - "$ROBOT" "$WORK/robot-ip.yaml" "$WORK/control.sock" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
text = re.sub(r"  - name: body-can\n    type: can\n(    .*\n)+?(?=  - name:)",
              "  - name: body-can\n    type: lcm\n    url: udpm://239.255.76.68:7668?ttl=0\n    latency_bound: 1ms\n    realtime: true\n", text)
text = re.sub(r"control_socket: .*", "control_socket: " + sys.argv[3], text)
open(sys.argv[2], "w").write(text)
PY
"$COSMICCTL" --json check "$WORK/robot-ip.yaml" >"$WORK/check.json"

# 2. Generate, fill in Fig. 8, build as its own CMake project.
"$COSMICCTL" gen "$ROBOT" --component speed_controller --output "$WORK/sc" 2>"$WORK/gen.log" || fail "gen: $(cat "$WORK/gen.log")"
cp "$HERE/speed_controller_logic.cpp" "$WORK/sc/speed_controller_logic.cpp"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
CCACHE_BASEDIR="$WORK" cmake -S "$WORK/sc" -B "$WORK/sc/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >"$WORK/build.log" 2>&1 &&
  CCACHE_BASEDIR="$WORK" nice cmake --build "$WORK/sc/build" >>"$WORK/build.log" 2>&1 || fail "the generated project does not build: $(tail -30 "$WORK/build.log")"

# 3. cosmicd, the generated component (asking cosmicd for its channels first), the probe.
"$COSMICD" --config "$WORK/robot-ip.yaml" --socket "$WORK/control.sock" --state-file "$WORK/state" 2>"$WORK/cosmicd.log" &
PIDS+=($!)
wait_until 30 "cosmicd" "$COSMICCTL" --socket "$WORK/control.sock" status
"$WORK/sc/build/speed_controller" --check "$WORK/control.sock" >"$WORK/sc.out" 2>&1 &
PIDS+=($!)
wait_until 30 "speed_controller ready" grep -q "speed_controller: ready on dds:0" "$WORK/sc.out"
echo "speed_controller asked cosmicd:"; grep -v ready "$WORK/sc.out" | sed 's/^/  /'
"$PROBE" --body "lcm:udpm://239.255.76.68:7668?ttl=0" --lan dds:0 --count "$COUNT" >"$WORK/probe.out" 2>&1
probe_status=$?
cat "$WORK/probe.out" | grep -v '^sample' | sed 's/^/probe: /'
[ $probe_status -eq 0 ] || fail "the chain did not carry every step (probe exit $probe_status)"
"$COSMICCTL" --socket "$WORK/control.sock" diagram "$ROBOT" >"$WORK/live.svg" || fail "live diagram"
grep -q "forwarded" "$WORK/live.svg" || fail "the live diagram has no counters"

# 4. Measured against promised: actual_speed's end-to-end bound + one controller period + speed's.
python3 - "$WORK/check.json" "$(tail -1 "$WORK/probe.out")" <<'PY'
import json, sys
report = {c["name"]: c for c in json.load(open(sys.argv[1]))["channels"]}
measured = json.loads(sys.argv[2])
e2e = lambda n: report[n]["end_to_end"]["latency_s"] * 1e6
period = 10_000  # speed's period in robot.yaml: the controller publishes at most this late
promised = e2e("actual_speed") + period + e2e("speed")
print(f"{'':34} {'p50':>9} {'p99':>9} {'max':>9}")
print(f"{'measured sensor -> drive (us)':34} {measured['p50_us']:9.0f} {measured['p99_us']:9.0f} {measured['max_us']:9.0f}   ({measured['samples']} samples)")
print(f"{'promised (us)':34} {'':>9} {'':>9} {promised:9.0f}   = actual_speed {e2e('actual_speed'):.0f} + period {period} + speed {e2e('speed'):.0f}")
print("obstacle: speed 0 sent to the drive" if measured["obstacle_stop"] else "obstacle: no stop")
PY
