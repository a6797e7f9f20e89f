#!/bin/bash
# The proof of issue 13 (docs/components.md): the paper's speed controller generated from
# config/robot.yaml by `cosmicctl gen`, filled in with Fig. 8 (speed_controller_logic.cpp), built
# as its own CMake project and run against cosmicd:
#   sensors (body segment) -> cosmicd -> speed_controller on DDS -> cosmicd -> drive (body segment)
# with the end-to-end reaction measured (cosmic-speed-probe) next to what admission promised.
# Environment:
#   PROOF_BODY=lcm (default)  the body bus is an LCM group (DDS/LCM-only proof; any host)
#   PROOF_BODY=can            the body bus is robot.yaml's CAN bus on vcan0 (inside scripts/can-vm)
#   PROOF_CONTROLLER_DIR=DIR  where the controller is generated and built (default: a temp dir)
#   PROOF_PREBUILT=1          use the controller already built in PROOF_CONTROLLER_DIR
#   PROOF_BUILD_ONLY=1        only generate and build the controller into PROOF_CONTROLLER_DIR
#                             (no network namespace needed; scripts/demo builds it on the host
#                             before running the proof inside scripts/can-vm)
#   PROOF_FMU="RUNNER FMU"    the controller is an FMU (issue 38, docs/fmu.md "Demo"): RUNNER is
#                             cosmic-fmu, FMU the SpeedController test FMU (a PI controller, run
#                             proportional: speed = command - actual_speed); actual_speed, command
#                             and speed become typed {value: int32} channels (the same 4 bytes), the
#                             component speed_controller an `fmus:` entry with a 10 ms step. Nothing
#                             is generated; the promise counts the step where Fig. 8 has the period
#   PROOF_SANITIZED=1         the programs are built with a sanitizer (tests/model/CMakeLists.txt
#                             sets it in an ASan or TSan build): everything is several times slower,
#                             so the waits below are longer; what the proof checks stays the same
# Every channel keeps robot.yaml's definition.
#   speed_proof.sh COSMICD COSMICCTL SPEED_PROBE ROBOT_YAML [COUNT]
set -u
BUILD_ONLY=${PROOF_BUILD_ONLY:-0}
if [ "$BUILD_ONLY" = 1 ]; then
  [ -n "${PROOF_CONTROLLER_DIR:-}" ] || { echo "PROOF_BUILD_ONLY=1 needs PROOF_CONTROLLER_DIR" >&2; exit 2; }
else
  [ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
fi
COSMICD=$1 COSMICCTL=$2 PROBE=$3 ROBOT=$4 COUNT=${5:-20}
HERE=$(cd "$(dirname "$0")" && pwd)
WORK=$(mktemp -d /tmp/cosmic-proof.XXXXXX)
PIDS=() NAMES=() LOGS=()  # cosmicd and the controller, running in the background
trap 'for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; rm -rf "$WORK"' EXIT
fail() {
  echo "FAIL: $*" >&2
  [ -s "$WORK/cosmicd.log" ] && tail -n 20 "$WORK/cosmicd.log" | sed 's/^/cosmicd: /' >&2
  exit 1
}
ended() {  # ended NAME STATUS LOG: a program of the chain ended; its sanitizer report (or its last lines), FAIL
  local report='Sanitizer|runtime error'
  if grep -q -E "$report" "$3" 2>/dev/null; then
    grep -A 80 -m 1 -E "$report" "$3" | sed "s/^/$1: /" >&2
  else
    tail -n 20 "$3" 2>/dev/null | sed "s/^/$1: /" >&2
  fi
  echo "FAIL: $1 exited with status $2" >&2
  exit 1
}
check_running() {  # fails at once when cosmicd or the controller is no longer running
  local i
  for i in "${!PIDS[@]}"; do
    kill -0 "${PIDS[$i]}" 2>/dev/null && continue  # bash reaps its children as they end: no zombies
    wait "${PIDS[$i]}"
    ended "${NAMES[$i]}" $? "${LOGS[$i]}"
  done
}
wait_until() {  # wait_until SECONDS WHAT CMD...: polls CMD until it succeeds
  local deadline=$((SECONDS + $1)) what=$2
  shift 2
  until "$@" >/dev/null 2>&1; do
    check_running
    [ "$SECONDS" -lt "$deadline" ] || fail "timed out waiting for $what"
    sleep 0.05
  done
}

# The system interpreter, as the CAN tests use it: a version manager's shim (pyenv) spawns dozens
# of processes per start, 7 s each time inside the emulated CAN VM.
python=/usr/bin/python3
[ -x "$python" ] || python=$(command -v python3) || { echo "speed proof: python3 not found" >&2; exit 2; }
BODY=${PROOF_BODY:-lcm}
SC=${PROOF_CONTROLLER_DIR:-$WORK/sc}
read -r FMU_RUNNER FMU_FILE <<<"${PROOF_FMU:-}"
CONTROLLER=${FMU_RUNNER:+fmu}
CONTROLLER=${CONTROLLER:-fig8}
body_segment="lcm:udpm://239.255.76.68:7668?ttl=0"
# How long to wait for cosmicd, the controller and the chain to carry (WAIT_S), and from the
# obstacle until the drive hears speed 0 (STOP_S); only a failing run waits that long. The obstacle
# goes from the probe to the controller directly, over DDS endpoints of the probe's that may still
# be matching when it gets there: Fast DDS discovery is slow in the VM, whose CPU is emulated, and
# more so with a sanitizer. Seen with ASan in the VM on a loaded 2-core host: the controller's
# first obstacle 0.03 to 11.2 s after the probe first sent one (those before were lost, unmatched),
# then speed 0 at the drive within 0.5 s.
WAIT_S=30 STOP_S=5
if [ "$BODY" = can ] && [ "$BUILD_ONLY" != 1 ]; then
  body_segment="can:vcan0?node=9"  # the probe's own TxNode; etags by GET_ETAG
  WAIT_S=180 STOP_S=60              # the VM emulates its CPU: everything starts slower
  ip link add vcan0 type vcan 2>/dev/null || true
  ip link set vcan0 up
fi
if [ "${PROOF_SANITIZED:-0}" = 1 ]; then
  WAIT_S=$((WAIT_S * 2)) STOP_S=$((STOP_S < 60 ? 60 : STOP_S))
fi

# 1. robot.yaml with its own control socket; for lcm the body bus becomes an LCM group
#    (real-time declared, as the CAN bus would be).
#    With PROOF_FMU the controller's channels are typed and the controller is the FMU.
"$python" - "$ROBOT" "$WORK/robot-run.yaml" "$WORK/control.sock" "$BODY" "$CONTROLLER" "${FMU_FILE:-}" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
if sys.argv[4] == "lcm":
  text = re.sub(r"  - name: body-can\n    type: can\n(    .*\n)+?(?=  - name:)",
                "  - name: body-can\n    type: lcm\n    url: udpm://239.255.76.68:7668?ttl=0\n    latency_bound: 1ms\n    realtime: true\n", text)
text = re.sub(r"control_socket: .*", "control_socket: " + sys.argv[3], text)
if sys.argv[5] == "fmu":
  for channel in ("speed", "command", "actual_speed"):
    text = re.sub(r"(  - name: %s\n(    .*\n)*?)    payload: 4B\n" % channel,
                  r"\1    type: {fields: [{name: value, type: int32, unit: mm/s}]}\n", text, count=1)
  text = re.sub(r"  - name: speed_controller .*\n(    .*\n)+", "", text)
  text += ("fmus:\n  - name: speed_controller\n    fmu: %s\n    segment: lan\n    step: 10ms\n"
           "    inputs: {speed: actual_speed.value, setpoint: command.value}\n    outputs: {drive: speed.value}\n"
           "    parameters: {kp: 1, ki: 0, drive_min: -1000, drive_max: 1000}\n" % sys.argv[6])
open(sys.argv[2], "w").write(text)
PY
"$COSMICCTL" --json check "$WORK/robot-run.yaml" >"$WORK/check.json"

# 2. Generate, fill in Fig. 8, build as its own CMake project.
if [ "$CONTROLLER" = fmu ]; then
  : # nothing to generate: cosmic-fmu runs the FMU the configuration names
elif [ "${PROOF_PREBUILT:-0}" = 1 ]; then
  [ -x "$SC/build/speed_controller" ] || fail "no controller built in $SC (run the lcm proof first)"
else
  "$COSMICCTL" gen "$ROBOT" --component speed_controller --output "$SC" 2>"$WORK/gen.log" || fail "gen: $(cat "$WORK/gen.log")"
  cp "$HERE/speed_controller_logic.cpp" "$SC/speed_controller_logic.cpp"
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  CCACHE_BASEDIR="$SC" cmake -S "$SC" -B "$SC/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >"$WORK/build.log" 2>&1 &&
    CCACHE_BASEDIR="$SC" nice cmake --build "$SC/build" >>"$WORK/build.log" 2>&1 || fail "the generated project does not build: $(tail -30 "$WORK/build.log")"
fi
if [ "$BUILD_ONLY" = 1 ]; then
  echo "speed_controller generated from $ROBOT and built: $SC/build/speed_controller"
  exit 0
fi

# 3. cosmicd, the generated component (asking cosmicd for its channels first), the probe.
"$COSMICD" --config "$WORK/robot-run.yaml" --socket "$WORK/control.sock" --state-file "$WORK/state" 2>"$WORK/cosmicd.log" &
PIDS+=($!) NAMES+=(cosmicd) LOGS+=("$WORK/cosmicd.log")
# cosmicd opens its control socket once its segments are up; a sanitized cosmicctl takes seconds
# to start in the VM, so it asks once the socket is there instead of polling.
wait_until "$WAIT_S" "cosmicd's control socket" test -S "$WORK/control.sock"
wait_until "$WAIT_S" "cosmicd" "$COSMICCTL" --socket "$WORK/control.sock" status
if [ "$CONTROLLER" = fmu ]; then
  "$FMU_RUNNER" --config "$WORK/robot-run.yaml" --name speed_controller --work-dir "$WORK" \
    --report-interval 200ms >"$WORK/sc.out" 2>&1 &
  PIDS+=($!) NAMES+=(speed_controller) LOGS+=("$WORK/sc.out")
  wait_until "$WAIT_S" "the speed_controller FMU stepping" grep -q "initialized on segment lan" "$WORK/sc.out"
  grep "initialized" "$WORK/sc.out" | sed 's/^.* info //; s/^/  /'
else
  "$SC/build/speed_controller" --check "$WORK/control.sock" >"$WORK/sc.out" 2>&1 &
  PIDS+=($!) NAMES+=(speed_controller) LOGS+=("$WORK/sc.out")
  wait_until "$WAIT_S" "speed_controller ready" grep -q "speed_controller: ready on dds:0" "$WORK/sc.out"
  echo "speed_controller asked cosmicd:"; grep -v ready "$WORK/sc.out" | sed 's/^/  /'
fi
"$PROBE" --body "$body_segment" --lan dds:0 --count "$COUNT" --ready-s "$WAIT_S" --stop-s "$STOP_S" \
  --controller "$CONTROLLER" >"$WORK/probe.out" 2>&1
probe_status=$?
cat "$WORK/probe.out" | grep -v '^sample' | sed 's/^/probe: /'
check_running
[ $probe_status -eq 0 ] || fail "the chain did not carry every step (probe exit $probe_status)"
"$COSMICCTL" --socket "$WORK/control.sock" diagram "$ROBOT" >"$WORK/live.svg" || fail "live diagram"
grep -q "forwarded" "$WORK/live.svg" || fail "the live diagram has no counters"

# 4. Measured against promised: actual_speed's end-to-end bound + one controller period (the FMU's
#    step: an event waits at most one step to be taken, and the step publishes) + speed's.
"$python" - "$WORK/check.json" "$(tail -1 "$WORK/probe.out")" "$CONTROLLER" <<'PY'
import json, os, sys
report = {c["name"]: c for c in json.load(open(sys.argv[1]))["channels"]}
measured = json.loads(sys.argv[2])
e2e = lambda n: report[n]["end_to_end"]["latency_s"] * 1e6
period = 10_000  # speed's period in robot.yaml (the FMU's step): the controller publishes at most this late
promised = e2e("actual_speed") + period + e2e("speed")
print(f"{'':34} {'p50':>9} {'p99':>9} {'max':>9}")
print(f"{'measured sensor -> drive (us)':34} {measured['p50_us']:9.0f} {measured['p99_us']:9.0f} {measured['max_us']:9.0f}   ({measured['samples']} samples)")
print(f"{'promised (us)':34} {'':>9} {'':>9} {promised:9.0f}   = actual_speed {e2e('actual_speed'):.0f} + period {period} + speed {e2e('speed'):.0f}")
if sys.argv[3] == "fig8":
  print(f"obstacle: speed 0 sent to the drive {measured['stop_ms']:.0f} ms after the first obstacle event"
        if measured["obstacle_stop"] else "obstacle: no stop")
# The verdict on the worst case (a figure, not a pass/fail test: the proof checks that the chain
# carries every step; timing in the emulated CAN VM is not a host's).
if measured["max_us"] <= promised:
    print(f"{'verdict':34} met: max {measured['max_us']:.0f} us <= promised {promised:.0f} us")
else:
    why = (" (inside the emulated CAN VM, whose software CPU is tens of times slower than a host)"
           if os.environ.get("CAN_VM") == "1" else "")
    print(f"{'verdict':34} MISSED: max {measured['max_us']:.0f} us > promised {promised:.0f} us{why}")
PY

# 5. The controller and cosmicd stop on SIGTERM and exit 0. In a sanitizer build a report in either
#    (while running or while stopping: a handler outliving its state, a race, a leak) fails the proof
#    here; the probe's own exit status is checked above.
stop_cleanly() {  # stop_cleanly INDEX: the program PIDS[INDEX]
  local pid=${PIDS[$1]} deadline=$((SECONDS + WAIT_S))
  kill -TERM "$pid" 2>/dev/null
  while kill -0 "$pid" 2>/dev/null; do
    [ "$SECONDS" -lt "$deadline" ] || fail "${NAMES[$1]} did not stop within $WAIT_S s of SIGTERM"
    sleep 0.05
  done
  wait "$pid"
  local status=$?
  [ "$status" -eq 0 ] || ended "${NAMES[$1]}" "$status" "${LOGS[$1]}"
}
stop_cleanly 1  # the controller, then cosmicd
[ "$CONTROLLER" = fig8 ] || grep "stopped:" "$WORK/sc.out" | sed 's/^.* info fmu /runner: /'
stop_cleanly 0
PIDS=()
