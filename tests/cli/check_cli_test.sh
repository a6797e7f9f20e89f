#!/usr/bin/env bash
# `cosmicctl check` end to end: exit codes 0/1/2, the --json contract, FILE:LINE:COL errors.
# Usage: check_cli_test.sh PATH_TO_cosmicctl PROJECT_SOURCE_DIR
set -u

. "$(dirname "${BASH_SOURCE[0]}")/cli_lib.sh"

# 1. The bundled robot: every channel bound, exit 0, JSON in the documented shape.
run robot_json 0 check "$SRC/config/robot.yaml" --json
json_check robot_json '
  set(d) == {"segments", "channels"}
  len(d["channels"]) == 8
  all(c["verdict"] == "bound" for c in d["channels"])
  all(c["reasons"] == [] for c in d["channels"])
  all({"name", "type", "utilization", "max_utilization"} <= set(s) for s in d["segments"])
  all({"name", "class", "verdict", "reasons", "hops", "end_to_end"} <= set(c) for c in d["channels"])
  all({"latency_s", "reaction_time_s", "ok"} <= set(c["end_to_end"]) for c in d["channels"])
  all({"segment", "role", "checks"} <= set(h) for c in d["channels"] for h in c["hops"])
  all(h["role"] in ("publisher", "subscriber") for c in d["channels"] for h in c["hops"])
  all(("can" in h) == (h["segment"] == "body-can") for c in d["channels"] for h in c["hops"])
  all({"priority", "can_id", "etag", "frame_bytes", "transmission_time_s", "response_time_s"} <= set(h["can"]) for c in d["channels"] for h in c["hops"] if "can" in h)
  all(h["can"]["can_id"] < 2**29 for c in d["channels"] for h in c["hops"] if "can" in h)
  all({"check", "value", "limit", "unit", "ok"} <= set(k) for c in d["channels"] for h in c["hops"] for k in h["checks"])
  all(k["ok"] for c in d["channels"] for h in c["hops"] for k in h["checks"])
  all(s["utilization"] <= s["max_utilization"] for s in d["segments"])
'
run robot_text 0 check "$SRC/config/robot.yaml"
contains robot_text out "8 bound, 0 degraded, 0 rejected"

# 2. The overloaded example: each kind of rejection and mismatch, exit 1.
run overloaded_json 1 check "$SRC/config/overloaded.yaml" --json
json_check overloaded_json '
  {c["name"] for c in d["channels"] if c["verdict"] == "rejected"} == {"collision_warning", "emergency_stop", "camera_status", "arm_torque"}
  {c["name"] for c in d["channels"] if c["verdict"] == "degraded"} == {"trailer_axle_load", "obstacle_map", "joint_state", "speed_plot"}
  {c["name"] for c in d["channels"] if c["verdict"] == "bound"} == {"brake_pressure", "wheel_speed", "battery", "diagnostics"}
  [c["verdict"] for c in d["channels"]][-4:] == ["rejected"] * 4
'
run overloaded_text 1 check "$SRC/config/overloaded.yaml"
contains overloaded_text out "would break hrt channel brake_pressure: end-to-end latency 5.34 ms > reaction_time 5 ms"
contains overloaded_text out "R = 2 ms > reaction_time 1.5 ms on body-can"
contains overloaded_text out "payload 12 B > frame 8 B on body-can"
contains overloaded_text out "utilization 64.0% > max_utilization 50.0% on trailer-can"
contains overloaded_text out "hrt on office, which declares no real-time guarantee"
contains overloaded_text out "end-to-end latency 5.5 ms > reaction_time 5 ms"
contains overloaded_text out ">= temp_validity 5 ms: events would arrive stale"
contains overloaded_text out "omission_degree 0 < 1 on viz, which does not retransmit"
contains overloaded_text out "4 bound, 4 degraded, 4 rejected"

# 3. A deployment asking more than a 125 kbit/s bus can give: rejected channels, R against
#    reaction_time, exit 1. Four HRT 8 B frames (1.28 ms each) every 5 ms, 3 ms reaction time
#    (equal deadlines: the subject orders them). front and rear: R = 1.28 (blocking) + 1.28 =
#    2.56 ms, bound; side, roof: R = 1.28 + 1.28 (front, rear) + 1.28 = 3.84 ms > 3 ms, rejected.
cat >"$WORK/slow_bus.yaml" <<'EOF'
gateway: {residence_bound: 100us}
segments:
  - {name: slow-can, type: can, interface: vcan0, bitrate: 125kbit/s, max_utilization: 90%}
  - {name: lan, type: dds, realtime: true, latency_bound: 100us}
channels:
  - {name: front, subject: 1, class: hrt, period: 5ms, reaction_time: 3ms, payload: 8B, publishers: [slow-can], subscribers: [lan]}
  - {name: rear, subject: 2, class: hrt, period: 5ms, reaction_time: 3ms, payload: 8B, publishers: [slow-can], subscribers: [lan]}
  - {name: side, subject: 3, class: hrt, period: 5ms, reaction_time: 3ms, payload: 8B, publishers: [slow-can], subscribers: [lan]}
  - {name: roof, subject: 4, class: hrt, period: 5ms, reaction_time: 3ms, payload: 8B, publishers: [slow-can], subscribers: [lan]}
EOF
run slow_bus_json 1 check "$WORK/slow_bus.yaml" --json
json_check slow_bus_json '
  [c["verdict"] for c in d["channels"]] == ["bound", "bound", "rejected", "rejected"]
  [c["name"] for c in d["channels"]] == ["front", "rear", "side", "roof"]
  all(any(k["check"] == "response_time" and not k["ok"] and k["value"] > k["limit"] == 0.003 for h in c["hops"] for k in h["checks"]) for c in d["channels"][2:])
  all(abs(c["hops"][0]["can"]["response_time_s"] - 0.00384) < 1e-12 for c in d["channels"][2:])
  all(abs(c["hops"][0]["can"]["response_time_s"] - 0.00256) < 1e-12 for c in d["channels"][:2])
'
run slow_bus_text 1 check "$WORK/slow_bus.yaml"
contains slow_bus_text out "R = 3.84 ms > reaction_time 3 ms on slow-can"
contains slow_bus_text out "2 bound, 0 degraded, 2 rejected"

# 4. A broken file: every error as FILE:LINE:COL on stderr, exit 2, nothing on stdout.
BROKEN="$SRC/tests/unit/bad_configs/several_errors.yaml"
run broken 2 check "$BROKEN"
contains broken err "$BROKEN:2:16: gateway.can_node_id: '300' is out of range"
contains broken err "$BROKEN:7:14: segments[0].bitrate:"
contains broken err "$BROKEN:10:5: segments[1].colour: unknown key 'colour'"
contains broken err "$BROKEN:23:19: channels[1].subscribers[0]:"
contains broken err "7 error(s) in $BROKEN"
[ -s "$WORK/broken.out" ] && fail "broken: unexpected stdout"
run broken_json 2 check "$BROKEN" --json
json_check broken_json '
  len(d["errors"]) == 7
  all({"file", "line", "column", "path", "message", "valid", "text"} <= set(e) for e in d["errors"])
  d["errors"][0]["line"] == 2 and d["errors"][0]["column"] == 16
'
run syntax 2 check "$SRC/tests/unit/bad_configs/yaml_syntax_error.yaml"
contains syntax err "yaml_syntax_error.yaml:7:10: YAML syntax error"

# 5. A missing file: exit 2, named on stderr.
run missing 2 check "$WORK/no-such-file.yaml"
contains missing err "$WORK/no-such-file.yaml:0:0: cannot read the file"

# 6. Usage errors are not configuration errors.
run usage 64 check

# 7. Background traffic from a DBC (issue 19): sixteen 8-byte frames 0x010..0x01F every 5 ms
#    (86.4 % of 500 kbit/s) beat the gateway's SRT frame (base bits 0x080) in arbitration.
{
  printf 'VERSION ""\n\nNS_ :\n\nBS_:\n\nBU_: Ecu\n\n'
  for i in $(seq 16 31); do printf 'BO_ %d F%d: 8 Ecu\n SG_ S : 0|8@1+ (1,0) [0|255] "" Vector__XXX\n\n' "$i" "$((i - 16))"; done
  printf 'BA_DEF_ BO_ "GenMsgCycleTime" INT 0 65535;\nBA_DEF_DEF_ "GenMsgCycleTime" 5;\n'
} >"$WORK/busy.dbc"
cat >"$WORK/busy.yaml" <<'YAML'
gateway: {name: gw, residence_bound: 500us}
segments:
  - {name: body, type: can, interface: vcan0, bitrate: 500kbit/s, max_utilization: 95%, background: {dbc: busy.dbc}}
  - {name: lan, type: dds, latency_bound: 1ms, realtime: true}
channels:
  - {name: speed, subject: 0x51, class: srt, period: 10ms, reaction_time: 4ms, omission_degree: 1, payload: 8B, publishers: [lan], subscribers: [body]}
YAML
run busy_text 0 check "$WORK/busy.yaml"
contains busy_text out "86.4% (16 frames)"
contains busy_text out "R = 6.14 ms > reaction_time 4 ms on body; background frames delaying it most: F0 (0x010) 270 us, F1 (0x011) 270 us, F2 (0x012) 270 us"
run busy_json 0 check "$WORK/busy.yaml" --json
json_check busy_json '
  d["segments"][0]["background"]["frames"] == 16
  abs(d["segments"][0]["background"]["utilization"] - 0.864) < 1e-9
  [b["name"] for b in d["channels"][0]["hops"][1]["background"]] == ["F0", "F1", "F2"]
  d["channels"][0]["hops"][1]["background"][0]["kind"] == "interference"
'
sed -i 's/BA_DEF_DEF_ "GenMsgCycleTime" 5;/BA_DEF_DEF_ "GenMsgCycleTime" 0;/' "$WORK/busy.dbc"
run busy_no_cycle 2 check "$WORK/busy.yaml"
contains busy_no_cycle err "$WORK/busy.dbc:9:1: segments[0].background.dbc: message F0 (0x010) has no GenMsgCycleTime"

# bind --match-timeout (issue 40): only with --replace, a duration from 0 to 60 s; refused before
# anything is sent (no gateway needed: the socket does not exist).
echo "{name: x, subject: 1, class: nrt, publishers: [a], subscribers: [b]}" >"$WORK/x.yaml"
run match_no_replace 64 --socket "$WORK/none.sock" bind --match-timeout 5s "$WORK/x.yaml"
contains match_no_replace err "--match-timeout requires --replace"
run match_too_long 64 --socket "$WORK/none.sock" bind --replace --match-timeout 61s "$WORK/x.yaml"
contains match_too_long err "--match-timeout: '61s' is not a duration from 0 to 60s"
run match_garbage 64 --socket "$WORK/none.sock" bind --replace --match-timeout soon "$WORK/x.yaml"
contains match_garbage err "--match-timeout: 'soon' is not a duration from 0 to 60s"
run match_fine_no_gateway 69 --socket "$WORK/none.sock" bind --replace --match-timeout 500ms "$WORK/x.yaml"

finish "cosmicctl check"
