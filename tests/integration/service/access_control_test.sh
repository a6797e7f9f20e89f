#!/usr/bin/env bash
# Access control of cosmicd's control socket with real unprivileged users (issue 5, item 3):
# the socket is 0660, group = the read group, in a 0750 directory; a user in no group is turned
# away; a member of the read group reads but may not bind, unbind or reload, and a refused bind
# changes nothing; a member of the admin group binds; the binding survives a restart; every
# mutating command leaves an audit line in cosmicd's log.
#
# The runtime directory is prepared as systemd's RuntimeDirectory= does for the unit (owned by
# the service's group, 0750); socket_directory_test.sh covers a directory cosmicd makes itself.
#
# Usage (as root, through scripts/netns-run): access_control_test.sh COSMICD COSMICCTL
set -u
COSMICD=${1:?path to cosmicd}
COSMICCTL=${2:?path to cosmicctl}
DOMAIN=71
LCM_PORT=7771
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"
in_netns_or_skip

WORK=$(mktemp -d /tmp/cosmic-svc-access.XXXXXX)
chmod 0755 "$WORK"  # the test users must reach $WORK/run/cosmicd
cleanup() {
  kill_daemon
  remove_accounts
  [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

make_accounts
note "accounts: read group $READ_GROUP, admin group $ADMIN_GROUP, users $OTHER (none), $READER (read), $ADMIN (read+admin)"
OTHER_UID=$(id -u "$OTHER")
READER_UID=$(id -u "$READER")
ADMIN_UID=$(id -u "$ADMIN")

SOCKET=$WORK/run/cosmicd/control.sock
STATE=$WORK/state/bindings.json
write_config "$WORK/cosmicd.yaml" "$SOCKET"
write_extra "$WORK/plot.yaml" plot 0x000000090000A010
chmod 0644 "$WORK/plot.yaml"
install -d -m 0755 "$WORK/run"
install -d -m 0750 -o root -g "$READ_GROUP" "$WORK/run/cosmicd"  # as RuntimeDirectory= would
DAEMON_ARGS=(--config "$WORK/cosmicd.yaml" --state-file "$STATE" --read-group "$READ_GROUP" --admin-group "$ADMIN_GROUP")

start_daemon "${DAEMON_ARGS[@]}" || finish
FIRST_LOG=$DAEMON_LOG

note "socket and directory modes"
got=$(mode_owner "$SOCKET")
[ "$got" = "660 root $READ_GROUP" ] || fail "socket is '$got', expected '660 root $READ_GROUP'"
got=$(mode_owner "$WORK/run/cosmicd")
[ "$got" = "750 root $READ_GROUP" ] || fail "runtime directory is '$got', expected '750 root $READ_GROUP'"
expect_channels "at start" "speed status"

note "a user in no group: turned away with a clear error"
# The directory and the socket's mode stop them at connect() (EACCES): cosmicctl names the
# socket and the reason, exit 77 (no permission).
for command in status channels; do
  ctl "other_$command" 77 as "$OTHER" "$command"
  contains "other_$command" err "cannot reach cosmicd at $SOCKET: Permission denied"
done
ctl other_bind 77 as "$OTHER" bind "$WORK/plot.yaml"
contains other_bind err "Permission denied"

note "a process that carries the read group but whose user is not in it: refused by SO_PEERCRED"
# The file mode lets it connect; cosmicd decides from the user database, not from the client's
# supplementary groups.
ctl_raw carried_status 77 setpriv --reuid "$OTHER" --regid "$(id -g "$OTHER")" --groups "$(getent group "$READ_GROUP" | cut -d: -f3)" \
  "$COSMICCTL" --socket "$SOCKET" status
contains carried_status err "uid $OTHER_UID may not read gateway state"
ctl_raw carried_status_json 77 setpriv --reuid "$OTHER" --regid "$(id -g "$OTHER")" --groups "$(getent group "$READ_GROUP" | cut -d: -f3)" \
  "$COSMICCTL" --socket "$SOCKET" --json status
json_check "$WORK/carried_status_json.out" '
  d["ok"] is False
  d["error"]["code"] == "permission_denied"'
log_matches "denied #[0-9]+: uid $OTHER_UID pid [0-9]+ may not run status"

note "a member of the read group: reads, may not change anything"
ctl reader_status 0 as "$READER" status
contains reader_status out "svc-test"
contains reader_status out "segments: 2/2 up"
ctl reader_channels 0 as "$READER" channels
contains reader_channels out "speed"
ctl reader_segments 0 as "$READER" segments
ctl reader_channel 0 as "$READER" channel speed
ctl reader_bind 77 as "$READER" bind "$WORK/plot.yaml"
contains reader_bind err "uid $READER_UID may not change the gateway (bind)"
ctl reader_bind_json 77 as "$READER" --json bind "$WORK/plot.yaml"
json_check "$WORK/reader_bind_json.out" '
  d["ok"] is False
  d["error"]["code"] == "permission_denied"'
ctl reader_unbind 77 as "$READER" unbind speed
contains reader_unbind err "may not change the gateway (unbind)"
ctl reader_reload 77 as "$READER" reload
contains reader_reload err "may not change the gateway (reload)"
expect_channels "after the reader's refused bind/unbind/reload" "speed status"
[ -e "$STATE" ] && fail "a refused bind wrote the state file $STATE"
log_matches "denied #[0-9]+: uid $READER_UID pid [0-9]+ may not run bind"
log_matches "denied #[0-9]+: uid $READER_UID pid [0-9]+ may not run unbind"
log_matches "denied #[0-9]+: uid $READER_UID pid [0-9]+ may not run reload"
! grep -qE "audit #[0-9]+: uid $READER_UID " "$DAEMON_LOG" || fail "a refused reader was audited as if it ran a command"

note "a member of the admin group: binds"
ctl admin_bind 0 as "$ADMIN" bind "$WORK/plot.yaml"
contains admin_bind out "plot"
contains admin_bind out "bound"
expect_channels "after the admin's bind" "plot speed status"
ctl reader_sees_plot 0 as "$READER" channel plot
log_matches "audit #[0-9]+: uid $ADMIN_UID pid "
grep -qE "audit #[0-9]+: uid $ADMIN_UID pid [0-9]+ runs bind" "$DAEMON_LOG" || fail "no audit line for the admin's bind"
[ -s "$STATE" ] || fail "the admin's bind did not write $STATE"

note "restart with the same state file: the binding is still there"
stop_daemon
start_daemon "${DAEMON_ARGS[@]}" || finish
expect_channels "after the restart" "plot speed status"
log_contains "restored runtime binding of channel plot"
ctl reader_after_restart 0 as "$READER" channel plot
contains reader_after_restart out "bound"
got=$(mode_owner "$SOCKET")
[ "$got" = "660 root $READ_GROUP" ] || fail "socket after restart is '$got', expected '660 root $READ_GROUP'"

note "unbind and reload by the admin: audited"
ctl admin_unbind 0 as "$ADMIN" unbind plot
contains admin_unbind out "unbound plot"
grep -qE "audit #[0-9]+: uid $ADMIN_UID pid [0-9]+ runs unbind plot" "$DAEMON_LOG" || fail "no audit line for the admin's unbind"
ctl admin_reload 0 as "$ADMIN" reload
contains admin_reload out "reloaded"
grep -qE "audit #[0-9]+: uid $ADMIN_UID pid [0-9]+ runs reload" "$DAEMON_LOG" || fail "no audit line for the admin's reload"
expect_channels "after unbind and reload" "speed status"
ctl root_status 0 status
n=$(grep -cE "audit #[0-9]+: " "$FIRST_LOG" "$DAEMON_LOG" | awk -F: '{s += $2} END {print s}')
[ "$n" -eq 3 ] || fail "expected 3 audit lines (bind, unbind, reload), found $n"

stop_daemon
[ -e "$SOCKET" ] && fail "cosmicd left its socket $SOCKET behind"
finish
