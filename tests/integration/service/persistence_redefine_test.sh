#!/usr/bin/env bash
# Runtime changes to channels of the configuration file survive restarts (issue 5, item 4):
#  1. unbind a configuration channel, restart, bind it again with the file's own definition:
#     after the next restart it is the file's channel again, no runtime binding is recorded for
#     it and nothing is "dropped";
#  2. redefine a configuration channel at run time (unbind, bind with another period): the
#     runtime definition is what runs after a restart, and after the one after that;
#  3. unbind that redefined channel: it stays unbound after a restart.
#
# Usage (as root, through scripts/netns-run): persistence_redefine_test.sh COSMICD COSMICCTL
set -u
COSMICD=${1:?path to cosmicd}
COSMICCTL=${2:?path to cosmicctl}
DOMAIN=74
LCM_PORT=7774
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"
in_netns_or_skip

WORK=$(mktemp -d /tmp/cosmic-svc-redefine.XXXXXX)
cleanup() {
  kill_daemon
  [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

SOCKET=$WORK/run/control.sock
STATE=$WORK/state/bindings.json
write_config "$WORK/cosmicd.yaml" "$SOCKET"
ARGS=(--config "$WORK/cosmicd.yaml" --state-file "$STATE")
speed_file() {  # speed_file FILE PERIOD: the configuration's `speed` with another period
  cat >"$1" <<EOF
- {name: speed, subject: 0x000000090000A002, class: srt, period: $2, reaction_time: 50ms,
   omission_degree: 1, temp_validity: 100ms, payload: 8B, publishers: [lan], subscribers: [viz]}
EOF
}
speed_file "$WORK/speed10.yaml" 10ms  # as in the configuration
speed_file "$WORK/speed40.yaml" 40ms

# speed_load: the utilization admission reserved for `speed` on lan (depends on its period).
speed_load() {
  "$COSMICCTL" --socket "$SOCKET" --json channel speed | "$PYTHON" -S -c '
import json, sys
c = json.load(sys.stdin)["channel"]
print(next(k["value"] for h in c["admission"]["hops"] if h["segment"] == "lan" for k in h["checks"] if k["check"] == "utilization"))'
}

note "1. unbind a configuration channel, restart, bind it again as the file has it"
start_daemon "${ARGS[@]}" || finish
FILE_LOAD=$(speed_load)
ctl unbind_speed 0 unbind speed
stop_daemon
start_daemon "${ARGS[@]}" || finish
expect_channels "restart after unbind" "status"
ctl bind_speed10 0 bind "$WORK/speed10.yaml"
json_check "$STATE" '
  d["unbound"] == []
  d["bound"] == []'
stop_daemon
start_daemon "${ARGS[@]}" || finish
expect_channels "restart after binding it again" "speed status"
log_lacks "could not be restored"
[ "$(speed_load)" = "$FILE_LOAD" ] || fail "speed is not the file's definition after the restart"
stop_daemon

note "2. redefine a configuration channel at run time"
start_daemon "${ARGS[@]}" || finish
ctl unbind_speed_again 0 unbind speed
ctl bind_speed40 0 bind "$WORK/speed40.yaml"
RUNTIME_LOAD=$(speed_load)
[ "$RUNTIME_LOAD" != "$FILE_LOAD" ] || fail "the 40ms speed reserves as much as the 10ms one ($RUNTIME_LOAD)"
for restart in first second; do
  stop_daemon
  start_daemon "${ARGS[@]}" || finish
  expect_channels "$restart restart after redefining speed" "speed status"
  log_lacks "could not be restored"
  got=$(speed_load)
  [ "$got" = "$RUNTIME_LOAD" ] ||
    fail "$restart restart: speed reserves $got, the file's definition ($FILE_LOAD), not the runtime one ($RUNTIME_LOAD)"
done

note "3. unbind the redefined channel: stays unbound"
ctl unbind_speed40 0 unbind speed
stop_daemon
start_daemon "${ARGS[@]}" || finish
expect_channels "restart after unbinding the redefined speed" "status"
stop_daemon
finish
