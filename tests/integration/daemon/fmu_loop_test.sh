#!/usr/bin/env bash
# FMUs as components (issue 38, items 1, 2 and 5; docs/fmu.md) end to end through cosmicd:
#   - the paper's speed loop as two FMUs in two cosmic-fmu processes on two networks: the Plant
#     (FMI 3.0) on LCM publishes `speed` and takes `drive`, the SpeedController (FMI 2.0) on DDS
#     publishes `drive` and takes `speed` and the setpoint from `command`, which an LCM peer sends;
#     cosmicd carries speed LCM -> DDS and drive and command DDS <- LCM. Each runner steps in real
#     time (10 ms), takes the newest event of each input before a step and writes its trace;
#   - the plant's speed settles as the same loop computed in one process does
#     (closed_loop_reference.hpp: a co-simulation master coupling the two with one step of delay):
#     from the first step the plant is driven, every speed is within 0.05 m/s (5% of the setpoint)
#     of the reference's. The network adds a step of delay or two, which moves this slow loop by at
#     most 0.013 m/s (three steps more, computed); a loop that did not close (drive never arriving)
#     stays at 0 and fails, a lost setpoint leaves drive at 0;
#   - the runners' status lines count their steps (and the skipped input events), and cosmicd
#     counts the events it forwarded for them;
#   - `cosmicctl diagram` draws each FMU as a component, with its step;
#   - unpaced (--pace free), the steps run back to back with none late and the FMU's time advancing;
#   - a doStep that fails (EveryType's `fail` input, set by an event) stops its runner with exit
#     code 1 and the FMU's own message in the log.
#   fmu_loop_test.sh COSMICD COSMICCTL COSMIC_FMU COSMIC_LCM_PEER FMU_DIR LOOP_REFERENCE
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 COSMIC_FMU=$3 LCM_PEER=$4 FMU_DIR=$5 LOOP_REFERENCE=$6
WORK=$(mktemp -d /tmp/cosmic-fmu-loop.XXXXXX)
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
trap 'cleanup; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT

VIZ="udpm://239.255.76.67:7861?ttl=0"
STEPS=300

cat >"$WORK/loop.yaml" <<YAML
gateway: {name: gw-loop}
segments:
  - {name: lan, type: dds, domain: 41}
  - {name: viz, type: lcm, url: "$VIZ", latency_bound: 2ms}
channels:
  - name: speed
    subject: 0x700
    class: srt
    period: 10ms
    reaction_time: 40ms
    type: {fields: [{name: value, type: float64, unit: m/s}]}
  - name: drive
    subject: 0x701
    class: srt
    period: 10ms
    reaction_time: 40ms
    type: {fields: [{name: value, type: float64}]}
  - name: command
    subject: 0x702
    class: srt
    period: 50ms
    reaction_time: 100ms
    publishers: [viz]
    type: {fields: [{name: setpoint, type: float64, unit: m/s}]}
  - name: fault
    subject: 0x703
    class: nrt
    period: 10ms
    publishers: [viz]
    type: {fields: [{name: fail, type: bool}]}
  - name: echoed
    subject: 0x704
    class: nrt
    period: 10ms
    subscribers: [viz]
    type: {fields: [{name: real, type: float64}]}
fmus:
  - name: plant
    fmu: $FMU_DIR/Plant-fmi3.fmu
    segment: viz
    step: 10ms
    inputs: {drive: drive.value}
    outputs: {speed: speed.value}
  - name: controller
    fmu: $FMU_DIR/SpeedController-fmi2.fmu
    segment: lan
    step: 10ms
    inputs: {speed: speed.value, setpoint: command.setpoint}
    outputs: {drive: drive.value}
  - name: every
    fmu: $FMU_DIR/EveryType-fmi2.fmu
    segment: lan
    step: 10ms
    inputs: {fail: fault.fail}
    outputs: {real_out: echoed.real}
YAML
start_daemon loop "$WORK/loop.yaml" || exit 1

# 0. The Event-Channel Diagram draws the FMUs as the components they are: the plant publishes speed
#    on viz (no bare segment node for it), with its step.
"$COSMICCTL" diagram --format dot "$WORK/loop.yaml" >"$WORK/loop.dot" || fail "cosmicctl diagram exited $?"
grep -q '"P_component_plant" .*class="component fmu publisher", label="plant\\n(FMU, 10 ms)"' "$WORK/loop.dot" ||
  fail "the diagram does not draw the plant FMU: $(grep plant "$WORK/loop.dot" | head -n 2)"
grep -q '"P_component_plant" -> "channel_speed"' "$WORK/loop.dot" || fail "no P edge from the plant FMU to speed"
grep -q 'segment viz (lcm) publishes command, fault (no modelled component)' "$WORK/loop.dot" ||
  fail "the diagram's bare viz segment: $(grep P_segment_viz "$WORK/loop.dot" | head -n 1)"

# 1. The loop: both runners, then the setpoint (1.0 m/s, every 100 ms) from an LCM peer.
"$COSMIC_FMU" --config "$WORK/loop.yaml" --name plant --steps $((STEPS + 200)) --trace "$WORK/plant.csv" \
  --socket "$WORK/loop.sock" --work-dir "$WORK" 2>"$WORK/plant.log" &
PLANT=$!
PIDS+=($PLANT)
"$COSMIC_FMU" --config "$WORK/loop.yaml" --name controller --steps $((STEPS + 200)) --trace "$WORK/controller.csv" \
  --socket "$WORK/loop.sock" --work-dir "$WORK" 2>"$WORK/controller.log" &
CONTROLLER=$!
PIDS+=($CONTROLLER)
both_stepping() { [ -s "$WORK/plant.csv" ] && [ -s "$WORK/controller.csv" ] && [ "$(wc -l <"$WORK/controller.csv")" -gt 10 ]; }
wait_until 60 "both runners stepping" both_stepping || exit 1
"$LCM_PEER" pub --url "$VIZ" --channel command --count 60 --rate 10 --subject 0x702 --payload-hex 000000000000f03f &
PIDS+=($!)
wait "$PLANT"
PLANT_RC=$?
wait "$CONTROLLER"
CONTROLLER_RC=$?
[ "$PLANT_RC" = 0 ] || fail "the plant runner exited with $PLANT_RC: $(tail -n 5 "$WORK/plant.log")"
[ "$CONTROLLER_RC" = 0 ] || fail "the controller runner exited with $CONTROLLER_RC: $(tail -n 5 "$WORK/controller.log")"

"$LOOP_REFERENCE" "$STEPS" >"$WORK/reference.csv"
python3 - "$WORK/plant.csv" "$WORK/reference.csv" "$STEPS" <<'PY' || fail "the loop through cosmicd does not follow the reference"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
reference = [float(line.split(",")[1]) for line in open(sys.argv[2])]
steps = int(sys.argv[3])
driven = next((i for i, r in enumerate(rows) if float(r["drive"]) != 0.0), None)
if driven is None:
    sys.exit("the plant was never driven: no drive event reached it")
if any(float(r["speed"]) != 0.0 for r in rows[:driven]):
    sys.exit("the plant moved before it was driven")
compared = rows[driven:driven + steps]
if len(compared) < steps:
    sys.exit(f"only {len(compared)} steps after the plant was first driven (step {driven}), {steps} needed")
worst = max(abs(float(r["speed"]) - reference[j + 1]) for j, r in enumerate(compared))
final = float(compared[-1]["speed"])
print(f"plant driven from step {driven}; speed after {steps} steps {final:.4f} m/s "
      f"(reference {reference[steps]:.4f}); largest difference {worst:.4f} m/s", file=sys.stderr)
if worst > 0.05:
    sys.exit(f"speed differs from the reference by {worst:.4f} m/s (at most 0.05 allowed)")
PY
grep -q "stopped: $((STEPS + 200)) steps of 10 ms" "$WORK/plant.log" || fail "the plant's last status line: $(tail -n 2 "$WORK/plant.log")"
grep -q "stopped: $((STEPS + 200)) steps of 10 ms" "$WORK/controller.log" ||
  fail "the controller's last status line: $(tail -n 2 "$WORK/controller.log")"
field_at_least loop speed lan tx 100 || fail "cosmicd forwarded $(channel_field loop speed lan tx) speed events to the controller"
field_at_least loop drive viz tx 100 || fail "cosmicd forwarded $(channel_field loop drive viz tx) drive events to the plant"
# cosmicd keeps each runner's last report (fmu_report; docs/fmu.md, "Timing and admission").
fmus_show() { ctl loop fmus | grep -Eq "$1"; }
wait_until 10 "cosmicctl fmus: the plant's last report" \
  fmus_show "^plant +Plant-fmi3\.fmu +3\.0 +viz +10 ms +stopped +$((STEPS + 200)) " || log "$(ctl loop fmus)"
wait_until 10 "cosmicctl fmus: the controller's last report" \
  fmus_show "^controller +SpeedController-fmi2\.fmu +2\.0 +lan +10 ms +stopped +$((STEPS + 200)) " || log "$(ctl loop fmus)"

# 2. Unpaced (--pace free, as against a replay): the steps run back to back, none is late, and the
#    FMU's time still advances by the step (2000 steps: t = 20 s at the end, in far less wall time).
"$COSMIC_FMU" --config "$WORK/loop.yaml" --name plant --pace free --steps 2000 --no-report --work-dir "$WORK" \
  --trace "$WORK/free.csv" 2>"$WORK/free.log" || fail "the unpaced runner failed: $(tail -n 3 "$WORK/free.log")"
[ "$(tail -n 1 "$WORK/free.csv" | cut -d, -f1,2)" = "1999,20" ] || fail "unpaced trace ends with $(tail -n 1 "$WORK/free.csv")"
grep -q "stopped: 2000 steps of 10 ms, 0 late" "$WORK/free.log" || fail "unpaced status: $(tail -n 1 "$WORK/free.log")"
grep -q "unpaced" "$WORK/free.log" || fail "the unpaced runner does not say so"

# 3. A doStep that fails stops the runner with the FMU's own words.
"$COSMIC_FMU" --config "$WORK/loop.yaml" --name every --socket "$WORK/loop.sock" --work-dir "$WORK" \
  --trace "$WORK/every.csv" 2>"$WORK/every.log" &
EVERY=$!
PIDS+=($EVERY)
every_stepping() { [ "$(wc -l <"$WORK/every.csv" 2>/dev/null || echo 0)" -gt 5 ]; }
wait_until 60 "the EveryType runner stepping" every_stepping || exit 1
"$LCM_PEER" pub --url "$VIZ" --channel fault --count 20 --rate 20 --subject 0x703 --payload-hex 01 &
PIDS+=($!)
wait "$EVERY"
EVERY_RC=$?
[ "$EVERY_RC" = 1 ] || fail "a failed doStep: exit code $EVERY_RC, expected 1"
grep -q "fmi2DoStep returned Error; the FMU said: step at t=.* failed: the fail input is set" "$WORK/every.log" ||
  fail "the failed step's log: $(tail -n 5 "$WORK/every.log")"
grep -q "\[Error\] logStatusError: step at t=" "$WORK/every.log" || fail "the FMU's own log lines are not shown"
every_failed() {
  ctl loop --json fmus | python3 -c '
import json, sys
r = next(f for f in json.load(sys.stdin)["fmus"] if f["name"] == "every")["report"]
sys.exit(0 if r and r["state"] == "failed" and "the fail input is set" in r["message"] else 1)'
}
wait_until 10 "cosmicctl fmus: the EveryType runner failed, with the FMU's words" every_failed
[ -z "$(find "$WORK" -mindepth 1 -maxdepth 1 -name 'cosmic-fmu-*')" ] || fail "a runner left its work directory behind"

[ "$FAILED" = 0 ] && echo "fmu loop: PASS"
exit "$FAILED"
