#!/usr/bin/env bash
# FMUs as components in cosmicd (issue 38, item 3; docs/fmu.md "Timing and admission"), end to end
# over real LCM: an FMU file (a zip with modelDescription.xml and a binary for this platform, which
# cosmicd reads and never loads) in the configuration's fmus:, and reports sent on the control
# socket as cosmic-fmu sends them.
#   - cosmicctl check refuses a step shorter than an output channel's period, located at
#     fmus[0].step, and shows the reason of a step longer than its temp_validity (degraded);
#   - cosmicctl fmus lists the FMU with "no report" until its runner reports, then its state, steps
#     and worst step with its share of the step; cosmicctl channel shows the FMU's part;
#   - a report of an FMU the configuration does not have is refused;
#   - a worst step beyond the step flags the output channel violated at run time (cosmicctl
#     channels, status, the log) with the reason, and cosmicctl fmus says so;
#   - a report older than 3 s is shown stale and flags nothing.
#   fmu_report_test.sh COSMICD COSMICCTL
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2
WORK=$(mktemp -d /tmp/cosmic-fmu.XXXXXX)
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
trap 'cleanup; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT

# The FMU: FMI 2.0 co-simulation, input actual_speed, output u.
/usr/bin/python3 - "$WORK/speed.fmu" <<'PY'
import sys, zipfile
description = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Speed" guid="{speed}">
  <CoSimulation modelIdentifier="Speed"/>
  <DefaultExperiment stepSize="0.01"/>
  <ModelVariables>
    <ScalarVariable name="actual_speed" valueReference="1" causality="input"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="u" valueReference="2" causality="output"><Real/></ScalarVariable>
  </ModelVariables>
  <ModelStructure/>
</fmiModelDescription>
"""
with zipfile.ZipFile(sys.argv[1], "w") as fmu:
    fmu.writestr("modelDescription.xml", description)
    fmu.writestr("binaries/linux64/Speed.so", b"\x7fELF (never loaded by cosmicd)")
PY

# config STEP [DRIVE_EXTRA]: speed comes from logbook to the FMU on viz; drive goes back.
config() {
  cat <<YAML
gateway: {name: gw-fmu, clean_interval: 1s}
segments:
  - {name: viz, type: lcm, url: "udpm://239.255.76.67:7841?ttl=0", latency_bound: 2ms}
  - {name: logbook, type: lcm, url: "udpm://239.255.76.67:7842?ttl=0", latency_bound: 2ms}
channels:
  - {name: speed, subject: 0x400, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1,
     publishers: [logbook], subscribers: [viz], type: {fields: [{name: v, type: float64}]}}
  - {name: drive, subject: 0x401, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1${2:-},
     publishers: [viz], subscribers: [logbook], type: {fields: [{name: v, type: float64}]}}
fmus:
  - {name: speed_fmu, fmu: speed.fmu, segment: viz, step: $1, inputs: {actual_speed: speed.v}, outputs: {u: drive.v}}
YAML
}

# send_report JSON: one request line on the control socket, as the runner sends it; prints the answer.
send_report() {
  /usr/bin/python3 - "$WORK/g.sock" "$1" <<'PY'
import socket, sys
s = socket.socket(socket.AF_UNIX)
s.connect(sys.argv[1])
s.sendall(sys.argv[2].encode() + b"\n")
print(s.makefile().readline().strip())
PY
}
report() {  # report WORST_STEP_NS
  send_report '{"command":"fmu_report","name":"speed_fmu","state":"running","step_ns":10000000,"steps":1234,"late_steps":2,"worst_step_ns":'"$1"',"p99_step_ns":300000,"skipped":{"actual_speed":3}}'
}
runtime_state() { ctl g --json channel "$1" | python3 -c 'import json,sys; print(json.load(sys.stdin)["channel"]["runtime_state"])'; }
is_violated() { [ "$(runtime_state drive)" = violated ]; }
is_bound() { [ "$(runtime_state drive)" = bound ]; }
fmus_has() { ctl g fmus | grep -qF -- "$1"; }

scenario "cosmicctl check: a step shorter than the period is located, one longer than temp_validity degrades"
config 5ms >"$WORK/fast.yaml"
"$COSMICCTL" check "$WORK/fast.yaml" >"$WORK/fast.out" 2>&1
code=$?
[ "$code" -eq 2 ] || fail "check of a 5 ms step exited $code, expected 2"
grep -qF "fast.yaml:11:59: fmus[0].step: 5ms publishes 'drive' every 5 ms, faster than its period 10 ms (a step at least the period of every output channel)" "$WORK/fast.out" ||
  fail "check: no located step error: $(cat "$WORK/fast.out")"
config 40ms ", temp_validity: 30ms" >"$WORK/slow.yaml"
"$COSMICCTL" check "$WORK/slow.yaml" >"$WORK/slow.out" 2>&1 || fail "check of a 40 ms step exited $?: $(cat "$WORK/slow.out")"
grep -Eq '^drive +srt +degraded ' "$WORK/slow.out" || fail "check: drive not degraded: $(cat "$WORK/slow.out")"
grep -qF -- "- fmu speed_fmu publishes every 40 ms (its step), longer than temp_validity 30 ms: between two steps subscribers hold a value older than its validity" "$WORK/slow.out" ||
  fail "check: no validity reason: $(cat "$WORK/slow.out")"
passed

config 10ms >"$WORK/g.yaml"
start_daemon g "$WORK/g.yaml" || exit 1

scenario "the FMU is listed without a report until its runner reports"
ctl g fmus >"$WORK/fmus.txt" || fail "cosmicctl fmus failed"
grep -Eq '^speed_fmu +speed\.fmu +2\.0 +viz +10 ms +- +- +- +- +no report$' "$WORK/fmus.txt" ||
  fail "cosmicctl fmus before a report: $(cat "$WORK/fmus.txt")"
answer=$(report 412000)
[ "$answer" = '{"ok":true}' ] || fail "fmu_report answered $answer"
ctl g fmus >"$WORK/fmus.txt"
grep -Eq '^speed_fmu +speed\.fmu +2\.0 +viz +10 ms +running +1234 +2 +412 us \(4\.1%\) +[0-9.]+s ago$' "$WORK/fmus.txt" ||
  fail "cosmicctl fmus after a report: $(cat "$WORK/fmus.txt")"
grep -qF "skipped input events: actual_speed=3" "$WORK/fmus.txt" || fail "cosmicctl fmus: no skipped events: $(cat "$WORK/fmus.txt")"
ctl g channel drive >"$WORK/drive.txt" || fail "cosmicctl channel drive failed"
grep -qF "speed_fmu publishes on viz, step 10 ms: running, worst step 412 us (4.1%), 2 late steps" "$WORK/drive.txt" ||
  fail "cosmicctl channel drive: no FMU part: $(cat "$WORK/drive.txt")"
ctl g channel speed | grep -qF "speed_fmu subscribes on viz, step 10 ms: running" || fail "cosmicctl channel speed: no FMU part"
unknown=$(send_report '{"command":"fmu_report","name":"plant","state":"running","step_ns":1,"steps":0,"late_steps":0,"worst_step_ns":0,"p99_step_ns":0,"skipped":{}}')
case $unknown in
  *'"not_found"'*"no FMU named 'plant' in the running configuration (its FMUs: speed_fmu); nothing kept"*) ;;
  *) fail "a report of an unknown FMU answered $unknown" ;;
esac
passed

scenario "a worst step beyond the step flags the output channel violated, with the reason"
reason="fmu speed_fmu's worst step 12.1 ms exceeds its step 10 ms"
answer=$(report 12100000)
[ "$answer" = '{"ok":true}' ] || fail "fmu_report answered $answer"
wait_until 10 "drive violated at run time" is_violated
[ "$(runtime_state speed)" = bound ] || fail "speed, the FMU's input, is $(runtime_state speed)"
ctl g channels | grep -Eq '^drive +srt +bound +VIOLATED ' || fail "cosmicctl channels: drive not VIOLATED: $(ctl g channels)"
ctl g status | grep -qF "1 violated at run time" || fail "cosmicctl status: $(ctl g status)"
grep -qF "channel drive violated its admitted bounds: $reason" "$WORK/g.log" || fail "log: no violation line with the reason"
fmus_has "! $reason: its output channels are flagged violated (drive)" || fail "cosmicctl fmus: no overrun line: $(ctl g fmus)"
ctl g channel drive | grep -qF "! $reason" || fail "cosmicctl channel drive: no overrun line"
passed

scenario "a report older than 3 s is stale and flags nothing"
wait_until 10 "the report shown stale" fmus_has "stale ("
fmus_has "! $reason" && fail "a stale report still flags: $(ctl g fmus)"
# clean_interval 1s: bound again a second after the report went stale.
wait_until 10 "drive bound again" is_bound
passed

[ "$FAILED" = 0 ] || exit 1
log "all scenarios passed"
