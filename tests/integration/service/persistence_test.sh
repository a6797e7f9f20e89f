#!/usr/bin/env bash
# Runtime bindings survive restarts (issue 5, item 4): a channel bound at run time is bound
# again after a restart; a configuration channel unbound at run time stays unbound; reload
# makes the file the truth again; the state file is versioned JSON written atomically (no
# temporary left); a corrupted, truncated, wrong-version or malformed state file gives a clear
# error naming the file, cosmicd starts from its configuration and exits 0 on SIGTERM.
#
# Usage (as root, through scripts/netns-run): persistence_test.sh COSMICD COSMICCTL
set -u
COSMICD=${1:?path to cosmicd}
COSMICCTL=${2:?path to cosmicctl}
DOMAIN=73
LCM_PORT=7773
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"
in_netns_or_skip

WORK=$(mktemp -d /tmp/cosmic-svc-persist.XXXXXX)
cleanup() {
  kill_daemon
  [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

SOCKET=$WORK/run/control.sock
STATE=$WORK/state/bindings.json
write_config "$WORK/cosmicd.yaml" "$SOCKET"
write_extra "$WORK/plot.yaml" plot 0x000000090000A010
write_extra "$WORK/trace.yaml" trace 0x000000090000A011
ARGS=(--config "$WORK/cosmicd.yaml" --state-file "$STATE")

no_temporary() {  # no_temporary WHEN
  local left
  left=$(find "$(dirname "$STATE")" -mindepth 1 ! -name "$(basename "$STATE")" 2>/dev/null)
  [ -z "$left" ] || fail "$1: left next to the state file: $left"
}

state_check() {  # state_check WHEN PYTHON_EXPRESSIONS
  if [ ! -s "$STATE" ]; then
    fail "$1: no state file $STATE"
    return
  fi
  json_check "$STATE" "$2"
  no_temporary "$1"
}

note "a fresh start: no state file, the configuration alone, nothing written"
start_daemon "${ARGS[@]}" || finish
expect_channels "fresh start" "speed status"
[ -e "$STATE" ] && fail "cosmicd wrote $STATE without any runtime change"
log_lacks "$STATE"
log_lacks "starting from the configuration alone"

note "bind at run time, restart: still bound"
ctl bind_plot 0 bind "$WORK/plot.yaml"
expect_channels "after bind" "plot speed status"
state_check "after bind" '
  d["version"] == 1
  [b["name"] for b in d["bound"]] == ["plot"]
  d["unbound"] == []'
got=$(stat -c '%a' "$STATE")
[ "$got" = 640 ] || fail "state file has mode $got, expected 640"
stop_daemon
start_daemon "${ARGS[@]}" || finish
expect_channels "after restart" "plot speed status"
log_contains "restored runtime binding of channel plot"
ctl plot_verdict 0 --json channel plot
json_check "$WORK/plot_verdict.out" 'd["channel"]["verdict"] == "bound"'

note "unbind a configuration channel, restart: still unbound"
ctl unbind_speed 0 unbind speed
expect_channels "after unbind" "plot status"
state_check "after unbind" '
  [b["name"] for b in d["bound"]] == ["plot"]
  d["unbound"] == ["speed"]'
stop_daemon
start_daemon "${ARGS[@]}" || finish
expect_channels "after restart" "plot status"

note "unbind a runtime binding, restart: gone"
ctl bind_trace 0 bind "$WORK/trace.yaml"
ctl unbind_plot 0 unbind plot
state_check "after unbinding plot" '
  [b["name"] for b in d["bound"]] == ["trace"]
  d["unbound"] == ["speed"]'
stop_daemon
start_daemon "${ARGS[@]}" || finish
expect_channels "after restart" "status trace"

note "bind a configuration channel again: no longer recorded as unbound"
cat >"$WORK/speed.yaml" <<'EOF'
- {name: speed, subject: 0x000000090000A002, class: srt, period: 10ms, reaction_time: 50ms,
   omission_degree: 1, temp_validity: 100ms, payload: 8B, publishers: [lan], subscribers: [viz]}
EOF
ctl rebind_speed 0 bind "$WORK/speed.yaml"
state_check "after binding speed again" 'd["unbound"] == []'
# (what the file records for it, and the log at the next start: persistence_redefine_test.sh)
stop_daemon
start_daemon "${ARGS[@]}" || finish
expect_channels "after restart" "speed status trace"

note "reload: the file is the truth again, also after a restart"
ctl reload 0 reload
expect_channels "after reload" "speed status"
state_check "after reload" '
  d["bound"] == []
  d["unbound"] == []'
stop_daemon
start_daemon "${ARGS[@]}" || finish
expect_channels "after reload and restart" "speed status"
stop_daemon

# corrupt NAME CONTENT EXPECTED_ERROR: cosmicd names the file and the problem, keeps the file aside
# unchanged (issue 22, item 10), starts from its configuration, keeps running, and writes a good
# file at the next change.
corrupt() {
  local name=$1 content=$2 expected=$3
  note "state file: $name"
  printf '%s' "$content" >"$STATE"
  start_daemon "${ARGS[@]}" || return
  log_contains "$STATE: $expected"
  log_contains "starting from the configuration alone"
  # The unusable file is kept aside, unchanged, so no later save can overwrite what it holds.
  local aside
  aside=$(find "$(dirname "$STATE")" -name "$(basename "$STATE").corrupt-*" | head -1)
  { [ -n "$aside" ] && cmp -s "$aside" <(printf '%s' "$content"); } ||
    fail "$name: the unusable state file was not kept aside unchanged"
  log_contains "kept aside as $aside"
  rm -f "$aside"
  grep -F "$STATE: $expected" "$DAEMON_LOG" | grep -q " error " ||
    fail "$name: the state file problem is not logged at level error"
  expect_channels "$name" "speed status"
  ctl "status_$name" 0 status
  contains "status_$name" out "channels: 2 bound"
  stop_daemon
  # The next change replaces the bad file with a good one.
  start_daemon "${ARGS[@]}" || return
  ctl "bind_after_$name" 0 bind "$WORK/plot.yaml"
  state_check "$name, then bind" '
    d["version"] == 1
    [b["name"] for b in d["bound"]] == ["plot"]'
  ctl "unbind_after_$name" 0 unbind plot
  stop_daemon
}

corrupt garbage $'\x00\x01garbage\xff{{{' "not a JSON object (corrupted state file)"
corrupt truncated '{"version": 1, "bound": [{"name": "plot", "ya' "not a JSON object (corrupted state file)"
corrupt empty '' "not a JSON object (corrupted state file)"
corrupt array '[1, 2, 3]' "not a JSON object (corrupted state file)"
corrupt version '{"version": 99, "bound": [], "unbound": []}' "unsupported state version (expected 1)"
corrupt no_version '{"bound": [], "unbound": []}' "unsupported state version (expected 1)"
corrupt malformed '{"version": 1, "bound": "plot", "unbound": []}' "malformed state file"
corrupt wrong_type '{"version": 1, "bound": [{"name": 7, "yaml": "x"}], "unbound": []}' "malformed state file"

note "a recorded binding that cannot be bound now (its segment is gone or failed at boot): kept for the next start"
cat >"$STATE" <<'EOF'
{"version": 1,
 "bound": [{"name": "ghost", "yaml": "{name: ghost, subject: 0x99, class: nrt, period: 1s, payload: 8B, publishers: [gone], subscribers: [lan]}"},
           {"name": "plot", "yaml": "{name: plot, subject: 0x000000090000a010, class: nrt, period: 200ms, omission_degree: 5, payload: 16B, publishers: [viz], subscribers: [lan]}"}],
 "unbound": ["no_such_channel"]}
EOF
start_daemon "${ARGS[@]}" || finish
log_contains "runtime binding of channel ghost could not be restored ("
log_contains "kept in the state file for the next start"
log_contains "restored runtime binding of channel plot"
expect_channels "stale binding" "plot speed status"
ctl unbind_after_ghost 0 unbind speed  # a later change rewrites the file: ghost stays in it
state_check "ghost kept" '[b["name"] for b in d["bound"]] == ["ghost", "plot"]'
stop_daemon

note "an entry whose name differs from the channel it defines: refused, never bound"
cat >"$STATE" <<'EOF'
{"version": 1,
 "bound": [{"name": "alias", "yaml": "{name: plot, subject: 0x000000090000a010, class: nrt, period: 200ms, omission_degree: 5, payload: 16B, publishers: [viz], subscribers: [lan]}"}],
 "unbound": []}
EOF
start_daemon "${ARGS[@]}" || finish
log_contains "entry 'alias' defines channel(s) plot instead of exactly the channel it is named after; entry dropped"
expect_channels "misnamed entry" "speed status"
ctl unbind_after_alias 0 unbind speed
state_check "misnamed entry dropped" 'd["bound"] == []'
stop_daemon

note "a state file that is a FIFO: refused at once, cosmicd starts from its configuration"
rm -f "$STATE"
mkfifo "$STATE"
start_daemon "${ARGS[@]}" || finish
log_contains "not a regular file; refusing to read it"
expect_channels "FIFO state" "speed status"
stop_daemon
rm -f "$STATE"

note "a state file cosmicd cannot write: the change is made, the answer says it was not saved"
rm -rf "$WORK/state"
echo "not a directory" >"$WORK/state"  # the state directory cannot be created
start_daemon "${ARGS[@]}" || finish
ctl bind_unwritable 1 bind "$WORK/plot.yaml"
contains bind_unwritable err "will not survive a restart"
log_contains "cannot save runtime bindings: create a temporary file beside $STATE"
expect_channels "unwritable state" "plot speed status"
stop_daemon
rm -f "$WORK/state"

finish
